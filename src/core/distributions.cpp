// Sampling distributions: analytic 1D densities inverted in closed form, piecewise-constant
// tables [PBR4, A.5], and the 2D table sampled as a marginal and a conditional.
//
// Conventions shared by every kind:
//  - sample(u) and cdf(x) are inverses. Each kernel measures offsets from the end of [a, b]
//    nearest to the probability it is computing (u <= 1/2 from a, u > 1/2 from b, where
//    1 - u is exact), and from the end where the density is largest when the density spans
//    many orders of magnitude, so tail probabilities keep their relative precision and
//    nothing overflows.
//  - pdf(x) depends on x alone. sample_block computes its densities with the very same
//    code as the scalar pdf, so it reproduces pdf(sample(u)) bit for bit.
//  - sample_block and multiply_pdf_block switch on the kind once per block; the loops
//    inside are kind-specific (see Distribution1DFactory::visit).
#include "core/distributions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>

#include "core/float_index.h"
#include "core/points.h"
#include "core/special.h"
#include "core/stats.h"

namespace mcp {
namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
constexpr double kHalfPi = 0.5 * kPi;
constexpr double kQuarterPi = 0.25 * kPi;
constexpr double kInvSqrt2Pi = 0.39894228040143267794;
constexpr size_t kMaxBins = size_t(1) << 22;
// Exponential with a negative rate: up to this |rate| (b - a) the inverse is written from a
// with expm1(|rate| (b - a)) <= 2.4e17; beyond it from b, where the mass within reach of a
// (e^-40 = 4e-18) is below the smallest u Pcg32 draws.
constexpr double kExpFromLowerLimit = 40.0;
// Truncated Gaussian: the end of [a, b] nearer mu at most this many sigma away, so tail
// probabilities (Q(30) = 5e-198) and exp(t^2 / 2) inside normal_quantile stay in range.
constexpr double kMaxTailSigmas = 30.0;

double clamp(double x, double lo, double hi) {
    return x < lo ? lo : (x > hi ? hi : x);
}

/// Shortest "%g" text that reads back as the same double.
std::string num(double v) {
    char buf[40];
    for (int digits = 1; digits <= 17; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (std::strtod(buf, nullptr) == v) break;
    }
    return buf;
}

std::string interval_text(double a, double b) {
    return "[" + num(a) + ", " + num(b) + "]";
}

/// Empty if [a, b] is a usable interval; otherwise the message, naming a and b.
std::string check_interval(const char* what, double a, double b, const char* na = "a",
                           const char* nb = "b") {
    std::string names = std::string(na) + " < " + nb;
    if (!(std::isfinite(a) && std::isfinite(b) && a < b))
        return std::string(what) + ": need finite " + names + ", got " + na + "=" + num(a) + ", " +
               nb + "=" + num(b);
    double len = b - a;
    if (!(std::isfinite(len) && std::isfinite(1.0 / len)))
        return std::string(what) + ": " + nb + " - " + na +
               " must be finite and not subnormal, got " + na + "=" + num(a) + ", " + nb + "=" +
               num(b);
    return {};
}

// --- Tabulated bins --------------------------------------------------------------------
// One formula maps x to its bin everywhere (1D pdf and cdf, the placement of samples, the 2D
// pdf), so a sample is always in the bin it was drawn from.

double bin_scale(double a, double b, size_t n) {
    return static_cast<double>(n) / (b - a);
}

size_t bin_of(double x, double a, double scale, size_t n) {
    double r = (x - a) * scale;
    if (!(r > 0.0)) return 0;
    size_t i = r < static_cast<double>(n) ? floor_to_index(r) : n - 1;
    return std::min(i, n - 1);
}

// --- Kernels ---------------------------------------------------------------------------
// One struct per kind with sample, pdf and cdf; built from the distribution's fields once
// per call or per block.

struct UniformK {
    double a, b, inv_len;
    double sample(double u) const { return clamp(a + u * (b - a), a, b); }
    double pdf(double x) const { return x >= a && x <= b ? inv_len : 0.0; }
    double cdf(double x) const { return x <= a ? 0.0 : (x >= b ? 1.0 : (x - a) / (b - a)); }
};

// p(x) = (k + 1) / L t^k with t = (x - a) / L; F = t^(k + 1); x = a + L u^(1/(k + 1)).
// Near a the density is infinite (k < 0) or zero (k > 0), and a + L t rounds to a once L t
// is below half an ulp of a (u < 1e-8 for k = -1/2 on [1, 2]); for k near -1, t itself
// underflows (u^(1/(k+1)) < 1e-308 has probability 8e-4 at k = -0.99). Samples are therefore
// raised to `lowest` = a + d0, the first point above a where the density is positive and
// finite (found by the factory), so that f / pdf stays defined; that moves mass cdf(lowest),
// e.g. 2e-162 for k = -1/2 on [0, 1].
struct PowerK {
    double a, b, len, k, kp1, inv_kp1, lowest;
    double sample(double u) const {
        return clamp(std::max(a + len * std::pow(u, inv_kp1), lowest), a, b);
    }
    double pdf(double x) const {
        if (!(x >= a && x <= b)) return 0.0;
        return kp1 / len * std::pow((x - a) / len, k);
    }
    double cdf(double x) const {
        if (x <= a) return 0.0;
        if (x >= b) return 1.0;
        return std::min(1.0, std::pow((x - a) / len, kp1));
    }
};

// p proportional to exp(-rate x). With s = |rate| and d the distance from the end where the
// density is largest (a for rate > 0, b for rate < 0), p = s e^{-s d} / (1 - e^{-s L}):
// no exponential of a positive argument, whatever the rate. m = expm1(-s L) in (-1, 0).
//   rate > 0: F(x) = expm1(-s (x - a)) / m, x = a - log1p(u m) / s.
//   rate < 0: F(x) = e^{-s (b - x)} expm1(-s (x - a)) / m (= expm1(s (x - a)) / expm1(s L)
//             without the overflow), x = a + log1p(u expm1(s L)) / s for s L <= 40, else
//             x = b + log(e^{-s L} - u m) / s.
// log1p and expm1 keep the small-rate limit (nearly uniform) and the small-u tail exact.
struct ExponentialK {
    double a, b, s, m, norm, e; // e: expm1(s L) or e^{-s L} (rate < 0), see above
    bool positive, from_lower;
    double sample(double u) const {
        double x;
        if (positive)
            x = a - std::log1p(u * m) / s;
        else if (from_lower)
            x = a + std::log1p(u * e) / s;
        else
            x = b + std::log(e - u * m) / s;
        return clamp(x, a, b);
    }
    double pdf(double x) const {
        if (!(x >= a && x <= b)) return 0.0;
        return norm * std::exp(-s * (positive ? x - a : b - x));
    }
    double cdf(double x) const {
        if (x <= a) return 0.0;
        if (x >= b) return 1.0;
        double f = std::expm1(-s * (x - a)) / m;
        if (!positive) f *= std::exp(-s * (b - x));
        return std::min(1.0, f);
    }
};

double exponential_span(double rate, double a, double b) {
    return std::fabs(rate) * (b - a);
}

// P(lo <= T <= hi) for a standard normal T, lo <= hi: a difference of upper tails when both
// ends are >= 1/2, of lower tails when both are <= -1/2, of erf values otherwise (both
// small, or of opposite signs). No 1 - tiny cancellation anywhere, e.g. [5, 6] is
// Q(5) - Q(6) = 2.9e-7 - 1.0e-9, and near 0 the erf values keep their relative precision.
double normal_mass(double lo, double hi) {
    if (lo >= 0.5) return normal_cdf(-lo) - normal_cdf(-hi);
    if (hi <= -0.5) return normal_cdf(hi) - normal_cdf(lo);
    return 0.5 * (std::erf(hi / kSqrt2) - std::erf(lo / kSqrt2));
}

// P(alpha <= T <= alpha + delta), delta >= 0, to full relative precision even for
// delta << |alpha|, where alpha + delta would round away most of delta. For
// delta (|alpha| + delta) <= 1/2 it integrates phi(alpha + v) = phi(alpha) e^{-v (alpha + v/2)}
// over [0, delta] by 5-point Gauss-Legendre: the exponent moves by at most 1/2, so the rule
// is exact to rounding; otherwise the difference of tails above.
double normal_mass_from(double alpha, double delta) {
    if (!(delta > 0.0)) return 0.0;
    if (delta * (std::fabs(alpha) + delta) <= 0.5) {
        // Nodes and weights on [-1, 1] [AS64, Table 25.4].
        constexpr double x1 = 0.53846931010568309104, x2 = 0.90617984593866399280;
        constexpr double w0 = 0.56888888888888888889, w1 = 0.47862867049936646804,
                         w2 = 0.23692688505618908751;
        const double h = 0.5 * delta;
        auto f = [alpha](double v) { return std::exp(-v * (alpha + 0.5 * v)); };
        double sum =
            w0 * f(h) + w1 * (f(h - x1 * h) + f(h + x1 * h)) + w2 * (f(h - x2 * h) + f(h + x2 * h));
        return kInvSqrt2Pi * std::exp(-0.5 * alpha * alpha) * h * sum;
    }
    return normal_mass(alpha, alpha + delta);
}

// The offset delta >= 0 with normal_mass_from(alpha, delta) = m, for m at most half the mass
// of the interval (so the answer lies in its half nearer alpha). The start solves
// Q(t) = Q(alpha) - m (alpha >= 0; the subtraction keeps at least half of Q(alpha)) or
// Phi(t) = Phi(alpha) + m (alpha < 0) with normal_quantile; one Newton step on
// normal_mass_from then restores what the start loses to rounding: m below the ulp of
// Phi(alpha), or p near 1/2 for an interval narrow against sigma.
double normal_solve_from(double alpha, double m) {
    double t = alpha >= 0.0 ? -normal_quantile(normal_cdf(-alpha) - m)
                            : normal_quantile(normal_cdf(alpha) + m);
    double delta = t - alpha;
    if (!(delta >= 0.0)) delta = 0.0;
    if (!std::isfinite(delta)) return delta;
    double density = kInvSqrt2Pi * std::exp(-0.5 * (alpha + delta) * (alpha + delta));
    if (density > 0.0) delta -= (normal_mass_from(alpha, delta) - m) / density;
    return std::max(delta, 0.0);
}

// In standard units on [alpha, beta], z = P(alpha <= T <= beta). Samples and the cdf work
// with offsets from a (u <= 1/2) or from b (u > 1/2, by the mirror image T -> -T), so both
// tails keep their relative precision wherever [a, b] lies:
//   F(x) = normal_mass_from(alpha, (x - a) / sigma) / z
//        = 1 - normal_mass_from(-beta, (b - x) / sigma) / z.
struct GaussianK {
    double a, b, mu, sigma, alpha, beta, z, norm; // norm = 1 / (sqrt(2 pi) z)
    double sample(double u) const {
        const double span = (b - a) / sigma;
        double x = u <= 0.5 ? a + sigma * std::min(normal_solve_from(alpha, u * z), span)
                            : b - sigma * std::min(normal_solve_from(-beta, (1.0 - u) * z), span);
        return clamp(x, a, b);
    }
    double pdf(double x) const {
        if (!(x >= a && x <= b)) return 0.0;
        double t = (x - mu) / sigma;
        return std::exp(-0.5 * t * t) * norm / sigma;
    }
    double cdf(double x) const {
        if (x <= a) return 0.0;
        if (x >= b) return 1.0;
        double lower = normal_mass_from(alpha, (x - a) / sigma);
        if (lower <= 0.5 * z) return lower / z;
        return clamp(1.0 - normal_mass_from(-beta, (b - x) / sigma) / z, 0.0, 1.0);
    }
};

// p proportional to cos(theta), theta = omega (x - x0) in [ta, tb] within [-pi/2, pi/2];
// d = sin tb - sin ta. The pdf alone needs no edge values.
struct CosinePdfK {
    double a, b, omega, x0, norm; // norm = omega / d
    double pdf(double x) const {
        if (!(x >= a && x <= b)) return 0.0;
        return norm * std::max(0.0, std::cos(omega * (x - x0)));
    }
};

// 1 + sin(t) = 2 sin^2(t/2 + pi/4) and 1 - sin(t) = 2 sin^2(pi/4 - t/2), exact near t = -+pi/2.
double one_plus_sin(double t) {
    double h = std::sin(0.5 * t + kQuarterPi);
    return 2.0 * h * h;
}
double one_minus_sin(double t) {
    double h = std::sin(kQuarterPi - 0.5 * t);
    return 2.0 * h * h;
}

// The offset g >= 0 from an edge angle te with sin(te + g) - sin(te) = delta, for te and
// te + g in [-pi/2, pi/2] and g at most about pi/2. se = sin te, ce = cos te >= 0, ope = 1 + se,
// ome = 1 - se. With s = se + delta and c = cos(te + g) = sqrt((1 + s)(1 - s)):
//   cos g = c ce + s se,   sin g = s ce - c se = delta (1 + cos g) / (ce + c),
// the last form free of the cancellation at small g (using c^2 - ce^2 = se^2 - s^2).
// asin(se + delta) would lose delta to the rounding of se + delta near sin = -1, where the
// density vanishes and the cdf grows like g^2.
double cosine_offset(double se, double ce, double ope, double ome, double delta) {
    if (!(delta > 0.0)) return 0.0;
    double s = se + delta;
    double c = std::sqrt(std::max(0.0, (ope + delta) * (ome - delta)));
    double cos_g = c * ce + s * se;
    double sin_g = delta * (1.0 + cos_g) / (ce + c);
    return std::atan2(sin_g, cos_g);
}

// Sampling measures the angle from a for u <= 1/2 and from b (mirrored, te = -tb) for u > 1/2.
// The cdf is sin(ta + g) - sin(ta) = 2 cos(ta + g/2) sin(g/2) with g = omega (x - a), from
// whichever end is nearer.
struct CosineK : CosinePdfK {
    double d, sa, ca, opa, oma, sb, cb, opb, omb;
    double sample(double u) const {
        double x;
        if (u <= 0.5)
            x = a + cosine_offset(sa, ca, opa, oma, u * d) / omega;
        else
            x = b - cosine_offset(-sb, cb, omb, opb, (1.0 - u) * d) / omega;
        return clamp(x, a, b);
    }
    double cdf(double x) const {
        if (x <= a) return 0.0;
        if (x >= b) return 1.0;
        if (x - a <= b - x) {
            double h = 0.5 * omega * (x - a);
            double sh = std::sin(h);
            return clamp(2.0 * (ca * std::cos(h) - sa * sh) * sh / d, 0.0, 1.0);
        }
        double h = 0.5 * omega * (b - x);
        double sh = std::sin(h);
        return clamp(1.0 - 2.0 * (cb * std::cos(h) + sb * sh) * sh / d, 0.0, 1.0);
    }
};

// Piecewise constant on n equal bins: func[i] the density on bin i, cdf[i] the cdf at its left
// edge. Sampling finds the bin with cdf[i] <= u < cdf[i + 1], which never selects a bin of zero
// probability (its cdf entries are equal), then interpolates linearly inside it. The bin is found
// from a guide table [ChenAsau74]: guide[g] is the bin of u = g / n, and the search walks forward
// from guide[floor(u n)], about two comparisons on average whatever the table's shape (a binary
// search takes log2(n) unpredictable branches). Block loops take one step of that walk without
// a branch and send the few points it does not settle to the full walk in a second pass.
struct TabulatedK {
    double a, b, width, scale; // width = (b - a) / n, scale = n / (b - a)
    const double* func;
    const double* cdf_edges;
    const uint32_t* guide;
    size_t n;
    size_t bin_of_u(double u) const {
        const double scaled = u * static_cast<double>(n);
        size_t i = guide[scaled < static_cast<double>(n) ? floor_to_index(scaled) : n - 1];
        while (i > 0 && cdf_edges[i] > u) --i; // u n rounded up onto the next guide entry
        while (cdf_edges[i + 1] <= u) ++i;     // ends at i = n - 1 at the latest: cdf[n] = 1 > u
        return i;
    }
    /// bin_of_u's walk cut to one step, branch-free: the guide's bin for u's cell, or the next
    /// one if u is past its upper edge. *settled says whether that is u's bin; it is not when
    /// the cell holds several edges past the guide's bin (bins of mass below 1/n) or u n
    /// rounded up onto the next cell.
    size_t guided_bin(double u, bool* settled) const {
        const double scaled = u * static_cast<double>(n);
        size_t i = guide[scaled < static_cast<double>(n) ? floor_to_index(scaled) : n - 1];
        i += static_cast<size_t>(u >= cdf_edges[i + 1]); // never past n - 1: cdf[n] = 1 > u
        *settled = cdf_edges[i] <= u && u < cdf_edges[i + 1];
        return i;
    }
    static double clamp_u(double u) { return u > 0.0 ? std::min(u, kOneMinusEpsilon) : 0.0; }
    /// u's place in bin i, cdf[i] <= u < cdf[i + 1].
    double place(double u, size_t i) const {
        const double lo = cdf_edges[i];
        const double t = (u - lo) / (cdf_edges[i + 1] - lo);
        return clamp(a + (index_to_double(static_cast<uint32_t>(i)) + t) * width, a, b);
    }
    /// sample_in_bin for a point guided_bin may not have settled: bin *bin, found by
    /// guided_bin, stands if it is u's and holds x; otherwise the full walk and the repair.
    double settle(double u, double x, size_t* bin) const {
        const double v = clamp_u(u);
        const size_t i = *bin;
        if (cdf_edges[i] <= v && v < cdf_edges[i + 1] && holds(x, i)) return x;
        x = sample_in_bin(u, bin);
        return holds(x, *bin) ? x : step_into_bin(x, *bin);
    }
    /// The point of bin *bin at u's place in it; rounding may leave it on a neighbouring bin's
    /// edge, which holds() detects and step_into_bin() repairs.
    double sample_in_bin(double u, size_t* bin) const {
        u = clamp_u(u);
        *bin = bin_of_u(u);
        return place(u, *bin);
    }
    /// bin_of(x) == i, by comparisons only (no conversion, no branch).
    bool holds(double x, size_t i) const {
        const double r = (x - a) * scale, fi = index_to_double(static_cast<uint32_t>(i));
        return (i == 0 || r >= fi) && (i + 1 == n || r < fi + 1.0);
    }
    double sample(double u) const {
        size_t i;
        const double x = sample_in_bin(u, &i);
        return holds(x, i) ? x : step_into_bin(x, i);
    }
    /// sample() and its density for a block. The loop has no branch on the point and no call
    /// (V8 compiles a loop with either to code 2x slower): it counts the points that
    /// guided_bin did not settle or rounding left outside their bin, and a second pass settles
    /// them; the results are sample()'s, point by point.
    void sample_block(const double* u, double* x, double* pdf_out, size_t* bins, size_t m) const {
        size_t unsettled = 0;
        for (size_t k = 0; k < m; ++k) {
            bool settled;
            const double v = clamp_u(u[k]);
            const size_t i = guided_bin(v, &settled);
            x[k] = place(v, i);
            pdf_out[k] = func[i];
            bins[k] = i;
            unsettled += !(settled && holds(x[k], i));
        }
        if (unsettled == 0) return;
        for (size_t k = 0; k < m; ++k) {
            x[k] = settle(u[k], x[k], &bins[k]);
            pdf_out[k] = func[bins[k]];
        }
    }
    // Rounding can carry x onto a neighbouring bin's edge; step back into bin i (the factory
    // guarantees every bin holds many doubles, so this takes one or two steps). Out of line:
    // the common path stays small enough to inline.
    __attribute__((noinline)) double step_into_bin(double x, size_t i) const {
        for (int guard = 0; guard < 64 && bin_of(x, a, scale, n) > i; ++guard)
            x = std::nextafter(x, -std::numeric_limits<double>::infinity());
        for (int guard = 0; guard < 64 && bin_of(x, a, scale, n) < i; ++guard)
            x = std::nextafter(x, std::numeric_limits<double>::infinity());
        return x;
    }
    double pdf(double x) const {
        if (!(x >= a && x <= b)) return 0.0;
        return func[bin_of(x, a, scale, n)];
    }
    double cdf(double x) const {
        if (x <= a) return 0.0;
        if (x >= b) return 1.0;
        size_t i = bin_of(x, a, scale, n);
        double t = clamp((x - a) * scale - static_cast<double>(i), 0.0, 1.0);
        return cdf_edges[i] + t * (cdf_edges[i + 1] - cdf_edges[i]);
    }
};

} // namespace

