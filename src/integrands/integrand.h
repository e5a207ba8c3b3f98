// Test integrands, evaluated a whole block of points at a time (one dispatch per block),
// each with its exact integral over a box where a closed form exists.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/caller_function.h"
#include "core/made.h"
#include "core/points.h"
#include "integrands/expression.h"
#include "integrands/genz.h"

namespace mcp {

enum class IntegrandKind {
    Constant,      ///< f = scale
    Monomial,      ///< f = scale * prod_j x_j^p_j (p_j > -1 for an integrable singularity)
    Exponential,   ///< f = scale * exp(sum_j a_j x_j)
    Gaussian,      ///< f = scale * exp(-|x - c|^2 / (2 sigma^2))
    IndicatorBall, ///< f = scale * [|x - c| < r]
    Expression,    ///< a user-typed expression, compiled (integrands/expression.h)
    Genz,          ///< one of Genz's six test families on [0,1]^d (integrands/genz.h)
    Function,      ///< a function given by the library's caller (core/caller_function.h)
};

struct Integrand {
    IntegrandKind kind = IntegrandKind::Constant;
    int dim = 1;
    double scale = 1.0;
    std::vector<double> coeffs;              ///< powers p_j (monomial) or rates a_j (exponential)
    std::vector<double> center;              ///< Gaussian and ball centre
    double width = 1.0;                      ///< Gaussian sigma or ball radius
    std::shared_ptr<const ExprProgram> expr; ///< Expression: shared, immutable
    GenzParams genz;                         ///< Genz: family, a, u
    std::shared_ptr<const CallerFunction> function; ///< Function: the caller's, shared
};

const char* integrand_kind_name(IntegrandKind kind);
bool parse_integrand_kind(const std::string& name, IntegrandKind* kind);

/// Validates the parameters (sizes match dim, finite values, powers > -1, width > 0).
Made<Integrand> make_integrand(IntegrandKind kind, int dim, double scale,
                               std::vector<double> coeffs, std::vector<double> center,
                               double width);

/// An integrand from an expression compiled for `dim` dimensions (error: "at position P: ...").
Made<Integrand> make_expression_integrand(const std::string& text, int dim);

/// An integrand that calls a caller's function on each block of points of dimension `dim`.
Integrand make_function_integrand(std::shared_ptr<const CallerFunction> function, int dim);

/// An integrand from validated Genz parameters.
Integrand make_genz_integrand(const GenzParams& params);

/// out[i] = f(x_i) for the x.n points of the block.
void evaluate_block(const Integrand& f, const PointBlock& x, double* out);

/// f at one point (for tests and tabulation; not for hot loops).
double evaluate_point(const Integrand& f, const double* x);

/// Exact integral over the box [lo, hi] when a closed form is known.
std::optional<double> exact_integral_over_box(const Integrand& f, const std::vector<double>& lo,
                                              const std::vector<double>& hi);

/// Whether |f| is bounded on any bounded domain by what its kind and parameters say: every
/// kind but an expression or a caller's function (unknown) and a monomial with a negative power
/// (a singularity).
bool integrand_bounded(const Integrand& f);

/// Whether int f^2 over the box [lo, hi] is finite, where f's kind says so: yes for a bounded
/// kind (integrand_bounded), for a monomial yes exactly when every power p_j whose coordinate
/// reaches 0 has 2 p_j > -1 (int_0 x^(2 p) dx); unknown (nullopt) otherwise.
std::optional<bool> integrand_square_integrable(const Integrand& f, const std::vector<double>& lo,
                                                const std::vector<double>& hi);

/// Volume of the d-dimensional ball of radius r: pi^(d/2) r^d / Gamma(d/2 + 1).
double ball_volume(int dim, double r);

/// Human-readable formula, e.g. "4 * x1^2 * x2^1".
std::string describe_integrand(const Integrand& f);

} // namespace mcp
