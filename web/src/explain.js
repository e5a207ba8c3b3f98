// What each estimator is, for the page's estimator panels: its formula, the order its variance
// should reach (the exponent of N) and what to look for. Keyed by the method the core names
// (sceneInfo.estimator_details[].method: the method of the estimator's kind, src/estimators/
// registry.h). A method without a text here (a new estimator) gets a generic one with the
// kind's own summary (estimator_details[].summary): no code change is needed for it to show.
// Pure data and functions, no DOM: web/test/explain.test.mjs.
//
// Orders of the variance of the estimate for square-integrable f/p [Owen13, chapters 2, 8-10,
// 15, 17]; where they depend on the integrand, the smooth case and the discontinuous one.

const ORDER_UNKNOWN = 'depends on the integrand';

/** The expected order of a stratified estimator's variance in dimension d, as text. */
function stratifiedOrder(d) {
  if (!Number.isInteger(d) || d < 1) return 'N^−(1+2/d) for smooth f, N^−(1+1/d) across a discontinuity';
  const smooth = 1 + 2 / d;
  const edge = 1 + 1 / d;
  const exp = (v) => (Number.isInteger(v) ? String(v) : v.toFixed(2).replace(/0$/, ''));
  return `N^−${exp(smooth)} for smooth f, N^−${exp(edge)} across a discontinuity (d = ${d})`;
}

