// Error against time: the time of a level, its interval, the clock's resolution, the error
// against time series (the equal-time verdict is claims/equal_time.js).
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.
import { positive, unionSorted } from './numbers.js';
import { fitSlope } from './variance.js';

/** The seconds per estimate a level is plotted at: the replicates' median (robust to the one
 *  that a busy machine delayed), or their mean when the level has no median. */
export function timeOf(l) {
  return positive(l.time_median_s) !== null ? l.time_median_s : l.time_mean_s;
}

/** The 95% interval of timeOf(l): the median's order-statistic interval, else the mean's t-free
 *  normal interval from time_std_s; null when neither is known. */
export function timeInterval(l) {
  const ci = l.time_median_ci95_s;
  if (Array.isArray(ci) && positive(ci[0]) !== null && positive(ci[1]) !== null) return [ci[0], ci[1]];
  if (positive(l.time_std_s) !== null && (l.reps || 0) > 1 && positive(l.time_mean_s) !== null) {
    const h = 1.959963984540054 * l.time_std_s / Math.sqrt(l.reps);
    return [Math.max(l.time_mean_s - h, l.time_mean_s * 1e-3), l.time_mean_s + h];
  }
  return null;
}

/**
 * The finest step of a clock (ms): the smallest positive difference between successive readings
 * of `now`, watched for at most `budgetMs` (or `maxReadings` readings). Browsers coarsen performance.now() (to 5 us, or
 * 100 us without cross-origin isolation), and the wasm core's timings are taken with it.
 */
export function clockResolution(now, budgetMs = 5, maxReadings = 1e6) {
  const start = now();
  let last = start;
  let step = Infinity;
  let seen = 0;
  for (let k = 0; seen < 20 && k < maxReadings; ++k) {
    const t = now();
    if (t > last) {
      step = Math.min(step, t - last);
      last = t;
      ++seen;
    }
    if (t - start > budgetMs) break;
  }
  return Number.isFinite(step) ? step : null;
}

/** Times under this many clock steps are not fitted: the clock's rounding is over 5% of them. */
export const CLOCK_STEPS_FITTED = 20;

/**
 * The equal-time plot: per estimator the points (timeOf, error) of its levels (error =
 * RMSE when the exact value is known, else sqrt(variance)), on the sorted union of all times
 * (uPlot's aligned data; null where a series has no point), the points in the order of N
 * (`points`: [time, error] pairs, for joining them), and the least-squares slope of log error on
 * log time over the points at t >= clockFloor (`fitted` of them; `untimed` below it, where the
 * clock's rounding bends the line). Adaptive estimators also get `estimating` (the [time minus training time, error]
 * pairs) and `trainingShare` (the mean share of the time spent training or probing; null for
 * the others).
 */
export function timeSeries(records, order, clockFloor = 0) {
  const named = order.filter((n) => records[n]);
  const pts = named.map((name) => records[name].levels
    .map((l) => [positive(timeOf(l)), positive(l.error)])
    .filter(([t, e]) => t !== null && e !== null));
  const x = unionSorted(pts.flat().map(([t]) => t));
  const index = new Map(x.map((t, i) => [t, i]));
  const series = named.map((name, k) => {
    const y = new Array(x.length).fill(null);
    for (const [t, e] of pts[k]) y[index.get(t)] = e;
    // The slope over the points the clock can time (t >= clockFloor): below, its rounding
    // would bend the line.
    const timed = pts[k].filter(([t]) => t >= clockFloor);
    const fit = fitSlope(timed.map((p) => p[0]), timed.map((p) => p[1]));
    // Adaptive estimators: the same errors at the time spent estimating only (training or
    // probing left out), and the mean share of the time that training took.
    const levels = records[name].levels.filter((l) => positive(timeOf(l)) !== null && positive(l.error) !== null);
    const trained = levels.filter((l) => l.training_time_mean_s > 0 && l.training_time_mean_s < l.time_mean_s);
    const estimating = trained.map((l) => [timeOf(l) * (1 - l.training_time_mean_s / l.time_mean_s), l.error]);
    const trainingShare = trained.length
      ? trained.reduce((a, l) => a + l.training_time_mean_s / l.time_mean_s, 0) / trained.length : null;
    // The timing's own uncertainty: the 95% interval of the median seconds over the replicates.
    const whiskers = levels.map((l) => timeInterval(l)).map((ci, i) => (ci ? [ci[0], ci[1], levels[i].error] : null))
      .filter(Boolean);
    return { name, y, points: pts[k], slope: fit ? fit.slope : null, fitted: timed.length,
      untimed: pts[k].length - timed.length, estimating, trainingShare, whiskers };
  });
  return { x, series };
}
