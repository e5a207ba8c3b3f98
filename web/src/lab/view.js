// The sampler lab's view: its controls dispatch actions to the lab's store (model.js), sync()
// writes the state back into them, render() draws the core's answers (draw.js, charts.js).
// Also the page's two tabs (the study and the lab), keyboard-operable as WAI-ARIA tabs.
import { el } from '../dom.js';
import {
  SAMPLERS, QMC_SAMPLERS, PIXEL_SAMPLERS, RANDOMIZATIONS, DOMAIN_TYPES, NAMED_WARPS, NAMED_WARP_PARAMS, TYPED, isPixelSampler,
  measureRows, skippedLines,
  verdictText, warpFacts, integrateText, num, displayRows, problemChoices,
} from './model.js';
import { heatGrid, sequentialColor, residualColor, RESIDUAL_SCALE, residuals, sharedMax, mapCounts } from './colors.js';
import { drawHeat, drawColorBar, drawSpectrum, drawScatter } from './draw.js';
import { renderCurve, renderRadial, renderDensity1d } from './charts.js';
import { colorAt } from '../palette.js';

const $ = (id) => document.getElementById(id);

function option(value, text) {
  const o = document.createElement('option');
  o.value = value;
  o.textContent = text;
  return o;
}

function optgroup(label, options) {
  const g = document.createElement('optgroup');
  g.label = label;
  g.append(...options);
  return g;
}

/** What some named warps' parameters are, beside their names (docs/scene-format.md, "Warps"). */
const PARAM_HINTS = Object.freeze({
  lower: 'corner', upper: 'corner', values: 'the table', f: 'to tabulate', nx: 'columns', ny: 'rows',
  alpha: 'roughness', wo: 'view direction', a: 'corner', b: 'corner', c: 'corner',
});

/** Tabs: click or arrow keys / Home / End select; `onSelect(id)` is told the tab chosen. */
function tablist(list, onSelect) {
  const tabs = [...list.querySelectorAll('[role=tab]')];
  list.addEventListener('click', (e) => {
    const t = e.target.closest('[role=tab]');
    if (t) onSelect(t.id);
  });
  list.addEventListener('keydown', (e) => {
    const i = tabs.indexOf(document.activeElement);
    if (i < 0) return;
    let j = null;
    if (e.key === 'ArrowRight' || e.key === 'ArrowDown') j = (i + 1) % tabs.length;
    else if (e.key === 'ArrowLeft' || e.key === 'ArrowUp') j = (i - 1 + tabs.length) % tabs.length;
    else if (e.key === 'Home') j = 0;
    else if (e.key === 'End') j = tabs.length - 1;
    if (j === null) return;
    e.preventDefault();
    tabs[j].focus();
    onSelect(tabs[j].id);
  });
}

function selectTab(ids, chosen) {
  for (const id of ids) {
    const t = $(id);
    const on = id === chosen;
    t.setAttribute('aria-selected', String(on));
    t.tabIndex = on ? 0 : -1;
    $(t.getAttribute('aria-controls')).hidden = !on;
  }
}

/** Wires the lab's controls to `store` (the lab's store); `hooks.openStudy(sceneName)` opens a
 *  warp scene's study in the other view. */
