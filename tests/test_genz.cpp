// Genz's test families [Genz84]: every closed form against an independent computation
// (nested adaptive quadrature for d <= 3, the corner-peak vertex sum in long double, long
// double products, Monte Carlo at d = 32 and 64), the parameter normalisation, block against
// point evaluation, and input validation. Fixed seeds; no values copied from a run.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "core/points.h"
#include "core/quadrature.h"
#include "core/rng.h"
#include "core/special.h"
#include "core/stats.h"
#include "integrands/genz.h"
#include "test_support.h"

using namespace mcp;

namespace {

constexpr GenzFamily kAll[] = {GenzFamily::Oscillatory, GenzFamily::ProductPeak,
                               GenzFamily::CornerPeak,  GenzFamily::Gaussian,
                               GenzFamily::Continuous,  GenzFamily::Discontinuous};

// Genz's (h, e), restated here from [Genz87] rather than read from the implementation.
double genz_target_sum(GenzFamily f, int d, double difficulty) {
    switch (f) {
    case GenzFamily::Oscillatory: return difficulty * 110.0 / std::pow(d, 1.5);
    case GenzFamily::ProductPeak:
    case GenzFamily::CornerPeak: return difficulty * 600.0 / (double(d) * d);
    case GenzFamily::Gaussian: return difficulty * 100.0 / d;
    case GenzFamily::Continuous: return difficulty * 150.0 / (double(d) * d);
    case GenzFamily::Discontinuous: return difficulty * 100.0 / (double(d) * d);
    }
    return 0.0;
}

// The integrand written out from the definitions (not through genz_evaluate_*), for the
// reference quadratures.
double reference_f(const GenzParams& p, const double* x) {
    const int d = p.dim();
    double s = 0.0, prod = 1.0;
    switch (p.family) {
    case GenzFamily::Oscillatory:
        for (int i = 0; i < d; ++i) s += p.a[i] * x[i];
        return std::cos(2.0 * kPi * p.u[0] + s);
    case GenzFamily::ProductPeak:
        // 1 / (a^-2 + t^2) = a^2 / (1 + (a t)^2)
        for (int i = 0; i < d; ++i) {
            const double at = p.a[i] * (x[i] - p.u[i]);
            prod *= p.a[i] * p.a[i] / (1.0 + at * at);
        }
        return prod;
    case GenzFamily::CornerPeak:
        for (int i = 0; i < d; ++i) s += p.a[i] * x[i];
        for (int i = 0; i <= d; ++i) prod /= 1.0 + s;
        return prod;
    case GenzFamily::Gaussian:
        for (int i = 0; i < d; ++i) s += p.a[i] * p.a[i] * (x[i] - p.u[i]) * (x[i] - p.u[i]);
        return std::exp(-s);
    case GenzFamily::Continuous:
        for (int i = 0; i < d; ++i) s += p.a[i] * std::fabs(x[i] - p.u[i]);
        return std::exp(-s);
    case GenzFamily::Discontinuous:
        if (x[0] > p.u[0] || (d > 1 && x[1] > p.u[1])) return 0.0;
        for (int i = 0; i < d; ++i) s += p.a[i] * x[i];
        return std::exp(s);
    }
    return 0.0;
}

// Nested adaptive quadrature over [0,1]^d (d <= 3), each coordinate's range split at u_j
// where the family has a kink, a jump or a peak there, so that every piece is smooth.
struct Nested {
    const GenzParams& p;
    double rel_tol, abs_tol;
    double x[3] = {0, 0, 0};
    long evaluations = 0;

