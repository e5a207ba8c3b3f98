// Renders the state into the four uPlot charts and their legends: variance (or MSE) against N,
// error against time per estimate, the z-score histogram and the coverage against N. A pure
// render of the state: it reads state.run and writes only into the plot containers and legends.
// A chart is rebuilt when its set of series changes and otherwise gets setData.
import uPlot from '../vendor/uPlot.esm.js';
import {
  varianceSeries, anchorOf, referenceLines, timeSeries, calibrationSeries, coverageSeries,
  decadeRange, fitText, fmt,
} from './series.js';
import { colorAt, withAlpha } from './palette.js';

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
  const every = shown.length * 42 > width ? (shown.length * 21 > width ? 4 : 2) : 1;
  const last = Math.round(Math.log2(shown[shown.length - 1] || 1));
  return splits.map((v) => {
    if (typeof v !== 'number' || !(v > 0)) return '';
    const k = Math.round(Math.log2(v));
    if (Math.abs(v - 2 ** k) > 1e-6 * v || (last - k) % every !== 0) return '';
    return v <= 65536 ? String(v) : `2${sup(k)}`;
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
    c.u = new uPlot({ ...plotSize(el), legend: { show: false }, padding: [14, 36, 0, 0], ...opts }, data, el);
    charts[key] = c;
  } else {
    Object.assign(c, ranges);
    c.u.setData(data);
  }
  return c;
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

// ---------------------------------------------------------------------------------------------
// Legends (plain DOM; text only, never HTML from data)

function el(tag, props = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'dataset') Object.assign(e.dataset, v);
    else if (k === 'style') e.style.cssText = v;
    else e[k] = v;
  }
  for (const c of children) if (c !== null && c !== undefined) e.append(c);
  return e;
}

function swatch(color, dashed = false) {
  return el('span', {
    className: 'swatch',
    style: dashed ? `background: repeating-linear-gradient(90deg, ${color} 0 4px, transparent 4px 7px)` : `background: ${color}`,
  });
}

function badge(w) {
  return el('span', { className: 'badge', title: w.message }, w.code);
}

const legendSigs = {};