// The one friend of Distribution1D: builds distributions and their per-kind kernels.
struct Distribution1DFactory {
    static Distribution1D make(Dist1DKind kind, double a, double b, double p0, double p1, double c0,
                               double c1) {
        Distribution1D d;
        d.kind_ = kind;
        d.a_ = a;
        d.b_ = b;
        d.p0_ = p0;
        d.p1_ = p1;
        d.c0_ = c0;
        d.c1_ = c1;
        return d;
    }
    static void set_table(Distribution1D& d, std::vector<double> func, std::vector<double> cdf) {
        d.func_ = std::move(func);
        d.cdf_ = std::move(cdf);
        // guide[g] = the bin of u = g / n: the last i with cdf[i] <= g / n.
        const size_t n = d.func_.size();
        d.guide_.assign(n, 0);
        size_t i = 0;
        for (size_t g = 0; g < n; ++g) {
            const double u = static_cast<double>(g) / static_cast<double>(n);
            while (i + 1 < n && d.cdf_[i + 1] <= u) ++i;
            d.guide_[g] = static_cast<uint32_t>(i);
        }
    }

    // Kernels. Fields: power p0 = k, p1 = d0 (see PowerK), c0 = k + 1, c1 = 1 / (k + 1);
    // exponential p0 = rate, p1 = expm1(s L) or e^{-s L}, c0 = expm1(-s L), c1 = s / -c0;
    // Gaussian p0 = mu, p1 = sigma, c0 = z, c1 = 1 / (sqrt(2 pi) z); cosine p0 = omega,
    // p1 = x0, c0 = d, c1 = omega / d; tabulated c0 = bin width, c1 = 1 / bin width.
    static UniformK uniform(const Distribution1D& d) { return {d.a_, d.b_, 1.0 / (d.b_ - d.a_)}; }
    static PowerK power(const Distribution1D& d) {
        return {d.a_, d.b_, d.b_ - d.a_, d.p0_, d.c0_, d.c1_, d.a_ + d.p1_};
    }
    static ExponentialK exponential(const Distribution1D& d) {
        bool positive = d.p0_ > 0.0;
        bool from_lower = exponential_span(d.p0_, d.a_, d.b_) <= kExpFromLowerLimit;
        return {d.a_, d.b_, std::fabs(d.p0_), d.c0_, d.c1_, d.p1_, positive, from_lower};
    }
    static GaussianK gaussian(const Distribution1D& d) {
        return {d.a_,  d.b_, d.p0_, d.p1_, (d.a_ - d.p0_) / d.p1_, (d.b_ - d.p0_) / d.p1_,
                d.c0_, d.c1_};
    }
    static CosinePdfK cosine_pdf(const Distribution1D& d) {
        return {d.a_, d.b_, d.p0_, d.p1_, d.c1_};
    }
    static CosineK cosine(const Distribution1D& d) {
        double ta = std::max(-kHalfPi, d.p0_ * (d.a_ - d.p1_));
        double tb = std::min(kHalfPi, d.p0_ * (d.b_ - d.p1_));
        CosineK k;
        static_cast<CosinePdfK&>(k) = cosine_pdf(d);
        k.d = d.c0_;
        k.sa = std::sin(ta);
        k.ca = std::cos(ta);
        k.opa = one_plus_sin(ta);
        k.oma = one_minus_sin(ta);
        k.sb = std::sin(tb);
        k.cb = std::cos(tb);
        k.opb = one_plus_sin(tb);
        k.omb = one_minus_sin(tb);
        return k;
    }
    static TabulatedK tabulated(const Distribution1D& d) {
        return {d.a_,           d.b_,          d.c0_,           d.c1_,
                d.func_.data(), d.cdf_.data(), d.guide_.data(), d.func_.size()};
    }

