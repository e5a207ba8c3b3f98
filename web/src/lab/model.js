// The sampler lab's state, pure: its reducer, its part of the URL, the requests it sends to the
// core (warp test, points, analysis, discrepancy curve, integration with given points) and the
// words it shows for the core's answers. No DOM, no workers: web/test/lab_model.test.mjs runs
// it under Node. The numbers are the core's; nothing here computes a statistic.

/** The samplers of mcp_points and their randomizations (src/core/qmc.h); "default" sends none
 *  (the core's default: Owen for Sobol' and Halton, a random shift for lattices). */
export const SAMPLERS = Object.freeze(['uniform', 'stratified', 'latin_hypercube', 'sobol', 'halton', 'lattice']);
export const QMC_SAMPLERS = Object.freeze(['sobol', 'halton', 'lattice']);
/** The renderer's per-pixel samplers (mcp_render_pixel_points, the render core): one pixel's
 *  samples, n = spp, dim 2, 4, 6 or 8; sampler names as the CLI's (mcplay points pixel_sobol). */
export const PIXEL_SAMPLERS = Object.freeze(['pixel_independent', 'pixel_stratified', 'pixel_sobol', 'pixel_padded_sobol']);
/** Every sampler of the point-set view (the discrepancy curve takes SAMPLERS only). */
export const POINT_SAMPLERS = Object.freeze([...SAMPLERS, ...PIXEL_SAMPLERS]);
export const isPixelSampler = (name) => PIXEL_SAMPLERS.includes(name);
export const RANDOMIZATIONS = Object.freeze(['default', 'none', 'owen', 'lms_shift', 'digital_shift', 'permutation', 'random_shift']);
export const DOMAIN_TYPES = Object.freeze(['disk', 'interval', 'box', 'triangle', 'sphere', 'hemisphere']);
export const NAMED_WARPS = Object.freeze(['uniform', 'polar_disk', 'concentric_disk', 'uniform_sphere',
  'uniform_hemisphere', 'cosine_hemisphere', 'triangle', 'tabulated_1d', 'tabulated_2d', 'ggx_visible_normals',
  'spherical_triangle']);
/**
 * The parameters of each named warp (docs/scene-format.md, "Warps"), in the order the form
 * shows them: [key, kind, default as the docs give it]. Kinds: 'number', 'whole', 'vector' (a
 * JSON array of numbers), 'matrix' (a JSON array of arrays), 'expr' (an expression text).
 */
export const NAMED_WARP_PARAMS = Object.freeze({
  uniform: [['lower', 'vector', '[0, 0]'], ['upper', 'vector', '[1, 1]']],
  polar_disk: [['center', 'vector', '[0, 0]'], ['radius', 'number', '1']],
  concentric_disk: [['center', 'vector', '[0, 0]'], ['radius', 'number', '1']],
  uniform_sphere: [],
  uniform_hemisphere: [],
  cosine_hemisphere: [],
  triangle: [['vertices', 'matrix', '[[0, 0], [1, 0], [0, 1]]']],
  tabulated_1d: [['lower', 'vector', '[0]'], ['upper', 'vector', '[1]'], ['values', 'vector', 'or f below'], ['f', 'expr', 'in x'], ['bins', 'whole', '64']],
  tabulated_2d: [['lower', 'vector', '[0, 0]'], ['upper', 'vector', '[1, 1]'], ['values', 'matrix', 'ny rows of nx, or f below'], ['nx', 'whole', '16'], ['ny', 'whole', '16'], ['f', 'expr', 'in x, y']],
  ggx_visible_normals: [['alpha', 'number', '0.5, in [0.001, 10]'], ['wo', 'vector', '[0.6, 0, 0.8]']],
  spherical_triangle: [['a', 'vector', 'corner [x, y, z]'], ['b', 'vector', 'corner [x, y, z]'], ['c', 'vector', 'corner [x, y, z]'], ['viewpoint', 'vector', '[0, 0, 0]']],
});
/** Every parameter key of any named warp (the state keeps one text per key). */
export const WARP_PARAM_KEYS = Object.freeze([...new Set(Object.values(NAMED_WARP_PARAMS).flat().map(([k]) => k))]);

/** Samples of a warp test offered by the page (the core's default is 10^6; 10^5 is quicker). */
export const WARP_SAMPLES = Object.freeze([10000, 100000, 1000000]);
export const LAB_LIMITS = Object.freeze({ nMax: 2 ** 20, dimMax: 64, curveNMax: 65536, repsMax: 64, fileBytes: 64 * 1024 * 1024 });

