// The core's codes and raw numbers in plain words: each diagnostic code's sentence and chip
// text, p-values, tail indices, densities and error methods. The code stays beside the words as
// a detail (for searching docs/result-schema.md), never in their place.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { fmt } from '../series/text.js';
import { CONSERVATIVE_METHOD_WORDS } from './errorbars.js';

/** Each diagnostic code: `title`, the sentence a reader needs, and `short`, the chip text. */
export const FLAG_WORDS = Object.freeze({
  no_estimate: { title: 'No estimate: every replicate failed', short: 'no estimate' },
  nonfinite_estimate: { title: 'The estimate is not a number', short: 'estimate not a number' },
  nonfinite_variance: { title: 'The error bar is not a number', short: 'error bar not a number' },
  zero_error_bar: { title: 'An error bar of zero where the replicates disagree: the interval is wrong', short: 'zero error bar' },
  nonfinite: { title: 'Samples that were not numbers were dropped', short: 'samples dropped' },
  zero_pdf_samples: { title: 'Points where the density is zero but f is not: that mass is missed', short: 'density zero where f is not' },
  skewed_weights: { title: 'Skewed weights: the error bar is not yet trustworthy at this N', short: 'skewed weights' },
  low_ess: { title: 'Few effective samples: a handful of points carry the estimate', short: 'few effective samples' },
  exact_outside_ci: { title: 'The exact value is outside the replicates\' interval: biased or wrong error bars', short: 'exact value outside the interval' },
  heavy_tail: { title: 'Heavy tail: the variance may be infinite', short: 'heavy tail: variance may be infinite' },
  heavy_tail_4: { title: 'Heavy tail: the fourth moment may be infinite (the error bar\'s own error converges slowly)', short: 'heavy tail: error bar erratic' },
  pdf_support: { title: 'The density misses part of where f is non-zero: biased', short: 'density misses part of f' },
  level_drift: { title: 'The estimates drift across N more than their error bars allow', short: 'estimates drift across N' },
  iterations_disagree: { title: 'The iterations disagree more than their error bars allow', short: 'iterations disagree' },
  error_bars_understate: { title: 'The error bars are too small for the spread of the replicates', short: 'error bars too small' },
  error_bars_unstable: { title: 'The replicates\' error bars disagree with each other: some saw a feature others missed', short: 'error bars disagree' },
  replicate_far_off: { title: 'A replicate lies far outside its own error bar: its error bar is far too small', short: 'a replicate far off' },
  values_underflow: { title: 'The values are so small that their squares underflow: no error bar can be computed', short: 'values underflow' },
  bias_dominates: { title: 'The bias dominates the error from some N on', short: 'bias dominates' },
  conservative_error_bars: { title: 'Conservative error bars: wider than the replicates\' spread', short: 'error bars wider than needed' },
  float32_accumulator: { title: 'A single-precision accumulator limits the accuracy', short: 'single-precision sums' },
  below_reference_noise: { title: 'The error is below the reference\'s own noise', short: 'below the reference\'s noise' },
  reference_noise: { title: 'The reference is noisy', short: 'noisy reference' },
  slow_convergence: { title: 'Slower convergence than an unbiased estimator\'s', short: 'slow convergence' },
  pixel_error_bars: { title: 'The pixels\' error bars cover too rarely', short: 'pixel error bars too small' },
  few_pixel_errors: { title: 'A few pixel errors make this level\'s error: it rests on rare events', short: 'a few pixels make the error' },
  rare_large_errors: { title: 'Rare large pixel errors make the error: levels that missed them understate it', short: 'rare large pixel errors' },
  tolerance_not_met: { title: 'The requested accuracy was not reached', short: 'accuracy not reached' },
  fireflies: { title: 'Fireflies: a few samples far brighter than the rest carry the image', short: 'fireflies: rare very bright samples' },
  black_reference: { title: 'The reference image is black: relative errors have nothing to compare with', short: 'black reference' },
  no_lights: { title: 'The scene has no light: every image is black', short: 'no lights' },
  degenerate_lights: { title: 'Lights of zero area or zero emission were left out', short: 'degenerate lights left out' },
  gltf: { title: 'Parts of the glTF file were ignored', short: 'glTF features ignored' },
});

