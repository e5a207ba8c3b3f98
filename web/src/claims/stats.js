// The few distributions the claims test against: the chi-square upper tail (regularized
// incomplete gamma Q), the trigamma function (the variance of the log of a chi-square variable)
// and a least-squares line with its residual standard error.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.

/** ln Gamma(a) for a a positive multiple of 1/2 (chi-square degrees of freedom / 2), by the
 *  recurrence Gamma(a + 1) = a Gamma(a) from Gamma(1) = 1 and Gamma(1/2) = sqrt(pi). */
function logGammaHalf(a) {
  let x = a;
  let s = 0;
  while (x > 1.25) {
    x -= 1;
    s += Math.log(x);
  }
  return s + (x < 0.75 ? 0.5 * Math.log(Math.PI) : 0);
}

/** Q(a, x) = Gamma(a, x) / Gamma(a), a a multiple of 1/2: the series of P below a + 1, a continued fraction above. */
export function gammaQ(a, x) {
  if (!(a > 0) || !(x >= 0)) return NaN;
  if (x === 0) return 1;
  const lead = -x + a * Math.log(x) - logGammaHalf(a);
  if (x < a + 1) {
    let term = 1 / a;
    let sum = term;
    for (let n = 1; n < 10000; n++) {
      term *= x / (a + n);
      sum += term;
      if (Math.abs(term) < Math.abs(sum) * 1e-16) break;
    }
    return Math.max(0, 1 - sum * Math.exp(lead));
  }
  // Lentz's method on the continued fraction of Q.
  const tiny = 1e-300;
  let b = x + 1 - a;
  let c = 1 / tiny;
  let d = 1 / b;
  let h = d;
  for (let i = 1; i < 10000; i++) {
    const an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (Math.abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (Math.abs(c) < tiny) c = tiny;
    d = 1 / d;
    const delta = d * c;
    h *= delta;
    if (Math.abs(delta - 1) < 1e-16) break;
  }
  return Math.exp(lead) * h;
}

/** P(chi^2_dof >= x). */
export function chi2Sf(x, dof) {
  if (!(dof > 0)) return NaN;
  return gammaQ(dof / 2, Math.max(0, x) / 2);
}

/** The trigamma function psi'(x), x > 0: recurrence up to 6, then its asymptotic series. */
export function trigamma(x) {
  let s = 0;
  while (x < 6) {
    s += 1 / (x * x);
    x += 1;
  }
  const x2 = 1 / (x * x);
  return s + 1 / x + x2 / 2 + (1 / x) * x2 * (1 / 6 - x2 * (1 / 30 - x2 * (1 / 42 - x2 / 30)));
}

/**
 * The least-squares line of ys on xs, each point with standard deviation `sd` (a number or an
 * array): {slope, intercept, slopeSe (the larger of the sampling one and the residuals'), chi2,
 * dof, p}, or null with fewer than 3 points or one x.
 */
export function fitLine(xs, ys, sd) {
  const n = xs.length;
  if (n < 3) return null;
  const sds = Array.isArray(sd) ? sd : xs.map(() => sd);
  let sw = 0;
  let swx = 0;
  let swy = 0;
  for (let i = 0; i < n; i++) {
    const w = 1 / (sds[i] * sds[i]);
    sw += w; swx += w * xs[i]; swy += w * ys[i];
  }
  const mx = swx / sw;
  const my = swy / sw;
  let sxx = 0;
  let sxy = 0;
  for (let i = 0; i < n; i++) {
    const w = 1 / (sds[i] * sds[i]);
    sxx += w * (xs[i] - mx) ** 2;
    sxy += w * (xs[i] - mx) * (ys[i] - my);
  }
  if (!(sxx > 0)) return null;
  const slope = sxy / sxx;
  const intercept = my - slope * mx;
  let chi2 = 0;
  for (let i = 0; i < n; i++) chi2 += ((ys[i] - intercept - slope * xs[i]) / sds[i]) ** 2;
  const dof = n - 2;
  const sampling = Math.sqrt(1 / sxx);
  const residual = Math.sqrt(chi2 / dof / sxx);
  return { slope, intercept, slopeSe: Math.max(sampling, residual), chi2, dof, p: chi2Sf(chi2, dof) };
}
