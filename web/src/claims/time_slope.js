// The slope of error against time the page states: with its uncertainty, over the points the
// clock can time and where the time grows with N (a fixed set-up cost makes the error fall while
// the time stands still: no slope there), only where a line fits, and never under an infinite
// variance (the MSE legend's rule: claims/fit.js). A fixed cost is named only where the timings
// show one (fixedCost below), not where they merely scatter.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { positive } from '../series/numbers.js';
import { fixed3, fmt } from '../series/text.js';
import { timeOf, timeInterval } from '../series/time.js';
import { recordExactness } from './exact.js';
import { infiniteVariance, infiniteVarianceText } from './fit.js';
import { fitLine, trigamma } from './stats.js';
import { pWords } from './words.js';

/** A level whose seconds per sample differ from the largest N's by more than this factor is
 *  dominated by a fixed cost (set-up, training, the page's own overhead). */
export const COST_PER_SAMPLE_SPREAD = 1.25;

/** A fixed cost is shown when its fitted size is this many standard errors above 0. */
export const FIXED_COST_Z = 3;

const Z95 = 1.959963984540054;

/**
 * Does a fixed cost show in the timings? `points`: [{n, t, sdLog}] (sdLog the standard deviation
 * of ln t from the level's own replicates, or null). Fits t = a + c N by weighted least squares
 * with relative errors (weights 1 / (sdLog t)^2; equal relative weights where a level's sdLog is
 * unknown) and judges a against its standard error, inflated by the residuals when the points
 * scatter beyond their own intervals (their scatter alone when no interval is known). Shown when
 * a is FIXED_COST_Z standard errors above 0 and dominates at the smallest N (a > c N_min: there
 * the time is flat, at most 1.5 times as long at twice the N). {shown, a, c, seA, z}.
 */
export function fixedCost(points) {
  const pts = points.filter((p) => positive(p.t) !== null && p.n > 0);
  if (pts.length < 3) return { shown: false, a: null, c: null, seA: null, z: null };
  const known = pts.every((p) => positive(p.sdLog) !== null);
  let s = 0;
  let sx = 0;
  let sxx = 0;
  let sy = 0;
  let sxy = 0;
  const w = pts.map((p) => 1 / ((known ? p.sdLog : 1) * p.t) ** 2);
  pts.forEach((p, i) => {
    s += w[i]; sx += w[i] * p.n; sxx += w[i] * p.n * p.n; sy += w[i] * p.t; sxy += w[i] * p.n * p.t;
  });
  const det = s * sxx - sx * sx;
  if (!(det > 0)) return { shown: false, a: null, c: null, seA: null, z: null };
  const a = (sxx * sy - sx * sxy) / det;
  const c = (s * sxy - sx * sy) / det;
  let chi2 = 0;
  pts.forEach((p, i) => { chi2 += w[i] * (p.t - a - c * p.n) ** 2; });
  const dof = pts.length - 2;
  const residual = chi2 / dof;
  const seA = Math.sqrt((sxx / det) * (known ? Math.max(1, residual) : residual));
  const z = seA > 0 ? a / seA : (a > 0 ? Infinity : 0);
  const nMin = Math.min(...pts.map((p) => p.n));
  return { shown: z > FIXED_COST_Z && a > c * nMin, a, c, seA, z };
}

/** sd of ln t from a level's 95% timing interval, or null when it has none. */
function sdLogTime(l) {
  const ci = timeInterval(l);
  return ci && ci[1] > ci[0] ? (Math.log(ci[1]) - Math.log(ci[0])) / (2 * Z95) : null;
}

/**
 * {text (the legend's words), slope, se, p, holds, evidence} for one estimator's error-time
 * points. `floorSeconds`: the clock's fitted floor; `measure`: 'mse' (RMSE plotted) or
 * 'variance'.
 */
export function timeSlopeClaim(record, { exact = null, floorSeconds = 0, measure = 'mse', nName = 'N',
  measureName = measure === 'mse' ? 'MSE' : 'variance' } = {}) {
  const none = (text, evidence = {}) => ({ text, slope: null, se: null, p: null, holds: false, evidence });
  if (!record || !record.levels || !record.levels.length) return none('');
  const ex = recordExactness(record, exact);
  if (ex.all === 'exact') return none('exact: the error is round-off, no slope');
  if (infiniteVariance(record)) return none(infiniteVarianceText(record, measureName), { heavyTail: true });
  const pts = record.levels.map((l) => ({ n: l.n, t: positive(timeOf(l)), e: positive(l.error), reps: l.reps || 0,
    sdLog: sdLogTime(l) }))
    .filter((p) => p.t !== null && p.e !== null);
  if (!pts.length) return none('');
  const timed = pts.filter((p) => p.t >= floorSeconds);
  if (timed.length < 3) {
    return none(timed.length < pts.length ? 'no slope: too fast for the clock' : 'no slope: fewer than 3 timed points',
      { timed: timed.length, points: pts.length });
  }
  // The cost per sample the timed levels share: their median (one slow level, a busy machine,
  // does not make the others look like a fixed cost).
  const costs = timed.map((p) => p.t / p.n).sort((a, b) => a - b);
  const perSample = costs[Math.floor((costs.length - 1) / 2)];
  const steady = timed.filter((p) => {
    const r = (p.t / p.n) / perSample;
    return r <= COST_PER_SAMPLE_SPREAD && r >= 1 / COST_PER_SAMPLE_SPREAD;
  });
  if (steady.length < 3) {
    const cost = fixedCost(timed);
    if (cost.shown) {
      return none(`no slope: the time does not grow in proportion to ${nName} (a fixed cost dominates it)`,
        { steady: steady.length, fixedCost: cost });
    }
    return none(`no slope: the time per sample varies ${fmt(costs[costs.length - 1] / costs[0], 2)}× between levels, and no fixed cost shows in it`,
      { steady: steady.length, fixedCost: cost });
  }
  // log error has the sampling noise of a chi-square variance: sd(log s^2) = sqrt(trigamma(k / 2)),
  // k = R (MSE) or R - 1 (variance); the error is its square root.
  const sd = steady.map((p) => {
    const k = measure === 'mse' ? p.reps : p.reps - 1;
    return k >= 2 ? 0.5 * Math.sqrt(trigamma(k / 2)) : 0.5;
  });
  const fit = fitLine(steady.map((p) => Math.log(p.t)), steady.map((p) => Math.log(p.e)), sd);
  if (!fit) return none('no slope');
  const from = steady[0].t;
  const evidence = { slope: fit.slope, se: fit.slopeSe, p: fit.p, points: steady.length, from };
  if (fit.p < 1e-3) {
    return { text: `no straight line in time (χ² ${pWords(fit.p)})`, slope: null, se: null, p: fit.p, holds: false, evidence };
  }
  const bias = (record.warnings || []).some((w) => w.code === 'bias_dominates') && fit.slope > -0.1;
  if (bias) {
    return { text: 'the error is a bias: it does not fall with time', slope: fit.slope, se: fit.slopeSe, p: fit.p, holds: true, evidence };
  }
  return { text: `error ∝ t^${fixed3(fit.slope)} ± ${fixed3(fit.slopeSe)}`, slope: fit.slope, se: fit.slopeSe, p: fit.p,
    holds: true, evidence };
}
