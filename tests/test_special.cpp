// Special functions against closed forms and identities (no values copied from a run).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/exp_block.h"
#include "core/rng.h"
#include "core/special.h"

using namespace mcp;

TEST(Special, NormalQuantileInvertsCdf) {
    for (double p : {1e-300, 1e-20, 1e-10, 1e-4, 0.01, 0.1, 0.3, 0.5, 0.7, 0.975, 0.999}) {
        double x = normal_quantile(p);
        EXPECT_NEAR(normal_cdf(x) / p, 1.0, 1e-12) << "p=" << p;
    }
    EXPECT_NEAR(normal_quantile(1.0 - 1e-10), -normal_quantile(1e-10), 1e-5);
    EXPECT_NEAR(normal_quantile(0.5), 0.0, 1e-15);
}

TEST(Special, StudentTQuantileExactSmallDof) {
    // nu = 1 is Cauchy: t = tan(pi (p - 1/2)); nu = 2 has a closed-form CDF.
    EXPECT_NEAR(student_t_quantile(0.975, 1), std::tan(kPi * 0.475), 1e-12);
    const double t2 = student_t_quantile(0.975, 2);
    EXPECT_NEAR(0.5 + t2 / (2.0 * std::sqrt(2.0 + t2 * t2)), 0.975, 1e-12);
    // Large nu tends to the normal quantile.
    EXPECT_NEAR(student_t_quantile(0.975, 1e6), normal_quantile(0.975), 1e-5);
}

TEST(Special, StudentTQuantileMatchesCdfByQuadrature) {
    // CDF of t with nu dof by Simpson integration of its density, at the quantile.
    for (double nu : {3.0, 7.0, 31.0}) {
        const double t = student_t_quantile(0.975, nu);
        const double c =
            std::exp(std::lgamma(0.5 * (nu + 1)) - std::lgamma(0.5 * nu)) / std::sqrt(nu * kPi);
        auto pdf = [&](double x) { return c * std::pow(1.0 + x * x / nu, -0.5 * (nu + 1)); };
        const int m = 20000;
        double h = t / m, s = pdf(0) + pdf(t);
        for (int i = 1; i < m; ++i) s += (i % 2 ? 4.0 : 2.0) * pdf(i * h);
        EXPECT_NEAR(0.5 + s * h / 3.0, 0.975, 1e-3) << "nu=" << nu;
    }
}

TEST(Special, StudentTTailClosedForms) {
    // nu = 1 (Cauchy): P(T > t) = 1/2 - atan(t) / pi; nu = 2: 1/2 - t / (2 sqrt(2 + t^2)).
    for (double t : {-3.0, -0.5, 0.0, 0.7, 2.0, 40.0}) {
        EXPECT_NEAR(student_t_sf(t, 1), 0.5 - std::atan(t) / kPi, 1e-13) << t;
        EXPECT_NEAR(student_t_sf(t, 2), 0.5 - t / (2.0 * std::sqrt(2.0 + t * t)), 1e-13) << t;
    }
    // Large nu tends to the normal tail; the tail at the 97.5% quantile is 2.5%.
    EXPECT_NEAR(student_t_sf(3.0, 1e7), 1.0 - normal_cdf(3.0), 1e-7);
    for (double nu : {3.0, 9.0, 31.0})
        EXPECT_NEAR(student_t_sf(student_t_quantile(0.975, nu), nu), 0.025, 1e-3) << nu;
    EXPECT_EQ(student_t_sf(INFINITY, 9), 0.0);
    EXPECT_EQ(student_t_sf(-INFINITY, 9), 1.0);
}

// The tail quantile inverts the tail: closed forms at nu = 1, 2, and the bisection where the
// Cornish-Fisher expansion fails (t_3 at a one-sided 5e-5: 28.0; the expansion gives ~12).
TEST(Special, StudentTTailQuantile) {
    for (double tail : {0.25, 0.025, 1e-4, 3e-7}) {
        EXPECT_NEAR(student_t_isf(tail, 1), std::tan(kPi * (0.5 - tail)), 1e-9 / tail) << tail;
        for (double nu : {1.0, 1.5, 2.0, 3.0, 7.0, 15.0, 150.0}) {
            const double t = student_t_isf(tail, nu);
            EXPECT_NEAR(student_t_sf(t, nu) / tail, 1.0, 1e-6) << "nu=" << nu << " tail=" << tail;
        }
    }
    EXPECT_NEAR(student_t_isf(5e-5, 3), 28.0, 0.05);
    EXPECT_EQ(student_t_isf(0.5, 4), 0.0);
    EXPECT_TRUE(std::isnan(student_t_isf(0.0, 4)));
}