/** Warps the page carries itself, so the lab has examples before any warp_*.json scene. */
export const BUILTIN_WARPS = Object.freeze([
  {
    name: 'polar_disk_wrong',
    label: 'polar disk, r = u₁ (wrong: crowds the centre)',
    look: 'r = u₁ crowds the centre but claims the uniform density 1/π: the test fails, the residual map is red in the first column (small |x|², the centre) and blue towards the rim, and the verdict says where the mass is wrong.',
    scene: { name: 'polar_disk_wrong', warp: { domain: { type: 'disk', radius: 1 }, g: ['u1*cos(2*pi*u2)', 'u1*sin(2*pi*u2)'], p: '1/pi' } },
  },
  {
    name: 'polar_disk_right',
    label: 'polar disk, r = √u₁ (uniform)',
    look: 'The fix, r = √u₁: uniform on the disk; the test passes and the residual map is pale noise.',
    scene: { name: 'polar_disk_right', warp: { domain: { type: 'disk', radius: 1 }, g: ['sqrt(u1)*cos(2*pi*u2)', 'sqrt(u1)*sin(2*pi*u2)'], p: '1/pi' } },
  },
  { name: 'concentric_disk', label: 'concentric disk (Shirley–Chiu, named)', look: 'The core\'s named concentric map: uniform on the disk, so the test passes.', scene: { name: 'concentric_disk', warp: 'concentric_disk' } },
]);

/** The value of the example select that stands for the typed warp. */
export const TYPED = 'typed';

const NAME_RE = /^[A-Za-z0-9_.-]{1,100}$/;

export function initialLab() {
  return {
    view: 'study', // 'study' | 'lab': which of the page's two views is shown
    tab: 'warp',   // 'warp' | 'points'
    examples: BUILTIN_WARPS.map((w) => ({ name: w.name, label: w.label, look: w.look, builtin: true, hasIntegrand: false })),
    warp: {
      example: BUILTIN_WARPS[0].name,
      typed: { domain: 'disk', params: '"radius": 1', g1: 'sqrt(u1)*cos(2*pi*u2)', g2: 'sqrt(u1)*sin(2*pi*u2)', g3: '', p: '1/pi', named: '', wp: {} },
      samples: 100000,
      seed: '1',
      status: 'idle', // idle | running | done | error
      result: null,
      message: '',
      id: 0,
    },
    points: {
      source: 'sampler', // 'sampler' | 'file'
      sampler: 'sobol',
      randomization: 'default',
      n: '1024',
      dim: '2',
      seed: '1',
      sets: '1',
      axes: [0, 1],
      file: null, // {name, request} or null
      fileError: '',
      status: 'idle',
      analysis: null,
      shownRows: [], // the rows the scatter shows (not in the URL)
      message: '',
      id: 0,
      problem: '', // a scene of the manifest (integration with the points, the curve's error)
      integrate: { status: 'idle', result: null, message: '', id: 0 },
    },
    curve: {
      samplers: ['uniform', 'stratified', 'sobol', 'halton'],
      dim: '2',
      n_min: '16',
      n_max: '4096',
      reps: '8',
      seed: '1',
      status: 'idle',
      result: null,
      message: '',
      id: 0,
    },
  };
}

/** A whole number from a text in [lo, hi], or null. */
export function whole(text, lo, hi) {
  const t = String(text ?? '').trim();
  if (!/^\d{1,16}$/.test(t)) return null;
  const v = Number(t);
  return Number.isSafeInteger(v) && v >= lo && v <= hi ? v : null;
}

// ---------------------------------------------------------------------------------------------
// Reducer