export function mountLab(store, hooks = {}) {
  const { dispatch } = store;
  tablist(document.querySelector('.views [role=tablist]'), (id) => dispatch({ type: 'lab/view', payload: { view: id === 'tab-lab' ? 'lab' : 'study' } }));
  tablist(document.querySelector('.lab-tabs'), (id) => dispatch({ type: 'lab/tab', payload: { tab: id === 'lab-tab-points' ? 'points' : 'warp' } }));

  // Warp test
  $('warp-domain').replaceChildren(...DOMAIN_TYPES.map((d) => option(d, d)));
  $('warp-named').replaceChildren(option('', 'none: the expressions below'), ...NAMED_WARPS.map((n) => option(n, n)));
  const warpEdit = (field) => (e) => dispatch({ type: 'lab/warp/edit', payload: { field, value: e.target.value } });
  $('warp-example').addEventListener('change', warpEdit('example'));
  $('warp-samples').addEventListener('change', warpEdit('samples'));
  $('warp-seed').addEventListener('input', warpEdit('seed'));
  for (const [id, field] of [['warp-named', 'named'], ['warp-domain', 'domain'], ['warp-params', 'params'], ['warp-g1', 'g1'],
    ['warp-g2', 'g2'], ['warp-g3', 'g3'], ['warp-p', 'p']]) {
    $(id).addEventListener(id === 'warp-named' || id === 'warp-domain' ? 'change' : 'input', warpEdit(field));
  }
  // Enter in a field of the typed warp tests that warp (not the example chosen above)
  $('warp-typed').addEventListener('keydown', (e) => {
    if (e.key !== 'Enter' || e.target.tagName !== 'INPUT') return;
    e.preventDefault();
    $('warp-use-typed').click();
  });
  $('warp-use-typed').addEventListener('click', () => {
    dispatch({ type: 'lab/warp/edit', payload: { field: 'example', value: TYPED } });
    dispatch({ type: 'lab/warp/request' });
  });
  $('warp-form').addEventListener('submit', (e) => {
    e.preventDefault();
    dispatch({ type: 'lab/warp/request' });
  });
  $('warp-study').addEventListener('click', () => {
    if (hooks.openStudy) hooks.openStudy(store.getState().warp.example);
  });

  // Point sets
  $('points-sampler').replaceChildren(
    optgroup('the integration samplers', SAMPLERS.map((s) => option(s, s))),
    optgroup('the renderer\'s per-pixel samplers (n = spp)', PIXEL_SAMPLERS.map((s) => option(s, `${s.replace('pixel_', '')} (renderer, one pixel)`))),
  );
  $('points-randomization').replaceChildren(...RANDOMIZATIONS.map((r) => option(r, r === 'default' ? 'the sampler\'s default' : r)));
  const pointsEdit = (field) => (e) => dispatch({ type: 'lab/points/edit', payload: { field, value: e.target.value } });
  for (const [id, field] of [['points-sampler', 'sampler'], ['points-randomization', 'randomization']]) $(id).addEventListener('change', pointsEdit(field));
  for (const [id, field] of [['points-n', 'n'], ['points-dim', 'dim'], ['points-seed', 'seed'], ['points-sets', 'sets']]) {
    $(id).addEventListener('input', pointsEdit(field));
    // choosing sampler settings means the sampler is the source
    $(id).addEventListener('focus', () => dispatch({ type: 'lab/points/edit', payload: { field: 'source', value: 'sampler' } }));
  }
  for (const r of document.querySelectorAll('input[name=points-source]')) r.addEventListener('change', pointsEdit('source'));
  const axes = () => [Number($('points-axis-a').value), Number($('points-axis-b').value)];
  $('points-axis-a').addEventListener('change', () => dispatch({ type: 'lab/points/edit', payload: { field: 'axes', value: axes() } }));
  $('points-axis-b').addEventListener('change', () => dispatch({ type: 'lab/points/edit', payload: { field: 'axes', value: axes() } }));
  $('points-file').addEventListener('change', (e) => {
    const file = e.target.files && e.target.files[0];
    if (file) dispatch({ type: 'lab/points/open', payload: { file } });
    e.target.value = ''; // the same file may be chosen again
  });
  $('points-form').addEventListener('submit', (e) => {
    e.preventDefault();
    dispatch({ type: 'lab/points/request' });
  });
  $('points-problem').addEventListener('change', (e) => {
    const opt = e.target.selectedOptions[0];
    dispatch({ type: 'lab/points/edit', payload: { field: 'problem', value: e.target.value } });
    if (opt && opt.dataset.dimension) dispatch({ type: 'lab/curve/edit', payload: { field: 'dim', value: opt.dataset.dimension } });
  });
  $('points-integrate').addEventListener('click', () => dispatch({ type: 'lab/integrate/request' }));

  // Discrepancy curve
  $('curve-samplers').replaceChildren(...SAMPLERS.map((s, i) => {
    const box = el('input', { type: 'checkbox', id: `curve-s-${s}` });
    box.dataset.sampler = s;
    box.addEventListener('change', () => dispatch({ type: 'lab/curve/edit', payload: { field: 'sampler', value: s, checked: box.checked } }));
    return el('label', { htmlFor: box.id }, box, el('span', { className: 'swatch', style: `background:${colorAt(i)}` }), s);
  }));
  for (const [id, field] of [['curve-dim', 'dim'], ['curve-n-min', 'n_min'], ['curve-n-max', 'n_max'], ['curve-reps', 'reps']]) {
    $(id).addEventListener('input', (e) => dispatch({ type: 'lab/curve/edit', payload: { field, value: e.target.value } }));
  }
  $('curve-form').addEventListener('submit', (e) => {
    e.preventDefault();
    dispatch({ type: 'lab/curve/request' });
  });
}