function setLegend(key, ul, items) {
  const sig = JSON.stringify(items);
  if (legendSigs[key] === sig && ul.childElementCount === items.length) return;
  legendSigs[key] = sig;
  ul.replaceChildren(...items.map((it) => el('li', { dataset: it.data || {} },
    swatch(it.color, it.dashed),
    el('span', { className: it.ref ? 'name ref' : 'name' }, it.name),
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
    for (const k of ['variance', 'time', 'calibration', 'coverage']) ro.observe(dom[k]);
  }
}

function colorOf(run, name) {
  return colorAt(run.colors && name in run.colors ? run.colors[name] : run.order.indexOf(name));
}

/** Draws everything of state.run. */
export function renderPlots(state) {
  if (!dom) return;
  const run = state.run;
  if (!run.order.length) {
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

function renderVariance(state, run, records) {
  const vs = varianceSeries(records, run.order, run.exact, run.ladder);
  const anchor = anchorOf(vs.x, vs.series);
  const refs = referenceLines(vs.x, anchor);
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
  // Three reference series always (all null until there is a first point), so the chart keeps
  // its series while the levels stream in.
  const refItems = [];
  ['N⁻¹', 'N⁻²', 'N⁻³'].forEach((label, i) => {
    refItems.push({ idx: data.length, label });
    data.push(refs[i] ? lgAll(refs[i].y) : vs.x.map(() => null));
    series.push({ label, stroke: '#8a8f96', width: 1, dash: [6, 5], points: { show: false } });
  });
  const values = vs.series.flatMap((s) => [...s.y, ...s.lo, ...s.hi]);
  const yRange = log10Range(values);
  const xRange = vs.x.length > 1 ? [vs.x[0], vs.x[vs.x.length - 1]] : [vs.x[0] / 2, vs.x[0] * 2];
  const quantity = vs.quantity === 'mse' ? 'MSE of the estimate' : 'variance of the estimate';
  const title = document.getElementById('variance-title');
  if (title) title.textContent = vs.quantity === 'mse' ? 'MSE against N (exact value known)' : 'Variance against N';
  const sig = JSON.stringify([vs.quantity, run.order, run.colors]);
  draw('variance', dom.variance, sig, (c) => ({
    scales: { x: logX(c, 2), y: log10Y(c) },
    axes: [
      { ...AXIS, label: 'N [samples]', values: nTicks, space: 30 },
      { ...AXIS, ...LOG10_AXIS, label: quantity },
    ],
    series,
    bands,
    cursor: { drag: { x: false, y: false } },
    hooks: { drawAxes: [minorLogGrid], draw: [(u) => labelHook(refItems)(u)] },
  }), data, { xRange, yRange });

  setLegend('variance', dom['legend-variance'], vs.series.map((s) => {
    const r = records[s.name];
    return {
      name: s.name,
      color: colorOf(run, s.name),
      parts: [
        vs.quantity === 'mse' ? 'order of variance' : 'order',
        { fit: fitText(r.fit), name: s.name },
        ...(r.warnings || []).map((w) => ({ warning: w })),
      ],
    };
  }));
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
    for (const { color, points } of getPaths()) {
      ctx.strokeStyle = color;
      ctx.lineWidth = 2 * px;
      ctx.beginPath();
      points.forEach(([x, y], i) => {
        const cx = u.valToPos(x, 'x', true);
        const cy = u.valToPos(y, 'y', true);
        if (i === 0) ctx.moveTo(cx, cy);
        else ctx.lineTo(cx, cy);
      });
      ctx.stroke();
    }
    ctx.restore();
  };
}

function renderTime(state, run, records) {
  const ts = timeSeries(records, run.order);
  const data = [ts.x, ...ts.series.map((s) => lgAll(s.y))];
  const noLine = () => null;
  const series = [{}, ...ts.series.map((s) => {
    const color = colorOf(run, s.name);
    return { label: s.name, stroke: color, width: 2, paths: noLine, points: { show: true, size: 7, fill: color } };
  })];
  const lines = ts.series.map((s) => ({ color: colorOf(run, s.name), points: s.points.map(([t, e]) => [t, lg(e)]) }));
  const known = run.exact !== null && run.exact !== undefined;
  const xRange = decadeRange(ts.x, [1e-6, 1]);
  const yRange = log10Range(ts.series.flatMap((s) => s.y));
  const sig = JSON.stringify([run.order, run.colors, known]);
  if (!ts.x.length) {
    drop('time');
    empty(dom.time, run.status === 'running' ? 'Waiting for the first N…' : 'No timings.');
  } else {
    draw('time', dom.time, sig, (c) => ({
      scales: { x: logX(c, 10), y: log10Y(c) },
      axes: [
        { ...AXIS, label: 'wall time per estimate [seconds]', values: (u, splits) => splits.map(decadeLabel), space: 20 },
        { ...AXIS, ...LOG10_AXIS, label: known ? 'RMSE (error against the exact value)' : 'error = sqrt(variance)' },
      ],
      series,
      cursor: { drag: { x: false, y: false } },
      hooks: { drawAxes: [minorLogGrid], draw: [(u) => pathsInOrder(() => charts.time.lines)(u)] },
    }), data, { xRange, yRange, lines });
  }
  setLegend('time', dom['legend-time'], ts.series.map((s) => ({
    name: s.name,
    color: colorOf(run, s.name),
    parts: [s.slope === null ? '' : { text: `error ∝ t^${s.slope.toFixed(2)}`, className: 'fit' }],
  })));
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
  const sig = JSON.stringify([run.order, run.colors]);
  const known = run.exact !== null && run.exact !== undefined;
  draw('calibration', dom.calibration, sig, (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
    axes: [
      { ...AXIS, label: known ? 'z = (estimate − exact) / std. error' : 'z = (estimate − mean of replicates) / std. error', space: 40 },
      { ...AXIS, label: 'density', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 2)) },
    ],
    series,
    cursor: { drag: { x: false, y: false } },
  }), data, { xRange: [cs.x[0], cs.x[cs.x.length - 1]], yRange: [0, Math.ceil(ymax * 1.1 * 10) / 10] });

  const note = document.getElementById('calibration-note');
  if (note) {
    note.textContent = known
      ? 'Histogram of z = (estimate − exact) / std. error over the replicates, against the standard normal density (black): calibrated error bars follow it; about 95% of z lie within ±1.96.'
      : 'No exact value: z is taken against each N\'s mean of the replicates, which checks the size of the error bars but not a bias.';
  }
  setLegend('calibration', dom['legend-calibration'], [
    { name: 'N(0, 1)', color: '#000', ref: true, parts: [] },
    ...cs.series.map((s) => {
      const parts = [];
      if (s.total) parts.push({ text: `${(100 * s.within2 / s.total).toFixed(0)}% within ±1.96 (${s.total} z)`, className: 'fit' });
      else parts.push('no replicates yet');
      if (s.below + s.above) parts.push({ text: `${s.below + s.above} beyond ±5`, className: 'badge' });
      if (s.zeroSe) parts.push({ text: `${s.zeroSe} with a zero error bar`, className: 'badge' });
      return { name: s.name, color: colorOf(run, s.name), parts };
    }),
  ]);
}

function renderCoverage(state, run, records) {
  const cs = coverageSeries(records, run.order, run.ladder);
  const reps = run.settings ? run.settings.reps : 32;
  const half = 1.96 * Math.sqrt(0.95 * 0.05 / reps);
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
  const known = run.exact !== null && run.exact !== undefined;
  if (!known) {
    drop('coverage');
    empty(dom.coverage, 'Coverage needs the exact value, which this scene does not know.');
  } else {
    const xRange = cs.x.length > 1 ? [cs.x[0], cs.x[cs.x.length - 1]] : [cs.x[0] / 2, cs.x[0] * 2];
    draw('coverage', dom.coverage, JSON.stringify([run.order, run.colors, reps]), (c) => ({
      scales: { x: logX(c, 2), y: { range: () => c.yRange } },
      axes: [
        { ...AXIS, label: 'N [samples]', values: nTicks, space: 30 },
        { ...AXIS, label: 'coverage of the 95% intervals', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 2)) },
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
      parts: [{ text: last === undefined ? '—' : `${fmt(last, 3)} at the largest N`, className: 'fit' }],
    };
  }));
}

/**
 * The chart `key` as a PNG data URL: the canvas (axes and series) on white, with the plot's
 * title above and its legend lines below. null when the chart is not drawn.
 */
export function plotPng(key) {
  const c = charts[key];
  if (!c || !c.u) return null;
  const src = c.u.ctx.canvas;
  const px = src.width / c.u.width || 1;
  const legendItems = [...(dom[`legend-${key}`] ? dom[`legend-${key}`].children : [])];
  const line = 18 * px;
  const head = 28 * px;
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
  ctx.fillText(title ? title.textContent : key, 10 * px, head / 2);
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