export function labReducer(state, action) {
  const p = action.payload || {};
  switch (action.type) {
    case 'lab/view':
      return p.view === 'lab' || p.view === 'study' ? { ...state, view: p.view } : state;
    case 'lab/tab':
      return p.tab === 'warp' || p.tab === 'points' ? { ...state, tab: p.tab } : state;
    case 'lab/examples': {
      // {entries: manifest entries with a warp}: added after the built-in ones
      const more = (p.entries || []).filter((e) => e && NAME_RE.test(e.name))
        .map((e) => ({ name: e.name, label: e.description ? `${e.name}: ${e.description}` : e.name, file: e.file, builtin: false,
          hasIntegrand: Boolean(e.hasIntegrand), look: typeof e.look === 'string' ? e.look : '' }));
      // The page's own examples stand in until the site brings warp scenes.
      const examples = more.length ? more : state.examples.filter((e) => e.builtin);
      const known = state.warp.example === TYPED || examples.some((e) => e.name === state.warp.example);
      return { ...state, examples, warp: known ? state.warp : { ...state.warp, example: examples[0].name } };
    }
    case 'lab/warp/edit':
      if (p.field === 'example' || p.field === 'samples' || p.field === 'seed') {
        const value = p.field === 'samples' ? Number(p.value) : String(p.value);
        if (p.field === 'samples' && !WARP_SAMPLES.includes(value)) return state;
        return { ...state, warp: { ...state.warp, [p.field]: value } };
      }
      if (p.field === 'wp' && WARP_PARAM_KEYS.includes(p.key)) {
        const wp = { ...state.warp.typed.wp };
        if (String(p.value ?? '') === '') delete wp[p.key];
        else wp[p.key] = String(p.value);
        return { ...state, warp: { ...state.warp, typed: { ...state.warp.typed, wp } } };
      }
      if (p.field !== 'wp' && Object.prototype.hasOwnProperty.call(state.warp.typed, p.field)) {
        return { ...state, warp: { ...state.warp, typed: { ...state.warp.typed, [p.field]: String(p.value) } } };
      }
      return state;
    case 'lab/warp/start':
      return { ...state, warp: { ...state.warp, status: 'running', id: p.id, message: '' } };
    case 'lab/warp/done':
      if (p.id !== state.warp.id) return state;
      return { ...state, warp: { ...state.warp, status: 'done', result: p.result, message: '' } };
    case 'lab/warp/error':
      if (p.id !== undefined && p.id !== state.warp.id) return state;
      return { ...state, warp: { ...state.warp, status: 'error', result: null, message: p.message } };
    case 'lab/points/edit': {
      const pts = state.points;
      if (p.field === 'axes') {
        const axes = Array.isArray(p.value) ? p.value.map(Number) : pts.axes;
        return { ...state, points: { ...pts, axes } };
      }
      if (p.field === 'sampler' && !POINT_SAMPLERS.includes(String(p.value))) return state;
      if (['source', 'sampler', 'randomization', 'n', 'dim', 'seed', 'sets', 'problem'].includes(p.field)) {
        return { ...state, points: { ...pts, [p.field]: String(p.value) } };
      }
      return state;
    }
    case 'lab/points/file':
      // {name, request} or {name, error}: what fileRequest made of the chosen file
      return {
        ...state,
        points: {
          ...state.points, source: 'file', file: p.error ? null : { name: p.name, request: p.request }, fileError: p.error || '',
          ...(p.error ? { status: 'error', analysis: null, message: p.error } : {}),
        },
      };
    case 'lab/points/start':
      return { ...state, points: { ...state.points, status: 'running', id: p.id, message: '' } };
    case 'lab/points/done':
      if (p.id !== state.points.id) return state;
      return { ...state, points: { ...state.points, status: 'done', analysis: p.analysis, shownRows: p.rows || [], message: '', fileError: '' } };
    case 'lab/points/error':
      if (p.id !== undefined && p.id !== state.points.id) return state;
      return { ...state, points: { ...state.points, status: 'error', analysis: null, shownRows: [], message: p.message } };
    case 'lab/integrate/start':
      return { ...state, points: { ...state.points, integrate: { status: 'running', result: null, message: '', id: p.id } } };
    case 'lab/integrate/done':
      if (p.id !== state.points.integrate.id) return state;
      return { ...state, points: { ...state.points, integrate: { ...state.points.integrate, status: 'done', result: p.result } } };
    case 'lab/integrate/error':
      if (p.id !== state.points.integrate.id) return state;
      return { ...state, points: { ...state.points, integrate: { ...state.points.integrate, status: 'error', message: p.message } } };
    case 'lab/curve/edit': {
      const c = state.curve;
      if (p.field === 'sampler') {
        const set = new Set(c.samplers);
        if (p.checked) set.add(p.value);
        else set.delete(p.value);
        return { ...state, curve: { ...c, samplers: SAMPLERS.filter((s) => set.has(s)) } };
      }
      if (['dim', 'n_min', 'n_max', 'reps', 'seed'].includes(p.field)) return { ...state, curve: { ...c, [p.field]: String(p.value) } };
      return state;
    }
    case 'lab/curve/start':
      return { ...state, curve: { ...state.curve, status: 'running', id: p.id, message: '' } };
    case 'lab/curve/done':
      if (p.id !== state.curve.id) return state;
      return { ...state, curve: { ...state.curve, status: 'done', result: p.result, message: '' } };
    case 'lab/curve/error':
      if (p.id !== undefined && p.id !== state.curve.id) return state;
      return { ...state, curve: { ...state.curve, status: 'error', result: null, message: p.message } };
    default:
      return state;
  }
}

// ---------------------------------------------------------------------------------------------
// URL: the lab's inputs (not its results), so that a view can be linked. Keys start with the
// part they belong to; the study's keys (state.js) are not touched.

const enc = (v) => encodeURIComponent(v).replace(/%2C/g, ',').replace(/%2F/g, '/');