    /// Calls f with the kernel of d's kind: one switch, then f's loop runs on a concrete type.
    /// With kFull false the cosine kernel skips the edge values only sample and cdf need.
    template <bool kFull, class F>
    static auto visit(const Distribution1D& d, F&& f) -> decltype(f(UniformK{})) {
        switch (d.kind_) {
        case Dist1DKind::Power: return f(power(d));
        case Dist1DKind::Exponential: return f(exponential(d));
        case Dist1DKind::TruncatedGaussian: return f(gaussian(d));
        case Dist1DKind::Cosine:
            if constexpr (kFull)
                return f(cosine(d));
            else
                return f(cosine_pdf(d));
        case Dist1DKind::Tabulated: return f(tabulated(d));
        case Dist1DKind::Uniform: break;
        }
        return f(uniform(d));
    }
};

// --- Distribution1D ----------------------------------------------------------------------

double Distribution1D::sample(double u) const {
    return Distribution1DFactory::visit<true>(*this, [u](const auto& k) { return k.sample(u); });
}

double Distribution1D::pdf(double x) const {
    return Distribution1DFactory::visit<false>(*this, [x](const auto& k) { return k.pdf(x); });
}

double Distribution1D::cdf(double x) const {
    return Distribution1DFactory::visit<true>(*this, [x](const auto& k) { return k.cdf(x); });
}