// An input shows the state's value unless the reader is typing in it.
function setValue(id, value) {
  const e = $(id);
  if (document.activeElement !== e && e.value !== String(value)) e.value = String(value);
}

let examplesSig = null;
let namedSig = null;

/** The fields of the chosen named warp's parameters (rebuilt when the name changes). */
function namedParamFields(name, dispatch) {
  const params = NAMED_WARP_PARAMS[name] || [];
  if (!name) return [];
  if (!params.length) return [el('p', { className: 'small muted wide' }, `${name} takes no parameters.`)];
  return params.flatMap(([key, kind, dflt]) => {
    const input = el('input', { id: `warp-np-${key}`, type: 'text', spellcheck: false, autocomplete: 'off',
      className: kind === 'number' || kind === 'whole' ? '' : 'mono', placeholder: dflt });
    input.dataset.param = key;
    input.addEventListener('input', () => dispatch({ type: 'lab/warp/edit', payload: { field: 'wp', key, value: input.value } }));
    return [el('label', { htmlFor: input.id }, key, PARAM_HINTS[key] ? el('span', { className: 'muted' }, ` (${PARAM_HINTS[key]})`) : null), input];
  });
}
let problemsSig = null;
let axesSig = null;

/** Writes the lab's state into its controls; `scenes` is the manifest (the problems offered). */
export function syncLab(lab, scenes, dispatch = null) {
  const inLab = lab.view === 'lab';
  selectTab(['tab-study', 'tab-lab'], inLab ? 'tab-lab' : 'tab-study');
  $('intro').hidden = inLab;
  if (!inLab) return;
  selectTab(['lab-tab-warp', 'lab-tab-points'], lab.tab === 'points' ? 'lab-tab-points' : 'lab-tab-warp');

  const w = lab.warp;
  const sig = JSON.stringify(lab.examples.map((e) => [e.name, e.label]));
  if (sig !== examplesSig) {
    examplesSig = sig;
    $('warp-example').replaceChildren(...lab.examples.map((e) => option(e.name, e.label)), option(TYPED, 'the warp typed below'));
  }
  setValue('warp-example', w.example);
  if (w.example === TYPED && !$('warp-typed').open) $('warp-typed').open = true;
  setValue('warp-samples', w.samples);
  setValue('warp-seed', w.seed);
  for (const [id, field] of [['warp-named', 'named'], ['warp-domain', 'domain'], ['warp-params', 'params'], ['warp-g1', 'g1'],
    ['warp-g2', 'g2'], ['warp-g3', 'g3'], ['warp-p', 'p']]) setValue(id, w.typed[field]);
  for (const id of ['warp-domain', 'warp-params', 'warp-g1', 'warp-g2', 'warp-g3', 'warp-p']) $(id).disabled = Boolean(w.typed.named);
  if (dispatch && namedSig !== w.typed.named) {
    namedSig = w.typed.named;
    $('warp-named-params').replaceChildren(...namedParamFields(w.typed.named, dispatch));
  }
  $('warp-named-params').hidden = !w.typed.named;
  $('warp-expr-fields').hidden = Boolean(w.typed.named);
  for (const input of $('warp-named-params').querySelectorAll('input')) setValue(input.id, w.typed.wp[input.dataset.param] ?? '');
  $('warp-run').disabled = w.status === 'running';
  $('warp-status').textContent = w.status === 'running' ? 'testing…' : w.status === 'done' ? 'done' : '';
  const ex = lab.examples.find((e) => e.name === w.example);
  $('warp-study').hidden = !(ex && ex.hasIntegrand);
  const look = w.example !== TYPED && ex && ex.look ? ex.look : '';
  $('warp-look').hidden = !look;
  $('warp-look-text').textContent = look;

  const pt = lab.points;
  for (const r of document.querySelectorAll('input[name=points-source]')) r.checked = r.value === pt.source;
  setValue('points-sampler', pt.sampler);
  setValue('points-randomization', pt.randomization);
  $('points-randomization').disabled = !QMC_SAMPLERS.includes(pt.sampler);
  const pixel = isPixelSampler(pt.sampler);
  $('points-sets').disabled = pixel;
  $('points-pixel-note').hidden = !pixel;
  $('points-n').previousElementSibling.textContent = pixel ? 'points n (spp)' : 'points n';
  setValue('points-n', pt.n);
  setValue('points-dim', pt.dim);
  setValue('points-seed', pt.seed);
  setValue('points-sets', pt.sets);
  $('points-file-name').textContent = pt.file ? `file: ${pt.file.name}${pt.source === 'file' ? '' : ' (choose “your file” to use it)'}` : '';
  const dim = pt.source === 'file' ? (pt.analysis ? pt.analysis.dim : 2) : Math.max(1, Number(pt.dim) || 1);
  const aSig = JSON.stringify([dim]);
  if (aSig !== axesSig) {
    axesSig = aSig;
    const opts = () => Array.from({ length: Math.min(64, dim) }, (_, k) => option(String(k), `x${k + 1}`));
    $('points-axis-a').replaceChildren(...opts());
    $('points-axis-b').replaceChildren(...opts());
  }
  setValue('points-axis-a', pt.axes[0]);
  setValue('points-axis-b', pt.axes[1]);
  $('points-run').disabled = pt.status === 'running';
  $('points-status').textContent = pt.status === 'running' ? 'analysing…' : pt.status === 'done' ? 'done' : '';
  const problems = problemChoices(scenes);
  const pSig = JSON.stringify(problems);
  if (pSig !== problemsSig) {
    problemsSig = pSig;
    $('points-problem').replaceChildren(option('', 'none'), ...problems.map((p) => {
      const o = option(p.name, `${p.name} (${p.dimension}D)`);
      o.dataset.dimension = String(p.dimension);
      return o;
    }));
  }
  setValue('points-problem', pt.problem);
  $('points-integrate').disabled = !pt.problem || pt.integrate.status === 'running';

  const c = lab.curve;
  for (const box of document.querySelectorAll('#curve-samplers input')) box.checked = c.samplers.includes(box.dataset.sampler);
  setValue('curve-dim', c.dim);
  setValue('curve-n-min', c.n_min);
  setValue('curve-n-max', c.n_max);
  setValue('curve-reps', c.reps);
  $('curve-run').disabled = c.status === 'running';
  $('curve-status').textContent = c.status === 'running' ? 'computing…' : c.status === 'done' ? 'done' : '';
}