/** The lab's query string ('?view=lab&lab=points&...'), or '' when the study is shown. */
export function labToQuery(lab) {
  if (lab.view !== 'lab') return '';
  const parts = [];
  const add = (k, v) => { if (v !== null && v !== undefined && v !== '') parts.push(`${k}=${enc(String(v))}`); };
  add('view', 'lab');
  add('lab', lab.tab);
  if (lab.tab === 'warp') {
    const w = lab.warp;
    add('warp', w.example);
    if (w.example === TYPED) {
      const t = w.typed;
      if (t.named) {
        add('named', t.named);
        for (const [k] of NAMED_WARP_PARAMS[t.named] || []) add(`wp.${k}`, t.wp[k]);
      } else {
        add('domain', t.domain);
        add('params', t.params);
        add('g1', t.g1);
        add('g2', t.g2);
        add('g3', t.g3);
        add('pdf', t.p);
      }
    }
    add('samples', w.samples);
    add('seed', w.seed);
  } else {
    const pt = lab.points;
    add('sampler', pt.sampler);
    if (QMC_SAMPLERS.includes(pt.sampler) && pt.randomization !== 'default') add('rand', pt.randomization);
    add('n', pt.n);
    add('dim', pt.dim);
    add('seed', pt.seed);
    if (pt.sets !== '1' && !isPixelSampler(pt.sampler)) add('sets', pt.sets);
    if (pt.axes[0] !== 0 || pt.axes[1] !== 1) add('axes', pt.axes.join(','));
    add('problem', pt.problem);
    const c = lab.curve;
    add('curve', c.samplers.join(','));
    add('cdim', c.dim);
    add('cn', `${c.n_min},${c.n_max}`);
    add('creps', c.reps);
  }
  return `?${parts.join('&')}`;
}

