// Calibration of the error bars: z-scores against the exact value, their histogram beside the
// normal density, and the coverage of the 95% intervals against N.
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.
import { unionSorted, round9 } from './numbers.js';
import { levelExactness } from '../claims/exact.js';

/**
 * z = (estimate - reference) / std_error of every replicate of `levels` (all of them, or the
 * one with n === which). The reference is the exact value, or when it is unknown each level's
 * mean of its replicates. Replicates with a zero or missing error bar are counted in zeroSe
 * (a zero error bar with a wrong estimate is the confident wrong answer), not in z. Levels exact
 * to round-off and equal to the exact value (claims/exact.js) are counted in exactRuns, not in z:
 * their z is round-off over round-off.
 */
export function zScores(levels, exact = null, which = 'all') {
  const useExact = exact !== null && exact !== undefined && Number.isFinite(exact);
  const z = [];
  let zeroSe = 0;
  let exactRuns = 0;
  for (const l of levels) {
    if (which !== 'all' && l.n !== which) continue;
    const rep = l.replicates;
    if (!rep) continue;
    // Only levels that equal the exact value (claims/exact.js): replicates that merely agree on a
    // wrong value have z = error / 0, counted in zeroSe below.
    if (levelExactness(l, useExact ? exact : null) === 'exact') {
      exactRuns += rep.estimate.length;
      continue;
    }
    const ref = useExact ? exact : l.mean;
    for (let i = 0; i < rep.estimate.length; i++) {
      const est = rep.estimate[i];
      const se = rep.std_error[i];
      if (typeof est !== 'number' || !Number.isFinite(est) || typeof ref !== 'number') continue;
      if (typeof se === 'number' && se > 0 && Number.isFinite(se)) z.push((est - ref) / se);
      else zeroSe++;
    }
  }
  return { z, zeroSe, exactRuns, reference: useExact ? 'exact' : 'mean' };
}

/**
 * Histogram of `values` over [lo, hi) in bins of `width`: counts, and density = counts /
 * (all values x width) so that it compares with a density; values outside go to below/above.
 */
export function histogram(values, { lo = -5, hi = 5, width = 0.5 } = {}) {
  const bins = Math.round((hi - lo) / width);
  const edges = Array.from({ length: bins + 1 }, (_, i) => round9(lo + i * width));
  const counts = new Array(bins).fill(0);
  let below = 0;
  let above = 0;
  let total = 0;
  for (const v of values) {
    if (typeof v !== 'number' || Number.isNaN(v)) continue;
    total++;
    if (v < lo) below++;
    else if (v >= hi) above++;
    else counts[Math.min(bins - 1, Math.floor((v - lo) / width))]++;
  }
  const density = counts.map((c) => (total ? c / (total * width) : 0));
  return { edges, counts, density, below, above, total };
}

export function normalDensity(x) {
  return Math.exp(-0.5 * x * x) / Math.sqrt(2 * Math.PI);
}

/**
 * The calibration plot: x a grid over [lo, hi] (step 0.1, a multiple of the bin width), the
 * standard normal density on it, and per estimator its z-score histogram as a step function
 * (y at grid point x = the density of the bin starting at or before x).
 */
export function calibrationSeries(records, order, exact = null, which = 'all',
  { lo = -5, hi = 5, width = 0.5, step = 0.1 } = {}) {
  const count = Math.round((hi - lo) / step);
  const x = Array.from({ length: count + 1 }, (_, i) => round9(lo + i * step));
  const normal = x.map(normalDensity);
  const series = order.filter((n) => records[n]).map((name) => {
    const zs = zScores(records[name].levels, exact, which);
    const h = histogram(zs.z, { lo, hi, width });
    const bins = h.counts.length;
    const y = x.map((v) => (h.total ? h.density[Math.min(bins - 1, Math.floor((v - lo) / width + 1e-9))] : null));
    return {
      name, y, total: h.total, below: h.below, above: h.above, zeroSe: zs.zeroSe, exactRuns: zs.exactRuns,
      reference: zs.reference, within2: zs.z.filter((v) => Math.abs(v) <= 1.96).length,
    };
  });
  return { x, normal, series };
}

/** coverage95 against N per estimator (null where unknown: no exact value). */
export function coverageSeries(records, order, xs = null) {
  const named = order.filter((n) => records[n]);
  const x = xs ? xs.slice() : unionSorted(named.flatMap((n) => records[n].levels.map((l) => l.n)));
  const series = named.map((name) => {
    const byN = new Map(records[name].levels.map((l) => [l.n, l]));
    return {
      name,
      y: x.map((n) => {
        const l = byN.get(n);
        return l && typeof l.coverage95 === 'number' ? l.coverage95 : null;
      }),
    };
  });
  return { x, series };
}