let drawn = { warp: null, points: null, curve: null, integrate: null, tab: null };

/** Draws the core's answers (only what changed since the last call). */
export function renderLab(lab) {
  if (lab.view !== 'lab') return;
  const tabChanged = drawn.tab !== lab.tab;
  drawn.tab = lab.tab;
  if (lab.tab === 'warp') {
    $('warp-error').textContent = lab.warp.status === 'error' ? lab.warp.message : '';
    if (drawn.warp !== lab.warp.result || tabChanged) {
      drawn.warp = lab.warp.result;
      renderWarp(lab.warp.result);
    }
    return;
  }
  const pt = lab.points;
  $('points-error').textContent = pt.status === 'error' ? pt.message : '';
  if (drawn.points !== pt.analysis || tabChanged) {
    drawn.points = pt.analysis;
    renderPoints(pt);
  }
  $('points-integrate-out').textContent = pt.integrate.status === 'done' ? integrateText(pt.integrate.result)
    : pt.integrate.status === 'running' ? 'integrating…' : '';
  $('points-integrate-error').textContent = pt.integrate.status === 'error' ? pt.integrate.message : '';
  $('curve-error').textContent = lab.curve.status === 'error' ? lab.curve.message : '';
  if (drawn.curve !== lab.curve.result || tabChanged) {
    drawn.curve = lab.curve.result;
    renderCurve($('curve-plot'), lab.curve.result);
    $('curve-legend').replaceChildren(...(lab.curve.result ? lab.curve.result.curves.map((cv) => el('li', {},
      el('span', { className: 'swatch', style: `background:${colorAt(Math.max(0, SAMPLERS.indexOf(cv.sampler === 'independent' ? 'uniform' : cv.sampler)))}` }),
      el('span', { className: 'name' }, cv.sampler))) : []));
    if (lab.curve.result && lab.curve.result.problem) {
      $('curve-legend').append(el('li', { className: 'ref' }, `dashed: RMS error of ${lab.curve.result.problem} (exact ${num(lab.curve.result.exact, 8)})`));
    }
  }
}

