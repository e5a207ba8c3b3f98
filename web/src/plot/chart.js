// uPlot charts by key ('variance', 'time', 'calibration', 'coverage', 'overlay', 'misweights',
// 'weights'): each built in its element, rebuilt when its set of series changes and otherwise
// given new data (draw), with a hover readout and the hidden estimators applied; the page's
// plot elements (dom, filled by plot.js); and the parts the log-scale plots share (scales, N
// ticks, log-paper grid). The only module that imports uPlot: pixel_ratio.js first, so that it
// keeps uPlot's pixel-ratio listeners (PNG exports at 2x); the others take uPlot from here.
import '../pixel_ratio.js';
import uPlot from '../../vendor/uPlot.esm.js';
import { fmt } from '../series.js';
import { el } from '../dom.js';
import { nTickLabels, axisPx, fitAxisTitle } from './axes.js';
import { hidesLabel } from './legend.js';
import { textPx, onTextSize } from '../ui/text_size.js';

export { uPlot };

export const charts = {}; // key -> {u, sig, el, xRange, yRange, ...the ranges given to draw}

/** The plot and legend elements by key ('variance', 'legend-variance', 'samples', ...). */
export const dom = {};

function plotSize(el) {
  const width = Math.max(280, Math.floor(el.clientWidth || 480));
  const height = Math.round(Math.min(380, Math.max(240, width * 0.58)));
  return { width, height };
}

/** Resizes the charts whose element changed size. */
export function resizeAll() {
  for (const c of Object.values(charts)) {
    if (!c.u) continue;
    const size = plotSize(c.el);
    if (size.width !== c.u.width || size.height !== c.u.height) c.u.setSize(size);
  }
}

/** Replaces what `el` shows by a line of text (no chart). */
export function empty(el, text) {
  el.replaceChildren();
  const d = document.createElement('div');
  d.className = 'empty';
  d.textContent = text;
  el.append(d);
}

/** Sets the text of the element `id` (a title or a note), when it differs. */
export function setText(id, text) {
  const e = document.getElementById(id);
  if (e && e.textContent !== text) e.textContent = text;
}

export function drop(key) {
  const c = charts[key];
  if (c) {
    c.u.destroy();
    delete charts[key];
  }
}

const fittedTitle = (title) => (u, i) => {
  const along = u.axes[i].side % 2 === 0 ? u.bbox.width : u.bbox.height;
  return fitAxisTitle(title, (t) => u.ctx.measureText(t).width <= along);
};

/** The axes of a chart in the current text size: room for larger ticks and titles in
 *  large-text mode (sizes and spacing scaled with the font), titles fitted to their axis. */
function sizedAxes(axes) {
  const k = axisPx() / 12;
  return axes.map((a) => {
    const b = { ...a };
    if (typeof b.label === 'string') b.label = fittedTitle(b.label);
    if (k === 1) return b;
    if (typeof b.size !== 'function') b.size = Math.round((b.size ?? 50) * k);
    b.labelSize = Math.round((b.labelSize ?? 30) * k);
    if (typeof b.space === 'number') b.space = Math.round(b.space * k);
    return b;
  });
}

function build(key, c, data) {
  const opts = c.makeOpts(c);
  const hooks = { ...(opts.hooks || {}), setCursor: [...((opts.hooks && opts.hooks.setCursor) || []), readout(key)] };
  if (opts.axes) opts.axes = sizedAxes(opts.axes);
  c.u = new uPlot({ ...plotSize(c.el), legend: { show: false }, padding: [14, 36, 0, 0], ...opts, hooks }, data, c.el);
}

/** Builds every chart again with its data (the text size changed: fonts and room). */
export function rebuildAll() {
  for (const [key, c] of Object.entries(charts)) {
    const { data } = c.u;
    c.u.destroy();
    c.el.replaceChildren();
    build(key, c, data);
    applyHidden(c);
  }
}
onTextSize(rebuildAll);