void Distribution1D::sample_block(const double* u, double* x, double* pdf_out, size_t n) const {
    Distribution1DFactory::visit<true>(*this, [&](const auto& k) {
        if constexpr (std::is_same_v<std::decay_t<decltype(k)>, TabulatedK>) {
            size_t bins[kBlockSize];
            for (size_t start = 0; start < n; start += kBlockSize)
                k.sample_block(u + start, x + start, pdf_out + start, bins,
                               std::min(kBlockSize, n - start));
            return;
        }
        for (size_t i = 0; i < n; ++i) {
            x[i] = k.sample(u[i]);
            pdf_out[i] = k.pdf(x[i]);
        }
    });
}

void Distribution1D::multiply_pdf_block(const double* x, double* pdf_out, size_t n) const {
    Distribution1DFactory::visit<false>(*this, [&](const auto& k) {
        for (size_t i = 0; i < n; ++i) pdf_out[i] *= k.pdf(x[i]);
    });
}

std::string Distribution1D::describe() const {
    std::string on = " on " + interval_text(a_, b_);
    switch (kind_) {
    case Dist1DKind::Power: return "power(k=" + num(p0_) + ")" + on;
    case Dist1DKind::Exponential: return "exponential(rate=" + num(p0_) + ")" + on;
    case Dist1DKind::TruncatedGaussian:
        return "truncated_gaussian(mu=" + num(p0_) + ", sigma=" + num(p1_) + ")" + on;
    case Dist1DKind::Cosine: return "cosine(omega=" + num(p0_) + ", x0=" + num(p1_) + ")" + on;
    case Dist1DKind::Tabulated: return "tabulated(" + std::to_string(func_.size()) + " bins)" + on;
    case Dist1DKind::Uniform: break;
    }
    return "uniform" + on;
}