/** The test rejected the warp (not passed, and not "could not verify"). */
const failed = (r) => r.outcome ? r.outcome === 'failed' : r.passed === false;

function renderWarp(r) {
  const maps = $('warp-maps');
  const oneD = r && Array.isArray(r.bins) && r.bins.length === 1;
  $('warp-verdict').textContent = r ? verdictText(r) : '';
  $('warp-verdict').className = `lab-verdict${r ? (r.passed === true ? ' pass' : r.passed === false ? ' fail' : ' unverified') : ''}`;
  maps.hidden = !r || oneD;
  $('warp-scales').hidden = !r || oneD;
  $('warp-1d').hidden = !oneD;
  renderDensity1d($('warp-1d'), oneD ? r : null, oneD && r.coordinates ? r.coordinates[0] : 'x');
  const facts = $('warp-facts');
  const worst = $('warp-worst');
  facts.hidden = !r;
  // the bins farthest from the density say something only when the samples do not follow it
  worst.hidden = !r || !failed(r) || !Array.isArray(r.worst_bins) || !r.worst_bins.length;
  $('warp-axes').textContent = oneD ? `Samples per bin over ${r.coordinates ? r.coordinates[0] : 'the coordinate'} (${r.bins[0]} bins of equal measure): orange, observed; dashed black, expected from p.` : '';
  if (!r) return;
  facts.tBodies[0].replaceChildren(...warpFacts(r).map(([k, v]) => el('tr', {}, el('th', { scope: 'row' }, k), el('td', {}, v))));
  const coords = Array.isArray(r.coordinates) ? r.coordinates : [];
  if (!worst.hidden) {
    worst.tHead.replaceChildren(el('tr', {}, ...coords.map((c) => el('th', { scope: 'col' }, c)),
      el('th', { scope: 'col' }, 'observed'), el('th', { scope: 'col' }, 'expected'), el('th', { scope: 'col' }, '(o − e)/√e')));
    worst.tBodies[0].replaceChildren(...r.worst_bins.map((b) => el('tr', {},
      ...coords.map((_, k) => el('td', {}, b.range && b.range[k] ? `[${num(b.range[k][0])}, ${num(b.range[k][1])})` : '–')),
      el('td', {}, num(b.observed, 6)), el('td', {}, num(b.expected, 6)),
      el('td', {}, b.residual === null && b.expected === 0 ? '∞ (p = 0 there)' : num(b.residual, 3)))));
  }
  if (oneD || !Array.isArray(r.bins) || !Array.isArray(r.observed)) return;
  const m = mapCounts(r);
  const top = sharedMax(m.observed, m.expected) || 1;
  const countColor = (v) => sequentialColor(v / top);
  const res = residuals(m);
  const scale = RESIDUAL_SCALE;
  drawHeat($('warp-observed'), heatGrid(m.observed, m.bins), countColor);
  drawHeat($('warp-expected'), heatGrid(m.expected, m.bins), countColor);
  drawHeat($('warp-residual'), heatGrid(res, m.bins), residualColor);
  drawColorBar($('warp-count-bar'), (v) => sequentialColor(v / top), 0, top, 160);
  drawColorBar($('warp-residual-bar'), residualColor, -scale, scale, 160);
  $('warp-count-text').textContent = `samples per bin: 0 (left) to ${num(top, 4)} (right), the same scale for observed and expected`;
  $('warp-residual-text').textContent = `residual on a fixed scale: −${scale} and below (full blue) · 0 (white) · +${scale} and above (full red); ` +
    'noise, |r| ≤ 2, stays pale; grey: no expected samples';
  const [cx, cy] = coords;
  $('warp-axes').textContent = `Horizontal: ${cx ?? 'first coordinate'} (${r.bins[0]} bins), vertical: ${cy ?? 'second coordinate'} (${r.bins[1]} bins), growing up.` +
    (m.summed ? ` Summed over ${coords[2] ?? 'the third coordinate'} (${r.bins[2]} bins): the maps show the marginal counts.` : '');
  for (const id of ['warp-observed', 'warp-expected', 'warp-residual']) {
    $(id).setAttribute('aria-description', `${r.bins[0]} by ${r.bins[1]} bins over ${coords.join(' and ')}`);
  }
}

