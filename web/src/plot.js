// Renders the state into the four uPlot charts and their legends: variance (or MSE) against N,
// error against time per estimate, the z-score histogram and the coverage against N. A pure
// render of the state: it reads state.run and writes only into the plot containers and legends.
// A chart is rebuilt when its set of series changes and otherwise gets setData.
// Before uPlot: it keeps uPlot's pixel-ratio listeners (exports at 2x).
import { devicePixelRatioNow, withPixelRatio } from './pixel_ratio.js';
import uPlot from '../vendor/uPlot.esm.js';
import {
  varianceSeries, anchorOf, referenceLines, timeSeries, calibrationSeries, coverageSeries, equalTimeVerdict,
  CLOCK_STEPS_FITTED, runningEstimate, replayIsEstimator, conservativeErrorBars, severityOf, SEVERITIES,
  decadeRange, fitText, fmt, curveOverlay, misWeightCurves, weightBins, weightHistogram, domainView, mapFor, mappedGrid,
} from './series.js';
import { colorAt, withAlpha } from './palette.js';
import { keptFor } from './state.js';
import { el } from './dom.js';

const FONT = '12px "DejaVu Sans", system-ui, sans-serif';
const LABEL_FONT = 'bold 12px "DejaVu Sans", system-ui, sans-serif';
const AXIS = { stroke: '#1b1f24', font: FONT, labelFont: LABEL_FONT, grid: { stroke: '#e3e7eb', width: 1 }, ticks: { stroke: '#b8c0c8', width: 1 } };
const SUPERSCRIPT = { '-': '⁻', 0: '⁰', 1: '¹', 2: '²', 3: '³', 4: '⁴', 5: '⁵', 6: '⁶', 7: '⁷', 8: '⁸', 9: '⁹' };

const charts = {};   // key -> {u, sig, el, xRange, yRange, legendSig}
let dom = null;

function sup(n) {
  return String(n).split('').map((c) => SUPERSCRIPT[c] ?? c).join('');
}

/** 10^k as "10⁻³" (1 and 10 plainly); other values get no label (log-paper minor ticks). */
function decadeLabel(v) {
  if (typeof v !== 'number' || !(v > 0)) return '';
  const k = Math.round(Math.log10(v));
  if (Math.abs(v / 10 ** k - 1) > 1e-9) return '';
  if (k === 0) return '1';
  if (k === 1) return '10';
  return `10${sup(k)}`;
}

/** N ticks (powers of two): plain up to 65536, then 2^k; thinned to what fits. */
function nTicks(u, splits) {
  const width = u.bbox.width / (uPlot.pxRatio || 1);
  const shown = splits.filter((v) => typeof v === 'number' && v > 0);
  const last = Math.round(Math.log2(shown[shown.length - 1] || 1));
  // One notation per axis: plain numbers while the largest fits in 6 digits, else 2^k for all.
  const powers = 2 ** last > 999999;
  // Labels on every `every`-th split (counted from the last), as many as fit side by side
  // (about 8.5 px a character of the axis font, and a gap).
  const need = (powers ? 3 : String(2 ** last).length) * 8.5 + 10;
  const step = width / Math.max(1, shown.length - 1);
  let every = 1;
  while (every * step < need && every < shown.length) every *= 2;
  let i = shown.length;
  return splits.map((v) => {
    if (typeof v !== 'number' || !(v > 0)) return '';
    i -= 1; // this split's position counted from the last
    const k = Math.round(Math.log2(v));
    if (Math.abs(v - 2 ** k) > 1e-6 * v || i % every !== 0) return '';
    return powers ? `2${sup(k)}` : String(v);
  });
}

function plotSize(el) {
  const width = Math.max(280, Math.floor(el.clientWidth || 480));
  const height = Math.round(Math.min(380, Math.max(240, width * 0.58)));
  return { width, height };
}

function empty(el, text) {
  el.replaceChildren();
  const d = document.createElement('div');
  d.className = 'empty';
  d.textContent = text;
  el.append(d);
}

function drop(key) {
  const c = charts[key];
  if (c) {
    c.u.destroy();
    delete charts[key];
  }
}

/** Creates or updates chart `key` in `el`: `sig` changes when the series change. */
function draw(key, el, sig, makeOpts, data, ranges) {
  let c = charts[key];
  if (!c || c.sig !== sig || c.el !== el) {
    drop(key);
    el.replaceChildren();
    c = { sig, el, ...ranges };
    const opts = makeOpts(c);
    const hooks = { ...(opts.hooks || {}), setCursor: [...((opts.hooks && opts.hooks.setCursor) || []), readout(key)] };
    c.u = new uPlot({ ...plotSize(el), legend: { show: false }, padding: [14, 36, 0, 0], ...opts, hooks }, data, el);
    charts[key] = c;
  } else {
    Object.assign(c, ranges);
    c.u.setData(data);
  }
  applyHidden(c);
  return c;
}

// Plots whose y values are log10 of what they show (see lg below).
const LOG10_Y = new Set(['variance', 'time']);

/** The hover readout of a chart: the x under the cursor and each shown estimator's value there
 *  (bands, references and hidden series left out), in a box in the plot's corner. */
function readout(key) {
  return (u) => {
    let box = u.root.querySelector('.readout');
    if (!box) {
      box = el('div', { className: 'readout', role: 'status' });
      u.root.querySelector('.u-over').after(box);
    }
    const i = u.cursor.idx;
    if (i === null || i === undefined || u.cursor.left < 0) {
      box.hidden = true;
      return;
    }
    const x = u.data[0][i];
    const lines = [];
    u.series.forEach((ser, k) => {
      if (k === 0 || !ser.show || typeof ser.label !== 'string' || / 95% |^N|^spp|normal|exact/.test(ser.label)) return;
      const v = u.data[k][i];
      if (v === null || v === undefined || !Number.isFinite(v)) return;
      lines.push(`${ser.label}: ${fmt(LOG10_Y.has(key) ? 10 ** v : v, 3)}`);
    });
    if (!lines.length) {
      box.hidden = true;
      return;
    }
    box.hidden = false;
    box.textContent = `${key === 'time' ? 't' : key === 'calibration' ? 'z' : 'N'} = ${fmt(x, 4)}\n${lines.join('\n')}`;
  };
}

// Estimators the reader hid by clicking their legend entry (every plot follows).
const hiddenSeries = new Set();

/** Shows or hides each series of a chart by the estimator it belongs to: its label is the
 *  estimator's name, or the name and a suffix ("uniform 95% high"). */
function applyHidden(c) {
  if (!c || !c.u) return;
  c.u.series.forEach((ser, i) => {
    if (i === 0 || typeof ser.label !== 'string') return;
    let hide = false;
    for (const name of hiddenSeries) if (ser.label === name || ser.label.startsWith(`${name} `)) hide = true;
    if (Boolean(ser.show) === hide) c.u.setSeries(i, { show: !hide });
  });
}

/**
 * A click on an estimator's legend entry hides it in every plot (or shows it again); with Shift
 * or Alt, it isolates it (every other estimator hidden), and the same again shows them all.
 */
function onLegendClick(e) {
  const li = e.target.closest('li[data-series]');
  if (!li) return;
  const name = li.dataset.series;
  const all = [...new Set([...document.querySelectorAll('.legend li[data-series]')].map((x) => x.dataset.series))];
  if (e.shiftKey || e.altKey) {
    const isolated = all.every((n) => (n === name) !== hiddenSeries.has(n));
    hiddenSeries.clear();
    if (!isolated) for (const n of all) if (n !== name) hiddenSeries.add(n);
  } else if (hiddenSeries.has(name)) {
    hiddenSeries.delete(name);
  } else {
    hiddenSeries.add(name);
  }
  for (const item of document.querySelectorAll('.legend li[data-series]')) {
    item.classList.toggle('off', hiddenSeries.has(item.dataset.series));
    const b = item.querySelector('button.toggle');
    if (b) b.setAttribute('aria-pressed', String(!hiddenSeries.has(item.dataset.series)));
  }
  for (const c of Object.values(charts)) {
    applyHidden(c);
    if (c && c.u) c.u.redraw(false);
  }
}

/** The estimators hidden in the plots (for tests: window.mcplayDebug). */
export function hiddenEstimators() {
  return [...hiddenSeries];
}

function logX(c, base = 2) {
  return { time: false, distr: 3, log: base, range: () => c.xRange };
}
// The y axes of the variance and error plots hold log10 of the values on a linear scale:
// uPlot's own log scale only knows increments between 1e-32 and 1e32, and an (almost) exact
// estimator's variance goes below that.
const lg = (v) => (v === null || v === undefined ? null : Math.log10(v));
const lgAll = (a) => a.map(lg);

function log10Y(c) {
  return { range: () => c.yRange };
}

/** [lo, hi] in whole decades, as log10. */
function log10Range(values) {
  return decadeRange(values).map((v) => Math.round(Math.log10(v)));
}

/** Tick labels of a log10 axis: 10^k at whole k, nothing between. */
function log10Ticks(u, splits) {
  return splits.map((v) => (typeof v === 'number' && Math.abs(v - Math.round(v)) < 1e-9 ? decadeLabel(Number(`1e${Math.round(v)}`)) : ''));
}