namespace {

// "x", "(x - 0.5)" or "(x + 1)": the variable measured from x0 (without the parentheses when
// nothing multiplies it).
std::string shifted_text(const std::string& x, double x0, bool parentheses = true) {
    if (x0 == 0.0) return x;
    const std::string d = x + (x0 > 0.0 ? " - " + num(x0) : " + " + num(-x0));
    return parentheses ? "(" + d + ")" : d;
}

// "x", "-x", "0.8 x": c times the variable.
std::string scaled_text(double c, const std::string& x) {
    if (c == 1.0) return x;
    if (c == -1.0) return "-" + x;
    return num(c) + " " + x;
}

} // namespace

std::string shortest_number_text(double v) {
    return num(v);
}

std::string Distribution1D::describe_text(const std::string& x) const {
    const std::string on = " on " + interval_text(a_, b_);
    switch (kind_) {
    case Dist1DKind::Power: {
        if (p0_ == 0.0) return "uniform" + on;
        const std::string base = shifted_text(x, a_);
        const std::string power =
            p0_ == 1.0 ? base : base + "^" + (p0_ < 0.0 ? "(" + num(p0_) + ")" : num(p0_));
        return "power-law density proportional to " + power + on;
    }
    case Dist1DKind::Exponential: {
        // p proportional to exp(-rate x).
        const std::string arg = scaled_text(-p0_, x);
        return "exponential density proportional to e^" + (arg == x ? arg : "(" + arg + ")") + on;
    }
    case Dist1DKind::TruncatedGaussian:
        return "normal density of mean " + num(p0_) + " and standard deviation " + num(p1_) +
               ", cut to " + interval_text(a_, b_);
    case Dist1DKind::Cosine:
        return "cosine density proportional to cos(" +
               (p0_ == 1.0 ? shifted_text(x, p1_, false) : scaled_text(p0_, shifted_text(x, p1_))) +
               ")" + on;
    case Dist1DKind::Tabulated:
        return "piecewise-constant density on " + std::to_string(func_.size()) + " equal bin" +
               (func_.size() == 1 ? "" : "s") + " of " + interval_text(a_, b_);
    case Dist1DKind::Uniform: break;
    }
    return "uniform" + on;
}