    double level(int j) {
        const int d = p.dim();
        if (j == d) {
            ++evaluations;
            return reference_f(p, x);
        }
        auto inner = [&](double t) {
            x[j] = t;
            return level(j + 1);
        };
        const bool split =
            p.family != GenzFamily::Oscillatory && p.family != GenzFamily::CornerPeak;
        if (!split || p.u[j] <= 0.0 || p.u[j] >= 1.0)
            return integrate_adaptive(inner, 0.0, 1.0, rel_tol, abs_tol).value;
        return integrate_adaptive(inner, 0.0, p.u[j], rel_tol, abs_tol).value +
               integrate_adaptive(inner, p.u[j], 1.0, rel_tol, abs_tol).value;
    }
};

// |I| can be small by cancellation (oscillatory): measure errors against the amplitude
// prod_i |sin(a_i/2) / (a_i/2)| that bounds |I|; elsewhere against |I|.
double error_scale(const GenzParams& p, double exact) {
    if (p.family != GenzFamily::Oscillatory) return std::fabs(exact);
    double amp = 1.0;
    for (double a : p.a) amp *= a == 0.0 ? 1.0 : std::fabs(std::sin(0.5 * a) / (0.5 * a));
    return std::max(std::fabs(exact), amp);
}

// The corner peak as the vertex sum [Genz84]:
//   I = (1 / (d! prod a_i)) sum_v (-1)^|v| / (1 + a.v),
// in long double (compensated) and in plain double.
long double corner_vertex_sum_ld(const GenzParams& p) {
    const int d = p.dim();
    long double sum = 0.0L, comp = 0.0L;
    for (unsigned v = 0; v < (1u << d); ++v) {
        long double s = 1.0L;
        int bits = 0;
        for (int i = 0; i < d; ++i)
            if (v >> i & 1u) {
                s += static_cast<long double>(p.a[i]);
                ++bits;
            }
        const long double term = (bits % 2 ? -1.0L : 1.0L) / s;
        const long double t = sum + term; // Neumaier
        comp += std::fabs(sum) >= std::fabs(term) ? (sum - t) + term : (term - t) + sum;
        sum = t;
    }
    long double scale = 1.0L;
    for (int i = 0; i < d; ++i) scale *= static_cast<long double>(p.a[i]) * (i + 1);
    return (sum + comp) / scale;
}

// The same sum with the last two dimensions' second difference taken in closed form,
//   g(c) - g(c + al) - g(c + be) + g(c + al + be)
//     = al be (2c + al + be) / (c (c + al) (c + be) (c + al + be))
// for g(c) = 1/c: 2^(d-2) terms without the two innermost levels of cancellation, so the long
// double sum keeps ~3 more digits at d = 12 (needed where the plain one is only ~1e-12).
long double corner_vertex_sum_paired_ld(const GenzParams& p) {
    const int d = p.dim();
    const int m = d - 2;
    const long double al = p.a[m], be = p.a[m + 1];
    long double sum = 0.0L, comp = 0.0L;
    for (unsigned v = 0; v < (1u << m); ++v) {
        long double c = 1.0L;
        int bits = 0;
        for (int i = 0; i < m; ++i)
            if (v >> i & 1u) {
                c += static_cast<long double>(p.a[i]);
                ++bits;
            }
        long double term =
            al * be * (2.0L * c + al + be) / (c * (c + al) * (c + be) * (c + al + be));
        if (bits % 2) term = -term;
        const long double t = sum + term;
        comp += std::fabs(sum) >= std::fabs(term) ? (sum - t) + term : (term - t) + sum;
        sum = t;
    }
    long double scale = 1.0L;
    for (int i = 0; i < d; ++i) scale *= static_cast<long double>(p.a[i]) * (i + 1);
    return (sum + comp) / scale;
}

double corner_vertex_sum_double(const GenzParams& p) {
    const int d = p.dim();
    double sum = 0.0;
    for (unsigned v = 0; v < (1u << d); ++v) {
        double s = 1.0;
        int bits = 0;
        for (int i = 0; i < d; ++i)
            if (v >> i & 1u) {
                s += p.a[i];
                ++bits;
            }
        sum += (bits % 2 ? -1.0 : 1.0) / s;
    }
    double scale = 1.0;
    for (int i = 0; i < d; ++i) scale *= p.a[i] * (i + 1);
    return sum / scale;
}

// log I for the product-form families from one-dimensional factors in long double (on
// x86-64 the 80-bit format; under Emscripten binary128 arithmetic, but musl's long double
// transcendental functions are only double accurate there, hence expm1 rather than 1 - exp).
long double log_product_ld(const GenzParams& p) {
    const int d = p.dim();
    long double prod = 1.0L;
    for (int i = 0; i < d; ++i) {
        const long double a = p.a[i], u = p.u[i];
        long double f = 0.0L;
        switch (p.family) {
        case GenzFamily::ProductPeak: f = a * (std::atan(a * (1.0L - u)) + std::atan(a * u)); break;
        case GenzFamily::Gaussian:
            f = std::sqrt(static_cast<long double>(kPi)) / (2.0L * a) *
                (std::erf(a * (1.0L - u)) + std::erf(a * u));
            break;
        case GenzFamily::Continuous:
            f = (-std::expm1(-a * u) - std::expm1(-a * (1.0L - u))) / a;
            break;
        case GenzFamily::Discontinuous: f = std::expm1(i < 2 ? a * u : a) / a; break;
        default: f = std::sin(a / 2.0L) / (a / 2.0L); break;
        }
        prod *= f;
    }
    // log through frexp: Emscripten's musl evaluates long double logl (and expl, erfl) in
    // double, which cannot hold the d = 64 product peak (~1e-350).
    int e = 0;
    const long double m = std::frexp(std::fabs(prod), &e);
    return std::log(static_cast<double>(m)) + e * 0.693147180559945309417232121458176568L;
}

// Fills a block with uniform points from rng.
void fill(PointBlock* block, size_t n, Pcg32* rng) {
    block->n = n;
    for (int j = 0; j < block->dim; ++j) {
        double* c = block->coord(j);
        for (size_t i = 0; i < n; ++i) c[i] = rng->next_double();
    }
}

} // namespace