const METHODS = {
  uniform: {
    title: 'Plain Monte Carlo',
    formula: 'I_N = (1/N) Σ f(xᵢ)/p(xᵢ), xᵢ independent and uniform (p = 1/|D|)',
    order: () => 'N⁻¹ (the error falls as N^−1/2)',
    look: 'The baseline: a straight line of slope −1 on the variance plot. Every other estimator is judged against it.',
  },
  importance: {
    title: 'Importance sampling',
    formula: 'I_N = (1/N) Σ f(xᵢ)/p(xᵢ), xᵢ independent from p',
    order: () => 'N⁻¹, with a smaller constant when p follows |f|',
    look: 'The same slope as uniform sampling, lower when p follows |f| (exact when p ∝ f ≥ 0). Where p is small but f is not, the weights f/p are huge: see the weights plot and the tail flags.',
  },
  stratified: {
    title: 'Stratified sampling',
    formula: 'I_N = Σ_k |D_k| · f(x_k), one uniform point x_k in each of N equal cells D_k',
    order: (d) => stratifiedOrder(d),
    look: 'A steeper slope than uniform sampling, steepest in low dimension. With one point per cell the spread within a cell cannot be measured: the error bar comes from pairs of cells and is conservative for smooth f.',
  },
  stratified_importance: {
    title: 'Stratified importance sampling',
    formula: 'I_N = (1/N) Σ_k f(x_k)/p(x_k), x_k the warp by p of one point per cell of the unit cube',
    order: (d) => stratifiedOrder(d),
    look: 'The gains of both: the slope of stratification on the smoother f/p.',
  },
  latin_hypercube: {
    title: 'Latin hypercube sampling',
    formula: 'I_N = (1/N) Σ f(xᵢ), every axis cut into N intervals with one point in each',
    order: () => 'N⁻¹; the additive part of f is removed (N^−3 for it in 1-D)',
    look: 'Wins when f is close to a sum of functions of one coordinate each, and is never much worse than uniform sampling (at most N/(N−1) times its variance).',
  },
  rqmc: {
    title: 'Randomized quasi-Monte Carlo',
    formula: 'I_N = (1/K) Σ_k (K/N) Σ_{i in batch k} f(xᵢ), K independent randomizations of a low-discrepancy point set',
    order: () => 'up to N⁻³ (times log factors) for smooth f with scrambled nets; N⁻¹ at worst',
    look: 'A slope steeper than −1 on smooth integrands, in any dimension where f depends mostly on a few coordinates. The error bar comes from the K randomizations (K − 1 degrees of freedom).',
  },
  rqmc_walsh: {
    title: 'Randomized Sobol\' points with a Walsh error bound',
    formula: 'I_N = (1/N) Σ f(xᵢ), one linearly scrambled Sobol\' sequence of N = 2^m points; error bound 5·2^−m Σ |ỹ_κ| over one band of its Walsh coefficients',
    order: () => 'up to N⁻³ (times log factors) for smooth f; N⁻¹ at worst',
    look: 'The whole N in one sequence, so its error falls faster than K randomizations of N/K points. The error bar is a bound read from the run\'s own Walsh coefficients (Hickernell and Jiménez Rugama): it holds when they decay steadily, and is usually wider than the error, so coverage near 1 is expected; a spike the points never saw escapes it.',
  },
  qmc: {
    title: 'Quasi-Monte Carlo (not randomized)',
    formula: 'I_N = (1/N) Σ f(xᵢ), xᵢ a deterministic low-discrepancy point set',
    order: () => 'error up to N⁻¹ (log N)^d; no error bar',
    look: 'Deterministic points: no replicate spread and no error bar, so no calibration either.',
  },
  vegas: {
    title: 'VEGAS (adaptive importance sampling)',
    formula: 'learn a separable map y → x whose density follows |f| on each axis, then I_N = (1/N) Σ f(x(yᵢ)) · J(yᵢ)',
    order: () => 'N⁻¹ once the map is trained, with a smaller constant',
    look: 'The map is trained on part of the budget (dashed lines on the time plot leave that time out). It helps when f is close to a product of one-dimensional peaks, and can lock onto one peak and miss another.',
  },
  vegas_plus: {
    title: 'VEGAS+ (adaptive importance sampling and stratification)',
    formula: 'VEGAS\'s map, plus hypercubes of the y space sampled in proportion to their measured spread',
    order: () => 'N⁻¹ or steeper, with a smaller constant',
    look: 'Adds adaptive stratification to VEGAS: better on peaks the map alone cannot follow (diagonal or several peaks).',
  },
  miser: {
    title: 'MISER (recursive stratified sampling)',
    formula: 'bisect the box along the axis whose halves have the smallest sum of standard deviations, share the points in proportion to those, and recurse; I_N sums the boxes\' estimates',
    order: () => 'N⁻¹ or steeper, with a smaller constant',
    look: 'Points go where f varies. The sample view draws the boxes. A few points per box explore first, and that share of the budget is part of the cost.',
  },
  mis: {
    title: 'Multiple importance sampling',
    formula: 'I_N = Σ_k (1/N_k) Σ_i w_k(x_{k,i}) f(x_{k,i}) / p_k(x_{k,i}), Σ_k w_k(x) = 1 (balance, power, maximum or optimal weights)',
    order: () => 'N⁻¹, with a constant close to the best technique\'s wherever it is best',
    look: 'No single technique is good everywhere, and the weights hand each region of x to the technique that samples it well. Compare the heuristics, and the weight curves w_k(x) under the overlay.',
  },
  control_variates: {
    title: 'Control variates',
    formula: 'I_N = (1/N) Σ [f(xᵢ) − c·(g(xᵢ) − G)], with ∫g = G known and c fitted',
    order: () => 'N⁻¹, the variance times 1 − ρ² (ρ the correlation of f and g)',
    look: 'The same slope, a lower line: how much lower depends on how well g follows f. A fitted c costs a little bias at small N.',
  },
  antithetic: {
    title: 'Antithetic variates',
    formula: 'I_N = (2/N) Σ_{i ≤ N/2} [f(uᵢ)/p(uᵢ) + f(1 − uᵢ)/p(1 − uᵢ)] / 2, uᵢ independent and uniform (warped by p)',
    order: () => 'N⁻¹, the variance times 1 + ρ (ρ the correlation of f at u and at 1 − u)',
    look: 'The same slope as uniform sampling, a lower line when f is monotone in each coordinate (then ρ < 0); a higher one when f is symmetric about the centre (ρ > 0). The error bar comes from the N/2 pair means.',
  },
  ris: {
    title: 'Resampled importance sampling',
    formula: 'I_N = (1/N) Σᵢ f(yᵢ)/g(yᵢ) · (1/M) Σⱼ g(xᵢⱼ)/p(xᵢⱼ): M candidates xᵢⱼ from p, yᵢ one of them kept with probability ∝ g/p',
    order: () => 'N⁻¹, the constant falling with M towards importance sampling with g',
    look: 'The variance falls as M grows while each point costs M candidates: compare the efficiency of ris_m1 to ris_m16 for the M that pays. With g = |f| a point is just the mean of M weights (no gain per call of f); a cheap g that follows f gains. Unbiased only where g > 0 wherever f ≠ 0: a target that misses f is flagged.',
  },
};

/** The methods this module explains. */
export const EXPLAINED = Object.freeze(Object.keys(METHODS));

/**
 * The explanation of an estimator from its details ({name, method, summary, sampler, pdf}) and
 * the problem's dimension: {title, formula, order, look, density}, or for a method this module
 * does not know a generic text with the core's summary of its kind.
 */
export function explainEstimator(detail, dimension = null) {
  const m = detail && METHODS[detail.method];
  if (!m) {
    return {
      title: detail && detail.method ? detail.method : 'Estimator',
      formula: 'I_N = (1/N) Σ f(xᵢ)/p(xᵢ)',
      order: ORDER_UNKNOWN,
      look: detail && typeof detail.summary === 'string' ? detail.summary : '',
      density: detail && (detail.pdf_text || detail.pdf) ? detail.pdf_text || detail.pdf : '',
    };
  }
  return {
    title: m.title,
    formula: m.formula,
    order: m.order(dimension),
    look: m.look,
    density: detail.pdf_text || detail.pdf || '',
  };
}
