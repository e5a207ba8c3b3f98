#include "integrands/genz.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/quadrature.h"
#include "core/rng.h"
#include "core/special.h"

namespace mcp {

namespace {

constexpr GenzFamily kFamilies[] = {GenzFamily::Oscillatory, GenzFamily::ProductPeak,
                                    GenzFamily::CornerPeak,  GenzFamily::Gaussian,
                                    GenzFamily::Continuous,  GenzFamily::Discontinuous};

std::string fmt(double v) {
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
}

// A product sign * m * 2^e with m in [0.5, 1) and a 64-bit exponent: the binary logarithm of
// the magnitude is carried exactly, so a product of d factors neither under- nor overflows
// before the end, and loses only d roundings (as a plain product would, were it in range).
struct ScaledProduct {
    int sign = 1;
    double m = 0.5;
    int64_t e = 1; // 0.5 * 2^1 = 1

    void mul(double f) {
        if (f == 0.0 || sign == 0) {
            sign = 0;
            return;
        }
        if (f < 0.0) {
            sign = -sign;
            f = -f;
        }
        int kf = 0, km = 0;
        const double mf = std::frexp(f, &kf); // exact
        m = std::frexp(m * mf, &km);          // m * mf in [0.25, 1): one rounding, no underflow
        e += int64_t(kf) + km;
    }

    /// Multiplies by exp(c) for any finite c (exp(c) itself may be outside the double range).
    void mul_exp(double c) {
        if (std::fabs(c) < 700.0) {
            mul(std::exp(c));
            return;
        }
        // c = k ln2 + r with |r| <= ln2 / 2, ln2 split in two parts (Cody-Waite) so that
        // k ln2_hi is exact for |k| < 2^20.
        constexpr double kLn2Hi = 6.93147180369123816490e-01; // 32 significant bits
        constexpr double kLn2Lo = 1.90821492927058770002e-10;
        const double k = std::nearbyint(c / 0.69314718055994530942);
        const double r = (c - k * kLn2Hi) - k * kLn2Lo;
        mul(std::exp(r));
        e += static_cast<int64_t>(k);
    }

    double value() const {
        if (sign == 0) return 0.0;
        const int64_t clamped = std::max<int64_t>(-4000, std::min<int64_t>(4000, e));
        return sign * std::ldexp(m, static_cast<int>(clamped));
    }