/** The lab's state from a query string: every value malformed or out of range keeps its default. */
export function queryToLab(search, base = initialLab()) {
  let q;
  try {
    q = new URLSearchParams(typeof search === 'string' ? search : '');
  } catch {
    return base;
  }
  if (q.get('view') !== 'lab') return base;
  const out = { ...base, view: 'lab', warp: { ...base.warp, typed: { ...base.warp.typed } }, points: { ...base.points }, curve: { ...base.curve } };
  const tab = q.get('lab');
  if (tab === 'warp' || tab === 'points') out.tab = tab;
  const text = (k, max = 2000) => {
    const v = q.get(k);
    return v !== null && v.length <= max && !v.includes('\0') ? v : null;
  };
  const num = (k, lo, hi) => {
    const v = q.get(k);
    return v !== null && whole(v, lo, hi) !== null ? String(whole(v, lo, hi)) : null;
  };
  // warp
  const ex = text('warp', 100);
  if (ex !== null && (ex === TYPED || NAME_RE.test(ex))) out.warp.example = ex;
  const named = text('named', 100);
  if (named !== null && NAME_RE.test(named)) out.warp.typed.named = named;
  const wp = {};
  for (const k of WARP_PARAM_KEYS) {
    const v = text(`wp.${k}`, 20000);
    if (v !== null && v !== '') wp[k] = v;
  }
  out.warp.typed.wp = wp;
  const dom = text('domain', 20);
  if (dom !== null && DOMAIN_TYPES.includes(dom)) out.warp.typed.domain = dom;
  for (const [k, field] of [['params', 'params'], ['g1', 'g1'], ['g2', 'g2'], ['g3', 'g3'], ['pdf', 'p']]) {
    const v = text(k);
    if (v !== null) out.warp.typed[field] = v;
  }
  if (out.warp.example === TYPED && (q.has('g1') || q.has('pdf')) && !q.has('named')) out.warp.typed.named = '';
  const samples = Number(q.get('samples'));
  if (WARP_SAMPLES.includes(samples)) out.warp.samples = samples;
  const seed = num('seed', 0, Number.MAX_SAFE_INTEGER);
  if (seed !== null) out.warp.seed = seed;
  // points
  const sampler = q.get('sampler');
  if (POINT_SAMPLERS.includes(sampler)) out.points.sampler = sampler;
  const rand = q.get('rand');
  if (RANDOMIZATIONS.includes(rand)) out.points.randomization = rand;
  const n = num('n', 1, LAB_LIMITS.nMax);
  if (n !== null) out.points.n = n;
  const dim = num('dim', 1, LAB_LIMITS.dimMax);
  if (dim !== null) out.points.dim = dim;
  if (seed !== null) out.points.seed = seed;
  const sets = num('sets', 1, 1024);
  if (sets !== null) out.points.sets = sets;
  const axes = (q.get('axes') || '').split(',').map((a) => whole(a, 0, LAB_LIMITS.dimMax - 1));
  if (axes.length === 2 && axes.every((a) => a !== null) && axes[0] !== axes[1]) out.points.axes = axes;
  const problem = text('problem', 100);
  if (problem !== null && NAME_RE.test(problem)) out.points.problem = problem;
  const curve = q.get('curve');
  if (curve !== null) {
    const names = curve.split(',').filter((s) => SAMPLERS.includes(s));
    if (names.length) out.curve.samplers = SAMPLERS.filter((s) => names.includes(s));
  }
  const cdim = num('cdim', 1, LAB_LIMITS.dimMax);
  if (cdim !== null) out.curve.dim = cdim;
  const cn = (q.get('cn') || '').split(',').map((v) => whole(v, 1, LAB_LIMITS.curveNMax));
  if (cn.length === 2 && cn[0] !== null && cn[1] !== null && cn[0] <= cn[1]) {
    out.curve.n_min = String(cn[0]);
    out.curve.n_max = String(cn[1]);
  }
  const creps = num('creps', 1, LAB_LIMITS.repsMax);
  if (creps !== null) out.curve.reps = creps;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Requests

/**
 * The domain object of the typed warp: its type and the parameters typed as JSON members
 * ('"radius": 1, "center": [0, 0]', braces optional). Returns {domain} or {error}.
 */
export function typedDomain(type, params) {
  if (!DOMAIN_TYPES.includes(type)) return { error: `unknown domain type '${type}' (expected ${DOMAIN_TYPES.join(', ')})` };
  const t = String(params ?? '').trim();
  let extra = {};
  if (t) {
    try {
      extra = JSON.parse(t.startsWith('{') ? t : `{${t}}`);
    } catch (e) {
      return { error: `domain parameters: not JSON members such as "radius": 1 (${e.message})` };
    }
    if (extra === null || typeof extra !== 'object' || Array.isArray(extra)) return { error: 'domain parameters: expected members such as "radius": 1' };
    if ('type' in extra) return { error: 'domain parameters: the type is chosen in the list' };
  }
  return { domain: { type, ...extra } };
}

/**
 * One parameter of a named warp from its text: a number ('number', 'whole'), a JSON array
 * ('vector', 'matrix'; the outer brackets may be left out: "0.6, 0, 0.8") or the text itself
 * ('expr'). Returns {value} or {error}; what the value must be (range, length) is the core's to say.
 */
export function warpParam(key, kind, text, example = kind === 'matrix' ? '[[0, 0], [1, 0], [0, 1]]' : '[0.6, 0, 0.8]') {
  const t = String(text ?? '').trim();
  if (kind === 'expr') return { value: t };
  if (kind === 'number' || kind === 'whole') {
    const v = Number(t);
    if (!t || !Number.isFinite(v)) return { error: `${key}: '${t}' is not a number` };
    return { value: v };
  }
  try {
    const v = JSON.parse(t.startsWith('[') ? t : `[${t}]`);
    if (Array.isArray(v)) return { value: v };
  } catch {
    // said below
  }
  return { error: `${key}: '${t}' is not a list of numbers such as ${example}` };
}

/** A named warp with the parameters typed for it (only those of its name that are filled in):
 *  {warp: name} when none is, {warp: {name, ...params}} otherwise; or {error}. */
export function namedWarp(name, wp = {}) {
  const warp = { name };
  for (const [key, kind, dflt] of NAMED_WARP_PARAMS[name] || []) {
    if (wp[key] === undefined || String(wp[key]).trim() === '') continue;
    const p = warpParam(key, kind, wp[key], dflt.startsWith('[') ? dflt : undefined);
    if (p.error) return p;
    warp[key] = p.value;
  }
  return { warp: Object.keys(warp).length > 1 ? warp : name };
}

/** The scene of the typed warp: a named warp, or the domain, g (1 to 3 expressions) and p.
 *  Returns {scene} or {error}. */
export function typedWarpScene(typed) {
  if (typed.named) {
    if (!NAME_RE.test(typed.named)) return { error: `'${typed.named}' is not a warp name` };
    const made = namedWarp(typed.named, typed.wp);
    return made.error ? made : { scene: { name: typed.named, warp: made.warp } };
  }
  const d = typedDomain(typed.domain, typed.params);
  if (d.error) return d;
  const g = [typed.g1, typed.g2, typed.g3].map((s) => String(s ?? '').trim());
  while (g.length && !g[g.length - 1]) g.pop();
  if (!g.length) return { error: 'type g: one expression in u1 (and u2, u3) per coordinate of the domain' };
  if (g.includes('')) return { error: `g${g.indexOf('') + 1} is empty` };
  const p = String(typed.p ?? '').trim();
  if (!p) return { error: 'type p, the density the warp claims, in x, y, z' };
  // one coordinate (an interval): g is a single expression, as in the scene files
  return { scene: { name: 'typed_warp', warp: { domain: d.domain, g: g.length === 1 ? g[0] : g, p } } };
}

/** The lab opens on a running example: true when the warp test's view is first shown with the
 *  examples in and the core loaded, and no test has run yet (a link's chosen example or typed
 *  warp is the one run). `ready`: {examples, core} loaded. */
export function opensOnExample(lab, ready) {
  return lab.view === 'lab' && lab.tab === 'warp' && Boolean(ready.examples && ready.core) &&
    lab.warp.status === 'idle' && !lab.warp.result;
}

/** The options of a warp test from the lab's state: {options} or {error}. */
export function warpOptions(warp) {
  const seed = whole(warp.seed, 0, Number.MAX_SAFE_INTEGER);
  if (seed === null) return { error: 'seed must be a whole number' };
  return { options: { samples: warp.samples, seed } };
}

/** True when a scene has an integrand (f or integrand) besides its warp: its study can be opened. */
export function hasIntegrand(scene) {
  return Boolean(scene && typeof scene === 'object' && (scene.f !== undefined || scene.integrand !== undefined));
}

/** The sampler part of a request ({sampler, n, dim, seed, randomization?, sets?}) or {error}. */
export function samplerRequest(pts) {
  const n = whole(pts.n, 1, LAB_LIMITS.nMax);
  if (n === null) return { error: `n must be a whole number in 1..${LAB_LIMITS.nMax}` };
  const dim = whole(pts.dim, 1, LAB_LIMITS.dimMax);
  if (dim === null) return { error: `dim must be a whole number in 1..${LAB_LIMITS.dimMax}` };
  const seed = whole(pts.seed, 0, Number.MAX_SAFE_INTEGER);
  if (seed === null) return { error: 'seed must be a whole number' };
  const sets = whole(pts.sets, 1, 1024);
  if (sets === null) return { error: 'sets must be a whole number in 1..1024' };
  const sampler = { sampler: pts.sampler, n, dim, seed };
  if (QMC_SAMPLERS.includes(pts.sampler) && pts.randomization !== 'default') sampler.randomization = pts.randomization;
  if (sets > 1) sampler.sets = sets;
  return { sampler };
}

/**
 * A chosen file as the request's point source: a .json file's rows ({points}, parsed here only
 * to pass them on: the core checks them), anything else as CSV text ({csv}). Returns
 * {request} or {error} (a file too large, or JSON that does not parse).
 */
export function fileRequest(name, text, bytes = text.length) {
  if (bytes > LAB_LIMITS.fileBytes) return { error: `${name}: ${bytes} bytes, more than the limit of ${LAB_LIMITS.fileBytes}` };
  if (/\.json$/i.test(name)) {
    try {
      return { request: { points: JSON.parse(text) } };
    } catch (e) {
      return { error: `${name}: not valid JSON (${e.message})` };
    }
  }
  return { request: { csv: text } };
}

/** The request of a renderer's pixel sampler (mcp_render_pixel_points): {pixel_sampler, spp =
 *  n, dim, seed}, one pixel of a 1 x 1 image; or {error}. The core checks spp (a power of two for
 *  sobol) and dim (2, 4, 6 or 8) and says what is wrong. */
export function pixelRequest(pts) {
  if (!isPixelSampler(pts.sampler)) return { error: `'${pts.sampler}' is not one of the renderer's pixel samplers` };
  const spp = whole(pts.n, 1, LAB_LIMITS.nMax);
  if (spp === null) return { error: `n (the pixel's spp) must be a whole number in 1..${LAB_LIMITS.nMax}` };
  const dim = whole(pts.dim, 1, LAB_LIMITS.dimMax);
  if (dim === null) return { error: `dim must be a whole number in 1..${LAB_LIMITS.dimMax}` };
  const seed = whole(pts.seed, 0, Number.MAX_SAFE_INTEGER);
  if (seed === null) return { error: 'seed must be a whole number' };
  return { pixel: { pixel_sampler: pts.sampler.slice('pixel_'.length), spp, dim, seed } };
}

/** The point source of an analysis or an integration: the file's, or the sampler's; for a
 *  renderer's pixel sampler {pixel: request}, whose rows the caller fetches first (pixelPoints)
 *  and sends as {points: rows}. */
export function pointSource(pts) {
  if (pts.source === 'file') {
    if (!pts.file) return { error: pts.fileError || 'choose a file of points (CSV or JSON)' };
    return { source: pts.file.request };
  }
  if (isPixelSampler(pts.sampler)) return pixelRequest(pts);
  const s = samplerRequest(pts);
  return s.error ? s : { source: { sampler: s.sampler } };
}

/** The analysis request: the source, the spectrum of the chosen axes (when the points have two
 *  coordinates or more; the core checks them against the points). */
export function analyzeRequest(pts, rows = null) {
  const s = pointSource(pts);
  if (s.error) return s;
  if (s.pixel && !rows) return { error: 'the pixel\'s points are needed first (pixelPoints)' };
  const source = s.pixel ? { points: rows } : s.source;
  return { request: { ...source, spectrum: { axes: pts.axes.slice(), size: 256 } } };
}

/** The discrepancy curve's request ({samplers, dim, n_min, n_max, reps, seed, scene?}) or {error}. */
export function curveRequest(curve, problemScene = null) {
  if (!curve.samplers.length) return { error: 'choose at least one sampler' };
  const dim = whole(curve.dim, 1, LAB_LIMITS.dimMax);
  if (dim === null) return { error: `dim must be a whole number in 1..${LAB_LIMITS.dimMax}` };
  const nMin = whole(curve.n_min, 1, LAB_LIMITS.curveNMax);
  const nMax = whole(curve.n_max, 1, LAB_LIMITS.curveNMax);
  if (nMin === null || nMax === null || nMin > nMax) return { error: `N must run over 1 <= n_min <= n_max <= ${LAB_LIMITS.curveNMax}` };
  const reps = whole(curve.reps, 1, LAB_LIMITS.repsMax);
  if (reps === null) return { error: `reps must be a whole number in 1..${LAB_LIMITS.repsMax}` };
  const seed = whole(curve.seed, 0, Number.MAX_SAFE_INTEGER);
  if (seed === null) return { error: 'seed must be a whole number' };
  const request = { samplers: curve.samplers.slice(), dim, n_min: nMin, n_max: nMax, reps, seed };
  if (problemScene) request.scene = problemScene;
  return { request };
}

/** The problems offered for the points (integration, the curve's error): the integral scenes of
 *  the manifest whose dimension is known, each with it. */
export function problemChoices(scenes) {
  return (scenes || []).filter((s) => s && s.kind !== 'render' && s.kind !== 'warp' && Number.isInteger(s.dimension))
    .map((s) => ({ name: s.name, dimension: s.dimension }));
}

// ---------------------------------------------------------------------------------------------
// Words for the core's answers

/** The verdict of a warp test in plain words: the core's own verdict, led by passed / failed. */
export function verdictText(result) {
  if (!result) return '';
  // the core's verdict starts with its own word for the outcome: said once, ours
  const v = typeof result.verdict === 'string' ? result.verdict.replace(/^(passed|rejected|failed|accepted|could not verify)\s*:\s*/i, '') : '';
  if (result.passed === true) return v ? `Passed: ${v}` : 'Passed: the samples agree with the density.';
  if (result.passed === false) return v ? `Failed: ${v}` : 'Failed: the samples do not follow the density.';
  // the third outcome: the core's quadrature could not settle the expected counts
  if (result.outcome === 'unverified') return v ? `Could not verify: ${v}` : 'Could not verify the warp.';
  return v;
}

/** A number for the tables: 4 significant digits, exponent when far from 1; '–' for null. */
export function num(v, digits = 4) {
  if (v === null || v === undefined) return '–';
  if (typeof v !== 'number') return String(v);
  if (!Number.isFinite(v)) return String(v);
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e-3 && a < 1e6) return String(Number(v.toPrecision(digits)));
  return v.toExponential(digits - 1);
}