TEST(Genz, NamesRoundTrip) {
    for (GenzFamily f : kAll) {
        GenzFamily g = GenzFamily::Oscillatory;
        ASSERT_TRUE(parse_genz_family(genz_family_name(f), &g));
        EXPECT_EQ(g, f);
    }
    EXPECT_STREQ(genz_family_name(GenzFamily::ProductPeak), "genz_product_peak");
    GenzFamily g = GenzFamily::Gaussian;
    EXPECT_FALSE(parse_genz_family("gaussian", &g));
    EXPECT_EQ(g, GenzFamily::Gaussian);
}

TEST(Genz, ClosedFormsMatchNestedQuadratureInOneToThreeDimensions) {
    for (GenzFamily f : kAll) {
        double worst[4] = {0, 0, 0, 0};
        for (int d = 1; d <= 3; ++d)
            for (double level : {0.5, 1.0, 4.0})
                for (uint64_t seed : {1u, 2u, 3u}) {
                    // Keep the suite fast: d = 3 costs ~1e7 evaluations per case at
                    // difficulty 4 for the peaks; run it at difficulty 2 and two seeds.
                    if (d == 3 && seed == 3u) continue;
                    const double difficulty = d == 3 && level == 4.0 ? 2.0 : level;
                    const GenzParams p = genz_random(f, d, seed, difficulty);
                    const double exact = genz_exact(p);
                    // Oscillatory integrands cross zero: an absolute floor on the inner
                    // integrals (|f| <= 1 on a unit box); the others are positive.
                    const double abs_tol = f == GenzFamily::Oscillatory ? 1e-14 : 0.0;
                    Nested nested{p, 1e-10, abs_tol};
                    const double q = nested.level(0);
                    const double err = std::fabs(q - exact) / error_scale(p, exact);
                    worst[d] = std::max(worst[d], err);
                    EXPECT_LT(err, 1e-9) << genz_family_name(f) << " d=" << d << " seed=" << seed
                                         << " difficulty=" << difficulty << " exact=" << exact
                                         << " quadrature=" << q;
                    EXPECT_TRUE(std::isfinite(exact));
                    if (f != GenzFamily::Oscillatory) {
                        EXPECT_GT(exact, 0.0);
                    }
                }
        std::printf("  %-20s max relative difference to nested quadrature: d=1 %.1e, d=2 %.1e, "
                    "d=3 %.1e\n",
                    genz_family_name(f), worst[1], worst[2], worst[3]);
    }
}