// --- Factories ---------------------------------------------------------------------------

Made<Distribution1D> make_uniform(double a, double b) {
    std::string err = check_interval("uniform", a, b);
    if (!err.empty()) return made_error<Distribution1D>(err);
    return {Distribution1DFactory::make(Dist1DKind::Uniform, a, b, 0, 0, 0, 0), {}};
}

Made<Distribution1D> make_power(double a, double b, double k) {
    std::string err = check_interval("power", a, b);
    if (!err.empty()) return made_error<Distribution1D>(err);
    if (!(k > -1.0 && std::isfinite(k)))
        return made_error<Distribution1D>("power: k must be finite and > -1, got " + num(k));
    double kp1 = k + 1.0;
    // p1 = d0, the smallest offset (to a factor 2) from a with a positive, finite density;
    // 0 when the density at a itself is (k = 0). The doubling ends by b - a at the latest,
    // where t = 1 and the density (k + 1) / L is positive and finite.
    Distribution1D d = Distribution1DFactory::make(Dist1DKind::Power, a, b, k, 0, kp1, 1.0 / kp1);
    double d0 = 0.0;
    for (;;) {
        double p = d.pdf(a + d0);
        if ((p > 0.0 && std::isfinite(p)) || a + d0 >= b) break;
        d0 = d0 == 0.0 ? std::nextafter(a, b) - a : 2.0 * d0;
    }
    d0 = std::min(d0, b - a);
    return {Distribution1DFactory::make(Dist1DKind::Power, a, b, k, d0, kp1, 1.0 / kp1), {}};
}

Made<Distribution1D> make_exponential(double a, double b, double rate) {
    std::string err = check_interval("exponential", a, b);
    if (!err.empty()) return made_error<Distribution1D>(err);
    if (!(std::isfinite(rate) && rate != 0.0))
        return made_error<Distribution1D>("exponential: rate must be finite and != 0, got " +
                                          num(rate));
    double s = std::fabs(rate);
    double span = exponential_span(rate, a, b);
    double m = std::expm1(-span);
    if (!(m < 0.0))
        return made_error<Distribution1D>("exponential: |rate| (b - a) underflows, got rate=" +
                                          num(rate) + " on " + interval_text(a, b));
    double norm = s / -m;
    if (!std::isfinite(norm))
        return made_error<Distribution1D>("exponential: the density overflows, got rate=" +
                                          num(rate) + " on " + interval_text(a, b));
    double e = 0.0;
    if (rate < 0.0) e = span <= kExpFromLowerLimit ? std::expm1(span) : std::exp(-span);
    return {Distribution1DFactory::make(Dist1DKind::Exponential, a, b, rate, e, m, norm), {}};
}

Made<Distribution1D> make_truncated_gaussian(double a, double b, double mu, double sigma) {
    std::string err = check_interval("truncated_gaussian", a, b);
    if (!err.empty()) return made_error<Distribution1D>(err);
    if (!std::isfinite(mu))
        return made_error<Distribution1D>("truncated_gaussian: mu must be finite, got " + num(mu));
    if (!(sigma > 0.0 && std::isfinite(sigma)))
        return made_error<Distribution1D>("truncated_gaussian: sigma must be finite and > 0, got " +
                                          num(sigma));
    double alpha = (a - mu) / sigma, beta = (b - mu) / sigma;
    double nearest = alpha > 0.0 ? alpha : (beta < 0.0 ? -beta : 0.0);
    if (!(nearest <= kMaxTailSigmas))
        return made_error<Distribution1D>(
            "truncated_gaussian: [a, b] must come within 30 sigma of mu, got " +
            interval_text(a, b) + " with mu=" + num(mu) + ", sigma=" + num(sigma));
    double z = normal_mass_from(alpha, (b - a) / sigma);
    double norm = kInvSqrt2Pi / z;
    if (!(z > 0.0 && std::isfinite(norm / sigma)))
        return made_error<Distribution1D>(
            "truncated_gaussian: the probability of [a, b] underflows, got " + interval_text(a, b) +
            " with mu=" + num(mu) + ", sigma=" + num(sigma));
    return {Distribution1DFactory::make(Dist1DKind::TruncatedGaussian, a, b, mu, sigma, z, norm),
            {}};
}