// widened_limit: k t_0.975 / 1.96 from 15 degrees of freedom up; below, the point crossed as
// rarely as that limit is at 15 (never nearer than the widened one).
TEST(Special, WidenedLimitKeepsItsTailBelowFifteenDegreesOfFreedom) {
    for (double nu : {15.0, 31.0, 1000.0})
        EXPECT_DOUBLE_EQ(widened_limit(5.0, nu), 5.0 * student_t_quantile(0.975, nu) / kNormal975);
    const double reference_tail = student_t_sf(widened_limit(5.0, 15.0), 15.0);
    for (double nu : {1.0, 2.0, 3.0, 7.0, 14.0}) {
        const double limit = widened_limit(5.0, nu);
        EXPECT_GE(limit, 5.0 * student_t_quantile(0.975, nu) / kNormal975 - 1e-12) << nu;
        EXPECT_LE(student_t_sf(limit, nu), reference_tail * (1.0 + 1e-6)) << nu;
    }
    EXPECT_NEAR(widened_limit(5.0, 1.0), 1.0 / std::tan(kPi * reference_tail), 1e-6 * 9000.0);
}

TEST(Special, IncompleteGammaIdentities) {
    // P(1, x) = 1 - e^-x; chi-square with 2 dof has survival e^(-x/2).
    for (double x : {0.01, 0.5, 1.0, 3.0, 10.0, 50.0}) {
        EXPECT_NEAR(gamma_p(1.0, x), -std::expm1(-x), 1e-14);
        EXPECT_NEAR(chi_square_sf(x, 2.0) / std::exp(-0.5 * x), 1.0, 1e-12);
        EXPECT_NEAR(gamma_p(3.5, x) + gamma_q(3.5, x), 1.0, 1e-14);
    }
    // P(1/2, x) = erf(sqrt(x)).
    for (double x : {0.1, 1.0, 4.0}) EXPECT_NEAR(gamma_p(0.5, x), std::erf(std::sqrt(x)), 1e-13);
}

TEST(Special, ChiSquareQuantileInverts) {
    for (double k : {1.0, 2.0, 5.0, 31.0, 200.0})
        for (double p : {0.025, 0.5, 0.975}) {
            double x = chi_square_quantile(p, k);
            EXPECT_NEAR(1.0 - chi_square_sf(x, k), p, 1e-10) << "k=" << k << " p=" << p;
        }
}

TEST(Special, TrigammaKnownValues) {
    EXPECT_NEAR(trigamma(1.0), kPi * kPi / 6.0, 1e-12);
    EXPECT_NEAR(trigamma(0.5), kPi * kPi / 2.0, 1e-12);
    EXPECT_NEAR(trigamma(10.5) - trigamma(11.5), 1.0 / (10.5 * 10.5), 1e-14);
}

TEST(Special, IncompleteBetaAndFTailIdentities) {
    for (double x : {0.01, 0.3, 0.5, 0.9, 0.999}) {
        EXPECT_NEAR(beta_regularized(2.5, 1.0, x), std::pow(x, 2.5), 1e-13);
        EXPECT_NEAR(beta_regularized(1.0, 3.5, x), 1.0 - std::pow(1.0 - x, 3.5), 1e-13);
        EXPECT_NEAR(beta_regularized(4.2, 7.3, x), 1.0 - beta_regularized(7.3, 4.2, 1.0 - x),
                    1e-13);
    }
    // F(2, 2): P(F > f) = 1 / (1 + f).
    for (double f : {0.1, 1.0, 7.0, 300.0}) EXPECT_NEAR(f_sf(f, 2.0, 2.0), 1.0 / (1.0 + f), 1e-13);
    // F(1, nu) is T(nu)^2: P(F > t^2) = 2 P(T > t) = 0.05 at t = t_0.975 (the quantile is a
    // Cornish-Fisher expansion, good to 1e-3 for nu >= 3).
    for (double nu : {5.0, 12.0, 40.0}) {
        const double t = student_t_quantile(0.975, nu);
        EXPECT_NEAR(f_sf(t * t, 1.0, nu), 0.05, 2e-4) << nu;
    }
    // d2 -> infinity: d1 F -> chi^2(d1).
    EXPECT_NEAR(f_sf(1.7, 15.0, 1e8), chi_square_sf(15.0 * 1.7, 15.0), 1e-6);
    EXPECT_EQ(f_sf(0.0, 3.0, 4.0), 1.0);
    EXPECT_EQ(f_sf(std::numeric_limits<double>::infinity(), 3.0, 4.0), 0.0);
}