/** The heavy-tail codes at severity info: the Hill estimate looks heavy but the weights are
 *  bounded (or the sign is weak), so the words must not say the variance may be infinite. */
const INFO_WORDS = Object.freeze({
  heavy_tail: { title: 'The weights\' tail looks heavy, but the core finds no sign of an infinite variance (bounded weights, or too weak a sign)', short: 'tail looks heavy: no alarm' },
  heavy_tail_4: { title: 'The weights\' tail looks heavy in the fourth moment, but the core finds no sign that the error bar is erratic', short: 'tail looks heavy: no alarm' },
});

function wordsOf(code, severity) {
  if (severity === 'info' && INFO_WORDS[code]) return INFO_WORDS[code];
  return FLAG_WORDS[code];
}

/** The plain-language title of a diagnostic code (at its severity); an unknown code in words
 *  (its underscores as spaces), never the bare identifier. */
export function flagTitle(code, severity = null) {
  const w = wordsOf(code, severity);
  if (w) return w.title;
  return `The core's flag "${String(code).replace(/_/g, ' ')}"`;
}

/** The chip text of a diagnostic code (plain words, short). */
export function flagShort(code, severity = null) {
  const w = wordsOf(code, severity);
  if (w) return w.short;
  return String(code).replace(/_/g, ' ');
}

/** A p-value in words: never "p = 0" (an underflowed p is below the smallest double printed). */
export function pWords(p) {
  if (typeof p !== 'number' || Number.isNaN(p)) return 'p unknown';
  if (p < 1e-300) return 'p < 1e-300';
  return `p = ${fmt(p, 2)}`;
}

/**
 * The Hill tail index of the weights in words (docs/result-schema.md): below 2 the variance is
 * infinite, below 4 the fourth moment (the error bar converges erratically); above 10 no sign of
 * a heavy tail (a large index such as 52200 means a light tail, not an alarm).
 */
export function tailWords(index) {
  if (typeof index !== 'number' || !Number.isFinite(index)) return 'no tail estimate';
  if (index <= 0) return 'no tail estimate (too few nonzero weights)';
  if (index <= 2) return `heavy: infinite variance (tail index ${fmt(index, 3)})`;
  if (index <= 4) return `heavy: infinite 4th moment, erratic error bars (tail index ${fmt(index, 3)})`;
  if (index <= 10) return `moderate (tail index ${fmt(index, 3)})`;
  return 'light: no sign of a heavy tail';
}

/** The density of an estimator in words: the core's pdf_text when it gives one, else its
 *  notation as it is (marked as notation by the caller). */
export function densityWords(record) {
  if (!record) return '';
  return record.pdf_text || record.pdf || '';
}

/** How an error bar is computed, in words. */
export const METHOD_WORDS = Object.freeze({
  iid: 'the sample variance of independent points',
  ...CONSERVATIVE_METHOD_WORDS,
  paired_strata: 'paired strata: two points per stratum',
  randomizations: 'the spread of independent randomizations',
  parts_sum: 'the sum of the strata\'s variances',
  regression: 'the residuals of a regression on the control variates',
  walsh_bound: 'a bound from the points\' own Walsh coefficients',
  none: 'no error bar',
});

export function methodWords(method) {
  return METHOD_WORDS[method] || (method ? String(method).replace(/_/g, ' ') : 'unknown');
}

const INPUT_NAMES = { f: 'f, the integrand', p: 'p, the density', exact: 'the exact value' };

/**
 * A core error about a typed expression in words: the scene path the core names
 * ("scene.estimators[3].pdf.shape: at position 2: ...") is the page's own construction, not the
 * reader's; the words name the input instead ("p, the density: at position 2: ...").
 */
export function inputErrorWords(message, field) {
  const text = String(message || '');
  const rest = text.replace(/^scene(\.[\w]+|\[\d+\])*:\s*/, '');
  return `${INPUT_NAMES[field] || 'the input'}: ${rest}`;
}
