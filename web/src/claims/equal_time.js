// Who wins at equal time, said only where the data and the clock support it: the efficiency
// 1 / (error^2 x seconds) at the largest N each estimator reached, with its uncertainty in log
// space; no winner from times the clock cannot resolve, from an infinite variance, from
// replicates that merely agree, or without an uncertainty to test the difference. A render
// level at the reference's noise has no efficiency (its relative MSE is no number the data
// support: claims/reference_noise.js): a render estimator is compared at its largest spp above it.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { positive } from '../series/numbers.js';
import { fmt } from '../series/text.js';
import { timeOf, timeInterval } from '../series/time.js';
import { levelExactness } from './exact.js';
import { infiniteVariance } from './fit.js';
import { referenceNoiseWords } from './reference_noise.js';

const Z95 = 1.959963984540054;

/**
 * se of log(MSE) from R replicates of an estimate with variance v and bias b (normal
 * estimates): Var(mean of (x - exact)^2) = (2 v^2 + 4 b^2 v) / R. With b = 0 it is the chi-square
 * interval's; with the bias dominating, 2 se(b) / |b|.
 */
export function seLogMse(level) {
  const v = positive(level.variance);
  const mse = positive(level.mse);
  const r = level.reps || 0;
  if (v === null || mse === null || r < 2) return null;
  const b = typeof level.bias === 'number' && Number.isFinite(level.bias) ? level.bias : 0;
  return Math.sqrt((2 * v * v + 4 * b * b * v) / r) / mse;
}

/**
 * The equal-time claim: {text, winner (a name or null), ranked, left: [{name, why}]}.
 * `floorSeconds`: times below it are not compared (20 clock steps); `clockKnown` false names no
 * winner at all; `render`: relative MSE per image, `referenceFloor` the reference's relative-MSE
 * floor (for the words).
 */
export function equalTimeClaim(records, order, { exact = null, floorSeconds = 0, clockKnown = true, render = false,
  nName = render ? 'spp' : 'N', referenceFloor = null } = {}) {
  const useMse = !render && typeof exact === 'number' && Number.isFinite(exact);
  const what = render ? 'relative MSE' : useMse ? 'MSE' : 'variance';
  const rows = [];
  const exactOnes = [];
  const left = [];
  const belowNoise = [];
  for (const name of order) {
    const r = records[name];
    // a render study's largest level above the reference's noise
    const usable = r ? (render ? r.levels.filter((x) => x.below_reference_noise !== true) : r.levels) : [];
    const l = usable.length ? usable[usable.length - 1] : null;
    if (!l) {
      if (r && r.levels.length) {
        left.push({ name, why: `relative MSE ${referenceNoiseWords(referenceFloor)} at every ${nName}` });
      }
      continue;
    }
    if (render && l !== r.levels[r.levels.length - 1]) belowNoise.push(name);
    const kind = render ? 'no' : levelExactness(l, exact);
    if (kind === 'exact') {
      // Exact from which N on (every level after it is exact too): "at any time" only when
      // exact at every N.
      const kinds = r.levels.map((x) => levelExactness(x, exact));
      let from = kinds.length - 1;
      while (from > 0 && kinds[from - 1] === 'exact') from--;
      exactOnes.push({ name, fromN: from === 0 ? null : r.levels[from].n });
      continue;
    }
    if (kind === 'agree') {
      left.push({ name, why: 'zero spread without an exact value to check it against' });
      continue;
    }
    if (infiniteVariance(r)) {
      left.push({ name, why: 'infinite variance (heavy tail): no efficiency' });
      continue;
    }
    const v = l.variance;
    const q = useMse && positive(l.mse) !== null ? l.mse : v;
    const t = timeOf(l);
    if (positive(q) === null || positive(t) === null) {
      left.push({ name, why: positive(t) === null ? 'no time measured' : `zero ${what}` });
      continue;
    }
    if (t < floorSeconds) {
      left.push({ name, why: 'too fast for this clock' });
      continue;
    }
    let seLogQ = null;
    if (q === v || render) {
      const ci = l.variance_ci95;
      seLogQ = ci && positive(ci[0]) !== null && positive(ci[1]) !== null ? (Math.log(ci[1]) - Math.log(ci[0])) / (2 * Z95) : null;
    } else {
      seLogQ = seLogMse(l);
    }
    const tci = timeInterval(l);
    const seLogT = tci ? (Math.log(tci[1]) - Math.log(tci[0])) / (2 * Z95) : null;
    const logE = -Math.log(q) - Math.log(t);
    // A timing interval of zero width is a clock that did not move between replicates, not a
    // certainty: no uncertainty, no test.
    const se = seLogQ === null || seLogT === null || !(seLogT > 0) ? null : Math.sqrt(seLogQ * seLogQ + seLogT * seLogT);
    rows.push({ name, n: l.n, efficiency: Math.exp(logE), logE, se,
      lo: se === null ? null : Math.exp(logE - Z95 * se), hi: se === null ? null : Math.exp(logE + Z95 * se) });
  }
  rows.sort((a, b) => b.logE - a.logE);
  const leftText = left.length ? ` Not compared: ${left.map((x) => `${x.name} (${x.why})`).join('; ')}.` : '';
  if (exactOnes.length) {
    const always = exactOnes.filter((e) => e.fromN === null).map((e) => e.name);
    if (always.length) {
      return { winner: always[0], ranked: rows, left,
        text: `${always.join(' and ')} ${always.length > 1 ? 'are' : 'is'} exact at every ${nName} (every replicate equals the exact value to round-off): nothing beats that at any time.` };
    }
    const e = exactOnes[0];
    return { winner: e.name, ranked: rows, left,
      text: `${e.name} equals the exact value to round-off from ${nName} = ${e.fromN} on (below, it has an error): at the largest ${nName}, nothing with an error beats it.` };
  }
  if (!clockKnown) {
    return { winner: null, ranked: rows, left, text: 'The clock could not be measured: no timing is compared.' };
  }
  if (rows.length < 2) {
    return { winner: null, ranked: rows, left,
      text: left.length ? `Fewer than two estimators can be compared at equal time.${leftText}` : '' };
  }
  const [a, b] = rows;
  const above = render && belowNoise.length ? ' above the reference\'s noise' : '';
  const lead = `at the largest ${nName} each reached${above} (1 / (${what} × seconds); it grows with ${nName} for estimators steeper than ${nName}⁻¹)`;
  if (a.se === null || b.se === null) {
    return { winner: null, ranked: rows, left,
      text: `No winner named at equal time: ${a.name} is ${fmt(a.efficiency / b.efficiency, 2)}× ${b.name} ${lead}, but without an uncertainty of both (error and timing) the difference cannot be tested.${leftText}` };
  }
  const z = (a.logE - b.logE) / Math.sqrt(a.se * a.se + b.se * b.se);
  if (z > Z95) {
    return { winner: a.name, ranked: rows, left,
      text: `Equal-time winner ${lead}: ${a.name}, ${fmt(a.efficiency / b.efficiency, 2)}× as efficient as the next, ${b.name} (z = ${fmt(z, 2)}, with the error's and the timing's uncertainty).${leftText}` };
  }
  return { winner: null, ranked: rows, left,
    text: `No significant difference at equal time between ${a.name} and ${b.name} ${lead}: ${fmt(a.efficiency / b.efficiency, 2)}× (z = ${fmt(z, 2)} < 1.96).${leftText}` };
}
