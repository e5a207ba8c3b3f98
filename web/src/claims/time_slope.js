// The slope of error against time the page states: with its uncertainty, over the points the
// clock can time and where the time grows with N (a fixed set-up cost makes the error fall while
// the time stands still: no slope there), and only where a line fits.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { positive } from '../series/numbers.js';
import { fixed3 } from '../series/text.js';
import { timeOf } from '../series/time.js';
import { recordExactness } from './exact.js';
import { fitLine, trigamma } from './stats.js';
import { pWords } from './words.js';

/** A level whose seconds per sample differ from the largest N's by more than this factor is
 *  dominated by a fixed cost (set-up, training, the page's own overhead). */
export const COST_PER_SAMPLE_SPREAD = 1.25;

/**
 * {text (the legend's words), slope, se, p, holds, evidence} for one estimator's error-time
 * points. `floorSeconds`: the clock's fitted floor; `measure`: 'mse' (RMSE plotted) or
 * 'variance'.
 */
export function timeSlopeClaim(record, { exact = null, floorSeconds = 0, measure = 'mse', nName = 'N' } = {}) {
  const none = (text, evidence = {}) => ({ text, slope: null, se: null, p: null, holds: false, evidence });
  if (!record || !record.levels || !record.levels.length) return none('');
  const ex = recordExactness(record, exact);
  if (ex.all === 'exact') return none('exact: the error is round-off, no slope');
  const pts = record.levels.map((l) => ({ n: l.n, t: positive(timeOf(l)), e: positive(l.error), reps: l.reps || 0 }))
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
    return none(`no slope: the time does not grow in proportion to ${nName} (a fixed cost dominates it)`,
      { steady: steady.length });
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