function renderPoints(pt) {
  const a = pt.analysis;
  const table = $('points-measures');
  table.hidden = !a;
  const scatter = $('points-scatter');
  const spectrum = $('points-spectrum');
  if (!a) {
    scatter.getContext('2d').clearRect(0, 0, scatter.width, scatter.height);
    spectrum.getContext('2d').clearRect(0, 0, spectrum.width, spectrum.height);
    renderRadial($('points-radial'), null);
    $('points-skipped').replaceChildren();
    return;
  }
  table.tBodies[0].replaceChildren(...measureRows(a).map((m) => el('tr', { dataset: { measure: m.key } },
    el('th', { scope: 'row' }, m.label),
    el('td', {}, m.value === null ? (m.skipped ? 'skipped' : '–') : num(m.value, 4)),
    el('td', {}, m.iid === null ? '–' : num(m.iid, 4)))));
  $('points-skipped').replaceChildren(...skippedLines(a).map((line) => el('li', {}, `skipped: ${line}`)));
  const rows = pt.shownRows || [];
  const [ax, ay] = a.spectrum ? a.spectrum.axes : pt.axes;
  if (rows.length && a.dim >= 2) drawScatter(scatter, rows, ax, ay >= 0 ? ay : 1);
  else if (rows.length) drawScatter(scatter, rows.map((r) => [r[0], 0.5]), 0, 1);
  scatter.setAttribute('aria-label', `${rows.length} points, coordinates x${ax + 1} and x${(ay >= 0 ? ay : 1) + 1}`);
  $('points-scatter-title').textContent = `The points${a.sets > 1 ? ' (first set)' : ''}: x${ax + 1} across, x${(ay >= 0 ? ay : 1) + 1} up`;
  if (a.spectrum) {
    drawSpectrum(spectrum, a.spectrum.power, a.spectrum.size);
    spectrum.setAttribute('aria-label', `power spectrum on a ${a.spectrum.size} by ${a.spectrum.size} frequency grid`);
    spectrum.dataset.drawn = 'true';
  }
  renderRadial($('points-radial'), a.spectrum || null);
}

export { displayRows };