const LOG10_AXIS = { values: log10Ticks, incrs: [1, 2, 3, 4, 5, 10, 20, 50, 100], size: 62, space: 22 };

/** Minor grid lines at 2..9 x 10^k on a log10 y axis (log paper), under the series. */
function minorLogGrid(u) {
  const { min, max } = u.scales.y;
  if (!(max - min <= 14)) return;
  const ctx = u.ctx;
  const px = uPlot.pxRatio || 1;
  ctx.save();
  ctx.strokeStyle = '#eef1f4';
  ctx.lineWidth = px;
  ctx.beginPath();
  for (let k = Math.floor(min); k < Math.ceil(max); k++) {
    for (let m = 2; m <= 9; m++) {
      const v = k + Math.log10(m);
      if (v <= min || v >= max) continue;
      const y = Math.round(u.valToPos(v, 'y', true)) + 0.5;
      ctx.moveTo(u.bbox.left, y);
      ctx.lineTo(u.bbox.left + u.bbox.width, y);
    }
  }
  ctx.stroke();
  ctx.restore();
}

/** Draws labels at the last visible point of the given series (reference lines). */
function labelHook(items) {
  return (u) => {
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    ctx.font = `${11 * px}px "DejaVu Sans", sans-serif`;
    ctx.fillStyle = '#555';
    ctx.textBaseline = 'bottom';
    const { min: ymin, max: ymax } = u.scales.y;
    for (const { idx, label } of items) {
      const ys = u.data[idx];
      if (!ys) continue;
      let last = -1;
      for (let i = 0; i < ys.length; i++) if (ys[i] !== null && ys[i] >= ymin && ys[i] <= ymax) last = i;
      if (last < 0) continue;
      const w = ctx.measureText(label).width;
      let x = u.valToPos(u.data[0][last], 'x', true) + 4 * px;
      x = Math.min(x, u.bbox.left + u.bbox.width - w - 2 * px);
      const y = Math.max(u.bbox.top + 12 * px, u.valToPos(ys[last], 'y', true) - 2 * px);
      ctx.fillText(label, x, y);
    }
    ctx.restore();
  };
}

/** Marks the levels that are exact to round-off (no point on a log axis): a row of squares in
 *  the series' colour along the bottom of the plot, one row per such estimator (the legend
 *  says which). */
function exactHook(rows) {
  return (u) => {
    if (!rows.length) return;
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    rows.forEach(({ color, exactAt }, r) => {
      const y = u.bbox.top + u.bbox.height - (7 + 11 * r) * px;
      ctx.fillStyle = color;
      exactAt.forEach((isExact, i) => {
        if (!isExact) return;
        const x = u.valToPos(u.data[0][i], 'x', true);
        ctx.fillRect(x - 3.5 * px, y - 3.5 * px, 7 * px, 7 * px);
      });
    });
    ctx.restore();
  };
}

// ---------------------------------------------------------------------------------------------
// Legends (plain DOM; text only, never HTML from data)


function swatch(color, dashed = false) {
  return el('span', {
    className: 'swatch',
    style: dashed ? `background: repeating-linear-gradient(90deg, ${color} 0 4px, transparent 4px 7px)` : `background: ${color}`,
  });
}

function badge(w) {
  const severity = severityOf(w);
  return el('span', { className: `badge${severity === 'error' ? ' badge-error' : ''}`, title: w.message, dataset: { severity } }, w.code);
}

/** An estimator's level flags of severity error or warning (one per code) that its own
 *  estimator-level warnings do not already say: shown beside the plot they concern. */
function levelFlags(r) {
  const own = new Set((r.warnings || []).map((w) => w.code));
  const seen = new Map();
  for (const l of r.levels || []) {
    for (const w of l.warnings || []) {
      const sev = severityOf(w);
      if ((sev === 'error' || sev === 'warning') && !own.has(w.code) && !seen.has(w.code)) seen.set(w.code, w);
    }
  }
  return [...seen.values()].sort((a, b) => SEVERITIES.indexOf(severityOf(a)) - SEVERITIES.indexOf(severityOf(b)));
}

const legendSigs = {};

function setLegend(key, ul, items) {
  const sig = JSON.stringify(items);
  if (legendSigs[key] === sig && ul.childElementCount === items.length) return;
  legendSigs[key] = sig;
  // An estimator's entry: its name is a toggle button (hide or show it in every plot).
  const nameOf = (it) => {
    if (it.ref) return el('span', { className: 'name ref' }, it.name);
    const b = el('button', { type: 'button', className: 'name toggle', title: 'click: hide or show in every plot; Shift+click: show only this one' }, it.name);
    b.setAttribute('aria-pressed', String(!hiddenSeries.has(it.name)));
    return b;
  };
  ul.replaceChildren(...items.map((it) => el('li', {
    dataset: { ...(it.data || {}), ...(it.ref ? {} : { series: it.name }) },
    ...(it.ref ? {} : { className: hiddenSeries.has(it.name) ? 'off' : '' }),
  },
    swatch(it.color, it.dashed),
    nameOf(it),
    ...(it.parts || []).map((p) => (typeof p === 'string' ? p : p.fit !== undefined
      ? el('span', { className: 'fit', dataset: { fit: p.name } }, p.fit)
      : p.warning ? badge(p.warning) : el('span', { className: p.className || '' }, p.text))))));
}

// ---------------------------------------------------------------------------------------------

/** Remembers the plot and legend elements and redraws on resize. */
export function initPlots(elements) {
  dom = elements;
  if (typeof ResizeObserver === 'function') {
    const ro = new ResizeObserver(() => {
      for (const c of Object.values(charts)) {
        if (!c.u) continue;
        const size = plotSize(c.el);
        if (size.width !== c.u.width || size.height !== c.u.height) c.u.setSize(size);
      }
    });
    for (const k of ['variance', 'time', 'calibration', 'coverage', 'overlay', 'misweights', 'weights']) if (dom[k]) ro.observe(dom[k]);
  }
  for (const [k, ul] of Object.entries(dom)) {
    if (!k.startsWith('legend-') || !ul) continue;
    ul.addEventListener('click', onLegendClick); // the name buttons take Enter and Space
  }
  mountSampleControls();
}

function colorOf(run, name) {
  return colorAt(run.colors && name in run.colors ? run.colors[name] : run.order.indexOf(name));
}

const isRender = (run) => run.kind === 'render';

const VARIANCE_NOTE = {
  integral: 'Shaded: 95% interval of the variance (chi-square); dashed grey: reference slopes N⁻¹, N⁻², N⁻³ from the first point. Order = the core\'s least-squares fit of log variance on log N.',
  render: 'Relative MSE of each estimator\'s images against the reference (mean over the replicates; shaded: its 95% interval from their spread); dashed grey: the reference slope spp⁻¹ of an unbiased estimator, from the first point. Order = the core\'s least-squares fit of log relative MSE on log spp.',
};
const COVERAGE_NOTE = {
  integral: 'Share of replicates whose own 95% interval holds the exact value; grey: 0.95 and its binomial 95% band for the number of replicates.',
  render: 'Share of the pixels (and colour channels) whose own 95% error bar covers the reference pixel, averaged over the replicates; grey: 0.95. At 1 spp a pixel has no error bar.',
};

function setText(id, text) {
  const e = document.getElementById(id);
  if (e && e.textContent !== text) e.textContent = text;
}

/** The titles and notes of the plots before a run, for the kind of scene shown. */
function emptyTexts(render) {
  setText('variance-title', render ? 'Relative MSE against spp' : 'Variance against N');
  setText('variance-note', VARIANCE_NOTE[render ? 'render' : 'integral']);
  setText('time-title', render ? 'Error against time per image' : 'Error against run time');
  setText('coverage-note', COVERAGE_NOTE[render ? 'render' : 'integral']);
}

/** Axis and text names of a run: what N is (settings.n_name) and what the error is
 *  (settings.error_name), e.g. spp and relative MSE for render studies. */
export function runLabels(run) {
  const nName = run.nName || 'N';
  const spp = nName === 'spp';
  const error = run.errorName || 'variance';
  const readable = { relative_mse: 'relative MSE', mse: 'MSE', variance: 'variance' }[error] || error.replace(/_/g, ' ');
  return {
    n: nName,
    nAxis: spp ? 'spp [samples per pixel]' : `${nName} [samples]`,
    error: readable,
    errorAxis: error === 'relative_mse' ? 'relative MSE against the reference' : null,
    rootAxis: error === 'relative_mse' ? 'relative RMSE (√ relative MSE)' : null,
    timeAxis: spp ? 'wall time per image [seconds]' : 'wall time per estimate [seconds]',
  };
}