    double log_abs() const {
        if (sign == 0) return -INFINITY;
        return std::log(m) + static_cast<double>(e) * 0.69314718055994530942;
    }
};

// sin(x) / x, continuous at 0 (relative error of the two-term series < x^4 / 120 < 1e-18).
double sinc(double x) {
    if (std::fabs(x) < 1e-4) return 1.0 - x * x / 6.0;
    return std::sin(x) / x;
}

// expm1(c) / a for c = a * w > 0 (w in (0, 1]), as a factor of the product: direct while
// expm1 is finite, through its logarithm c + log(1 - e^-c) - log a beyond.
void mul_expm1_over_a(ScaledProduct* prod, double a, double c) {
    if (c < 700.0) {
        prod->mul(std::expm1(c) / a);
    } else {
        prod->mul_exp(c);
        prod->mul(-std::expm1(-c) / a);
    }
}

// corner_peak through (1 + s)^-(d+1) = (1/d!) int_0^inf t^d e^-(1+s) t dt (the vertex
// inclusion-exclusion sum cancels catastrophically): integrating x over [0,1]^d first,
//   I = (1/d!) int_0^inf e^-t prod_i q_i(t) dt,  q_i(t) = (1 - e^-a_i t) / a_i,
// with q_i = -expm1(-a_i t) / a_i computed without cancellation,
// an integral of a positive, log-concave function (each log q_i is concave). Its logarithm
//   L(t) = -t + sum_i log(q_i(t) / (i + 1))    (the 1/d! spread over the factors)
// is evaluated in logs (64 factors of 1/a_i could overflow), and shifted by its maximum L(t*),
// so the integrand exp(L(t) - L(t*)) peaks at exactly 1 whatever the parameters.
// t* solves L'(t) = 0, i.e. sum_i a_i / expm1(a_i t) = 1, whose left side falls from +inf to
// 0; and t* <= d since a / expm1(a t) < 1 / t.
double corner_log_integrand(const GenzParams& p, double t) {
    double l = -t;
    const int d = p.dim();
    for (int i = 0; i < d; ++i) {
        const double a = p.a[static_cast<size_t>(i)];
        l += std::log(-std::expm1(-a * t) / a / (i + 1));
    }
    return l;
}

double corner_peak_argmax(const GenzParams& p) {
    auto slope = [&](double t) {
        double s = -1.0;
        for (double a : p.a) s += a / std::expm1(a * t);
        return s;
    };
    // Bisection on log t: slope > 0 at lo, <= 0 at hi = d.
    double lo = std::log(static_cast<double>(p.dim())) - 40.0;
    double hi = std::log(static_cast<double>(p.dim()));
    while (lo > -700.0 && !(slope(std::exp(lo)) > 0.0)) lo -= 40.0;
    for (int it = 0; it < 100 && hi - lo > 1e-12; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (slope(std::exp(mid)) > 0.0)
            lo = mid;
        else
            hi = mid;
    }
    return std::exp(0.5 * (lo + hi));
}

ScaledProduct corner_peak_exact(const GenzParams& p) {
    const double t_star = corner_peak_argmax(p);
    const double shift = corner_log_integrand(p, t_star);
    auto g = [&](double t) { return std::exp(corner_log_integrand(p, t) - shift); };
    // The integrand is positive, so QUADPACK's rounding floor is ~1e-14 relative: 1e-13 is
    // reachable, and the estimate is pessimistic (the true error is typically ~1e-15).
    const QuadratureResult q = integrate_to_infinity(g, 0.0, 1e-13, 0.0, 4000);
    ScaledProduct prod;
    prod.mul(q.value);
    prod.mul_exp(shift);
    return prod;
}

ScaledProduct exact_scaled(const GenzParams& p) {
    ScaledProduct prod;
    const int d = p.dim();
    const double* a = p.a.data();
    const double* u = p.u.data();
    switch (p.family) {
    case GenzFamily::Oscillatory: {
        // Re[e^(i 2 pi u1) prod_i (e^(i a_i) - 1) / (i a_i)]
        //   = cos(2 pi u1 + sum a_i / 2) prod_i sin(a_i / 2) / (a_i / 2).
        double phase = 2.0 * kPi * u[0];
        for (int i = 0; i < d; ++i) phase += 0.5 * a[i];
        prod.mul(std::cos(phase));
        for (int i = 0; i < d; ++i) prod.mul(sinc(0.5 * a[i]));
        break;
    }
    case GenzFamily::ProductPeak:
        // int_0^1 dx / (a^-2 + (x - u)^2) = a (atan(a (1 - u)) + atan(a u)); both terms >= 0.
        for (int i = 0; i < d; ++i)
            prod.mul(a[i] * (std::atan(a[i] * (1.0 - u[i])) + std::atan(a[i] * u[i])));
        break;
    case GenzFamily::CornerPeak: return corner_peak_exact(p);
    case GenzFamily::Gaussian: {
        // int_0^1 exp(-a^2 (x - u)^2) dx = sqrt(pi) / (2a) (erf(a (1 - u)) + erf(a u)).
        const double half_sqrt_pi = 0.5 * std::sqrt(kPi);
        for (int i = 0; i < d; ++i)
            prod.mul(half_sqrt_pi * (std::erf(a[i] * (1.0 - u[i])) + std::erf(a[i] * u[i])) / a[i]);
        break;
    }
    case GenzFamily::Continuous:
        // int_0^1 exp(-a |x - u|) dx = ((1 - e^-a u) + (1 - e^-a (1 - u))) / a.
        for (int i = 0; i < d; ++i)
            prod.mul((-std::expm1(-a[i] * u[i]) - std::expm1(-a[i] * (1.0 - u[i]))) / a[i]);
        break;
    case GenzFamily::Discontinuous: {
        // x_1 (and x_2) cut at u: int_0^u e^(a x) dx = expm1(a u) / a; int_0^1 = expm1(a) / a.
        const int cut = std::min(d, 2);
        for (int i = 0; i < d; ++i) {
            if (i < cut && u[i] == 0.0) {
                prod.mul(0.0);
                break;
            }
            mul_expm1_over_a(&prod, a[i], i < cut ? a[i] * u[i] : a[i]);
        }
        break;
    }
    }
    return prod;
}

} // namespace

const char* genz_family_name(GenzFamily f) {
    switch (f) {
    case GenzFamily::Oscillatory: return "genz_oscillatory";
    case GenzFamily::ProductPeak: return "genz_product_peak";
    case GenzFamily::CornerPeak: return "genz_corner_peak";
    case GenzFamily::Gaussian: return "genz_gaussian";
    case GenzFamily::Continuous: return "genz_continuous";
    case GenzFamily::Discontinuous: return "genz_discontinuous";
    }
    return "?";
}

bool parse_genz_family(const std::string& name, GenzFamily* out) {
    for (GenzFamily f : kFamilies) {
        if (name == genz_family_name(f)) {
            *out = f;
            return true;
        }
    }
    return false;
}

Made<GenzParams> make_genz(GenzFamily f, std::vector<double> a, std::vector<double> u) {
    const std::string name = genz_family_name(f);
    if (a.empty() || a.size() > 64)
        return made_error<GenzParams>(name + ": dimension (entries of a) must be in 1..64, got " +
                                      std::to_string(a.size()));
    if (u.size() != a.size())
        return made_error<GenzParams>(name + ": u has " + std::to_string(u.size()) +
                                      " entries, a has " + std::to_string(a.size()) +
                                      " (one of each per dimension)");
    const bool allow_zero = f == GenzFamily::Oscillatory;
    for (size_t i = 0; i < a.size(); ++i) {
        const std::string field = name + ": a[" + std::to_string(i) + "] must be ";
        if (!std::isfinite(a[i])) return made_error<GenzParams>(field + "finite, got " + fmt(a[i]));
        if (allow_zero ? !(a[i] >= 0.0) : !(a[i] > 0.0))
            return made_error<GenzParams>(field + (allow_zero ? ">= 0" : "> 0") + ", got " +
                                          fmt(a[i]));
    }
    for (size_t i = 0; i < u.size(); ++i) {
        const std::string field = name + ": u[" + std::to_string(i) + "] must be ";
        if (!std::isfinite(u[i])) return made_error<GenzParams>(field + "finite, got " + fmt(u[i]));
        if (!(u[i] >= 0.0 && u[i] <= 1.0))
            return made_error<GenzParams>(field + "in [0, 1], got " + fmt(u[i]));
    }
    GenzParams p;
    p.family = f;
    p.a = std::move(a);
    p.u = std::move(u);
    return {p, {}};
}

GenzParams genz_random(GenzFamily f, int dim, uint64_t seed, double difficulty) {
    // Genz's normalisation constants (h, e) [Genz87], one row per family in enum order.
    static constexpr double kH[6] = {110.0, 600.0, 600.0, 100.0, 150.0, 100.0};
    static constexpr double kE[6] = {1.5, 2.0, 2.0, 1.0, 2.0, 2.0};
    const int d = std::max(1, std::min(64, dim));
    if (!(difficulty > 0.0) || !std::isfinite(difficulty)) difficulty = 1.0;
    const size_t row = static_cast<size_t>(f);

    GenzParams p;
    p.family = f;
    p.a.resize(static_cast<size_t>(d));
    p.u.resize(static_cast<size_t>(d));
    Pcg32 rng(seed, hash_string("genz"));
    for (double& v : p.a) v = rng.next_double(); // in (0, 1): never 0
    for (double& v : p.u) v = rng.next_double();
    double sum = 0.0;
    for (double v : p.a) sum += v;
    const double target = difficulty * kH[row] / std::pow(static_cast<double>(d), kE[row]);
    const double scale = target / sum;
    for (double& v : p.a) v *= scale;
    return p;
}

void genz_evaluate_block(const GenzParams& p, const PointBlock& x, double* out) {
    const size_t n = x.n;
    const int d = p.dim();
    const double* a = p.a.data();
    const double* u = p.u.data();
    switch (p.family) {
    case GenzFamily::Oscillatory: {
        const double phase = 2.0 * kPi * u[0];
        for (size_t i = 0; i < n; ++i) out[i] = phase;
        for (int j = 0; j < d; ++j) {
            const double aj = a[j];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) out[i] += aj * xj[i];
        }
        for (size_t i = 0; i < n; ++i) out[i] = std::cos(out[i]);
        break;
    }
    case GenzFamily::ProductPeak:
        for (size_t i = 0; i < n; ++i) out[i] = 1.0;
        for (int j = 0; j < d; ++j) {
            const double c = 1.0 / (a[j] * a[j]), uj = u[j];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) {
                const double t = xj[i] - uj;
                out[i] /= c + t * t;
            }
        }
        break;
    case GenzFamily::CornerPeak: {
        for (size_t i = 0; i < n; ++i) out[i] = 1.0;
        for (int j = 0; j < d; ++j) {
            const double aj = a[j];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) out[i] += aj * xj[i];
        }
        const double power = -static_cast<double>(d + 1);
        for (size_t i = 0; i < n; ++i) out[i] = std::pow(out[i], power);
        break;
    }
    case GenzFamily::Gaussian:
        for (size_t i = 0; i < n; ++i) out[i] = 0.0;
        for (int j = 0; j < d; ++j) {
            const double aj = a[j], uj = u[j];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) {
                const double t = aj * (xj[i] - uj);
                out[i] += t * t;
            }
        }
        for (size_t i = 0; i < n; ++i) out[i] = std::exp(-out[i]);
        break;
    case GenzFamily::Continuous:
        for (size_t i = 0; i < n; ++i) out[i] = 0.0;
        for (int j = 0; j < d; ++j) {
            const double aj = a[j], uj = u[j];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) out[i] += aj * std::fabs(xj[i] - uj);
        }
        for (size_t i = 0; i < n; ++i) out[i] = std::exp(-out[i]);
        break;
    case GenzFamily::Discontinuous: {
        for (size_t i = 0; i < n; ++i) out[i] = 0.0;
        for (int j = 0; j < d; ++j) {
            const double aj = a[j];
            const double* xj = x.coord(j);
            for (size_t i = 0; i < n; ++i) out[i] += aj * xj[i];
        }
        const double* x0 = x.coord(0);
        const double u0 = u[0];
        if (d == 1) {
            for (size_t i = 0; i < n; ++i) out[i] = x0[i] > u0 ? 0.0 : std::exp(out[i]);
        } else {
            const double* x1 = x.coord(1);
            const double u1 = u[1];
            for (size_t i = 0; i < n; ++i)
                out[i] = (x0[i] > u0 || x1[i] > u1) ? 0.0 : std::exp(out[i]);
        }
        break;
    }
    }
}