/** The facts of a warp test as [label, value] rows (what the core returned, in that order). */
export function warpFacts(r) {
  if (!r) return [];
  const rows = [];
  const add = (label, v) => { if (v !== undefined) rows.push([label, v]); };
  if (r.warp !== undefined) add('warp', `${r.warp}${r.domain ? ` on the ${r.domain}` : ''}`);
  if (r.pdf_integral !== undefined) {
    add('∫ p over the domain (should be 1)', `${num(r.pdf_integral, 8)}${r.pdf_integral_error !== undefined ? ` ± ${num(r.pdf_integral_error, 2)}` : ''}` +
      (r.pdf_integral_ok === false ? (r.outcome === 'unverified' ? ' (the quadrature could not settle it)' : ' (not 1: p is not a density)') : ''));
  }
  if (r.statistic !== undefined) add('chi-square statistic', num(r.statistic, 6));
  if (r.dof !== undefined) add('degrees of freedom', String(r.dof));
  if (r.cells !== undefined) add('cells in the statistic', String(r.cells));
  if (r.pooled_bins !== undefined) add('bins pooled (expected < 5)', String(r.pooled_bins));
  if (r.zero_bins_hit) add('samples where p = 0', String(r.zero_bins_hit));
  if (r.p_value !== undefined) add('p-value', num(r.p_value, 4));
  if (r.significance !== undefined) add('significance', num(r.significance, 4));
  if (r.tests !== undefined) add('tests (Šidák)', String(r.tests));
  const level = r.sidak_level ?? r.level ?? r.threshold;
  if (level !== undefined) add('Šidák level (reject below)', num(level, 4));
  if (r.samples !== undefined) add('samples', `${r.samples}${r.seed !== undefined ? `, seed ${r.seed}` : ''}`);
  return rows;
}