/** Draws everything of state.run. */
export function renderPlots(state) {
  if (!dom) return;
  renderSampleViews(state);
  const run = state.run;
  if (!run.order.length) {
    emptyTexts(state.sceneInfo && state.sceneInfo.kind === 'render');
    for (const k of ['variance', 'time', 'calibration', 'coverage']) {
      drop(k);
      if (!dom[k].querySelector('.empty')) empty(dom[k], 'Press Run to start a study.');
      setLegend(k, dom[`legend-${k}`], []);
    }
    return;
  }
  // Every estimator of the run has a series from the start (empty until its first level).
  const records = {};
  for (const n of run.order) records[n] = run.records[n] || { name: n, levels: [], fit: null, warnings: [] };
  renderVariance(state, run, records);
  renderTime(state, run, records);
  renderCalibration(state, run, records);
  renderCoverage(state, run, records);
}

let exactRows = [];

function renderVariance(state, run, records) {
  const render = isRender(run);
  const names = runLabels(run);
  // A render level's variance is its relative MSE against the reference (mse is the same number).
  // With a run kept for comparison (same scene), the x axis spans both ladders.
  const kept = keptFor(state);
  const xs = kept ? [...new Set([...run.ladder, ...kept.ladder])].sort((a, b) => a - b) : run.ladder;
  const vs = varianceSeries(records, run.order, render ? null : run.exact, xs);
  const anchor = anchorOf(vs.x, vs.series);
  const orders = render ? [1] : [1, 2, 3];
  const refs = referenceLines(vs.x, anchor, orders);
  const data = [vs.x];
  const series = [{}];
  const bands = [];
  vs.series.forEach((s) => {
    const color = colorOf(run, s.name);
    const yi = data.length;
    data.push(lgAll(s.y), lgAll(s.hi), lgAll(s.lo));
    series.push(
      { label: s.name, stroke: color, width: 2, points: { show: true, size: 6, fill: color } },
      { label: `${s.name} 95% high`, stroke: withAlpha(color, 0.35), width: 0.5, points: { show: false } },
      { label: `${s.name} 95% low`, stroke: withAlpha(color, 0.35), width: 0.5, points: { show: false } },
    );
    bands.push({ series: [yi + 1, yi + 2], fill: withAlpha(color, 0.14) });
  });
  // The kept run's variance, dashed and lighter.
  const keptSeries = kept ? varianceSeries(kept.records, kept.order, render ? null : kept.exact, vs.x).series : [];
  keptSeries.forEach((s) => {
    const color = colorOf(run, s.name);
    data.push(lgAll(s.y));
    series.push({ label: `${s.name} (kept)`, stroke: withAlpha(color, 0.7), width: 1.5, dash: [5, 4],
      points: { show: true, size: 4, fill: '#fff' } });
  });
  // Three reference series always (all null until there is a first point), so the chart keeps
  // its series while the levels stream in.
  const refItems = [];
  orders.map((k) => `${render ? 'spp' : 'N'}${sup(-k)}`).forEach((label, i) => {
    refItems.push({ idx: data.length, label });
    data.push(refs[i] ? lgAll(refs[i].y) : vs.x.map(() => null));
    series.push({ label, stroke: '#8a8f96', width: 1, dash: [6, 5], points: { show: false } });
  });
  const values = [...vs.series.flatMap((s) => [...s.y, ...s.lo, ...s.hi]), ...keptSeries.flatMap((s) => s.y)];
  const yRange = log10Range(values);
  // Exact levels, drawn as a labelled row along the bottom (the hook reads the latest rows).
  exactRows = vs.series.filter((s) => s.exactAt.some(Boolean)).map((s) => ({ color: colorOf(run, s.name), exactAt: s.exactAt }));
  const xRange = vs.x.length > 1 ? [vs.x[0], vs.x[vs.x.length - 1]] : [vs.x[0] / 2, vs.x[0] * 2];
  const quantity = render ? names.errorAxis || names.error
    : vs.quantity === 'mse' ? 'MSE of the estimate' : 'variance of the estimate';
  const title = document.getElementById('variance-title');
  if (title) {
    title.textContent = render ? `${names.error[0].toUpperCase()}${names.error.slice(1)} against ${names.n}`
      : vs.quantity === 'mse' ? 'MSE against N (exact value known)' : 'Variance against N';
  }
  setText('variance-note', VARIANCE_NOTE[render ? 'render' : 'integral']);
  const sig = JSON.stringify([vs.quantity, run.order, run.colors, run.kind, names.nAxis, quantity,
    keptSeries.map((k) => k.name)]);
  draw('variance', dom.variance, sig, (c) => ({
    scales: { x: logX(c, 2), y: log10Y(c) },
    axes: [
      { ...AXIS, label: names.nAxis, values: nTicks, space: 30 },
      { ...AXIS, ...LOG10_AXIS, label: quantity },
    ],
    series,
    bands,
    cursor: { drag: { x: false, y: false } },
    hooks: { drawAxes: [minorLogGrid], draw: [(u) => labelHook(refItems)(u), (u) => exactHook(exactRows)(u)] },
  }), data, { xRange, yRange });

  setLegend('variance', dom['legend-variance'], vs.series.map((s) => {
    const r = records[s.name];
    return {
      name: s.name,
      color: colorOf(run, s.name),
      parts: [
        // The plotted MSE's own order, then the variance's (a flat MSE under a falling
        // variance is a bias: bias_dominates says from which N).
        ...(vs.quantity === 'mse' && !render && !s.exact
          ? ['order of MSE', { text: fitText(r.mse_fit), className: 'fit' }] : []),
        ...(s.exact ? [{ fit: 'exact: zero variance at every N (■ along the bottom)', name: s.name }] : [
          render ? `order of ${names.error}` : vs.quantity === 'mse' ? 'of variance' : 'order of variance',
          { fit: fitText(r.fit), name: s.name }]),
        ...levelFlags(r).map((w) => ({ warning: w })),
        ...(r.warnings || []).map((w) => ({ warning: w })),
      ],
    };
  }).concat(keptSeries.map((k) => ({
    name: `${k.name} (kept)`,
    color: withAlpha(colorOf(run, k.name), 0.7),
    dashed: true,
    parts: [{ text: `${kept.label}: order ${fitText(k.fit)}`, className: 'fit' }],
  }))));
}

/** Joins each series' points in the order of N (time is not monotone in N: uPlot's own
 *  lines would join them in the order of x). */
function pathsInOrder(getPaths) {
  return (u) => {
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    ctx.beginPath();
    ctx.rect(u.bbox.left, u.bbox.top, u.bbox.width, u.bbox.height);
    ctx.clip();
    for (const { name, color, points, dash = null, whiskers = [], width = null, label = null } of getPaths()) {
      if (hiddenSeries.has(name)) continue;
      // each point's timing interval (95%, over the replicates), with end caps
      ctx.strokeStyle = color;
      ctx.lineWidth = 1 * px;
      ctx.setLineDash([]);
      for (const [lo, hi, y] of whiskers) {
        const cy = u.valToPos(y, 'y', true);
        const x0 = u.valToPos(lo, 'x', true);
        const x1 = u.valToPos(hi, 'x', true);
        ctx.beginPath();
        ctx.moveTo(x0, cy); ctx.lineTo(x1, cy);
        ctx.moveTo(x0, cy - 3 * px); ctx.lineTo(x0, cy + 3 * px);
        ctx.moveTo(x1, cy - 3 * px); ctx.lineTo(x1, cy + 3 * px);
        ctx.stroke();
      }
      ctx.strokeStyle = color;
      ctx.lineWidth = (width ?? (dash ? 1.5 : 2)) * px;
      ctx.setLineDash(dash ? dash.map((v) => v * px) : []);
      ctx.beginPath();
      points.forEach(([x, y], i) => {
        const cx = u.valToPos(x, 'x', true);
        const cy = u.valToPos(y, 'y', true);
        if (i === 0) ctx.moveTo(cx, cy);
        else ctx.lineTo(cx, cy);
      });
      ctx.stroke();
      if (label && points.length) {
        // a reference line's name at its end (inside the plot)
        const [x, y] = points[points.length - 1];
        ctx.setLineDash([]);
        ctx.fillStyle = '#555';
        ctx.font = `${11 * px}px "DejaVu Sans", sans-serif`;
        ctx.textAlign = 'right';
        ctx.textBaseline = 'bottom';
        ctx.fillText(label, Math.min(u.valToPos(x, 'x', true), u.bbox.left + u.bbox.width) - 2 * px, u.valToPos(y, 'y', true) - 2 * px);
      }
    }
    ctx.restore();
  };
}

/** A duration in seconds, short: 0.1 ms, 25 us, 1.5 s. */
function shortSeconds(t) {
  if (t >= 1) return `${+t.toPrecision(2)} s`;
  if (t >= 1e-3) return `${+(t * 1e3).toPrecision(2)} ms`;
  return `${+(t * 1e6).toPrecision(2)} µs`;
}

