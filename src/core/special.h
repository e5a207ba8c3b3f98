// Special functions for error bars and goodness-of-fit tests: the normal and Student t
// quantiles, the regularised incomplete gamma function (chi-square tail probabilities),
// and the trigamma function (the variance of a log sample variance).
#pragma once

#include <string>

namespace mcp {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvPi = 0.31830988618379067154;
constexpr double kSqrt2 = 1.41421356237309504880;
/// The standard normal's 0.975 quantile: the half-width of a 95% interval in standard errors.
constexpr double kNormal975 = 1.95996398454005423552;

/// Standard normal CDF Phi(x), accurate in both tails.
double normal_cdf(double x);

/// Standard normal quantile Phi^-1(p) for p in (0, 1): the rational starting value of
/// [AS64, 26.2.23] refined by Halley steps on erfc, good to a few ulps.
double normal_quantile(double p);

/// Quantile of Student's t with nu degrees of freedom: exact for nu = 1, 2; the
/// Cornish-Fisher expansion [AS64, 26.7.5] otherwise (error < 1e-3 for nu >= 3).
double student_t_quantile(double p, double nu);

/// Regularised lower incomplete gamma P(a, x) = gamma(a, x) / Gamma(a), and Q = 1 - P
/// computed without cancellation: series for x < a + 1, continued fraction otherwise
/// [NR07, 6.2].
double gamma_p(double a, double x);
double gamma_q(double a, double x);

/// Upper tail probability of the chi-square distribution with k degrees of freedom.
double chi_square_sf(double x, double k);

/// Quantile of the chi-square distribution: P(X <= x) = p.
double chi_square_quantile(double p, double k);

/// Regularised incomplete beta I_x(a, b) for a, b > 0 and x in [0, 1], by its continued
/// fraction [NR07, 6.4] (on the side where it converges fast).
double beta_regularized(double a, double b, double x);

/// Upper tail probability of Student's t with nu > 0 degrees of freedom, P(T > t):
/// (1/2) I_{nu / (nu + t^2)}(nu / 2, 1 / 2) for t >= 0 [AS64, 26.7.1], by symmetry below.
double student_t_sf(double t, double nu);

/// The t > 0 with P(T > t) = tail for Student's t with nu > 0 degrees of freedom, tail in
/// (0, 1/2]: exact for nu = 1, 2; otherwise student_t_sf inverted by bisection, accurate where
/// the Cornish-Fisher expansion is not (tails below 1e-3 at few degrees of freedom).
double student_t_isf(double tail, double nu);

/// The degrees of freedom below which widened_limit stops widening by t_0.975 alone: 15, those
/// of the default 16 randomizations.
constexpr double kWidenedReferenceDof = 15.0;

/// A limit of `z` standard errors for a statistic that is Student t with nu degrees of freedom:
/// z widened by t_0.975(nu) / 1.96, and below kWidenedReferenceDof never nearer than the point
/// an honest draw crosses as rarely as it crosses the widened limit at the reference. The
/// widening alone is no tail of t at 1-3 degrees of freedom: 5 widened standard errors (32.4 at
/// nu = 1) are crossed by 2% of honest draws at nu = 1, 0.4% at 3, 0.007% at 15.
double widened_limit(double z, double nu);

/// Upper tail probability of Snedecor's F distribution with (d1, d2) degrees of freedom:
/// P(F > f) = I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2).
double f_sf(double f, double d1, double d2);

/// Trigamma psi'(x) for x > 0 (recurrence up to x >= 10, then the asymptotic series).
/// Var[log s^2] = psi'((R - 1) / 2) for a sample variance of R normal values.
double trigamma(double x);

/// A p-value for a sentence: "p = 3.1e-05" (`digits` significant digits), and "p < 1e-300"
/// below 1e-300, where a tail probability that underflowed to 0 would print as "p = 0" (a
/// p-value is never 0); "p = -" when it is not a number. Every message that states a p-value
/// formats it here.
std::string p_value_text(double p, int digits = 2);

} // namespace mcp
