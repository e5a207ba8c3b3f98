// Variance (or MSE) against N: aligned uPlot series with confidence bands, the anchor of the
// reference slopes, and the fitted slope of a log-log line.
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.
import { ladder, positive, unionSorted } from './numbers.js';
import { levelExactness, recordExactness } from '../claims/exact.js';
import { infiniteVariance } from '../claims/fit.js';

/**
 * The variance plot: x = every N any estimator has reached; per estimator y = its MSE when
 * the exact value is known (`exact` not null), else its variance, and the band lo/hi = the
 * core's variance_ci95 (chi-square interval of the variance). For the MSE the band is the same
 * interval scaled by mse / variance: the same relative uncertainty, centred on the plotted
 * value. Values that cannot sit on a log axis (0, null) are null. `xs` (optional) fixes the x
 * values, e.g. the whole N ladder of a run that is still going.
 */
// Under an infinite variance (the core's heavy_tail at warning or error: claims/fit.js) lo and hi
// are null: a chi-square interval describes a finite variance, and the plotted level of an
// infinite one is dominated by the largest weights seen so far (`infinite` true).
// noiseAt (per x): a render level at the reference's noise (below_reference_noise), whose value
// the page shows in words (claims/reference_noise.js).
// Each series also has exactAt (per x: 'exact' when that level's replicates equal the exact value
// to round-off, 'agree' when they only agree with each other (claims/exact.js), else false; y is
// null at both, a variance of 0 having no place on a log axis) and exact ('exact' or 'agree' when
// every level so far is, else null).
export function varianceSeries(records, order, exact = null, xs = null) {
  const useMse = exact !== null && exact !== undefined && Number.isFinite(exact);
  const named = order.filter((n) => records[n]);
  const x = xs ? xs.slice() : unionSorted(named.flatMap((n) => records[n].levels.map((l) => l.n)));
  const series = named.map((name) => {
    const byN = new Map(records[name].levels.map((l) => [l.n, l]));
    const infinite = infiniteVariance(records[name]);
    const y = [];
    const lo = [];
    const hi = [];
    const exactAt = [];
    const noiseAt = [];
    for (const n of x) {
      const l = byN.get(n);
      noiseAt.push(Boolean(l && l.below_reference_noise === true));
      const kind = l ? levelExactness(l, useMse ? exact : null) : 'no';
      exactAt.push(kind === 'no' ? false : kind);
      if (!l || kind !== 'no') {
        // an exact level (variance zero up to round-off) has no point on a log axis: the plot
        // marks it apart
        y.push(null); lo.push(null); hi.push(null);
        continue;
      }
      const variance = l.variance;
      const v = useMse && l.mse !== null && l.mse !== undefined ? l.mse : variance;
      y.push(positive(v));
      const ci = infinite ? null : l.variance_ci95;
      const scale = v === variance ? 1 : (positive(variance) ? v / variance : NaN);
      lo.push(ci ? positive(ci[0] * scale) : null);
      hi.push(ci ? positive(ci[1] * scale) : null);
    }
    const all = recordExactness(records[name], useMse ? exact : null).all;
    return { name, y, lo, hi, exactAt, noiseAt, exact: all, infinite, fit: records[name].fit || null };
  });
  return { quantity: useMse ? 'mse' : 'variance', x, series };
}

/** Where reference slopes start: the smallest N with a point, at the largest y there. */
export function anchorOf(x, series) {
  for (let i = 0; i < x.length; i++) {
    let y = null;
    for (const s of series) if (s.y[i] !== null && (y === null || s.y[i] > y)) y = s.y[i];
    if (y !== null) return { x: x[i], y };
  }
  return null;
}

/** Lines y = anchor.y (x / anchor.x)^-k for k in `orders` (N^-1, N^-2, N^-3 by default). */
export function referenceLines(x, anchor, orders = [1, 2, 3]) {
  if (!anchor) return [];
  return orders.map((k) => ({
    order: -k,
    label: `N^-${k}`,
    y: x.map((v) => anchor.y * (v / anchor.x) ** -k),
  }));
}

/**
 * Least-squares slope of log y on log x over the pairs where both are > 0 and finite:
 * {slope, intercept (of ln y at ln x = 0), n}, or null with fewer than two distinct x.
 * (The fitted order in the legend is the core's fit.order; this is for the plots' own lines.)
 */
export function fitSlope(xs, ys) {
  const px = [];
  const py = [];
  for (let i = 0; i < Math.min(xs.length, ys.length); i++) {
    if (positive(xs[i]) !== null && positive(ys[i]) !== null) {
      px.push(Math.log(xs[i]));
      py.push(Math.log(ys[i]));
    }
  }
  const n = px.length;
  if (n < 2) return null;
  const mx = px.reduce((s, v) => s + v, 0) / n;
  const my = py.reduce((s, v) => s + v, 0) / n;
  let sxx = 0;
  let sxy = 0;
  for (let i = 0; i < n; i++) {
    sxx += (px[i] - mx) ** 2;
    sxy += (px[i] - mx) * (py[i] - my);
  }
  if (!(sxx > 0)) return null;
  const slope = sxy / sxx;
  return { slope, intercept: my - slope * mx, n };
}