/** Shades the times below `floor` seconds (too short for the clock) and says so. */
function clockBandHook(floor, stepSeconds) {
  return (u) => {
    if (!(floor > 0)) return;
    const x1 = u.valToPos(floor, 'x', true);
    const x0 = u.bbox.left;
    if (!(x1 > x0)) return;
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    ctx.fillStyle = 'rgba(120, 128, 138, 0.10)';
    ctx.fillRect(x0, u.bbox.top, Math.min(x1, u.bbox.left + u.bbox.width) - x0, u.bbox.height);
    ctx.fillStyle = '#5a6470';
    ctx.font = `${10 * px}px "DejaVu Sans", sans-serif`;
    ctx.textBaseline = 'bottom';
    ctx.textAlign = 'left';
    const text = `under ${CLOCK_STEPS_FITTED} clock steps (${shortSeconds(stepSeconds)}): not fitted`;
    ctx.fillText(text, x0 + 4 * px, u.bbox.top + u.bbox.height - 4 * px, Math.max(40 * px, x1 - x0 - 8 * px));
    ctx.restore();
  };
}

function renderTime(state, run, records) {
  // The page's clock (performance.now, which the wasm core times with) rounds to a step: times
  // under CLOCK_STEPS_FITTED steps are drawn but not fitted.
  const step = state.clockStep > 0 ? state.clockStep / 1000 : 0;
  const floor = CLOCK_STEPS_FITTED * step;
  const ts = timeSeries(records, run.order, floor);
  const data = [ts.x, ...ts.series.map((s) => lgAll(s.y))];
  const noLine = () => null;
  const series = [{}, ...ts.series.map((s) => {
    const color = colorOf(run, s.name);
    return { label: s.name, stroke: color, width: 2, paths: noLine, points: { show: true, size: 7, fill: color } };
  })];
  const lines = ts.series.map((s) => ({
    name: s.name, color: colorOf(run, s.name), points: s.points.map(([t, e]) => [t, lg(e)]),
    whiskers: s.whiskers.map(([lo, hi, e]) => [lo, hi, lg(e)]),
  }));
  // Reference slopes, dashed grey, from the fastest timed point (at the largest error there) to
  // the right edge: t^-1/2 (Monte Carlo when the cost grows like N) and t^-1.
  const timed = ts.series.flatMap((s) => s.points).filter(([t]) => t >= floor);
  if (timed.length) {
    const t0 = Math.min(...timed.map(([t]) => t));
    const e0 = Math.max(...timed.filter(([t]) => t === t0).map(([, e]) => e));
    const tMax = Math.max(...ts.x);
    if (tMax > t0) {
      for (const [k, label] of [[0.5, 't⁻½'], [1, 't⁻¹']]) {
        lines.unshift({ name: `reference ${label}`, color: '#8a8f96', dash: [6, 5], width: 1, label,
          points: [[t0, lg(e0)], [tMax, lg(e0 * (tMax / t0) ** -k)]] });
      }
    }
  }
  // Adaptive estimators: dashed, the error at the time spent estimating only; the gap to the
  // solid line is what training (VEGAS) or probing (MISER) cost.
  for (const s of ts.series) {
    if (s.estimating.length) lines.push({ name: s.name, color: colorOf(run, s.name), dash: [6, 4], points: s.estimating.map(([t, e]) => [t, lg(e)]) });
  }
  const render = isRender(run);
  const names = runLabels(run);
  const known = render || (run.exact !== null && run.exact !== undefined);
  const xRange = decadeRange([...ts.x, ...ts.series.flatMap((s) => s.estimating.map(([t]) => t))], [1e-6, 1]);
  const yRange = log10Range(ts.series.flatMap((s) => s.y));
  // A short label where the plot is too short for the long one (a phone).
  const roomy = !dom.time || dom.time.clientHeight === 0 || dom.time.clientHeight >= 340;
  const yLabel = render ? names.rootAxis || names.error
    : known ? (roomy ? 'RMSE (error against the exact value)' : 'RMSE') : (roomy ? 'error = sqrt(variance)' : 'sqrt(variance)');
  const sig = JSON.stringify([run.order, run.colors, known, yLabel, names.timeAxis]);
  const title = document.getElementById('time-title');
  if (title) title.textContent = render ? 'Error against time per image' : 'Error against run time';
  if (!ts.x.length) {
    drop('time');
    empty(dom.time, run.status === 'running' ? 'Waiting for the first N…' : 'No timings.');
  } else {
    draw('time', dom.time, sig, (c) => ({
      scales: { x: logX(c, 10), y: log10Y(c) },
      axes: [
        { ...AXIS, label: names.timeAxis, values: (u, splits) => splits.map(decadeLabel), space: 20 },
        { ...AXIS, ...LOG10_AXIS, label: yLabel },
      ],
      series,
      cursor: { drag: { x: false, y: false } },
      hooks: { drawAxes: [minorLogGrid, (u) => clockBandHook(charts.time.floor, charts.time.step)(u)],
        draw: [(u) => pathsInOrder(() => charts.time.lines)(u)] },
    }), data, { xRange, yRange, lines, floor, step });
  }
  const slopeText = (s) => {
    if (s.slope === null) return s.untimed ? 'no slope: too fast for the clock' : '';
    return `error ∝ t^${s.slope.toFixed(2)}${s.untimed ? ` (fit at t ≥ ${shortSeconds(floor)})` : ''}`;
  };
  setLegend('time', dom['legend-time'], ts.series.map((s) => ({
    name: s.name,
    color: colorOf(run, s.name),
    parts: [slopeText(s) ? { text: slopeText(s), className: 'fit' } : '',
      s.trainingShare === null ? '' : { text: `training: ${Math.round(100 * s.trainingShare)}% of the time (dashed: without it)`, className: 'fit' }],
  })));
  // The equal-time statement, once the run is over (integrals: render studies have their own
  // efficiency in the tables).
  const verdict = run.status === 'running' || isRender(run) ? null : equalTimeVerdict(records, run.order, run.exact);
  setText('time-verdict', verdict ? verdict.text : '');
}

function renderCalibration(state, run, records) {
  const which = state.calibration;
  const cs = calibrationSeries(records, run.order, run.exact, which);
  const data = [cs.x, cs.normal, ...cs.series.map((s) => s.y)];
  const stepped = uPlot.paths.stepped({ align: 1 });
  const series = [{}, { label: 'standard normal', stroke: '#000', width: 2, points: { show: false } },
    ...cs.series.map((s) => {
      const color = colorOf(run, s.name);
      return { label: s.name, stroke: color, width: 2, fill: withAlpha(color, 0.08), paths: stepped, points: { show: false } };
    })];
  let ymax = 0.45;
  for (const s of cs.series) for (const v of s.y) if (v !== null && v > ymax) ymax = v;
  const render = isRender(run);
  const known = run.exact !== null && run.exact !== undefined;
  const sig = JSON.stringify([run.order, run.colors, render, known]);
  const zLabel = render ? 'z = (image mean luminance − mean of replicates) / std. error'
    : known ? 'z = (estimate − exact) / std. error' : 'z = (estimate − mean of replicates) / std. error';
  draw('calibration', dom.calibration, sig, (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
    axes: [
      { ...AXIS, label: zLabel, space: 40 },
      { ...AXIS, label: 'density', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 2)) },
    ],
    series,
    cursor: { drag: { x: false, y: false } },
  }), data, { xRange: [cs.x[0], cs.x[cs.x.length - 1]], yRange: [0, Math.ceil(ymax * 1.1 * 10) / 10] });

  const note = document.getElementById('calibration-note');
  if (note) {
    note.textContent = render
      ? 'Render studies: z of each image\'s mean luminance against the mean of the level\'s replicates, over its own error bar (from the pixels\' variances; 1 spp gives none). A check of the size of the error bars, not of a bias.'
      : known
      ? 'Histogram of z = (estimate − exact) / std. error over the replicates, against the standard normal density (black): calibrated error bars follow it; about 95% of z lie within ±1.96.'
      : 'No exact value: z is taken against each N\'s mean of the replicates, which checks the size of the error bars but not a bias.';
  }
  setLegend('calibration', dom['legend-calibration'], [
    { name: 'N(0, 1)', color: '#000', ref: true, parts: [] },
    ...cs.series.map((s) => {
      const parts = [];
      if (s.total) parts.push({ text: `${(100 * s.within2 / s.total).toFixed(0)}% within ±1.96 (${s.total} z)`, className: 'fit' });
      else if (s.exactRuns) parts.push({ text: 'exact to round-off: no z', className: 'fit' });
      else parts.push('no replicates yet');
      if (s.total && s.exactRuns) parts.push({ text: `${s.exactRuns} runs exact to round-off (no z)`, className: 'fit' });
      if (s.below + s.above) parts.push({ text: `${s.below + s.above} beyond ±5`, className: 'badge' });
      if (s.zeroSe) parts.push({ text: `${s.zeroSe} with a zero error bar`, className: 'badge' });
      const wide = conservativeErrorBars(records[s.name]);
      if (wide) parts.push({ text: `${wide}: z narrower than N(0, 1) by design`, className: 'fit' });
      return { name: s.name, color: colorOf(run, s.name), parts };
    }),
  ]);
}