namespace {

/// Arguments over exp's whole domain and near 0, with the ranges' ends and special values.
std::vector<double> exp_arguments(size_t n) {
    Pcg32 rng(21u, 5u);
    std::vector<double> x(n);
    for (size_t i = 0; i < n; ++i) {
        const double u = rng.next_double();
        switch (i % 4) {
        case 0: x[i] = -750.0 + 1465.0 * u; break; // underflow to overflow
        case 1: x[i] = -1.0 + 2.0 * u; break;
        case 2: x[i] = std::ldexp(u - 0.5, -int(i % 60)); break; // tiny arguments
        default: x[i] = -704.0 + 1408.0 * u; break;              // the table's range
        }
    }
    const double inf = std::numeric_limits<double>::infinity();
    for (double v : {0.0, -0.0, 1.0, -1.0, 703.99, -703.99, 704.0, -704.0, 709.78, 709.79, -708.4,
                     -745.1, -746.0, inf, -inf, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::denorm_min(), 1e-300})
        x.push_back(v);
    return x;
}

bool same_double(double a, double b) {
    return a == b || (std::isnan(a) && std::isnan(b));
}

} // namespace

TEST(ExpBlock, WithinOneUlpOfTheLibraryAndBlockEqualsScalar) {
    const std::vector<double> x = exp_arguments(400001); // odd: the block's scalar tail runs
    std::vector<double> y(x.size()), in_place = x;
    exp_block(x.data(), y.data(), x.size());
    exp_block(in_place.data(), in_place.data(), in_place.size());
    size_t equal = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double want = std::exp(x[i]), got = y[i];
        const double t = exp_tang(x[i]);
        ASSERT_TRUE(same_double(got, t)) << x[i];
        ASSERT_TRUE(same_double(in_place[i], t)) << x[i];
        if (std::isnan(want) || std::isinf(want)) { // NaN, overflow: the library's own
            ASSERT_TRUE(same_double(got, want)) << x[i];
            continue;
        }
        // Both within about half an ulp of e^x: equal or neighbours.
        const double ulp = std::nextafter(want, std::numeric_limits<double>::infinity()) - want;
        ASSERT_LE(std::fabs(got - want), ulp) << x[i];
        equal += got == want;
    }
    // A correctly rounded result most of the time (both are).
    EXPECT_GT(double(equal), 0.99 * double(x.size()));
}

namespace {

/// e^x in long double when it is IEEE quadruple (wasm: musl's expl there is exp itself):
/// x = k ln2 + r with ln2 in two parts (the first 33 bits, exact times k), then the Taylor
/// series of e^r to 30 terms, within a few units of 2^-113.
long double exp_quad_reference(double x) {
    const long double ln2_hi = 0x1.62e42fefp-1L;
    const long double ln2_lo = 7.4406171100123967161301568075500134360255e-11L;
    const long double k = std::nearbyint(x / 0.6931471805599453);
    const long double r = (static_cast<long double>(x) - k * ln2_hi) - k * ln2_lo;
    long double term = 1.0L, sum = 1.0L;
    for (int i = 1; i < 30; ++i) {
        term *= r / i;
        sum += term;
    }
    return std::ldexp(sum, static_cast<int>(k));
}

} // namespace

TEST(ExpBlock, AsAccurateAsTheLibrary) {
    // The reference: x87's 64-bit long double expl natively, the quadruple series in wasm.
    const int digits = std::numeric_limits<long double>::digits;
    if (digits != 64 && digits != 113)
        GTEST_SKIP() << "long double has " << digits << " bits: no reference to measure ulps";
    auto reference = [&](double x) {
        return digits == 64 ? expl(static_cast<long double>(x)) : exp_quad_reference(x);
    };
    const std::vector<double> x = exp_arguments(digits == 64 ? 400000 : 100000);
    std::vector<double> y(x.size());
    exp_block(x.data(), y.data(), x.size());
    double worst = 0.0, worst_library = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
        const long double ref = reference(x[i]);
        if (!std::isfinite(x[i]) || !std::isfinite(static_cast<double>(ref)) ||
            static_cast<double>(ref) < std::numeric_limits<double>::min())
            continue; // overflow, subnormal results: std::exp's own (asserted above)
        int e = 0;
        std::frexp(static_cast<double>(ref), &e);
        const long double ulp = std::ldexp(1.0L, e - 53);
        worst = std::max(worst, double(std::fabs(y[i] - ref) / ulp));
        worst_library = std::max(worst_library, double(std::fabs(std::exp(x[i]) - ref) / ulp));
    }
    // [Tang89]'s bound for 128 entries and a degree-5 polynomial: 0.5 + about 0.01 ulp.
    EXPECT_LT(worst, 0.51) << "library " << worst_library;
    EXPECT_LT(worst, worst_library + 0.005) << "library " << worst_library;
}