Made<Distribution1D> make_cosine(double a, double b, double omega, double x0) {
    std::string err = check_interval("cosine", a, b);
    if (!err.empty()) return made_error<Distribution1D>(err);
    if (!(omega > 0.0 && std::isfinite(omega)))
        return made_error<Distribution1D>("cosine: omega must be finite and > 0, got " +
                                          num(omega));
    if (!std::isfinite(x0))
        return made_error<Distribution1D>("cosine: x0 must be finite, got " + num(x0));
    // A few ulps of slack so that e.g. omega = 3 on [-pi/6, pi/6] passes despite rounding.
    const double limit = kHalfPi * (1.0 + 16.0 * kEpsilon);
    double ta = omega * (a - x0), tb = omega * (b - x0);
    if (!(ta >= -limit))
        return made_error<Distribution1D>(
            "cosine: |omega (x - x0)| must be <= pi/2 on [a, b], got omega (a - x0) = " + num(ta));
    if (!(tb <= limit))
        return made_error<Distribution1D>(
            "cosine: |omega (x - x0)| must be <= pi/2 on [a, b], got omega (b - x0) = " + num(tb));
    ta = std::max(ta, -kHalfPi);
    tb = std::min(tb, kHalfPi);
    // sin tb - sin ta as a product: no cancellation for a short interval away from x0.
    double d = 2.0 * std::cos(0.5 * (ta + tb)) * std::sin(0.5 * (tb - ta));
    double norm = omega / d;
    if (!(d > 0.0 && std::isfinite(norm)))
        return made_error<Distribution1D>("cosine: the integral of cos(omega (x - x0)) over " +
                                          interval_text(a, b) +
                                          " underflows, got omega=" + num(omega));
    return {Distribution1DFactory::make(Dist1DKind::Cosine, a, b, omega, x0, d, norm), {}};
}

Made<Distribution1D> make_tabulated(double a, double b, const std::vector<double>& values) {
    std::string err = check_interval("tabulated", a, b);
    if (!err.empty()) return made_error<Distribution1D>(err);
    const size_t n = values.size();
    if (n == 0) return made_error<Distribution1D>("tabulated: values must be non-empty");
    if (n > kMaxBins)
        return made_error<Distribution1D>("tabulated: values may hold at most 4194304 bins, got " +
                                          std::to_string(n));
    double vmax = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double v = values[i];
        if (!std::isfinite(v))
            return made_error<Distribution1D>("tabulated: values[" + std::to_string(i) +
                                              "] must be finite, got " + num(v));
        if (v < 0.0)
            return made_error<Distribution1D>("tabulated: values[" + std::to_string(i) +
                                              "] must be >= 0, got " + num(v));
        vmax = std::max(vmax, v);
    }
    if (!(vmax > 0.0))
        return made_error<Distribution1D>("tabulated: values must not all be zero (sum is 0)");
    const double len = b - a, width = len / static_cast<double>(n);
    // Every bin must hold enough doubles for a sample to be placed inside it.
    if (!(width > 16.0 * kEpsilon * std::max(std::fabs(a), std::fabs(b)) &&
          width >= std::numeric_limits<double>::min()))
        return made_error<Distribution1D>("tabulated: " + std::to_string(n) +
                                          " bins (values) are too narrow to resolve on " +
                                          interval_text(a, b));

    // Prefix sums of values / vmax (each <= 1, so no overflow) with Neumaier's compensation
    // [Neumaier74]. A zero bin repeats the previous entry exactly and the sequence is forced
    // monotone, so plateaus of the cdf are exactly the zero bins.
    std::vector<double> cdf(n + 1), func(n);
    NeumaierSum sum;
    cdf[0] = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double w = values[i] / vmax;
        sum.add(w);
        cdf[i + 1] = w > 0.0 ? std::max(cdf[i], sum.value()) : cdf[i];
    }
    const double total = cdf[n];
    for (size_t i = 1; i < n; ++i) cdf[i] = std::min(cdf[i] / total, 1.0);
    cdf[n] = 1.0;
    // Density of bin i: (values[i] / vmax) / total of the mass, spread over width.
    const double density_scale = static_cast<double>(n) / total / len;
    if (!std::isfinite(density_scale))
        return made_error<Distribution1D>("tabulated: the density overflows on " +
                                          interval_text(a, b));
    for (size_t i = 0; i < n; ++i) func[i] = values[i] / vmax * density_scale;

    Distribution1D d =
        Distribution1DFactory::make(Dist1DKind::Tabulated, a, b, 0, 0, width, bin_scale(a, b, n));
    Distribution1DFactory::set_table(d, std::move(func), std::move(cdf));
    return {std::move(d), {}};
}

// --- TabulatedDistribution2D ------------------------------------------------------------
// u2 drives the marginal in y (the row), u1 the conditional in x within that row, so
// sample(u1, u2) keeps u1 <-> x and u2 <-> y, and invert returns u1 = F(x | row), u2 = F_y(y).

std::string TabulatedDistribution2D::describe_text() const {
    return "piecewise-constant density on a " + std::to_string(nx_) + " x " + std::to_string(ny_) +
           " grid of cells over " + interval_text(x0_, x1_) + " x " + interval_text(y0_, y1_);
}

void TabulatedDistribution2D::sample(double u1, double u2, double* x, double* y,
                                     double* pdf_out) const {
    if (conditional_.empty()) { // default-constructed: no table
        *x = x0_;
        *y = y0_;
        *pdf_out = 0.0;
        return;
    }
    *y = marginal_.sample(u2);
    size_t iy = bin_of(*y, y0_, bin_scale(y0_, y1_, size_t(ny_)), size_t(ny_));
    *x = conditional_[iy].sample(u1);
    *pdf_out = pdf(*x, *y);
}

double TabulatedDistribution2D::pdf(double x, double y) const {
    if (!(x >= x0_ && x <= x1_ && y >= y0_ && y <= y1_) || values_.empty()) return 0.0;
    size_t ix = bin_of(x, x0_, bin_scale(x0_, x1_, size_t(nx_)), size_t(nx_));
    size_t iy = bin_of(y, y0_, bin_scale(y0_, y1_, size_t(ny_)), size_t(ny_));
    return values_[iy * size_t(nx_) + ix] / total_;
}