function renderCoverage(state, run, records) {
  const render = isRender(run);
  const names = runLabels(run);
  const cs = coverageSeries(records, run.order, run.ladder);
  const reps = run.settings ? run.settings.reps : 32;
  // Render studies: coverage is a share of pixels (not independent of each other): no band.
  const half = render ? 0 : 1.96 * Math.sqrt(0.95 * 0.05 / reps);
  setText('coverage-note', COVERAGE_NOTE[render ? 'render' : 'integral']);
  const data = [cs.x, cs.x.map(() => 0.95), cs.x.map(() => Math.min(1, 0.95 + half)), cs.x.map(() => 0.95 - half),
    ...cs.series.map((s) => s.y)];
  const series = [{}, { label: '0.95', stroke: '#8a8f96', width: 1, dash: [6, 5], points: { show: false } },
    { label: 'band high', stroke: 'transparent', width: 0, points: { show: false } },
    { label: 'band low', stroke: 'transparent', width: 0, points: { show: false } },
    ...cs.series.map((s) => {
      const color = colorOf(run, s.name);
      return { label: s.name, stroke: color, width: 2, points: { show: true, size: 6, fill: color } };
    })];
  let ymin = 0.8;
  for (const s of cs.series) for (const v of s.y) if (v !== null && v < ymin) ymin = v;
  ymin = Math.max(0, Math.floor((Math.min(ymin, 0.95 - half) - 0.02) * 10) / 10);
  const known = render || (run.exact !== null && run.exact !== undefined);
  if (!known) {
    drop('coverage');
    empty(dom.coverage, 'Coverage needs the exact value, which this scene does not know.');
  } else {
    const xRange = cs.x.length > 1 ? [cs.x[0], cs.x[cs.x.length - 1]] : [cs.x[0] / 2, cs.x[0] * 2];
    draw('coverage', dom.coverage, JSON.stringify([run.order, run.colors, reps, render, names.nAxis]), (c) => ({
      scales: { x: logX(c, 2), y: { range: () => c.yRange } },
      axes: [
        { ...AXIS, label: names.nAxis, values: nTicks, space: 30 },
        { ...AXIS, label: render ? 'pixels covered by their 95% error bars' : 'coverage of the 95% intervals', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 2)) },
      ],
      series,
      bands: [{ series: [2, 3], fill: 'rgba(120, 128, 136, 0.15)' }],
      cursor: { drag: { x: false, y: false } },
    }), data, { xRange, yRange: [ymin, 1.0001] });
  }
  setLegend('coverage', dom['legend-coverage'], cs.series.map((s) => {
    const last = [...s.y].reverse().find((v) => v !== null);
    return {
      name: s.name,
      color: colorOf(run, s.name),
      parts: [{ text: last === undefined ? '—' : `${fmt(last, 3)} at the largest ${names.n}`, className: 'fit' },
        conservativeErrorBars(records[s.name]) ? { text: `${conservativeErrorBars(records[s.name])}: above 0.95 by design`, className: 'fit' } : ''],
    };
  }));
}

// ---------------------------------------------------------------------------------------------
// Sample points, the 1D f/p overlay and the weight histograms (state.samples)

let samplesDrawn = null; // [data, weights, status, sceneInfo] last drawn

function sceneColor(state, name) {
  const names = state.sceneInfo && state.sceneInfo.estimators ? state.sceneInfo.estimators : [];
  const i = names.indexOf(name);
  return colorAt(i < 0 ? 0 : i);
}

// The replay of the sample view (presentation only, like VEGAS's training slider): the first k
// points of each set (null: all), and the pair of axes a set of d > 2 is projected on.
const replay = { k: null, axes: [0, 1], timer: null, state: null };

/** The sample view's own controls (#samples-k, #samples-play, the two axis selects), wired once. */
function mountSampleControls() {
  const $ = (id) => document.getElementById(id);
  const slider = $('samples-k');
  if (!slider) return;
  const redraw = () => {
    const st = replay.state;
    if (st && st.samples.data) renderScatter(st, st.samples.data);
  };
  slider.addEventListener('input', () => {
    clearInterval(replay.timer);
    replay.k = Number(slider.value);
    redraw();
  });
  $('samples-play').addEventListener('click', () => {
    const st = replay.state;
    if (!st || !st.samples.data) return;
    clearInterval(replay.timer);
    // k from 1 to n in about 60 steps spaced evenly in log k, so that the first points are seen
    const n = st.samples.data.n;
    const steps = [...new Set(Array.from({ length: 61 }, (_, i) => Math.max(1, Math.round(n ** (i / 60)))))];
    let i = 0;
    replay.k = steps[0];
    redraw();
    replay.timer = setInterval(() => {
      i += 1;
      replay.k = steps[Math.min(i, steps.length - 1)];
      redraw();
      if (i >= steps.length - 1) clearInterval(replay.timer);
    }, 70);
  });
  for (const [id, at] of [['samples-axis-a', 0], ['samples-axis-b', 1]]) {
    $(id).addEventListener('change', (e) => {
      replay.axes = at === 0 ? [Number(e.target.value), replay.axes[1]] : [replay.axes[0], Number(e.target.value)];
      redraw();
    });
  }
}

/** The replay controls of a new point set: k back to all, axes offered for d > 2. */
function syncSampleControls(data) {
  const $ = (id) => document.getElementById(id);
  const slider = $('samples-k');
  if (!slider) return;
  const n = data ? data.n : 1;
  slider.max = String(n);
  slider.disabled = !data;
  $('samples-play').disabled = !data;
  const d = data ? data.dimension : 0;
  $('samples-axes-block').hidden = !(d > 2);
  if (d > 2) {
    if (!(replay.axes[0] < d && replay.axes[1] < d)) replay.axes = [0, 1];
    for (const [id, at] of [['samples-axis-a', 0], ['samples-axis-b', 1]]) {
      const sel = $(id);
      if (sel.options.length !== d) {
        sel.replaceChildren(...Array.from({ length: d }, (_, k) => el('option', { value: String(k) }, `${at === 0 ? 'across' : 'up'}: axis ${k + 1}`)));
      }
      sel.value = String(replay.axes[at]);
    }
  }
}

function renderSampleViews(state) {
  if (!dom.samples) return;
  replay.state = state;
  const smp = state.samples;
  const sig = [smp.data, smp.weights, smp.status, state.sceneInfo, smp.message];
  if (samplesDrawn && sig.every((v, i) => v === samplesDrawn[i])) return;
  if (!samplesDrawn || samplesDrawn[0] !== smp.data) {
    clearInterval(replay.timer);
    replay.k = null;
    syncSampleControls(smp.data);
  }
  samplesDrawn = sig;
  dom.samples.classList.toggle('loading', smp.status === 'loading');
  if (smp.status === 'error') {
    empty(dom.samples, `No sample points: ${smp.message}`);
  } else if (!smp.data) {
    empty(dom.samples, smp.status === 'loading' ? 'Drawing the points…' : 'Select an estimator to see its points.');
  } else {
    renderScatter(state, smp.data);
  }
  renderOverlay(state, smp.data);
  renderMisWeights(state, smp.data);
  renderWeights(state, smp.weights);
}

const PANEL = 240; // logical size of a scatter panel (CSS scales it to the card)
const PAD = { l: 38, r: 6, t: 6, b: 18 };

/** A canvas of w x h logical pixels with a plot area mapping [xr] x [yr]; returns helpers. */
function panel(w, h, xr, yr, padLeft = PAD.l) {
  const P = { ...PAD, l: padLeft };
  const px = window.devicePixelRatio || 1;
  const c = document.createElement('canvas');
  c.width = Math.round(w * px);
  c.height = Math.round(h * px);
  const ctx = c.getContext('2d');
  ctx.scale(px, px);
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, w, h);
  const iw = w - P.l - P.r;
  const ih = h - P.t - P.b;
  const X = (v) => P.l + ((v - xr[0]) / (xr[1] - xr[0] || 1)) * iw;
  const Y = (v) => P.t + ih - ((v - yr[0]) / (yr[1] - yr[0] || 1)) * ih;
  const frame = () => {
    ctx.strokeStyle = '#b8c0c8';
    ctx.lineWidth = 1;
    ctx.strokeRect(P.l + 0.5, P.t + 0.5, iw - 1, ih - 1);
    ctx.fillStyle = '#5a6470';
    ctx.font = '10px "DejaVu Sans", sans-serif';
    ctx.textBaseline = 'top';
    ctx.textAlign = 'left';
    ctx.fillText(fmt(xr[0], 3), P.l, P.t + ih + 3);
    ctx.textAlign = 'right';
    ctx.fillText(fmt(xr[1], 3), P.l + iw, P.t + ih + 3);
    ctx.textBaseline = 'bottom';
    ctx.fillText(fmt(yr[0], 3), P.l - 3, P.t + ih);
    ctx.textBaseline = 'top';
    ctx.fillText(fmt(yr[1], 3), P.l - 3, P.t);
  };
  const clip = () => {
    ctx.beginPath();
    ctx.rect(P.l, P.t, iw, ih);
    ctx.clip();
  };
  const clear = () => {
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, w, h);
  };
  return { c, ctx, X, Y, frame, clip, clear, iw, ih, pad: P };
}