TEST(Genz, HandPickedParametersMatchQuadrature) {
    struct Case {
        GenzFamily f;
        std::vector<double> a, u;
    };
    const Case cases[] = {
        // a_i = 0 and tiny a_i: the sinc form's limit.
        {GenzFamily::Oscillatory, {0.0, 1e-9, 3.0}, {0.2, 0.5, 0.5}},
        {GenzFamily::Oscillatory, {1e-6}, {0.75}},
        // d = 1 discontinuous: only x_1 is cut.
        {GenzFamily::Discontinuous, {2.0}, {0.3}},
        // u at the edges of [0, 1].
        {GenzFamily::Gaussian, {5.0, 0.3}, {0.0, 1.0}},
        {GenzFamily::Continuous, {7.0, 1e-3}, {1.0, 0.0}},
        {GenzFamily::ProductPeak, {50.0, 1e-3}, {0.0, 1.0}},
        {GenzFamily::Discontinuous, {1e-3, 3.0, 2.0}, {1.0, 0.5, 0.9}},
        // Tiny and large difficulty for the corner peak.
        {GenzFamily::CornerPeak, {1e-8, 1e-8}, {0.5, 0.5}},
        {GenzFamily::CornerPeak, {1e4}, {0.5}},
        {GenzFamily::CornerPeak, {3000.0, 1e-4, 20.0}, {0.5, 0.5, 0.5}},
    };
    for (const Case& c : cases) {
        const Made<GenzParams> m = make_genz(c.f, c.a, c.u);
        ASSERT_TRUE(m.ok()) << m.error;
        const double exact = genz_exact(m.value);
        Nested nested{m.value, 1e-12, c.f == GenzFamily::Oscillatory ? 1e-14 : 0.0};
        const double q = nested.level(0);
        EXPECT_LT(std::fabs(q - exact), 1e-9 * error_scale(m.value, exact))
            << genz_family_name(c.f) << " d=" << m.value.dim() << " exact=" << exact
            << " quadrature=" << q;
    }
    // A cut at u = 0 leaves nothing.
    const Made<GenzParams> zero = make_genz(GenzFamily::Discontinuous, {1.0, 1.0}, {0.5, 0.0});
    ASSERT_TRUE(zero.ok());
    EXPECT_EQ(genz_exact(zero.value), 0.0);
    int sign = 7;
    EXPECT_EQ(genz_log_exact(zero.value, &sign), -INFINITY);
    EXPECT_EQ(sign, 0);
}

TEST(Genz, CornerPeakMatchesLongDoubleVertexSum) {
    double worst = 0.0;
    for (int d = 1; d <= 8; ++d)
        for (double difficulty : {0.25, 0.5, 1.0, 4.0})
            for (uint64_t seed : {1u, 2u, 3u}) {
                const GenzParams p = genz_random(GenzFamily::CornerPeak, d, seed, difficulty);
                const long double ref = corner_vertex_sum_ld(p);
                const double err = static_cast<double>(std::fabs((genz_exact(p) - ref) / ref));
                worst = std::max(worst, err);
                EXPECT_LT(err, 1e-13)
                    << "d=" << d << " seed=" << seed << " difficulty=" << difficulty;
            }
    std::printf(
        "  corner peak d <= 8: max relative difference to the long double vertex sum %.1e\n",
        worst);
}

TEST(Genz, CornerPeakStaysAccurateWhereTheVertexSumCancels) {
    // d = 12 at half Genz's difficulty: the 4096 alternating terms cancel by a factor ~1e8-1e9
    // (sum |terms| / |sum|). Plain double summation keeps only ~7 digits, plain long double
    // (x86-64: 11 more bits) ~1e-12; the long double sum with the innermost second difference
    // in closed form cancels far less and serves as the reference.
    const int d = 12;
    for (uint64_t seed : {1u, 2u, 3u, 4u}) {
        const GenzParams p = genz_random(GenzFamily::CornerPeak, d, seed, 0.5);
        const long double ref = corner_vertex_sum_paired_ld(p);
        const double stable = genz_exact(p);
        const double err_stable = static_cast<double>(std::fabs((stable - ref) / ref));
        const double err_ld = static_cast<double>(std::fabs((corner_vertex_sum_ld(p) - ref) / ref));
        const double err_naive =
            static_cast<double>(std::fabs((corner_vertex_sum_double(p) - ref) / ref));
        EXPECT_LT(err_stable, 1e-13) << "seed=" << seed;
        EXPECT_LT(err_ld, 2e-12) << "seed=" << seed;
        EXPECT_GT(err_naive, 1e-11) << "seed=" << seed;
        std::printf("  corner peak d=12 seed %d, relative to the paired long double sum: stable "
                    "%.1e, plain long double sum %.1e, plain double sum %.1e\n",
                    static_cast<int>(seed), err_stable, err_ld, err_naive);
    }
}