void TabulatedDistribution2D::invert(double x, double y, double* u1, double* u2) const {
    if (conditional_.empty()) {
        *u1 = *u2 = 0.0;
        return;
    }
    *u2 = marginal_.cdf(y);
    double yc = clamp(y, y0_, y1_);
    size_t iy = bin_of(yc, y0_, bin_scale(y0_, y1_, size_t(ny_)), size_t(ny_));
    *u1 = conditional_[iy].cdf(x);
}

void TabulatedDistribution2D::sample_block(const double* u1, const double* u2, double* x, double* y,
                                           double* pdf_out, size_t n) const {
    if (conditional_.empty()) {
        for (size_t i = 0; i < n; ++i) sample(u1[i], u2[i], x + i, y + i, pdf_out + i);
        return;
    }
    // The marginal and every conditional are tabulated: their kernels are used directly, so the
    // loops have no dispatch per point. Results equal sample() point by point: the density is
    // the cell's value, and the cell is the pair of bins the two kernels sampled in.
    const TabulatedK marginal = Distribution1DFactory::tabulated(marginal_);
    double row_density[kBlockSize];
    size_t row_of[kBlockSize], column_of[kBlockSize];
    for (size_t start = 0; start < n; start += kBlockSize) {
        const size_t m = std::min(kBlockSize, n - start);
        marginal.sample_block(u2 + start, y + start, row_density, row_of, m);
        size_t unsettled = 0;
        for (size_t k = 0; k < m; ++k) {
            const TabulatedK row = Distribution1DFactory::tabulated(conditional_[row_of[k]]);
            bool settled;
            const double v = TabulatedK::clamp_u(u1[start + k]);
            const size_t i = row.guided_bin(v, &settled);
            x[start + k] = row.place(v, i);
            column_of[k] = i;
            unsettled += !(settled && row.holds(x[start + k], i));
        }
        for (size_t k = 0; k < m && unsettled > 0; ++k) {
            const TabulatedK row = Distribution1DFactory::tabulated(conditional_[row_of[k]]);
            x[start + k] = row.settle(u1[start + k], x[start + k], &column_of[k]);
        }
        for (size_t k = 0; k < m; ++k) // pdf(x, y): both lie in the box
            pdf_out[start + k] = values_[row_of[k] * size_t(nx_) + column_of[k]] / total_;
    }
}

Made<TabulatedDistribution2D> make_tabulated_2d(double x0, double x1, double y0, double y1, int nx,
                                                int ny, const std::vector<double>& values) {
    using R = TabulatedDistribution2D;
    std::string err = check_interval("tabulated_2d", x0, x1, "x0", "x1");
    if (err.empty()) err = check_interval("tabulated_2d", y0, y1, "y0", "y1");
    if (!err.empty()) return made_error<R>(err);
    if (!(nx > 0 && ny > 0))
        return made_error<R>("tabulated_2d: nx and ny must be > 0, got nx=" + std::to_string(nx) +
                             ", ny=" + std::to_string(ny));
    const size_t cells = size_t(nx) * size_t(ny);
    if (cells > kMaxBins)
        return made_error<R>("tabulated_2d: nx * ny may be at most 4194304 bins, got " +
                             std::to_string(cells));
    if (values.size() != cells)
        return made_error<R>("tabulated_2d: values.size() must equal nx * ny = " +
                             std::to_string(cells) + ", got " + std::to_string(values.size()));
    double vmax = 0.0;
    for (size_t i = 0; i < cells; ++i) {
        double v = values[i];
        if (!(std::isfinite(v) && v >= 0.0))
            return made_error<R>("tabulated_2d: values[" + std::to_string(i) +
                                 "] must be finite and >= 0, got " + num(v));
        vmax = std::max(vmax, v);
    }
    if (!(vmax > 0.0)) return made_error<R>("tabulated_2d: values must not all be zero (sum is 0)");

    R r;
    r.nx_ = nx;
    r.ny_ = ny;
    r.x0_ = x0;
    r.x1_ = x1;
    r.y0_ = y0;
    r.y1_ = y1;
    // Row sums of values / vmax (the marginal is scale-free; no overflow).
    std::vector<double> rows(static_cast<size_t>(ny));
    NeumaierSum all;
    for (size_t iy = 0; iy < size_t(ny); ++iy) {
        NeumaierSum row;
        for (size_t ix = 0; ix < size_t(nx); ++ix) {
            double v = values[iy * size_t(nx) + ix];
            row.add(v / vmax);
            all.add(v);
        }
        rows[iy] = row.value();
    }
    Made<Distribution1D> marginal = make_tabulated(y0, y1, rows);
    if (!marginal.ok()) return made_error<R>("tabulated_2d: marginal in y: " + marginal.error);
    r.marginal_ = std::move(marginal.value);
    r.conditional_.reserve(size_t(ny));
    const std::vector<double> uniform_row(size_t(nx), 1.0);
    for (size_t iy = 0; iy < size_t(ny); ++iy) {
        // An all-zero row is never selected (its marginal weight is 0); a uniform conditional
        // keeps invert and sample defined there.
        std::vector<double> row(values.begin() + std::ptrdiff_t(iy * size_t(nx)),
                                values.begin() + std::ptrdiff_t((iy + 1) * size_t(nx)));
        Made<Distribution1D> c = make_tabulated(x0, x1, rows[iy] > 0.0 ? row : uniform_row);
        if (!c.ok())
            return made_error<R>("tabulated_2d: row " + std::to_string(iy) + ": " + c.error);
        r.conditional_.push_back(std::move(c.value));
    }
    const double cell_area = (x1 - x0) / nx * ((y1 - y0) / ny);
    r.total_ = all.value() * cell_area;
    if (!(r.total_ > 0.0 && std::isfinite(r.total_)))
        return made_error<R>("tabulated_2d: the integral of values (" + num(all.value()) +
                             " times the cell area " + num(cell_area) + ") is not representable");
    r.values_ = values;
    return {std::move(r), {}};
}

} // namespace mcp