function dots(ctx, xs, ys, X, Y, color, n) {
  const r = n <= 64 ? 2.6 : n <= 256 ? 1.9 : 1.3;
  ctx.fillStyle = color;
  ctx.beginPath();
  for (let i = 0; i < xs.length; i++) {
    const cx = X(xs[i]);
    const cy = Y(ys[i]);
    if (!Number.isFinite(cx) || !Number.isFinite(cy)) continue;
    ctx.moveTo(cx + r, cy);
    ctx.arc(cx, cy, r, 0, 2 * Math.PI);
  }
  ctx.fill();
}

const GRID_MAX = 64; // more cells per axis than this: the grid is not drawn (it would be a grey fill)

/** Lines across the unit square at the values v on the horizontal (axis 'x') or vertical axis. */
function linesAt(p, values, axis, style) {
  const { ctx, X, Y } = p;
  ctx.strokeStyle = style;
  ctx.lineWidth = 1;
  ctx.beginPath();
  for (const v of values) {
    if (axis === 'x') {
      const x = Math.round(X(v)) + 0.5;
      ctx.moveTo(x, Y(0));
      ctx.lineTo(x, Y(1));
    } else {
      const y = Math.round(Y(v)) + 0.5;
      ctx.moveTo(X(0), y);
      ctx.lineTo(X(1), y);
    }
  }
  ctx.stroke();
}

/** Strata lines at k / cells on the horizontal (axis 'x') or vertical axis. */
function strataLines(p, cells, axis) {
  if (!(cells > 1) || cells > GRID_MAX) return;
  linesAt(p, Array.from({ length: cells - 1 }, (_, k) => (k + 1) / cells), axis, 'rgba(90, 100, 112, 0.45)');
}

/**
 * VEGAS's map on the first two axes of the unit square: a line at every edge of its increments
 * (every k-th edge when there are more than GRID_MAX), so that dense lines show where the map
 * puts its points.
 */
function mapLines(p, edges, axis) {
  if (!Array.isArray(edges) || edges.length < 3) return;
  const step = Math.ceil((edges.length - 1) / GRID_MAX);
  const inner = edges.filter((_, k) => k > 0 && k < edges.length - 1 && k % step === 0);
  linesAt(p, inner, axis, 'rgba(150, 80, 20, 0.45)');
}

/** MISER's leaf boxes on the first two axes of the unit square (1D: their left edges). */
function boxOutlines(p, boxes, d, [a, b] = [0, 1]) {
  if (!boxes || !Array.isArray(boxes.lo)) return;
  const { ctx, X, Y } = p;
  ctx.strokeStyle = 'rgba(150, 80, 20, 0.5)';
  ctx.lineWidth = 1;
  ctx.beginPath();
  boxes.lo.forEach((lo, i) => {
    const hi = boxes.hi[i];
    if (d >= 2) ctx.rect(X(lo[a]), Y(hi[b]), X(hi[a]) - X(lo[a]), Y(lo[b]) - Y(hi[b]));
    else {
      ctx.moveTo(X(lo[0]), Y(0));
      ctx.lineTo(X(lo[0]), Y(1));
    }
  });
  ctx.stroke();
}

function strataText(e, d) {
  if (Array.isArray(e.map_edges) && e.map_edges.length) {
    const k = e.map_edges[0].length - 1;
    return `VEGAS map: ${k} increments per axis (brown lines${k > GRID_MAX ? `: every ${Math.ceil(k / GRID_MAX)}th edge` : ''}); the points the estimate uses, not the training ones`;
  }
  if (e.boxes && Array.isArray(e.boxes.lo)) {
    return `MISER: ${e.boxes.lo.length} leaf regions (brown boxes); the points the estimate uses, not the probes`;
  }
  const s = e.strata || [];
  if (e.randomizations > 0) {
    const k = e.randomizations;
    const n = Array.isArray(e.u) && e.u.length ? e.u[0].length : 0;
    const how = e.randomization === 'none' ? 'unrandomized' : `${e.randomization} randomization`;
    return k > 1 ? `${k} randomizations (${how}) of ${Math.round(n / k)} points each` : `one point set (${how})`;
  }
  if (!s.length) return e.sampler === 'latin_hypercube' ? 'Latin hypercube: one point per row and column' : 'no strata';
  const shown = d > 2 ? `${s.slice(0, 2).join(' × ')} (of ${s.join(' × ')})` : s.join(' × ');
  const per = e.samples_per_stratum > 1 ? `, ${e.samples_per_stratum} points per stratum` : '';
  const fine = s.slice(0, 2).some((c) => c > GRID_MAX) ? ' (too fine to draw)' : '';
  return `strata ${shown} cells${per}${fine}`;
}

/**
 * The running estimate of an estimator's first points (runningEstimate of its weights): the
 * mean of the first j against j (log axis) with its 95% band, the exact value dashed, and the
 * replay's k marked.
 */
function runningPanel(e, k, exact, color, band = true) {
  const w = Array.isArray(e.weight) ? e.weight : [];
  const n = w.length;
  if (n < 2) return null;
  const run = runningEstimate(w);
  const shown = [...run.mean, ...run.lo, ...run.hi].filter(Number.isFinite);
  if (exact !== null) shown.push(exact);
  // the band's extremes at the first few points would flatten the rest: the range of j >= 4
  const later = [...run.mean.slice(3), ...run.lo.slice(3), ...run.hi.slice(3)].filter(Number.isFinite);
  const vals = later.length ? [...later, ...(exact !== null ? [exact] : [])] : shown;
  let lo = Math.min(...vals);
  let hi = Math.max(...vals);
  if (!(hi > lo)) { lo -= 1; hi += 1; }
  const pad = 0.05 * (hi - lo);
  const p = panel(2 * PANEL, 110, [0, Math.log10(n)], [lo - pad, hi + pad], 58);
  const X = (j) => p.X(Math.log10(j));
  p.ctx.save();
  p.clip();
  p.ctx.fillStyle = withAlpha(color, band ? 0.16 : 0);
  p.ctx.beginPath();
  let started = false;
  for (let j = 2; j <= n; ++j) {
    if (!Number.isFinite(run.hi[j - 1])) continue;
    if (!started) { p.ctx.moveTo(X(j), p.Y(run.hi[j - 1])); started = true; } else p.ctx.lineTo(X(j), p.Y(run.hi[j - 1]));
  }
  for (let j = n; j >= 2; --j) if (Number.isFinite(run.lo[j - 1])) p.ctx.lineTo(X(j), p.Y(run.lo[j - 1]));
  p.ctx.closePath();
  p.ctx.fill();
  if (exact !== null) {
    p.ctx.strokeStyle = '#1b1f24';
    p.ctx.setLineDash([5, 4]);
    p.ctx.beginPath();
    p.ctx.moveTo(X(1), p.Y(exact));
    p.ctx.lineTo(X(n), p.Y(exact));
    p.ctx.stroke();
    p.ctx.setLineDash([]);
  }
  p.ctx.strokeStyle = color;
  p.ctx.lineWidth = 1.5;
  p.ctx.beginPath();
  for (let j = 1; j <= n; ++j) {
    if (!Number.isFinite(run.mean[j - 1])) continue;
    if (j === 1) p.ctx.moveTo(X(j), p.Y(run.mean[j - 1])); else p.ctx.lineTo(X(j), p.Y(run.mean[j - 1]));
  }
  p.ctx.stroke();
  // the replay's k
  p.ctx.strokeStyle = '#5a6470';
  p.ctx.beginPath();
  p.ctx.moveTo(Math.round(X(k)) + 0.5, p.Y(lo - pad));
  p.ctx.lineTo(Math.round(X(k)) + 0.5, p.Y(hi + pad));
  p.ctx.stroke();
  p.ctx.restore();
  p.frame();
  // the x axis is log10 j: label its ends as point counts
  const P = p.pad;
  p.ctx.fillStyle = '#fff';
  p.ctx.fillRect(P.l, p.ih + P.t + 1, p.iw, P.b - 1);
  p.ctx.fillStyle = '#5a6470';
  p.ctx.font = '10px "DejaVu Sans", sans-serif';
  p.ctx.textBaseline = 'top';
  p.ctx.textAlign = 'left';
  p.ctx.fillText('1', P.l, P.t + p.ih + 3);
  p.ctx.textAlign = 'right';
  p.ctx.fillText(`${n} points (log)`, P.l + p.iw, P.t + p.ih + 3);
  const at = run.mean[k - 1];
  const half = Number.isFinite(run.hi[k - 1]) ? run.hi[k - 1] - at : null;
  const text = `first ${k}: ${Number.isFinite(at) ? fmt(at, 5) : '—'}${half !== null && band ? ` ± ${fmt(half, 2)}` : ''}`;
  return { canvas: p.c, text };
}

