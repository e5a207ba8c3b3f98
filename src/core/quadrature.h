// Deterministic one-dimensional quadrature: adaptive Gauss-Kronrod (G7-K15) with global
// subdivision, as QUADPACK's QAG [Piessens83], and the same on [a, +infinity) by a change of
// variable. Used for reference values (closed forms that need one integral, tests); not a
// hot loop, so the integrand is a std::function.
#pragma once

#include <functional>

namespace mcp {

struct QuadratureResult {
    double value = 0.0;          ///< the Kronrod estimate summed over the final intervals
    double error_estimate = 0.0; ///< QUADPACK's error estimate (see integrate_adaptive)
    int evaluations = 0;         ///< calls of f
    bool converged = false;      ///< error_estimate <= max(abs_tol, rel_tol * |value|)
};

/// One application of the 15-point Kronrod rule and its embedded 7-point Gauss rule on
/// [a, b], with the quantities QUADPACK's QK15 derives from the same 15 values.
struct GaussKronrodEstimate {
    double kronrod = 0.0; ///< K15 (exact for polynomials of degree <= 22)
    double gauss = 0.0;   ///< G7 (exact for polynomials of degree <= 13)
    double abs = 0.0;     ///< K15 applied to |f|
    double asc = 0.0;     ///< K15 applied to |f - kronrod / (b - a)|
    double error = 0.0;   ///< error estimate of `kronrod` (see integrate_adaptive)
};

/// The G7-K15 pair on [a, b]. f is evaluated at the 15 interior nodes only, never at a or b.
GaussKronrodEstimate gauss_kronrod_15(const std::function<double(double)>& f, double a, double b);

/// Adaptive Gauss-Kronrod (G7-K15) on [a, b] with global subdivision: the interval with the
/// largest error estimate is bisected until the summed error estimate is
/// <= max(abs_tol, rel_tol * |value|), or max_intervals intervals exist, or progress stops.
///
/// Per interval the error estimate is QUADPACK's [Piessens83, QK15]:
///   E = asc * min(1, (200 |K15 - G7| / asc)^1.5), raised to at least 50 eps * abs,
/// pessimistic for smooth f. The 50 eps * abs floor accounts for rounding, so a target below
/// about 50 eps * int |f| / |int f| (e.g. a tight relative tolerance on an oscillating f whose
/// integral nearly cancels) is unreachable: the loop then stops early when bisection no
/// longer reduces the error (QUADPACK's round-off test) and reports converged = false.
/// Also converged = false when f returned a non-finite value (value is then non-finite), or
/// an interval became too narrow to bisect (a non-integrable singularity).
/// f is evaluated only at interior Gauss-Kronrod nodes, never at a or b, so integrable
/// end-point singularities (x^-0.5 at 0) are fine. b < a gives minus the integral over [b, a].
QuadratureResult integrate_adaptive(const std::function<double(double)>& f, double a, double b,
                                    double rel_tol = 1e-12, double abs_tol = 0.0,
                                    int max_intervals = 2000);

/// The same on [a, +infinity): x = a + t / (1 - t) maps t in [0, 1) onto [a, infinity), and
/// the integrand becomes f(a + t / (1 - t)) / (1 - t)^2 on [0, 1]; t = 1 is never evaluated.
/// Suits f decaying at least like x^-2 (then the transformed integrand stays bounded).
QuadratureResult integrate_to_infinity(const std::function<double(double)>& f, double a,
                                       double rel_tol = 1e-12, double abs_tol = 0.0,
                                       int max_intervals = 2000);

} // namespace mcp