TEST(Genz, ProductFormsMatchLongDoubleInHighDimension) {
    // Separable families: the stable double product (binary exponent carried apart) against
    // a plain long double product of long double factors, in log form since product_peak at
    // d = 64 (~1e-340) is below the double range.
    for (GenzFamily f : {GenzFamily::ProductPeak, GenzFamily::Gaussian, GenzFamily::Continuous,
                         GenzFamily::Discontinuous}) {
        double worst[3] = {0, 0, 0};
        for (int d : {12, 32, 64})
            for (uint64_t seed : {1u, 2u}) {
                const GenzParams p = genz_random(f, d, seed);
                int sign = 0;
                const double log_exact = genz_log_exact(p, &sign);
                EXPECT_EQ(sign, 1);
                const long double ref = log_product_ld(p);
                // 1e-13 relative on I is 1e-13 absolute on log I.
                EXPECT_NEAR(log_exact, static_cast<double>(ref), 1e-13)
                    << genz_family_name(f) << " d=" << d;
                double& w = worst[d == 12 ? 0 : d == 32 ? 1 : 2];
                w = std::max(w, std::fabs(log_exact - static_cast<double>(ref)));
                const double exact = genz_exact(p);
                if (log_exact > std::log(DBL_MIN)) {
                    EXPECT_NEAR(std::log(exact), log_exact, 1e-13) << genz_family_name(f);
                } else {
                    EXPECT_EQ(exact, 0.0) << genz_family_name(f) << " d=" << d;
                }
            }
        std::printf("  %-20s max |log I - log I_long_double|: d=12 %.1e, d=32 %.1e, d=64 %.1e\n",
                    genz_family_name(f), worst[0], worst[1], worst[2]);
    }
    // The oscillatory amplitude, and the sign from the cosine.
    for (int d : {12, 32, 64}) {
        const GenzParams p = genz_random(GenzFamily::Oscillatory, d, 5);
        double phase = 2.0 * kPi * p.u[0];
        for (double a : p.a) phase += 0.5 * a;
        int sign = 0;
        const double log_exact = genz_log_exact(p, &sign);
        EXPECT_EQ(sign, std::cos(phase) > 0.0 ? 1 : -1);
        const double ref =
            static_cast<double>(log_product_ld(p)) + std::log(std::fabs(std::cos(phase)));
        EXPECT_NEAR(log_exact, ref, 1e-13);
        std::printf("  genz_oscillatory d=%d |log|I| - reference| %.1e\n", d,
                    std::fabs(log_exact - ref));
    }
}

TEST(Genz, CornerPeakHighDimensionMatchesFixedPanelQuadrature) {
    // The same one-dimensional representation I = (1/d!) int_0^inf e^-t prod (1 - e^-a t)/a dt,
    // evaluated differently: composite 5-point Gauss-Legendre on [0, T] with fixed panels.
    // T = d + 60 sqrt(d) + 100: beyond it the integrand is below e^-t t^d / d!, whose tail
    // is < 1e-20 of the total.
    for (int d : {12, 32, 64})
        for (uint64_t seed : {1u, 2u}) {
            const GenzParams p = genz_random(GenzFamily::CornerPeak, d, seed);
            const double log_d_fact = std::lgamma(d + 1.0);
            auto g = [&](double t) {
                double l = -t - log_d_fact;
                for (double a : p.a) l += std::log(-std::expm1(-a * t) / a);
                return std::exp(l);
            };
            const double T = d + 60.0 * std::sqrt(double(d)) + 100.0;
            const double ref = test::gauss_legendre(g, 0.0, T, 4000);
            EXPECT_NEAR(genz_exact(p) / ref, 1.0, 1e-12) << "d=" << d << " seed=" << seed;
            std::printf("  corner peak d=%d seed %d: relative difference to fixed-panel "
                        "Gauss-Legendre %.1e\n",
                        d, static_cast<int>(seed), std::fabs(genz_exact(p) / ref - 1.0));
        }
}