function renderScatter(state, data) {
  const d = data.dimension;
  const view = domainView(data, state.scene && state.scene.domain, replay.axes);
  const [a, b] = d > 2 ? view.axes : [0, 1];
  const k = Math.max(1, Math.min(data.n, replay.k ?? data.n));
  const exact = state.sceneInfo && typeof state.sceneInfo.exact === 'number' ? state.sceneInfo.exact : null;
  const out = document.getElementById('samples-k-out');
  if (out) out.textContent = `${k} of ${data.n} points`;
  const slider = document.getElementById('samples-k');
  if (slider && Number(slider.value) !== k) slider.value = String(k);
  const mapped = {};
  const cards = data.estimators.map((full) => {
    const color = sceneColor(state, full.name);
    // the first k points (the replay); the strata, map and boxes are the whole set's
    const first = (arr) => (Array.isArray(arr) ? arr.slice(0, k) : arr);
    const e = { ...full, u: full.u.map(first), x: full.x.map(first), f: first(full.f), weight: first(full.weight) };
    const n = e.u[0] ? e.u[0].length : 0;
    // u space: the sampler's unit square (1D: u against the point's index)
    const pu = panel(PANEL, PANEL, [0, 1], [0, 1]);
    const uy = d >= 2 ? e.u[b] : e.u[0].map((_, i) => (i + 0.5) / full.u[0].length);
    const drawU = (edges) => {
      pu.clear();
      strataLines(pu, e.strata[a], 'x');
      if (d >= 2) strataLines(pu, e.strata[b], 'y');
      if (edges) {
        mapLines(pu, edges[a], 'x');
        if (d >= 2 && edges[b]) mapLines(pu, edges[b], 'y');
      }
      if (e.boxes) boxOutlines(pu, e.boxes, d, [a, b]);
      pu.frame();
      pu.ctx.save();
      pu.clip();
      dots(pu.ctx, e.u[a], uy, pu.X, pu.Y, color, full.u[0].length);
      pu.ctx.restore();
    };
    drawU(e.map_edges);
    // the training history holds the map's first two axes only
    const training = a === 0 && b === 1 ? mapTraining(e, drawU) : null;
    // a designed set's spread is not the error of its first points' mean: no band
    const running = runningPanel(full, k, exact, color, replayIsEstimator(full));
    // x space: the domain (1D: f at the points, with the curve of f)
    let px;
    if (d === 1) {
      const curve = data.curve;
      // the y range of f on the grid (or at the points), cut as in the overlay for a singular f
      const all = (curve ? curve.f : e.f).filter(Number.isFinite);
      const lo = Math.min(0, ...all);
      let hi = Math.max(...all);
      // a maximum at an end of the grid is an endpoint singularity: cut it as the overlay does
      const atEnd = curve && (curve.f[0] === hi || curve.f[curve.f.length - 1] === hi);
      const sorted = all.slice().sort((a, b) => a - b);
      const q = sorted[Math.floor(0.75 * (sorted.length - 1))];
      if (atEnd && hi > 20 * q && q > 0) hi = 20 * q;
      if (!(hi > lo)) hi = lo + 1;
      px = panel(PANEL, PANEL, view.xRange, [lo, hi]);
      px.frame();
      px.ctx.save();
      px.clip();
      if (curve) {
        px.ctx.strokeStyle = '#8a8f96';
        px.ctx.lineWidth = 1;
        px.ctx.beginPath();
        curve.x.forEach((x, i) => (i ? px.ctx.lineTo(px.X(x), px.Y(curve.f[i])) : px.ctx.moveTo(px.X(x), px.Y(curve.f[i]))));
        px.ctx.stroke();
      }
      dots(px.ctx, e.x[0], e.f, px.X, px.Y, color, n);
      // rug
      px.ctx.strokeStyle = color;
      px.ctx.beginPath();
      const yb = px.Y(lo);
      for (const x of e.x[0]) {
        const cx = Math.round(px.X(x)) + 0.5;
        px.ctx.moveTo(cx, yb);
        px.ctx.lineTo(cx, yb - 5);
      }
      px.ctx.stroke();
      px.ctx.restore();
    } else {
      px = panel(PANEL, PANEL, view.xRange, view.yRange);
      px.ctx.save();
      px.clip();
      const o = view.outline;
      px.ctx.strokeStyle = '#5a6470';
      px.ctx.lineWidth = 1;
      px.ctx.beginPath();
      if (o.type === 'circle') {
        const r = Math.abs(px.X(o.cx + o.r) - px.X(o.cx));
        px.ctx.ellipse(px.X(o.cx), px.Y(o.cy), r, Math.abs(px.Y(o.cy + o.r) - px.Y(o.cy)), 0, 0, 2 * Math.PI);
      } else if (o.type === 'polygon') {
        o.points.forEach(([x, y], i) => (i ? px.ctx.lineTo(px.X(x), px.Y(y)) : px.ctx.moveTo(px.X(x), px.Y(y))));
        px.ctx.closePath();
      }
      px.ctx.stroke();
      // the strata cells in the domain, when the sampler's map is known (checked on its points)
      const known = e.strata.length === 2 && e.strata[0] <= 64 && e.strata[1] <= 64 && data.domain === 'disk'
        ? mapFor(e, state.scene && state.scene.domain) : null;
      if (known) {
        px.ctx.strokeStyle = 'rgba(90, 100, 112, 0.4)';
        px.ctx.beginPath();
        for (const line of mappedGrid(known.map, e.strata)) {
          line.forEach(([x, y], i) => (i ? px.ctx.lineTo(px.X(x), px.Y(y)) : px.ctx.moveTo(px.X(x), px.Y(y))));
        }
        px.ctx.stroke();
        mapped[e.name] = known.name;
      }
      dots(px.ctx, e.x[view.axes[0]], e.x[view.axes[1]], px.X, px.Y, color, full.u[0].length);
      px.ctx.restore();
      px.frame();
    }
    const facts = `${e.sampler}; p: ${e.pdf}; ${strataText(full, d)}`;
    const runningCap = running ? `${running.text}. ${replayIsEstimator(full)
      ? 'Independent points: the mean of the first k is the estimate at N = k; shaded: its 95% interval.'
      : `A designed set: only all ${full.u[0].length} points make the estimate (the first k are not a design of k points).`}` : '';
    return el('div', { className: 'sample-card', dataset: { estimator: e.name, points: String(n) } },
      el('h3', {}, swatch(color), e.name, el('span', { className: 'muted small' }, `${n} points`)),
      el('p', { className: 'facts' }, facts),
      training,
      el('div', { className: 'pair' },
        el('div', {}, pu.c, el('p', { className: 'cap' }, d === 1 ? 'u (across) by point index (up)' : d > 2 ? `u: axes ${a + 1} (across) and ${b + 1} (up) of ${d}` : 'u (unit square)')),
        el('div', {}, px.c, el('p', { className: 'cap' }, d === 1 ? 'x (across), f(x) (up); grey: f' : `x: ${view.labels.join(', ')}${view.note ? ` (${view.note})` : ''}${mapped[e.name] ? `; strata through the ${mapped[e.name]} map` : ''}`))),
      running ? el('div', { className: 'running', dataset: { k: String(k) } }, running.canvas,
        el('p', { className: 'cap' }, `running estimate: ${runningCap}`)) : null);
  });
  dom.samples.replaceChildren(...cards);
  const adaptive = data.estimators.find((e) => e.run_n > data.n);
  if (dom.samplesNote) {
    dom.samplesNote.textContent = `The first ${data.n} points of each selected estimator (replicate 0 of the study at N = ${data.n}, seed ${data.seed}):`
      + ' left in the unit square of its sampler (u) with its strata grid, right in the domain (x)'
      + `${view.note ? `, ${view.note}` : ''}. A polar map squeezes the cells of u near r = 0; the concentric map keeps them even.`
      + (adaptive ? ` Adaptive estimators (VEGAS, MISER) learn from a run of N = ${adaptive.run_n} (replicate 0 at that N):`
        + ` they show what it learnt and the first ${data.n} points of its estimate; the slider replays VEGAS's training.` : '');
  }
}

let trainingTimer = null;

/**
 * VEGAS's map through its training (e.map_history: the first two axes' edges before training
 * and after each iteration): a slider over the snapshots and a replay button that steps through
 * them. `drawU(edges)` redraws the unit-square panel; the last snapshot shows the frozen map.
 */
function mapTraining(e, drawU) {
  const h = e.map_history;
  if (!Array.isArray(h) || h.length < 2) return null;
  const last = h.length - 1;
  const label = el('span', { className: 'small muted map-step' });
  const slider = el('input', { type: 'range', min: '0', max: String(last), value: String(last), className: 'map-iteration' });
  slider.setAttribute('aria-label', `${e.name}: VEGAS map after training step`);
  const show = (k) => {
    slider.value = String(k);
    label.textContent = k === 0 ? 'map before training' : k === last ? `map after training (${last} steps): frozen` : `map after training step ${k} of ${last}`;
    drawU(k === last ? e.map_edges : h[k]);
  };
  slider.addEventListener('input', () => {
    clearInterval(trainingTimer);
    show(Number(slider.value));
  });
  const play = el('button', { type: 'button', className: 'replay', textContent: '▶ replay training' });
  play.addEventListener('click', () => {
    clearInterval(trainingTimer);
    let k = 0;
    show(k);
    trainingTimer = setInterval(() => {
      k += 1;
      show(k);
      if (k >= last) clearInterval(trainingTimer);
    }, 350);
  });
  show(last);
  return el('div', { className: 'map-training', dataset: { steps: String(last) } }, play, slider, label);
}

