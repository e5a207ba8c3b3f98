// The canvases of the sample view (samples.js), drawn without uPlot: a panel mapping a range
// to a canvas with its frame, the points as dots, strata grids, VEGAS's map lines, MISER's
// boxes, the running estimate of the first k points with its band, and the sentence saying
// what structure a point set has (strataText).
import { runningEstimate, fmt } from '../series.js';
import { withAlpha } from '../palette.js';
import { textPx, largeText } from '../ui/text_size.js';

export const PANEL = 240; // logical size of a scatter panel (CSS scales it to the card)
const PAD = { l: 38, r: 6, t: 6, b: 18 };

/** The panels' label size in logical pixels: 10, or in large-text mode 16 / 0.8, so that the
 *  labels stay at least 16 CSS pixels on a canvas the page shows down to 0.8 of its size. */
const labelPx = () => (largeText() ? textPx(10) / 0.8 : 10);

/** A canvas of w x h logical pixels with a plot area mapping [xr] x [yr]; returns helpers. */
export function panel(w, h, xr, yr, padLeft = PAD.l) {
  const k = labelPx() / 10; // room for the labels
  const P = { ...PAD, l: Math.round(padLeft * k), b: Math.round(PAD.b * k) };
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
    ctx.font = `${labelPx()}px "DejaVu Sans", sans-serif`;
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

/** The points (xs[i], ys[i]) as dots of `color`, smaller when the whole set (n) is larger. */
export function dots(ctx, xs, ys, X, Y, color, n) {
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
export function strataLines(p, cells, axis) {
  if (!(cells > 1) || cells > GRID_MAX) return;
  linesAt(p, Array.from({ length: cells - 1 }, (_, k) => (k + 1) / cells), axis, 'rgba(90, 100, 112, 0.45)');
}


/**
 * VEGAS's map on the first two axes of the unit square: a line at every edge of its increments
 * (every k-th edge when there are more than GRID_MAX), so that dense lines show where the map
 * puts its points.
 */
export function mapLines(p, edges, axis) {
  if (!Array.isArray(edges) || edges.length < 3) return;
  const step = Math.ceil((edges.length - 1) / GRID_MAX);
  const inner = edges.filter((_, k) => k > 0 && k < edges.length - 1 && k % step === 0);
  linesAt(p, inner, axis, 'rgba(150, 80, 20, 0.45)');
}


/** MISER's leaf boxes on the first two axes of the unit square (1D: their left edges). */
export function boxOutlines(p, boxes, d, [a, b] = [0, 1]) {
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

/**
 * A randomized quasi-Monte Carlo set of K > 1 randomizations (e.randomizations): how many points
 * its first randomization holds, or null for any other set (all its points are one design).
 * The core gives the points randomization by randomization, so these are the first points;
 * drawn together, K randomizations of a net look like independent points.
 */
export function firstRandomizationSize(e) {
  const n = e && Array.isArray(e.u) && e.u.length ? e.u[0].length : 0;
  const k = e ? e.randomizations : 0;
  if (!(Number.isSafeInteger(k) && k > 1) || n < k) return null;
  return Math.floor(n / k);
}

/**
 * The cells of a Sobol' net drawn over its first two axes: 2^m points of one randomization
 * (Owen scrambling and digital shifts keep the net) hold one point in each of 2^⌊m/2⌋ × 2^⌈m/2⌉
 * cells (the first two Sobol' axes are a (0, 2)-sequence). [cells across, cells up], or null
 * when the set is not a Sobol' set of a power of two points, or the axes are not the first two.
 */
export function sobolNetCells(e, points, axes = [0, 1]) {
  if (!e || e.sampler !== 'sobol') return null;
  if (axes[0] !== 0 || axes[1] !== 1) return null;
  if (!(Number.isSafeInteger(points) && points >= 4 && (points & (points - 1)) === 0)) return null;
  const m = Math.round(Math.log2(points));
  return [2 ** Math.floor(m / 2), 2 ** Math.ceil(m / 2)];
}

/** What structure a point set has: strata, a VEGAS map, MISER boxes, randomized QMC sets. */
export function strataText(e, d) {
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
export function runningPanel(e, k, exact, color, band = true) {
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
  p.ctx.font = `${labelPx()}px "DejaVu Sans", sans-serif`;
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