TEST(Genz, HighDimensionExactAgreesWithMonteCarlo) {
    const size_t n_total = size_t(1) << 20;
    for (int d : {32, 64}) {
        GenzParams params[6];
        RunningMoments moments[6];
        RunningMoments scaled_peak; // product_peak / prod a_i^2, representable at any d
        for (GenzFamily f : kAll) params[static_cast<int>(f)] = genz_random(f, d, 100 + d);
        const GenzParams& peak = params[static_cast<int>(GenzFamily::ProductPeak)];

        Pcg32 rng(2024, static_cast<uint64_t>(d));
        PointBlock block;
        block.reset(d, kBlockSize);
        std::vector<double> out(kBlockSize);
        for (size_t done = 0; done < n_total; done += kBlockSize) {
            fill(&block, kBlockSize, &rng);
            for (int k = 0; k < 6; ++k) {
                genz_evaluate_block(params[k], block, out.data());
                moments[k].add_block(out.data(), block.n);
            }
            for (size_t i = 0; i < block.n; ++i) {
                double g = 1.0;
                for (int j = 0; j < d; ++j) {
                    const double t = peak.a[j] * (block.coord(j)[i] - peak.u[j]);
                    g /= 1.0 + t * t;
                }
                out[i] = g;
            }
            scaled_peak.add_block(out.data(), block.n);
        }
        for (GenzFamily f : kAll) {
            const int k = static_cast<int>(f);
            const double exact = genz_exact(params[k]);
            const double mean = moments[k].mean();
            const double se = std::sqrt(moments[k].variance() / static_cast<double>(n_total));
            EXPECT_TRUE(std::isfinite(exact)) << genz_family_name(f);
            if (f == GenzFamily::ProductPeak && d == 64) {
                // ~1e-340 is below the smallest double: both the integrand and I underflow.
                EXPECT_EQ(exact, 0.0);
                EXPECT_EQ(mean, 0.0);
                int sign = 0;
                const double log_i = genz_log_exact(params[k], &sign);
                double log_scale = 0.0;
                for (double a : params[k].a) log_scale += 2.0 * std::log(a);
                const double scaled_exact = std::exp(log_i - log_scale);
                const double scaled_se =
                    std::sqrt(scaled_peak.variance() / static_cast<double>(n_total));
                EXPECT_EQ(sign, 1);
                EXPECT_LT(std::fabs(scaled_peak.mean() - scaled_exact), 5.0 * scaled_se)
                    << "scaled product peak d=64: exact " << scaled_exact << " mean "
                    << scaled_peak.mean() << " se " << scaled_se;
                std::printf("  d=%d %-20s exact %.6e (log %.4f), scaled MC %.1f se off\n", d,
                            genz_family_name(f), exact, log_i,
                            (scaled_peak.mean() - scaled_exact) / scaled_se);
                continue;
            }
            if (f != GenzFamily::Oscillatory) {
                EXPECT_GT(exact, 0.0) << genz_family_name(f);
            }
            EXPECT_GT(se, 0.0);
            EXPECT_LT(std::fabs(mean - exact), 5.0 * se)
                << genz_family_name(f) << " d=" << d << ": exact " << exact << " mean " << mean
                << " se " << se;
            std::printf("  d=%d %-20s exact %.6e, MC %+.1f se off (se/|I| %.1e)\n", d,
                        genz_family_name(f), exact, (mean - exact) / se, se / std::fabs(exact));
        }
    }
}

TEST(Genz, RandomParametersFollowGenzNormalisation) {
    for (GenzFamily f : kAll)
        for (int d : {1, 2, 5, 32, 64})
            for (double difficulty : {1.0, 3.0}) {
                const GenzParams p = genz_random(f, d, 42, difficulty);
                ASSERT_EQ(p.dim(), d);
                ASSERT_EQ(p.u.size(), p.a.size());
                EXPECT_EQ(p.family, f);
                double sum = 0.0;
                for (int i = 0; i < d; ++i) {
                    sum += p.a[i];
                    EXPECT_GT(p.a[i], 0.0);
                    EXPECT_GE(p.u[i], 0.0);
                    EXPECT_LE(p.u[i], 1.0);
                }
                const double target = genz_target_sum(f, d, difficulty);
                EXPECT_NEAR(sum / target, 1.0, 1e-12) << genz_family_name(f) << " d=" << d;
                EXPECT_TRUE(make_genz(f, p.a, p.u).ok());
            }
    // Deterministic per seed, different across seeds.
    const GenzParams x = genz_random(GenzFamily::Gaussian, 8, 7);
    const GenzParams y = genz_random(GenzFamily::Gaussian, 8, 7);
    const GenzParams z = genz_random(GenzFamily::Gaussian, 8, 8);
    EXPECT_EQ(x.a, y.a);
    EXPECT_EQ(x.u, y.u);
    for (int i = 0; i < 8; ++i) {
        EXPECT_NE(x.a[i], z.a[i]);
        EXPECT_NE(x.u[i], z.u[i]);
    }
    // Difficulty scales a and leaves u alone.
    const GenzParams hard = genz_random(GenzFamily::Gaussian, 8, 7, 2.0);
    EXPECT_EQ(hard.u, x.u);
    for (int i = 0; i < 8; ++i) EXPECT_NEAR(hard.a[i], 2.0 * x.a[i], 1e-15 * x.a[i]);
}

