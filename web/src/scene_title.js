// A scene's readable title from its identifier (scene files have a name and a long description,
// no title): "stiff_peak_1e-8" -> "Stiff peak 1e-8", "genz_gaussian_32d" -> "Genz Gaussian 32D".
// The page shows the title and keeps the identifier beside it (what the CLI takes). Pure: no
// DOM (web/test/scene_title.test.mjs).

// Words written otherwise than in lower case: proper names and abbreviations.
const WORDS = Object.freeze({
  genz: 'Genz',
  gaussian: 'Gaussian',
  cornell: 'Cornell',
  veach: 'Veach',
  walsh: 'Walsh',
  sobol: 'Sobol\'',
  halton: 'Halton',
  latin: 'Latin',
  mis: 'MIS',
  ris: 'RIS',
  is: 'IS',
  vegas: 'VEGAS',
  miser: 'MISER',
  qmc: 'QMC',
  gltf: 'glTF',
  cos2: 'cos²',
});

/** One word of an identifier as the title writes it. */
function word(w) {
  const lower = w.toLowerCase();
  if (Object.prototype.hasOwnProperty.call(WORDS, lower)) return WORDS[lower];
  if (/^\d+d$/.test(lower)) return `${lower.slice(0, -1)}D`; // 32d -> 32D
  return w;
}

/**
 * The readable title of a scene identifier: words split at '_' (and '-' between letters),
 * proper names and abbreviations written as such (Genz, MIS, VEGAS), a dimension "32d" as
 * "32D", numbers kept as written (1e-8, 0.3), the first letter upper case. An empty or
 * non-string name gives ''.
 */
export function sceneTitle(name) {
  if (typeof name !== 'string') return '';
  const words = name.trim().split(/_+|(?<=[A-Za-z])-(?=[A-Za-z])|\s+/).filter(Boolean).map(word);
  if (!words.length) return '';
  const first = words[0];
  words[0] = /^[a-z]/.test(first) ? first[0].toUpperCase() + first.slice(1) : first;
  return words.join(' ');
}

/**
 * How the scene list names a scene: its title, and its kind or dimension in brackets
 * ("Stiff peak 1e-8 (1D)", "Cornell box (render)"), the dimension left out when the title
 * already ends with it ("Genz Gaussian 32D").
 */
export function sceneOptionLabel(entry) {
  const title = sceneTitle(entry && entry.name) || String((entry && entry.name) || '');
  if (entry && entry.kind === 'render') return `${title} (render)`;
  const dim = entry && entry.dimension !== undefined && entry.dimension !== null ? `${entry.dimension}D` : '?D';
  return title.endsWith(` ${dim}`) ? title : `${title} (${dim})`;
}