const MEASURES = Object.freeze([
  ['l2_star_discrepancy', 'L2-star discrepancy (Warnock)', 'l2_star_discrepancy'],
  ['centered_l2_discrepancy', 'centred L2 discrepancy (Hickernell)', 'centered_l2_discrepancy'],
  ['wraparound_l2_discrepancy', 'wrap-around L2 discrepancy', 'wraparound_l2_discrepancy'],
  ['min_distance', 'minimum distance', 'min_distance'],
  ['min_distance_toroidal', 'minimum distance on the torus', 'min_distance_toroidal'],
]);

/** The measures of an analysis as rows {key, label, value, iid, skipped}: the value (mean over
 *  the sets), the root mean square of N independent points when the core gives it, and why a
 *  measure was skipped, in the core's words. */
export function measureRows(a) {
  if (!a) return [];
  const iid = a.expected_iid || {};
  const skipped = a.skipped || {};
  return MEASURES.map(([key, label, iidKey]) => ({
    key,
    label,
    value: a[key] ?? null,
    iid: iid[iidKey] ?? null,
    skipped: skipped[key] || '',
  }));
}

/** What an integration with given points says: one set is a deterministic rule (its error
 *  against the exact value, no error bar); K sets give the t interval. */
export function integrateText(r) {
  if (!r) return '';
  const parts = [`${r.problem}: estimate ${num(r.estimate, 8)} from ${r.sets} set${r.sets === 1 ? '' : 's'} of ${r.n} points`];
  if (r.exact !== null && r.exact !== undefined) parts.push(`exact ${num(r.exact, 8)}, error ${num(r.error, 3)}`);
  if (r.error_bar) {
    const e = r.error_bar;
    parts.push(`95% t interval ± ${num(e.half_width_95, 3)} (standard error ${num(e.standard_error, 3)}, ${e.degrees_of_freedom} degrees of freedom: ${e.method})`);
  } else {
    parts.push('a deterministic rule: error against the exact value, no error bar');
  }
  return parts.join('; ');
}