function renderOverlay(state, data) {
  const exact = state.sceneInfo && typeof state.sceneInfo.exact === 'number' ? state.sceneInfo.exact : null;
  const ov = data && data.curve ? curveOverlay(data.curve, data.estimators.map((e) => e.name), { exact }) : null;
  if (!ov) {
    drop('overlay');
    empty(dom.overlay, data && data.dimension !== 1 ? `1D problems only (this one is ${data.dimension}D).` : data ? '1D problems only.' : '1D problems only; no points yet.');
    dom.overlay.dataset.drawn = 'false';
    setLegend('overlay', dom['legend-overlay'], []);
    return;
  }
  const data2 = [ov.x, ov.f, ...ov.pdfs.map((p) => p.y)];
  const series = [{}, { label: 'f / ∫|f|', stroke: '#000', width: 2.5, points: { show: false } },
    ...ov.pdfs.map((p) => ({ label: p.name, stroke: sceneColor(state, p.name), width: 1.5, points: { show: false } }))];
  const sig = JSON.stringify(['overlay', ov.pdfs.map((p) => p.name)]);
  draw('overlay', dom.overlay, sig, (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
    axes: [{ ...AXIS, label: 'x', space: 40 },
      { ...AXIS, label: 'density', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 3)) }],
    series,
    cursor: { drag: { x: false, y: false } },
  }), data2, { xRange: [ov.x[0], ov.x[ov.x.length - 1]], yRange: ov.yRange });
  dom.overlay.dataset.drawn = 'true';
  setLegend('overlay', dom['legend-overlay'], [
    { name: 'f / ∫|f|', color: '#000', parts: [{ text: ov.areaFrom === 'exact' ? `∫f = ${fmt(ov.area, 4)} (exact; the grid gives ${fmt(ov.trapezoid, 4)})` : `∫|f| ≈ ${fmt(ov.area, 4)}`, className: 'fit' }] },
    ...ov.pdfs.map((p) => ({ name: p.name, color: sceneColor(state, p.name), parts: [] })),
  ]);
  if (dom.overlayNote) {
    dom.overlayNote.textContent = 'f divided by ∫|f| (black, unit area; trapezoid rule on the grid) against each estimator\'s'
      + ' sampling density p(x): where p is much smaller than |f|, the weights f/p are large.'
      + (ov.areaFrom === 'exact' ? ' Here f is divided by its exact integral: the grid misses the mass of its singularity.' : '')
      + (ov.clipped ? ` The y axis is cut at ${fmt(ov.yRange[1], 3)}: a spike goes above it.` : '');
  }
}

const DASHES = [[], [8, 5], [2, 4], [10, 4, 2, 4]];

function renderMisWeights(state, data) {
  if (!dom.misweights) return;
  const lines = data ? misWeightCurves(data, data.estimators.map((e) => e.name)) : [];
  dom.misweightsBlock.hidden = !lines.length;
  if (!lines.length) {
    drop('misweights');
    setLegend('misweights', dom['legend-misweights'], []);
    return;
  }
  const x = data.curve.x;
  const series = [{}, ...lines.map((l) => ({
    label: `${l.name}: ${l.label}`, stroke: sceneColor(state, l.name), width: 1.75,
    dash: DASHES[l.k % DASHES.length], points: { show: false },
  }))];
  draw('misweights', dom.misweights, JSON.stringify(['misweights', lines.map((l) => [l.name, l.k])]), (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => [0, 1.02] } },
    axes: [{ ...AXIS, label: 'x', space: 40 }, { ...AXIS, label: 'weight', size: 52 }],
    series,
    cursor: { drag: { x: false, y: false } },
  }), [x, ...lines.map((l) => l.y)], { xRange: [x[0], x[x.length - 1]] });
  setLegend('misweights', dom['legend-misweights'], lines.map((l) => ({
    name: l.name, color: sceneColor(state, l.name), dashed: l.k > 0,
    data: { misweights: l.name, technique: String(l.k) }, parts: [{ text: l.label, className: 'fit' }],
  })));
}

function renderWeights(state, weights) {
  if (!weights || !weights.estimators.length) {
    drop('weights');
    empty(dom.weights, 'No weights yet.');
    setLegend('weights', dom['legend-weights'], []);
    return;
  }
  const bins = weightBins(weights.estimators.map((e) => e.weight));
  const hs = weights.estimators.map((e) => ({ name: e.name, h: weightHistogram(e.weight, bins) }));
  if (!bins) {
    drop('weights');
    empty(dom.weights, 'Every weight is 0 (or not finite).');
  } else {
    const x = bins.logEdges;
    const data = [x, ...hs.map(({ h }) => [...h.fraction, h.fraction[h.fraction.length - 1]].map((v) => (v > 0 ? Math.log10(v) : null)))];
    const stepped = uPlot.paths.stepped({ align: 1 });
    const series = [{}, ...hs.map(({ name }) => {
      const color = sceneColor(state, name);
      return { label: name, stroke: color, width: 2, paths: stepped, points: { show: false } };
    })];
    const lowest = Math.floor(Math.log10(1 / Math.max(...hs.map(({ h }) => h.total || 1))));
    draw('weights', dom.weights, JSON.stringify(['weights', hs.map((h) => h.name)]), (c) => ({
      scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
      axes: [{ ...AXIS, values: log10Ticks, incrs: LOG10_AXIS.incrs, label: '|w| = |f / p|', space: 30 },
        { ...AXIS, ...LOG10_AXIS, label: 'fraction of the points' }],
      series,
      cursor: { drag: { x: false, y: false } },
    }), data, { xRange: [x[0], x[x.length - 1]], yRange: [lowest, 0.15] });
  }
  setLegend('weights', dom['legend-weights'], hs.map(({ name, h }) => {
    const parts = [{ text: h.tail === null ? 'max|w| / mean|w| = —' : `max|w| / mean|w| = ${fmt(h.tail, 3)}`, className: 'fit' }];
    if (h.zeros) parts.push({ text: `${h.zeros} zero weights`, className: 'fit' });
    // the first edge may be a fractional power of ten (4 bins per decade)
    if (h.below) parts.push({ text: `${h.below} below ${fmt(10 ** bins.logEdges[0], 2)} (over 12 decades under the largest)`, className: 'fit' });
    if (h.negative) parts.push({ text: `${h.negative} negative`, className: 'fit' });
    if (h.nonFinite) parts.push({ text: `${h.nonFinite} not finite`, className: 'badge' });
    return { name, color: sceneColor(state, name), data: { weights: name, zeros: String(h.zeros) }, parts };
  }));
}

/**
 * The chart `key` as a PNG data URL: the canvas (axes and series) on white, with the plot's
 * title above and its legend lines below. null when the chart is not drawn.
 */
/**
 * The chart `key` as a PNG data URL at `scale` times the device's resolution (drawn again at that
 * pixel ratio for the export, withPixelRatio), with its title, `subtitle` and legend; null
 * for an empty chart.
 */
export async function plotPng(key, subtitle = '', scale = 2) {
  const c = charts[key];
  if (!c || !c.u) return null;
  return withPixelRatio(scale * devicePixelRatioNow(), () => composePng(key, subtitle));
}

function composePng(key, subtitle) {
  const c = charts[key];
  if (!c || !c.u) return null;
  const src = c.u.ctx.canvas;
  const px = src.width / c.u.width || 1;
  const legendItems = [...(dom[`legend-${key}`] ? dom[`legend-${key}`].children : [])];
  const line = 18 * px;
  const head = (subtitle ? 46 : 28) * px;
  const out = document.createElement('canvas');
  out.width = src.width;
  out.height = head + src.height + (legendItems.length ? legendItems.length * line + 10 * px : 0);
  const ctx = out.getContext('2d');
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, out.width, out.height);
  ctx.fillStyle = '#1b1f24';
  ctx.font = `bold ${14 * px}px "DejaVu Sans", sans-serif`;
  ctx.textBaseline = 'middle';
  const title = document.getElementById(`${key}-title`);
  ctx.fillText(title ? title.textContent : key, 10 * px, 14 * px);
  if (subtitle) {
    // the scene and the estimators shown: a PNG names what it plots
    ctx.font = `${12 * px}px "DejaVu Sans", sans-serif`;
    ctx.fillText(subtitle, 10 * px, 34 * px, out.width - 20 * px);
  }
  ctx.drawImage(src, 0, head);
  ctx.font = `${12 * px}px "DejaVu Sans", sans-serif`;
  legendItems.forEach((li, i) => {
    const y = head + src.height + 5 * px + (i + 0.5) * line;
    const sw = li.querySelector('.swatch');
    ctx.fillStyle = sw ? getComputedStyle(sw).backgroundColor : '#000';
    ctx.fillRect(10 * px, y - 2 * px, 16 * px, 4 * px);
    ctx.fillStyle = '#1b1f24';
    const text = [...li.childNodes].map((n) => n.textContent.trim()).filter(Boolean).join('  ');
    ctx.fillText(text.replace(/\s+/g, ' '), 32 * px, y);
  });
  return out.toDataURL('image/png');
}
