// The notes of a render study's plots, true to its estimators: the reference slope spp^-1 is an
// unbiased estimator's with independent pixel samples; stratified or Sobol' pixel samples fall
// faster, and the note says which estimators use them.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.

/** The estimators of a render run whose pixel samples are not independent. */
export function designedPixels(records, order) {
  return order.filter((n) => records[n] && records[n].pixel_sampler && records[n].pixel_sampler !== 'independent');
}

/** Under an infinite variance the plot shows points without a band and the legends no order. */
const INFINITE_NOTE = 'Where the core flags an infinite variance (heavy tail), no band and no order: each point is dominated by the largest weights seen so far.';

/** The variance plot's note. */
export function varianceNote(kind, records = {}, order = []) {
  if (kind !== 'render') {
    return `Shaded: 95% interval of the variance (chi-square); dashed grey: reference slopes N⁻¹, N⁻², N⁻³ from the first point. Order = the core's least-squares fit of log variance on log N, stated only where the levels follow a line (chi-square test against their own noise). ${INFINITE_NOTE}`;
  }
  const designed = designedPixels(records, order);
  const base = `Relative MSE of each estimator's images against the reference (mean over the replicates; shaded: its 95% interval from their spread); dashed grey: spp⁻¹ from the first point, the slope of an unbiased estimator with independent pixel samples. Order = the core's least-squares fit of log relative MSE on log spp, stated only where the levels follow a line. ${INFINITE_NOTE}`;
  if (!designed.length) return base;
  const names = designed.map((n) => `${n} (${records[n].pixel_sampler})`).join(', ');
  return `${base} ${names}: stratified or low-discrepancy pixel samples, so a slope steeper than spp⁻¹ is expected where the image is smooth.`;
}

/** The time plot's note, for the kind of study: `lead` (what a point is) and `adaptive` (the
 *  training cost of VEGAS and MISER, integration studies only); the clock's clause is clock.js's. */
export function timeNote(kind) {
  if (kind === 'render') {
    return { lead: 'Equal-time comparison: at a given cost (x), the lowest curve wins. Each point is the mean time of one image at that spp over the replicates, against its relative RMSE; whiskers: the 95% interval of that mean.',
      adaptive: '' };
  }
  return { lead: 'Equal-time comparison: at a given cost (x), the lowest curve wins. Each point is the replicates\' median time per estimate at one N (robust to a replicate a busy machine delayed), against its error; whiskers: its 95% interval (order statistics).',
    adaptive: ' Adaptive estimators (VEGAS, MISER) spend part of each run learning (training iterations, probes): their dashed line is the same error at the time spent estimating only, and the gap to the solid line is what the learning cost.' };
}