TEST(Genz, BlockEvaluationEqualsPointEvaluation) {
    Pcg32 rng(9, 9);
    for (GenzFamily f : kAll)
        for (int d : {1, 2, 3, 7, 64}) {
            const GenzParams p = genz_random(f, d, 11, 2.0);
            PointBlock block;
            block.reset(d, kBlockSize);
            fill(&block, 200, &rng); // a partly filled block
            // Points on the cuts and peaks themselves.
            for (int j = 0; j < d; ++j) block.coord(j)[0] = p.u[j];
            block.coord(0)[1] = 0.0;
            block.coord(0)[2] = 1.0;
            std::vector<double> out(kBlockSize, -1.0);
            genz_evaluate_block(p, block, out.data());
            std::vector<double> point(d);
            for (size_t i = 0; i < block.n; ++i) {
                for (int j = 0; j < d; ++j) point[j] = block.coord(j)[i];
                const double v = genz_evaluate_point(p, point.data());
                EXPECT_EQ(out[i], v) << genz_family_name(f) << " d=" << d << " i=" << i;
                // And the definition (|cos| <= 1: an absolute tolerance for the oscillatory).
                const double tol = f == GenzFamily::Oscillatory ? 1e-12 : 1e-12 * std::fabs(v);
                if (d <= 3) {
                    EXPECT_NEAR(v, reference_f(p, point.data()), tol) << genz_family_name(f);
                }
            }
            EXPECT_EQ(out[block.n], -1.0); // nothing written past n
        }
}

TEST(Genz, MakeGenzRejectsBadInput) {
    auto err = [](GenzFamily f, std::vector<double> a, std::vector<double> u) {
        return make_genz(f, std::move(a), std::move(u)).error;
    };
    EXPECT_EQ(err(GenzFamily::Gaussian, {1.0, 2.0, 3.0, -1.0}, {0.5, 0.5, 0.5, 0.5}),
              "genz_gaussian: a[3] must be > 0, got -1");
    EXPECT_NE(err(GenzFamily::Gaussian, {}, {}).find("dimension"), std::string::npos);
    EXPECT_NE(err(GenzFamily::Gaussian, std::vector<double>(65, 1.0), std::vector<double>(65, 0.5))
                  .find("got 65"),
              std::string::npos);
    EXPECT_NE(err(GenzFamily::Continuous, {1.0, 1.0}, {0.5}).find("u has 1 entries, a has 2"),
              std::string::npos);
    EXPECT_NE(err(GenzFamily::CornerPeak, {1.0, NAN}, {0.5, 0.5}).find("a[1] must be finite"),
              std::string::npos);
    EXPECT_NE(err(GenzFamily::ProductPeak, {0.0}, {0.5}).find("a[0] must be > 0"),
              std::string::npos);
    EXPECT_NE(err(GenzFamily::Discontinuous, {1.0, 1.0}, {0.5, 1.5}).find("u[1] must be in [0, 1]"),
              std::string::npos);
    EXPECT_NE(err(GenzFamily::Gaussian, {1.0}, {-0.25}).find("u[0] must be in [0, 1], got -0.25"),
              std::string::npos);
    EXPECT_NE(err(GenzFamily::Gaussian, {1.0}, {INFINITY}).find("u[0] must be finite"),
              std::string::npos);
    EXPECT_NE(err(GenzFamily::Oscillatory, {1.0, -0.5}, {0.5, 0.5}).find("a[1] must be >= 0"),
              std::string::npos);
    // Every message names its family.
    EXPECT_EQ(err(GenzFamily::Continuous, {1.0, 1.0}, {0.5}).rfind("genz_continuous: ", 0), 0u);
    // Accepted: a = 0 for the oscillatory family only, u at the ends of [0, 1].
    EXPECT_TRUE(make_genz(GenzFamily::Oscillatory, {0.0, 2.0}, {0.0, 1.0}).ok());
    const Made<GenzParams> ok = make_genz(GenzFamily::Gaussian, {1.0, 2.0}, {0.0, 1.0});
    ASSERT_TRUE(ok.ok());
    EXPECT_EQ(ok.value.dim(), 2);
    EXPECT_EQ(ok.value.family, GenzFamily::Gaussian);
}
