#include "integrands/integrand.h"

#include <cmath>
#include <sstream>

#include "core/exp_block.h"
#include "core/special.h"

namespace mcp {

const char* integrand_kind_name(IntegrandKind kind) {
    switch (kind) {
    case IntegrandKind::Constant: return "constant";
    case IntegrandKind::Monomial: return "monomial";
    case IntegrandKind::Exponential: return "exponential";
    case IntegrandKind::Gaussian: return "gaussian";
    case IntegrandKind::IndicatorBall: return "indicator_ball";
    case IntegrandKind::Expression: return "expression";
    case IntegrandKind::Genz: return "genz";
    case IntegrandKind::Function: return "function";
    }
    return "?";
}

bool parse_integrand_kind(const std::string& name, IntegrandKind* kind) {
    for (IntegrandKind k :
         {IntegrandKind::Constant, IntegrandKind::Monomial, IntegrandKind::Exponential,
          IntegrandKind::Gaussian, IntegrandKind::IndicatorBall}) {
        if (name == integrand_kind_name(k)) {
            *kind = k;
            return true;
        }
    }
    return false;
}

namespace {

bool all_finite(const std::vector<double>& v) {
    for (double x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

std::string fmt(double v) {
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
}

} // namespace

Made<Integrand> make_integrand(IntegrandKind kind, int dim, double scale,
                               std::vector<double> coeffs, std::vector<double> center,
                               double width) {
    const std::string name = integrand_kind_name(kind);
    if (dim < 1 || dim > 64)
        return made_error<Integrand>(name + ": dimension must be in 1..64, got " +
                                     std::to_string(dim));
    if (!std::isfinite(scale)) return made_error<Integrand>(name + ": scale must be finite");
    bool needs_coeffs = kind == IntegrandKind::Monomial || kind == IntegrandKind::Exponential;
    bool needs_center = kind == IntegrandKind::Gaussian || kind == IntegrandKind::IndicatorBall;
    const char* coeff_name = kind == IntegrandKind::Monomial ? "powers" : "rates";
    if (needs_coeffs) {
        if (coeffs.size() != static_cast<size_t>(dim))
            return made_error<Integrand>(
                name + ": " + coeff_name + " has " + std::to_string(coeffs.size()) +
                " entries, the domain has " + std::to_string(dim) + " dimensions");
        if (!all_finite(coeffs))
            return made_error<Integrand>(name + ": " + coeff_name + " must be finite numbers");
        if (kind == IntegrandKind::Monomial)
            for (size_t j = 0; j < coeffs.size(); ++j)
                if (!(coeffs[j] > -1.0))
                    return made_error<Integrand>("monomial: powers[" + std::to_string(j) +
                                                 "] must be > -1 (integrable), got " +
                                                 fmt(coeffs[j]));
    }
    if (needs_center) {
        if (center.empty()) center.assign(static_cast<size_t>(dim), 0.0);
        if (center.size() != static_cast<size_t>(dim))
            return made_error<Integrand>(name + ": center has " + std::to_string(center.size()) +
                                         " entries, the domain has " + std::to_string(dim) +
                                         " dimensions");
        if (!all_finite(center)) return made_error<Integrand>(name + ": center must be finite");
        if (!(width > 0.0) || !std::isfinite(width))
            return made_error<Integrand>(name + ": " +
                                         (kind == IntegrandKind::Gaussian ? "sigma" : "radius") +
                                         " must be a finite number > 0, got " + fmt(width));
    }
    Integrand f;
    f.kind = kind;
    f.dim = dim;
    f.scale = scale;
    f.coeffs = std::move(coeffs);
    f.center = std::move(center);
    f.width = width;
    return {f, {}};
}

Made<Integrand> make_expression_integrand(const std::string& text, int dim) {
    Made<std::shared_ptr<const ExprProgram>> program = compile_expression(text, dim);
    if (!program.ok()) return made_error<Integrand>(program.error);
    Integrand f;
    f.kind = IntegrandKind::Expression;
    f.dim = dim;
    f.expr = program.value;
    return {f, {}};
}

Integrand make_function_integrand(std::shared_ptr<const CallerFunction> function, int dim) {
    Integrand f;
    f.kind = IntegrandKind::Function;
    f.dim = dim;
    f.function = std::move(function);
    return f;
}

Integrand make_genz_integrand(const GenzParams& params) {
    Integrand f;
    f.kind = IntegrandKind::Genz;
    f.dim = params.dim();
    f.genz = params;
    return f;
}

void evaluate_block(const Integrand& f, const PointBlock& x, double* out) {
    const size_t n = x.n;
    const int d = f.dim;
    switch (f.kind) {
    case IntegrandKind::Expression: {
        const double* vars[64];
        for (int j = 0; j < d; ++j) vars[j] = x.coord(j);
        f.expr->evaluate(vars, n, out);
        break;
    }
    case IntegrandKind::Genz: genz_evaluate_block(f.genz, x, out); break;
    case IntegrandKind::Function: f.function->evaluate(x, 1, out, n); break;
    case IntegrandKind::Constant:
        for (size_t i = 0; i < n; ++i) out[i] = f.scale;
        break;
    case IntegrandKind::Monomial:
        for (size_t i = 0; i < n; ++i) out[i] = f.scale;
        for (int j = 0; j < d; ++j) {
            const double p = f.coeffs[static_cast<size_t>(j)];
            const double* xj = x.coord(j);
            if (p == 0.0) continue;
            if (p == 1.0)
                for (size_t i = 0; i < n; ++i) out[i] *= xj[i];
            else if (p == 2.0)
                for (size_t i = 0; i < n; ++i) out[i] *= xj[i] * xj[i];
            else
                for (size_t i = 0; i < n; ++i) out[i] *= std::pow(xj[i], p);
        }
        break;
    case IntegrandKind::Exponential:
        for (size_t i = 0; i < n; ++i) out[i] = 0.0;
        for (int j = 0; j < d; ++j) {
            const double a = f.coeffs[static_cast<size_t>(j)];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) out[i] += a * xj[i];
        }
        exp_block(out, out, n);
        for (size_t i = 0; i < n; ++i) out[i] = f.scale * out[i];
        break;
    case IntegrandKind::Gaussian:
    case IntegrandKind::IndicatorBall: {
        for (size_t i = 0; i < n; ++i) out[i] = 0.0;
        for (int j = 0; j < d; ++j) {
            const double c = f.center[static_cast<size_t>(j)];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) out[i] += (xj[i] - c) * (xj[i] - c);
        }
        if (f.kind == IntegrandKind::Gaussian) {
            const double k = -0.5 / (f.width * f.width);
            for (size_t i = 0; i < n; ++i) out[i] = k * out[i];
            exp_block(out, out, n);
            for (size_t i = 0; i < n; ++i) out[i] = f.scale * out[i];
        } else {
            const double r2 = f.width * f.width;
            for (size_t i = 0; i < n; ++i) out[i] = out[i] < r2 ? f.scale : 0.0;
        }
        break;
    }
    }
}

double evaluate_point(const Integrand& f, const double* x) {
    PointBlock block;
    block.reset(f.dim, 1);
    block.n = 1;
    for (int j = 0; j < f.dim; ++j) block.coord(j)[0] = x[j];
    double out = 0.0;
    evaluate_block(f, block, &out);
    return out;
}

bool integrand_bounded(const Integrand& f) {
    switch (f.kind) {
    case IntegrandKind::Constant:
    case IntegrandKind::Exponential:
    case IntegrandKind::Gaussian:
    case IntegrandKind::IndicatorBall:
    case IntegrandKind::Genz: return true; // Genz's six families are bounded on [0,1]^d [Genz84]
    case IntegrandKind::Monomial:
        for (double p : f.coeffs)
            if (p < 0.0) return false;
        return true;
    case IntegrandKind::Expression:
    case IntegrandKind::Function: return false;
    }
    return false;
}

std::optional<bool> integrand_square_integrable(const Integrand& f, const std::vector<double>& lo,
                                                const std::vector<double>& hi) {
    if (integrand_bounded(f)) return true;
    if (f.kind != IntegrandKind::Monomial || f.coeffs.size() != lo.size() ||
        f.coeffs.size() != hi.size())
        return std::nullopt;
    if (f.scale == 0.0) return true;
    for (size_t j = 0; j < f.coeffs.size(); ++j) {
        const bool reaches_zero = lo[j] <= 0.0 && hi[j] >= 0.0;
        if (reaches_zero && !(2.0 * f.coeffs[j] > -1.0)) return false;
    }
    return true;
}

double ball_volume(int dim, double r) {
    return std::pow(kPi, 0.5 * dim) * std::pow(r, dim) / std::tgamma(0.5 * dim + 1.0);
}

std::optional<double> exact_integral_over_box(const Integrand& f, const std::vector<double>& lo,
                                              const std::vector<double>& hi) {
    if (f.kind == IntegrandKind::Expression || f.kind == IntegrandKind::Function)
        return std::nullopt;
    if (f.kind == IntegrandKind::Genz) {
        for (int j = 0; j < f.dim; ++j)
            if (lo[static_cast<size_t>(j)] != 0.0 || hi[static_cast<size_t>(j)] != 1.0)
                return std::nullopt;
        return genz_exact(f.genz);
    }
    double result = f.scale;
    for (int j = 0; j < f.dim; ++j) {
        const double a = lo[static_cast<size_t>(j)], b = hi[static_cast<size_t>(j)];
        switch (f.kind) {
        case IntegrandKind::Expression:
        case IntegrandKind::Function:
        case IntegrandKind::Genz: return std::nullopt; // handled above
        case IntegrandKind::Constant: result *= b - a; break;
        case IntegrandKind::Monomial: {
            const double p = f.coeffs[static_cast<size_t>(j)];
            // Negative x with a fractional power has no real value: no closed form here.
            if (a < 0.0 && p != std::floor(p)) return std::nullopt;
            result *= (std::pow(b, p + 1.0) - std::pow(a, p + 1.0)) / (p + 1.0);
            break;
        }
        case IntegrandKind::Exponential: {
            // int_a^b e^(k x) dx = e^(k a) expm1(k (b - a)) / k, stable as k -> 0.
            const double k = f.coeffs[static_cast<size_t>(j)];
            result *= k == 0.0 ? b - a : std::exp(k * a) * std::expm1(k * (b - a)) / k;
            break;
        }
        case IntegrandKind::Gaussian: {
            // sigma sqrt(pi/2) [erf((b-c)/(sigma sqrt2)) - erf((a-c)/(sigma sqrt2))]
            const double c = f.center[static_cast<size_t>(j)], s = f.width * kSqrt2;
            double hi_t = (b - c) / s, lo_t = (a - c) / s;
            double diff = (lo_t > 0.0)   ? std::erfc(lo_t) - std::erfc(hi_t)
                          : (hi_t < 0.0) ? std::erfc(-hi_t) - std::erfc(-lo_t)
                                         : std::erf(hi_t) - std::erf(lo_t);
            result *= f.width * std::sqrt(0.5 * kPi) * diff;
            break;
        }
        case IntegrandKind::IndicatorBall: {
            // Closed form only when the ball lies inside the box.
            const double c = f.center[static_cast<size_t>(j)];
            if (c - f.width < a || c + f.width > b) return std::nullopt;
            if (j == f.dim - 1) return f.scale * ball_volume(f.dim, f.width);
            break;
        }
        }
    }
    return result;
}

std::string describe_integrand(const Integrand& f) {
    std::ostringstream s;
    s.precision(6);
    auto var = [&](int j) { return f.dim == 1 ? std::string("x") : "x" + std::to_string(j + 1); };
    switch (f.kind) {
    case IntegrandKind::Constant: s << f.scale; break;
    case IntegrandKind::Monomial:
        s << f.scale;
        for (int j = 0; j < f.dim; ++j)
            if (f.coeffs[static_cast<size_t>(j)] != 0.0)
                s << " * " << var(j) << "^" << f.coeffs[static_cast<size_t>(j)];
        break;
    case IntegrandKind::Exponential:
        s << f.scale << " * exp(";
        for (int j = 0; j < f.dim; ++j)
            s << (j ? " + " : "") << f.coeffs[static_cast<size_t>(j)] << " " << var(j);
        s << ")";
        break;
    case IntegrandKind::Gaussian:
        s << f.scale << " * exp(-|x - c|^2 / (2 * " << f.width << "^2))";
        break;
    case IntegrandKind::IndicatorBall: s << f.scale << " * [|x - c| < " << f.width << "]"; break;
    case IntegrandKind::Expression: s << f.expr->source(); break;
    case IntegrandKind::Function: s << "the caller's function " << f.function->name; break;
    case IntegrandKind::Genz:
        s << genz_family_name(f.genz.family) << " (d = " << f.dim << ", sum a = ";
        {
            double sum = 0.0;
            for (double a : f.genz.a) sum += a;
            s << sum << ")";
        }
        break;
    }
    return s.str();
}

} // namespace mcp
