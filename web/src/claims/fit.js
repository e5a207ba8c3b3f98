// The order of convergence the page states: a slope only where a power law holds. The core fits
// log variance (or MSE, or relative MSE) on log N by weighted least squares [fit_power_law,
// src/estimators/study.cpp] and reports the fit's chi-square against the levels' own sampling
// noise; a line that fails it is not a power law, and its slope means nothing.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { fitText, fixed3 } from '../series/text.js';
import { pWords } from './words.js';
import { recordExactness } from './exact.js';

/** A whole-range fit is a power law when its chi-square p is at least this. */
export const FIT_P_WHOLE = 1e-3;

/** The core's heavy_tail flag on an estimator at severity warning or error, else null. The
 *  core alone judges the tail (persistence over the levels, bounded contributions of a render
 *  estimator: src/render/contribution_bound.*); a tail index at or below 2 with the flag at
 *  info, or without it, is no infinite variance. */
export function heavyTailAlarm(record) {
  return ((record && record.warnings) || []).find((w) => w.code === 'heavy_tail'
    && (w.severity === 'warning' || w.severity === 'error')) || null;
}

/** Does the estimator carry a heavy_tail flag of severity warning or error: an infinite
 *  variance, which has no order? */
export function infiniteVariance(record) {
  return heavyTailAlarm(record) !== null;
}

/** Why an infinite variance has no order, in words (the MSE legend's and the time legend's). */
export function infiniteVarianceText(record, measure = 'variance') {
  const w = heavyTailAlarm(record);
  return `no order: the core flags a heavy tail of the weights (heavy_tail, ${w ? w.severity : 'warning'}), so the ${measure} is infinite and has no slope`;
}

function rangeText(n0, n1, nName) {
  return typeof n0 === 'number' && typeof n1 === 'number' ? `${nName} ${n0} … ${n1}` : '';
}

/**
 * The order claim of an estimator's fit (`which`: 'fit' for the variance or relative MSE,
 * 'mse_fit' for the MSE): {text, number (the CLI's "-1.503 ± 0.028", or null when no order is
 * stated), note (why not, or the range), holds (true: a power law; false: none stated; null:
 * the page cannot tell), evidence}.
 */
export function orderClaim(record, { which = 'fit', exact = null, nName = 'N', measure = 'variance' } = {}) {
  const fit = record ? record[which] : null;
  const ex = recordExactness(record, exact);
  const evidence = { order: fit && fit.order, se: fit && fit.order_se, p: fit ? fit.p_value : undefined };
  if (ex.all === 'exact') return { text: 'exact: nothing to fit', number: null, note: 'exact', holds: false, evidence };
  if (ex.all === 'agree') {
    return { text: 'zero spread at every N: nothing to fit', number: null, note: 'agree', holds: false, evidence };
  }
  if (infiniteVariance(record)) {
    return { text: infiniteVarianceText(record, measure), number: null, note: 'heavy tail', holds: false, evidence };
  }
  if (!fit || !fit.valid || typeof fit.order !== 'number') {
    const text = fitText(fit);
    return { text, number: null, note: fit && fit.note ? fit.note : 'no fit yet', holds: false, evidence };
  }
  const number = fitText(fit);
  if (typeof fit.p_value !== 'number') {
    // A result from before the core reported the fit's chi-square: the page cannot tell.
    return { text: `${number} (not checked for a power law)`, number, note: 'unchecked', holds: null, evidence };
  }
  if (fit.p_value >= FIT_P_WHOLE) {
    return { text: number, number, note: rangeText(fit.n_first, fit.n_last, nName), holds: true, evidence };
  }
  const s = fit.suffix;
  if (s && typeof s.order === 'number') {
    const sufNumber = `${fixed3(s.order)}${typeof s.order_se === 'number' ? ` ± ${fixed3(s.order_se)}` : ''}`;
    return { text: `${sufNumber} from ${nName} = ${s.n_first} (below it the ${measure} does not follow a power law, χ² ${pWords(fit.p_value)})`,
      number: sufNumber, note: `from ${nName} = ${s.n_first}`, holds: true,
      evidence: { ...evidence, suffix: s } };
  }
  return { text: `no power law: the ${measure} does not fall on a line (χ² ${pWords(fit.p_value)})`,
    number: null, note: 'not a power law', holds: false, evidence };
}