/** The skipped parts of an analysis in words, one line each ('spectrum: not asked for ...'). */
export function skippedLines(a) {
  return a && a.skipped ? Object.entries(a.skipped).map(([k, why]) => `${k.replace(/_/g, ' ')}: ${why}`) : [];
}

/**
 * The rows of the first point set of a request, for the scatter only (the core has read and
 * checked the same text): JSON rows (or the first of K sets), or the CSV's lines of numbers
 * (a header and '#' lines skipped; a "set" column dropped, only the first set's rows kept).
 * At most `max` rows.
 */
export function displayRows(request, max = 65536) {
  if (!request) return [];
  if (Array.isArray(request.points)) {
    const p = request.points;
    const rows = Array.isArray(p[0]) && Array.isArray(p[0][0]) ? p[0] : p;
    return rows.slice(0, max);
  }
  if (typeof request.csv !== 'string') return [];
  const out = [];
  let setColumn = -1;
  let firstSet = null;
  let seen = false; // a line of the file read (the first may be a header)
  for (const line of request.csv.split(/\r?\n/)) {
    const t = line.trim();
    if (!t || t.startsWith('#')) continue;
    const fields = t.split(/[,;\t ]+/);
    const first = !seen;
    seen = true;
    if (first && fields.some((f) => !Number.isFinite(Number(f)))) {
      setColumn = fields.findIndex((f) => f.toLowerCase() === 'set');
      continue;
    }
    if (setColumn >= 0) {
      const set = fields[setColumn];
      if (firstSet === null) firstSet = set;
      if (set !== firstSet) continue;
      fields.splice(setColumn, 1);
    }
    out.push(fields.map(Number));
    if (out.length >= max) break;
  }
  return out;
}

/** A structured-cloneable summary of the lab for window.mcplayDebug.lab() (tests): its inputs
 *  and statuses, the warp result, the analysis without the spectrum's grid. */
export function labSnapshot(lab) {
  const a = lab.points.analysis;
  const analysis = a ? { ...a, spectrum: a.spectrum ? { size: a.spectrum.size, axes: a.spectrum.axes, radial: a.spectrum.radial } : null } : null;
  return {
    view: lab.view,
    tab: lab.tab,
    query: labToQuery(lab),
    examples: lab.examples.map((e) => e.name),
    warp: { example: lab.warp.example, status: lab.warp.status, message: lab.warp.message, result: lab.warp.result },
    points: { source: lab.points.source, status: lab.points.status, message: lab.points.message, fileError: lab.points.fileError,
      file: lab.points.file ? lab.points.file.name : null, rows: lab.points.shownRows.length, analysis,
      integrate: { status: lab.points.integrate.status, message: lab.points.integrate.message, result: lab.points.integrate.result } },
    curve: { status: lab.curve.status, message: lab.curve.message, result: lab.curve.result },
  };
}