double genz_evaluate_point(const GenzParams& p, const double* x) {
    const int d = p.dim();
    const double* a = p.a.data();
    const double* u = p.u.data();
    double s = 0.0;
    switch (p.family) {
    case GenzFamily::Oscillatory:
        s = 2.0 * kPi * u[0];
        for (int j = 0; j < d; ++j) s += a[j] * x[j];
        return std::cos(s);
    case GenzFamily::ProductPeak:
        s = 1.0;
        for (int j = 0; j < d; ++j) {
            const double c = 1.0 / (a[j] * a[j]);
            const double t = x[j] - u[j];
            s /= c + t * t;
        }
        return s;
    case GenzFamily::CornerPeak:
        s = 1.0;
        for (int j = 0; j < d; ++j) s += a[j] * x[j];
        return std::pow(s, -static_cast<double>(d + 1));
    case GenzFamily::Gaussian:
        for (int j = 0; j < d; ++j) {
            const double t = a[j] * (x[j] - u[j]);
            s += t * t;
        }
        return std::exp(-s);
    case GenzFamily::Continuous:
        for (int j = 0; j < d; ++j) s += a[j] * std::fabs(x[j] - u[j]);
        return std::exp(-s);
    case GenzFamily::Discontinuous:
        for (int j = 0; j < d; ++j) s += a[j] * x[j];
        if (x[0] > u[0] || (d > 1 && x[1] > u[1])) return 0.0;
        return std::exp(s);
    }
    return 0.0;
}

double genz_exact(const GenzParams& p) {
    return exact_scaled(p).value();
}

double genz_log_exact(const GenzParams& p, int* sign) {
    const ScaledProduct prod = exact_scaled(p);
    if (sign) *sign = prod.sign;
    return prod.log_abs();
}

} // namespace mcp
