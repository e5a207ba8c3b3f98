// The plots' axes, without uPlot or the DOM (so web/test can import it): fonts and axis style
// (larger in large-text mode),
// tick labels of log axes (10⁻³, N as 2¹⁷), the log10 transform of the y values of the
// variance and error plots, short durations, and the axis texts of a run (N or spp, variance
// or relative MSE).
import { decadeRange } from '../series.js';
import { textPx } from '../ui/text_size.js';

/** The axes' font size in CSS pixels (16 in large-text mode: ui/text_size.js). */
export const axisPx = () => textPx(12);
const FAMILY = '"DejaVu Sans", system-ui, sans-serif';
/** The style every axis shares; its fonts read when a chart is built (spread), so that a chart
 *  built in large-text mode gets the large fonts (chart.js gives them the room they need). */
export const AXIS = {
  stroke: '#1b1f24',
  get font() { return `${axisPx()}px ${FAMILY}`; },
  get labelFont() { return `bold ${axisPx()}px ${FAMILY}`; },
  grid: { stroke: '#e3e7eb', width: 1 },
  ticks: { stroke: '#b8c0c8', width: 1 },
};
const SUPERSCRIPT = { '-': '⁻', 0: '⁰', 1: '¹', 2: '²', 3: '³', 4: '⁴', 5: '⁵', 6: '⁶', 7: '⁷', 8: '⁸', 9: '⁹' };

/** An integer in superscript digits: -3 -> "⁻³". */
export function sup(n) {
  return String(n).split('').map((c) => SUPERSCRIPT[c] ?? c).join('');
}

/** 10^k as "10⁻³" (1 and 10 plainly); other values get no label (log-paper minor ticks). */
export function decadeLabel(v) {
  if (typeof v !== 'number' || !(v > 0)) return '';
  const k = Math.round(Math.log10(v));
  if (Math.abs(v / 10 ** k - 1) > 1e-9) return '';
  if (k === 0) return '1';
  if (k === 1) return '10';
  return `10${sup(k)}`;
}

/** Labels of N ticks (powers of two) on an axis `width` CSS pixels wide: plain up to 65536,
 *  then 2^k; thinned to what fits. */
export function nTickLabels(width, splits) {
  const shown = splits.filter((v) => typeof v === 'number' && v > 0);
  const last = Math.round(Math.log2(shown[shown.length - 1] || 1));
  // One notation per axis: plain numbers while the largest fits in 6 digits, else 2^k for all.
  const powers = 2 ** last > 999999;
  // Labels on every `every`-th split (counted from the last), as many as fit side by side
  // (about 8.5 px a character of the axis font, and a gap).
  const need = (powers ? 3 : String(2 ** last).length) * 8.5 * (axisPx() / 12) + 10;
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

// The y axes of the variance and error plots hold log10 of the values on a linear scale:
// uPlot's own log scale only knows increments between 1e-32 and 1e32, and an (almost) exact
// estimator's variance goes below that.
export const lg = (v) => (v === null || v === undefined ? null : Math.log10(v));
export const lgAll = (a) => a.map(lg);

/** [lo, hi] in whole decades, as log10. */
export function log10Range(values) {
  return decadeRange(values).map((v) => Math.round(Math.log10(v)));
}

/** Tick labels of a log10 axis: 10^k at whole k, nothing between. */
export function log10Ticks(u, splits) {
  return splits.map((v) => (typeof v === 'number' && Math.abs(v - Math.round(v)) < 1e-9 ? decadeLabel(Number(`1e${Math.round(v)}`)) : ''));
}

export const LOG10_AXIS = { values: log10Ticks, incrs: [1, 2, 3, 4, 5, 10, 20, 50, 100], size: 62, space: 22 };

/**
 * An axis title that fits along its axis: `fits(text)` says whether a text fits; the title is the
 * whole title where it fits the plot's width (x) or height (y), else the title without its
 * parenthesised and bracketed asides, else that cut (at a word where it can) with an ellipsis;
 * never clipped by the canvas (a phone's narrow plots).
 */
export function fitAxisTitle(title, fits) {
  if (fits(title)) return title;
  const plain = title.replace(/\s*[([][^()[\]]*[)\]]/g, '').trim();
  if (plain && fits(plain)) return plain;
  let t = plain || title;
  // whole words first, then characters
  while (t.includes(' ') && !fits(`${t}…`)) t = t.slice(0, t.lastIndexOf(' ')).trimEnd();
  while (t.length > 1 && !fits(`${t}…`)) t = t.slice(0, -1).trimEnd();
  return `${t}…`;
}

/** A duration in seconds, short: 0.1 ms, 25 us, 1.5 s. */
export function shortSeconds(t) {
  if (t >= 1) return `${+t.toPrecision(2)} s`;
  if (t >= 1e-3) return `${+(t * 1e3).toPrecision(2)} ms`;
  return `${+(t * 1e6).toPrecision(2)} µs`;
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

/** True for a render study's run (its N is spp, its error a relative MSE against a reference). */
export const isRender = (run) => run.kind === 'render';