/** Creates or updates chart `key` in `el`: `sig` changes when the series change. */
export function draw(key, el, sig, makeOpts, data, ranges) {
  let c = charts[key];
  if (!c || c.sig !== sig || c.el !== el) {
    drop(key);
    el.replaceChildren();
    c = { sig, el, makeOpts, ...ranges };
    build(key, c, data);
    charts[key] = c;
  } else {
    Object.assign(c, ranges);
    c.u.setData(data);
  }
  applyHidden(c);
  return c;
}

// Plots whose y values are log10 of what they show (axes.js: lg).
const LOG10_Y = new Set(['variance', 'time', 'live-spp', 'live-seconds']);

/** The hover readout of a chart: the x under the cursor and each shown estimator's value there
 *  (bands, references and hidden series left out), in a box in the plot's corner; a chart's
 *  `readoutWords(series, index)` (given with its ranges) may put words in a value's place. */
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
      // a value the chart shows in words (a relative MSE at the reference's noise)
      const words = charts[key] && charts[key].readoutWords ? charts[key].readoutWords(k, i) : null;
      lines.push(`${ser.label}: ${words || fmt(LOG10_Y.has(key) ? 10 ** v : v, 3)}`);
    });
    if (!lines.length) {
      box.hidden = true;
      return;
    }
    box.hidden = false;
    box.textContent = `${key === 'time' || key === 'live-seconds' ? 't' : key === 'calibration' ? 'z' : key === 'live-spp' ? 'spp' : 'N'} = ${fmt(x, 4)}\n${lines.join('\n')}`;
  };
}

/** Shows or hides each series of a chart by the estimator it belongs to (legend.js). */
function applyHidden(c) {
  if (!c || !c.u) return;
  c.u.series.forEach((ser, i) => {
    if (i === 0 || typeof ser.label !== 'string') return;
    const hide = hidesLabel(ser.label);
    if (Boolean(ser.show) === hide) c.u.setSeries(i, { show: !hide });
  });
}

/** Applies the hidden estimators to every chart and redraws them (after a legend click). */
export function applyHiddenAll() {
  for (const c of Object.values(charts)) {
    applyHidden(c);
    if (c && c.u) c.u.redraw(false);
  }
}

// ---------------------------------------------------------------------------------------------
// Log scales

/** A log x scale (base 2 for N, 10 for time) over c.xRange. */
export function logX(c, base = 2) {
  return { time: false, distr: 3, log: base, range: () => c.xRange };
}

/** A y scale holding log10 of the values (axes.js: lg) over c.yRange. */
export function log10Y(c) {
  return { range: () => c.yRange };
}

/** N ticks (powers of two): plain up to 65536, then 2^k; thinned to what fits. */
export function nTicks(u, splits) {
  return nTickLabels(u.bbox.width / (uPlot.pxRatio || 1), splits);
}

/** Minor grid lines at 2..9 x 10^k on a log10 y axis (log paper), under the series. */
export function minorLogGrid(u) {
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

/** Draws labels at the last visible point of the given series (reference lines), left-aligned
 *  there and kept within the plot (shortened where it is narrower than the label). */
export function labelHook(items) {
  return (u) => {
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    ctx.font = `${textPx(11) * px}px "DejaVu Sans", sans-serif`;
    ctx.fillStyle = '#555';
    ctx.textAlign = 'left';
    ctx.textBaseline = 'bottom';
    const { min: ymin, max: ymax } = u.scales.y;
    for (const { idx, label } of items) {
      const ys = u.data[idx];
      if (!ys) continue;
      let last = -1;
      for (let i = 0; i < ys.length; i++) if (ys[i] !== null && ys[i] >= ymin && ys[i] <= ymax) last = i;
      if (last < 0) continue;
      // within the plot's width: shortened as axis titles are where it does not fit (a phone)
      const text = fitAxisTitle(label, (t) => ctx.measureText(t).width <= u.bbox.width - 4 * px);
      const w = ctx.measureText(text).width;
      let x = u.valToPos(u.data[0][last], 'x', true) + 4 * px;
      x = Math.max(u.bbox.left + 2 * px, Math.min(x, u.bbox.left + u.bbox.width - w - 2 * px));
      const y = Math.max(u.bbox.top + (textPx(11) + 1) * px, u.valToPos(ys[last], 'y', true) - 2 * px);
      ctx.fillText(text, x, y);
    }
    ctx.restore();
  };
}
