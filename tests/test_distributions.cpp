// 1D and 2D sampling distributions: cdf and sample are inverses, densities integrate to one and
// are the derivatives of the cdfs, cdfs agree with an independent quadrature of the densities,
// samples pass chi-square tests, tabulated zero bins are never sampled, blocks equal scalar
// calls, and the factories reject bad parameters with messages that name them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "core/distributions.h"
#include "core/float_index.h"
#include "core/rng.h"
#include "core/special.h"
#include "test_support.h"

using namespace mcp;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kChiSamples = 100000;

/// One distribution under test, with what the generic tests need to know about it.
struct Case {
    std::string name;
    Made<Distribution1D> made;
    double window_lo, window_hi; ///< chi-square cells: `cells` equal ones on the window, plus
    int cells;                   ///< [a, window_lo] and [window_hi, b] when not empty
    bool singular_at_a = false;  ///< density ~ (x - a)^-1/2: integrate in s, x = a + L s^2
    bool tail_relative = false;  ///< x - a is computed as an offset from a: check cdf(sample(u))
                                 ///< = u to 1e-8 relative for u down to 1e-12
    std::vector<double> table;   ///< tabulated values (empty for analytic kinds)
};

// gtest prints a parameter with this (instead of its bytes) when a test fails.
void PrintTo(const Case& c, std::ostream* os) {
    *os << c.name;
}

Case analytic(std::string name, Made<Distribution1D> made, bool tail_relative,
              double window_lo = NAN, double window_hi = NAN) {
    Case c;
    c.name = std::move(name);
    double a = made.value.lower(), b = made.value.upper();
    c.window_lo = std::isnan(window_lo) ? a : window_lo;
    c.window_hi = std::isnan(window_hi) ? b : window_hi;
    c.made = std::move(made);
    c.cells = 50;
    c.tail_relative = tail_relative;
    return c;
}

Case tabulated(std::string name, double a, double b, std::vector<double> values,
               bool tail_relative) {
    Case c;
    c.name = std::move(name);
    c.made = make_tabulated(a, b, values);
    c.window_lo = a;
    c.window_hi = b;
    c.cells = 4 * int(values.size()); // four chi-square cells per table bin, edges aligned
    c.tail_relative = tail_relative;
    c.table = std::move(values);
    return c;
}

std::vector<double> smooth_table() {
    std::vector<double> v(64);
    for (int i = 0; i < 64; ++i)
        v[size_t(i)] = 0.2 + std::pow(std::sin(0.3 * i), 2) + (i % 7 == 0 ? 2.0 : 0.0);
    return v;
}

/// A Cauchy-shaped peak: 49 of the 64 bins hold less than 1/64 of the mass, so many guide
/// cells hold several bin edges and the block loops' one guided step leaves points to the
/// full walk.
std::vector<double> peaked_table() {
    std::vector<double> v(64);
    for (int i = 0; i < 64; ++i) {
        const double z = (i - 19) / 3.0;
        v[size_t(i)] = 1.0 / (1.0 + z * z);
    }
    return v;
}

const std::vector<Case>& cases() {
    static const std::vector<Case> all = [] {
        const double h = 0.5 * kPi;
        std::vector<Case> c;
        c.push_back(analytic("uniform_0_1", make_uniform(0.0, 1.0), true));
        c.push_back(analytic("uniform_m2_3", make_uniform(-2.0, 3.0), false));
        c.push_back(analytic("power_k1", make_power(0.0, 1.0, 1.0), true));
        c.push_back(analytic("power_k3_on_m1_2", make_power(-1.0, 2.0, 3.0), false));
        c.push_back(analytic("power_k0", make_power(2.0, 5.0, 0.0), false));
        Case singular = analytic("power_k_m0p5", make_power(0.0, 1.0, -0.5), true);
        singular.singular_at_a = true;
        c.push_back(singular);
        c.push_back(analytic("exponential_rate_2", make_exponential(0.0, 1.0, 2.0), true));
        c.push_back(analytic("exponential_rate_m3", make_exponential(0.0, 1.0, -3.0), true));
        c.push_back(analytic("exponential_rate_1em9", make_exponential(0.0, 1.0, 1e-9), true));
        c.push_back(analytic("exponential_rate_m1em9", make_exponential(0.0, 1.0, -1e-9), true));
        c.push_back(
            analytic("exponential_rate_500", make_exponential(0.0, 1.0, 500.0), true, 0.0, 0.02));
        c.push_back(
            analytic("exponential_rate_m500", make_exponential(0.0, 1.0, -500.0), true, 0.98, 1.0));
        c.push_back(analytic("exponential_rate_m2000_on_1_3", make_exponential(1.0, 3.0, -2000.0),
                             false, 2.995, 3.0));
        c.push_back(
            analytic("gaussian_centred", make_truncated_gaussian(0.0, 1.0, 0.5, 0.1), true));
        c.push_back(
            analytic("gaussian_off_centre", make_truncated_gaussian(0.0, 1.0, 0.2, 0.3), true));
        c.push_back(
            analytic("gaussian_asymmetric", make_truncated_gaussian(-0.5, 3.0, 0.0, 1.0), false));
        c.push_back(
            analytic("gaussian_far_tail_5_6", make_truncated_gaussian(5.0, 6.0, 0.0, 1.0), false));
        c.push_back(analytic("gaussian_far_tail_m6_m5",
                             make_truncated_gaussian(-6.0, -5.0, 0.0, 1.0), false));
        c.push_back(analytic("gaussian_deep_tail_20_21",
                             make_truncated_gaussian(20.0, 21.0, 0.0, 1.0), false, 20.0, 20.25));
        c.push_back(
            analytic("gaussian_wide_sigma", make_truncated_gaussian(0.0, 1.0, 0.3, 1e3), true));
        c.push_back(
            analytic("gaussian_sigma_1e6", make_truncated_gaussian(0.0, 1.0, 0.3, 1e6), true));
        c.push_back(analytic("cosine_full_half_period", make_cosine(-h, h, 1.0, 0.0), true));
        c.push_back(analytic("cosine_omega2_sub_interval", make_cosine(0.0, 1.0, 2.0, 0.3), true));
        c.push_back(analytic("cosine_omega2_to_zero", make_cosine(0.0, 0.5 * h, 2.0, 0.0), true));
        c.push_back(analytic("cosine_omega0p5_off_centre", make_cosine(1.0, 3.0, 0.5, 0.5), false));
        c.push_back(tabulated("tabulated_64", 0.0, 1.0, smooth_table(), true));
        c.push_back(tabulated("tabulated_peaked", 0.0, 1.0, peaked_table(), true));
        c.push_back(tabulated("tabulated_zero_bins", -1.0, 3.0, {0, 1, 0, 0, 2, 0, 3, 0}, false));
        c.push_back(tabulated("tabulated_single_bin", -1.0, 1.0, {0, 0, 0, 5, 0, 0, 0}, false));
        c.push_back(tabulated("tabulated_huge_values", 0.0, 4.0, {1e300, 3e300, 0.0, 2e300}, true));
        return c;
    }();
    return all;
}

/// Chi-square tests in this file: one per case, one for the 2D table.
double chi_level() {
    return test::sidak_level(0.01, int(cases().size()) + 1);
}

/// Integral of the density over [lo, hi], computed without the distribution's cdf: Gauss-Legendre
/// on about `panels` panels per unit of (b - a); across table bins for tabulated cases (exact
/// for piecewise constants); in s with x = a + (b - a) s^2 where the density is singular at a,
/// which turns (x - a)^-1/2 into a constant.
double integrate_pdf(const Case& c, double lo, double hi, int panels) {
    const Distribution1D& d = c.made.value;
    const double a = d.lower(), b = d.upper(), len = b - a;
    auto pdf = [&d](double x) { return d.pdf(x); };
    if (c.singular_at_a) {
        return test::gauss_legendre(
            [&](double s) { return d.pdf(a + len * s * s) * 2.0 * len * s; },
            std::sqrt((lo - a) / len), std::sqrt((hi - a) / len), panels);
    }
    if (!c.table.empty()) {
        const int n = int(c.table.size());
        double sum = 0.0, left = lo;
        for (int i = 1; i <= n; ++i) {
            double edge = i == n ? b : a + len * i / n;
            if (edge <= left) continue;
            double right = std::min(edge, hi);
            sum += test::gauss_legendre(pdf, left, right, 1);
            left = right;
            if (left >= hi) break;
        }
        return sum;
    }
    int p = std::max(16, int(std::ceil(panels * (hi - lo) / len)));
    return test::gauss_legendre(pdf, lo, hi, p);
}

std::vector<double> chi_edges(const Case& c) {
    const Distribution1D& d = c.made.value;
    std::vector<double> e;
    if (c.window_lo > d.lower()) e.push_back(d.lower());
    for (int i = 0; i <= c.cells; ++i)
        e.push_back(i == c.cells ? c.window_hi
                                 : c.window_lo + (c.window_hi - c.window_lo) * i / c.cells);
    if (c.window_hi < d.upper()) e.push_back(d.upper());
    return e;
}

class Dist1D : public ::testing::TestWithParam<Case> {};

} // namespace

TEST_P(Dist1D, IsValid) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    EXPECT_FALSE(c.made.value.describe().empty());
}

// (a) cdf(sample(u)) = u. Random u: to 1e-9 relative to min(u, 1 - u), plus 1e-13 absolute
// (a few hundred ulps of cdf values <= 1), plus what the spacing of doubles near the ends
// allows: x is only known to eps max(|a|, |b|), which moves the cdf by pdf(x) times that
// (9e-13 for rate -2000 near b = 3). Lower tail: where x - a is an offset computed from a and
// a = 0 (cases marked tail_relative), to 1e-8 relative down to u = 1e-12.
TEST_P(Dist1D, CdfInvertsSample) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    const Distribution1D& d = c.made.value;
    const double ends = std::max(std::fabs(d.lower()), std::fabs(d.upper()));
    auto tolerance = [&](double u, double x) {
        return 1e-9 * std::min(u, 1.0 - u) + 1e-13 + 4.0 * d.pdf(x) * kEps * ends;
    };
    Pcg32 rng(101u, 7u);
    for (int i = 0; i < 20000; ++i) {
        double u = rng.next_double();
        double x = d.sample(u);
        ASSERT_GE(x, d.lower());
        ASSERT_LE(x, d.upper());
        ASSERT_NEAR(d.cdf(x), u, tolerance(u, x)) << "u=" << u << " x=" << x;
    }
    for (double u : {0.5, 1e-3, 1 - 1e-3, 1e-6, 1 - 1e-6, 0x1p-54, 1 - 0x1p-53}) {
        double x = d.sample(u);
        EXPECT_NEAR(d.cdf(x), u, tolerance(u, x)) << "u=" << u << " x=" << x;
    }
    if (c.tail_relative) {
        for (double u : {1e-3, 1e-6, 1e-9, 1e-12}) {
            double x = d.sample(u);
            EXPECT_NEAR(d.cdf(x), u, 1e-8 * u) << "u=" << u << " x=" << x;
        }
    }
}

// The cdf is non-decreasing, 0 at a and below, 1 at b and above; the density vanishes
// outside [a, b] and is finite and non-negative inside.
TEST_P(Dist1D, CdfAndPdfShape) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    const Distribution1D& d = c.made.value;
    const double a = d.lower(), b = d.upper();
    EXPECT_EQ(d.cdf(a), 0.0);
    EXPECT_EQ(d.cdf(b), 1.0);
    EXPECT_EQ(d.cdf(a - 1.0), 0.0);
    EXPECT_EQ(d.cdf(b + 1.0), 1.0);
    EXPECT_EQ(d.pdf(a - 1.0), 0.0);
    EXPECT_EQ(d.pdf(b + 1.0), 0.0);
    EXPECT_EQ(d.pdf(NAN), 0.0);
    double prev = 0.0;
    for (int i = 1; i < 4000; ++i) {
        double x = a + (b - a) * i / 4000.0;
        double f = d.cdf(x), p = d.pdf(x);
        ASSERT_GE(f, prev) << "x=" << x;
        ASSERT_LE(f, 1.0);
        ASSERT_GE(p, 0.0);
        ASSERT_TRUE(std::isfinite(p)) << "x=" << x;
        prev = f;
    }
}

// (b) The density integrates to 1 (composite Gauss-Legendre, 2000 panels; exact per table bin;
// in s = sqrt((x - a)/(b - a)) for the singular power, where the integrand is smooth).
TEST_P(Dist1D, PdfIntegratesToOne) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    const Distribution1D& d = c.made.value;
    EXPECT_NEAR(integrate_pdf(c, d.lower(), d.upper(), 2000), 1.0, 1e-9);
}

// (c) pdf = cdf' at interior points: central differences with h = 1e-4 times the local
// length scale min(b - a, 1 / pdf) (truncation ~ 1e-8, rounding ~ 1e-12 relative); at the
// centre of the bin with h = bin width / 4 for tables, where the cdf is exactly linear.
TEST_P(Dist1D, PdfIsDerivativeOfCdf) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    const Distribution1D& d = c.made.value;
    const double a = d.lower(), b = d.upper();
    for (double u : {0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95}) {
        double x = d.sample(u), h;
        if (!c.table.empty()) {
            const double n = double(c.table.size()), w = (b - a) / n;
            double bin = std::min(n - 1.0, std::floor((x - a) / w));
            x = a + (bin + 0.5) * w;
            h = 0.25 * w;
        } else {
            h = 1e-4 * std::min(b - a, 1.0 / d.pdf(x));
            h = std::min({h, 0.5 * (x - a), 0.5 * (b - x)});
        }
        double slope = (d.cdf(x + h) - d.cdf(x - h)) / (2.0 * h);
        EXPECT_NEAR(slope, d.pdf(x), 1e-5 * d.pdf(x)) << "u=" << u << " x=" << x << " h=" << h;
    }
}

// (d, first half) The cdf at the chi-square cell edges equals the integral of the density
// from a, computed by quadrature that never calls cdf: so the chi-square below, whose
// expected counts come from cdf differences, is not circular.
TEST_P(Dist1D, CdfMatchesQuadratureOfPdf) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    const Distribution1D& d = c.made.value;
    std::vector<double> edges = chi_edges(c);
    double cumulative = 0.0;
    EXPECT_EQ(d.cdf(edges[0]), 0.0);
    for (size_t i = 1; i < edges.size(); ++i) {
        cumulative += integrate_pdf(c, edges[i - 1], edges[i], 4000);
        EXPECT_NEAR(d.cdf(edges[i]), cumulative, 1e-9) << "x=" << edges[i];
    }
}

// (d) Pearson chi-square of 100k samples in the cells against n (cdf(e_i+1) - cdf(e_i)).
TEST_P(Dist1D, ChiSquare) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    const Distribution1D& d = c.made.value;
    std::vector<double> edges = chi_edges(c);
    const size_t cells = edges.size() - 1;
    std::vector<double> observed(cells, 0.0), expected(cells);
    for (size_t i = 0; i < cells; ++i)
        expected[i] = kChiSamples * (d.cdf(edges[i + 1]) - d.cdf(edges[i]));
    Pcg32 rng(202u, 9u);
    for (int n = 0; n < kChiSamples; ++n) {
        double x = d.sample(rng.next_double());
        size_t k = size_t(std::upper_bound(edges.begin(), edges.end(), x) - edges.begin());
        observed[std::min(std::max<size_t>(k, 1), cells) - 1] += 1.0;
    }
    auto r = test::chi_square(observed, expected);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    // No pooling beyond the cells of negligible mass: 4 per nonzero table bin, or most of the 50.
    int nonzero_bins =
        int(std::count_if(c.table.begin(), c.table.end(), [](double v) { return v > 0; }));
    EXPECT_GE(r.cells, c.table.empty() ? 20 : 4 * nonzero_bins);
}

// (f) The block forms reproduce the scalar calls bit for bit.
TEST_P(Dist1D, BlocksEqualScalarCalls) {
    const Case& c = GetParam();
    ASSERT_TRUE(c.made.ok()) << c.made.error;
    const Distribution1D& d = c.made.value;
    Pcg32 rng(303u, 5u);
    std::vector<double> u(1000);
    for (double& v : u) v = rng.next_double();
    u[0] = 0.5;
    u[1] = 0x1p-54;
    u[2] = 1.0 - 0x1p-53;
    // Just below the cdf at evenly spaced points (a table's bin edges among them), where
    // rounding can carry a sample onto the next bin: the block path repairs it as sample() does.
    for (int k = 1; k < 64; ++k) {
        const double edge = d.lower() + (d.upper() - d.lower()) * k / 64.0;
        const double below = std::nextafter(d.cdf(edge), 0.0);
        if (below >= 0x1p-54) u[2 + size_t(k)] = below; // no smaller u is ever drawn
    }
    std::vector<double> x(u.size()), pdf(u.size()), product(u.size(), 3.0);
    d.sample_block(u.data(), x.data(), pdf.data(), u.size());
    d.multiply_pdf_block(x.data(), product.data(), u.size());
    for (size_t i = 0; i < u.size(); ++i) {
        double xs = d.sample(u[i]);
        ASSERT_EQ(x[i], xs) << "u=" << u[i];
        ASSERT_EQ(pdf[i], d.pdf(xs)) << "u=" << u[i];
        ASSERT_EQ(product[i], 3.0 * d.pdf(xs)) << "u=" << u[i];
        ASSERT_GT(pdf[i], 0.0) << "u=" << u[i];
    }
}

INSTANTIATE_TEST_SUITE_P(All, Dist1D, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& p) { return p.param.name; });

// --- Specific claims -------------------------------------------------------------------

// Tables: the density of bin i is values[i] / sum(values) * n / (b - a).
TEST(Tabulated, PdfMatchesValues) {
    for (const Case& c : cases()) {
        if (c.table.empty()) continue;
        SCOPED_TRACE(c.name);
        ASSERT_TRUE(c.made.ok()) << c.made.error;
        const Distribution1D& d = c.made.value;
        const double a = d.lower(), b = d.upper(), n = double(c.table.size());
        double sum = 0.0;
        for (double v : c.table) sum += v / 1e300; // scaled: one case holds values near 1e300
        for (size_t i = 0; i < c.table.size(); ++i) {
            double expect = c.table[i] / 1e300 / sum * n / (b - a);
            EXPECT_NEAR(d.pdf(a + (b - a) * (i + 0.5) / n), expect, 1e-13 * expect) << "bin " << i;
        }
    }
}

// Far in the upper tail the normalisation is Q(5) - Q(6) = 2.87e-7 - 9.9e-10; computed as
// Phi(6) - Phi(5) it would carry an error of ~1e-16 / 2.9e-7 = 4e-10 relative. Compare the
// density and the cdf with erfc-based values to 1e-12.
TEST(TruncatedGaussian, FarTailMatchesErfc) {
    auto m = make_truncated_gaussian(5.0, 6.0, 0.0, 1.0);
    ASSERT_TRUE(m.ok()) << m.error;
    const Distribution1D& d = m.value;
    auto q = [](double t) { return 0.5 * std::erfc(t / std::sqrt(2.0)); };
    const double z = q(5.0) - q(6.0);
    for (double x : {5.0, 5.001, 5.1, 5.5, 5.9, 6.0}) {
        double pdf = std::exp(-0.5 * x * x) / std::sqrt(2.0 * kPi) / z;
        EXPECT_NEAR(d.pdf(x), pdf, 1e-12 * pdf) << "x=" << x;
        double cdf = (q(5.0) - q(x)) / z;
        EXPECT_NEAR(d.cdf(x), cdf, 1e-12 * cdf + 1e-15) << "x=" << x;
    }
    // Mirror image in the lower tail.
    auto lower = make_truncated_gaussian(-6.0, -5.0, 0.0, 1.0);
    ASSERT_TRUE(lower.ok());
    for (double x : {-5.9, -5.5, -5.1}) {
        EXPECT_NEAR(lower.value.pdf(x), d.pdf(-x), 1e-13 * d.pdf(-x));
        EXPECT_NEAR(lower.value.cdf(x), 1.0 - d.cdf(-x), 1e-12);
    }
    // Tail quantiles: the representation of x near 5 (ulp 8.9e-16) times the density (~5.2)
    // bounds the achievable agreement.
    for (double u : {1e-2, 1e-3, 1e-4}) {
        double x = d.sample(u);
        EXPECT_NEAR(d.cdf(x), u, 1e-9 * u + 8.0 * d.pdf(x) * 8.9e-16) << "u=" << u;
    }
}

// Tiny rates are the uniform limit, large ones never overflow.
TEST(Exponential, LimitsAndLargeRates) {
    for (double rate : {1e-9, -1e-9}) {
        auto m = make_exponential(0.0, 1.0, rate);
        ASSERT_TRUE(m.ok());
        for (double x : {0.1, 0.5, 0.9}) {
            EXPECT_NEAR(m.value.pdf(x), 1.0, 1e-8);
            EXPECT_NEAR(m.value.cdf(x), x, 1e-8);
        }
    }
    for (double rate : {500.0, -500.0, 1e5, -1e5}) {
        auto m = make_exponential(0.0, 1.0, rate);
        ASSERT_TRUE(m.ok()) << m.error;
        const double s = std::fabs(rate);
        const double mode = rate > 0 ? 0.0 : 1.0;
        // Density at the mode: s / (1 - e^{-s}) = s to double precision here.
        EXPECT_NEAR(m.value.pdf(mode), s, 1e-12 * s);
        for (double u : {1e-12, 0.5, 1 - 1e-12}) {
            double x = m.value.sample(u);
            EXPECT_TRUE(std::isfinite(x));
            EXPECT_TRUE(std::isfinite(m.value.pdf(x)));
            EXPECT_GT(m.value.pdf(x), 0.0);
        }
        // The median sits log(2) / s from the mode.
        // (to 1e-12 relative, plus the spacing of doubles near the mode 1)
        EXPECT_NEAR(std::fabs(m.value.sample(0.5) - mode), std::log(2.0) / s, 1e-12 / s + 4e-16);
    }
}

// The power density's singularity at a for k in (-1, 0): samples stay strictly above a and
// the density there is finite.
TEST(Power, SingularDensity) {
    auto m = make_power(0.0, 1.0, -0.5);
    ASSERT_TRUE(m.ok());
    for (double u : {0x1p-54, 1e-12, 1e-3}) {
        double x = m.value.sample(u);
        EXPECT_NEAR(x, u * u, 1e-15 * u * u); // x = u^(1/(k+1)) = u^2
        EXPECT_TRUE(std::isfinite(m.value.pdf(x)));
        EXPECT_NEAR(m.value.pdf(x), 0.5 / u, 1e-13 / u);
    }
}

// Where x = a + (b - a) u^(1/(k+1)) rounds to a (|a| large against the offset) or t underflows
// (k near -1), samples must still have a positive, finite density, or f / pdf breaks.
TEST(Power, SamplesNearAHavePositiveFiniteDensity) {
    struct Setting {
        double a, b, k;
    };
    for (Setting s : {Setting{1.0, 2.0, -0.5}, Setting{0.0, 1.0, -0.99},
                      Setting{1e9, 1e9 + 1.0, 1.0}, Setting{-3.0, -2.0, 2.0}}) {
        auto m = make_power(s.a, s.b, s.k);
        ASSERT_TRUE(m.ok()) << m.error;
        for (double u : {0x1p-54, 1e-20, 1e-12, 1e-6, 1e-4, 0.5}) {
            double x = m.value.sample(u);
            double p = m.value.pdf(x);
            EXPECT_GT(x, s.a) << m.value.describe() << " u=" << u;
            EXPECT_LE(x, s.b);
            EXPECT_GT(p, 0.0) << m.value.describe() << " u=" << u << " x=" << x;
            EXPECT_TRUE(std::isfinite(p)) << m.value.describe() << " u=" << u << " x=" << x;
        }
    }
}

TEST(Distribution1D, Describe) {
    EXPECT_EQ(make_uniform(0, 1).value.describe(), "uniform on [0, 1]");
    EXPECT_EQ(make_power(0, 1, 1).value.describe(), "power(k=1) on [0, 1]");
    EXPECT_EQ(make_exponential(0, 1, 2).value.describe(), "exponential(rate=2) on [0, 1]");
    EXPECT_EQ(make_truncated_gaussian(0, 1, 0.5, 0.1).value.describe(),
              "truncated_gaussian(mu=0.5, sigma=0.1) on [0, 1]");
    EXPECT_EQ(make_cosine(-1, 1, 1, 0).value.describe(), "cosine(omega=1, x0=0) on [-1, 1]");
    EXPECT_EQ(make_tabulated(0, 1, std::vector<double>(64, 1.0)).value.describe(),
              "tabulated(64 bins) on [0, 1]");
    EXPECT_EQ(make_exponential(-2.5, 1e-3, -1e-9).value.describe(),
              "exponential(rate=-1e-09) on [-2.5, 0.001]");
}

// The words beside the notation (results' "pdf_text"): every kind, no parameter names, no "="
// and no "_".
TEST(Distribution1D, DescribeText) {
    const std::vector<std::pair<Distribution1D, std::string>> cases = {
        {make_uniform(0, 1).value, "uniform on [0, 1]"},
        {make_power(0, 1, 1).value, "power-law density proportional to x on [0, 1]"},
        {make_power(0, 1, -0.45).value, "power-law density proportional to x^(-0.45) on [0, 1]"},
        {make_power(1, 2, 2).value, "power-law density proportional to (x - 1)^2 on [1, 2]"},
        {make_power(0, 1, 0).value, "uniform on [0, 1]"},
        {make_exponential(0, 1, -0.8).value,
         "exponential density proportional to e^(0.8 x) on [0, 1]"},
        {make_exponential(0, 1, 1).value, "exponential density proportional to e^(-x) on [0, 1]"},
        {make_exponential(0, 1, -1).value, "exponential density proportional to e^x on [0, 1]"},
        {make_truncated_gaussian(0, 1, 0.5, 1e-8).value,
         "normal density of mean 0.5 and standard deviation 1e-08, cut to [0, 1]"},
        {make_cosine(-1, 1, 1, 0).value, "cosine density proportional to cos(x) on [-1, 1]"},
        {make_cosine(0, 1, 3, 0.5).value,
         "cosine density proportional to cos(3 (x - 0.5)) on [0, 1]"},
        {make_cosine(-1, 1, 1, -0.25).value,
         "cosine density proportional to cos(x + 0.25) on [-1, 1]"},
        {make_tabulated(0, 1, std::vector<double>(64, 1.0)).value,
         "piecewise-constant density on 64 equal bins of [0, 1]"},
        {make_tabulated(0, 1, {1.0}).value, "piecewise-constant density on 1 equal bin of [0, 1]"},
    };
    std::set<Dist1DKind> kinds;
    for (const auto& [d, text] : cases) {
        kinds.insert(d.kind());
        EXPECT_EQ(d.describe_text(), text);
        EXPECT_EQ(d.describe_text().find_first_of("=_"), std::string::npos) << d.describe();
    }
    EXPECT_EQ(kinds.size(), 6u); // every Dist1DKind
    EXPECT_EQ(make_power(0, 1, 2).value.describe_text("x2"),
              "power-law density proportional to x2^2 on [0, 1]");
    const Made<TabulatedDistribution2D> table =
        make_tabulated_2d(0, 1, 0, 2, 4, 3, std::vector<double>(12, 1.0));
    ASSERT_TRUE(table.ok()) << table.error;
    EXPECT_EQ(table.value.describe_text(),
              "piecewise-constant density on a 4 x 3 grid of cells over [0, 1] x [0, 2]");
}

TEST(Distribution1D, DefaultIsUniformOnUnitInterval) {
    Distribution1D d;
    EXPECT_EQ(d.kind(), Dist1DKind::Uniform);
    EXPECT_EQ(d.pdf(0.3), 1.0);
    EXPECT_EQ(d.cdf(0.25), 0.25);
    EXPECT_EQ(d.sample(0.75), 0.75);
}

// (e) Zero bins are never sampled: not by random u, not by u equal to a plateau value of the
// cdf (the bin edges around zero bins), not at the extremes of (0, 1).
TEST(Tabulated, ZeroBinsNeverSampled) {
    const std::vector<double> values = {0, 1, 0, 0, 2, 0, 3, 0, 0, 1e-3, 0};
    const double a = -1.0, b = 3.0;
    auto m = make_tabulated(a, b, values);
    ASSERT_TRUE(m.ok()) << m.error;
    const Distribution1D& d = m.value;
    const int n = int(values.size());
    // Independent check: x must lie in (the closure of) a bin with a nonzero value.
    auto in_nonzero_bin = [&](double x) {
        double r = (x - a) / (b - a) * n;
        int k = std::min(n - 1, int(std::floor(r)));
        if (values[size_t(k)] > 0.0) return true;
        // On an edge (to rounding), the bin on the other side counts too.
        if (std::fabs(r - std::round(r)) < 1e-9) {
            int e = int(std::round(r));
            if (e - 1 >= 0 && values[size_t(e - 1)] > 0.0) return true;
            if (e < n && values[size_t(e)] > 0.0) return true;
        }
        return false;
    };
    std::vector<double> us = {0x1p-54, 1e-300, 1.0 - 0x1p-53, 0.5};
    for (int i = 0; i <= n; ++i) {
        double plateau = d.cdf(a + (b - a) * i / n);
        us.push_back(plateau);
        us.push_back(std::nextafter(plateau, 0.0));
        us.push_back(std::nextafter(plateau, 1.0));
    }
    Pcg32 rng(404u, 3u);
    for (int i = 0; i < 200000; ++i) us.push_back(rng.next_double());
    for (double u : us) {
        if (!(u > 0.0 && u < 1.0)) continue;
        double x = d.sample(u);
        ASSERT_GT(d.pdf(x), 0.0) << "u=" << u << " x=" << x;
        ASSERT_TRUE(in_nonzero_bin(x)) << "u=" << u << " x=" << x;
    }
    // The header's domain is (0, 1); the ends themselves still give points of nonzero density.
    EXPECT_GT(d.pdf(d.sample(0.0)), 0.0);
    EXPECT_GT(d.pdf(d.sample(1.0)), 0.0);
}

// The guide table's start cell comes from u n rounded; at and next to every u = g / n, and on a
// table whose mass sits in a few of many bins (guide cells spanning many bins), sampling still
// inverts the cdf.
TEST(Tabulated, GuideTableInvertsAtCellEdges) {
    std::vector<double> values(1000, 1e-9);
    values[3] = 1.0;
    values[500] = 5.0;
    values[501] = 0.0;
    values[998] = 2.0;
    auto m = make_tabulated(0.0, 1.0, values);
    ASSERT_TRUE(m.ok()) << m.error;
    const Distribution1D& d = m.value;
    const double n = double(values.size());
    for (int g = 1; g < int(values.size()); ++g) {
        const double edge = g / n;
        for (double u : {std::nextafter(edge, 0.0), edge, std::nextafter(edge, 1.0)}) {
            const double x = d.sample(u);
            ASSERT_GT(d.pdf(x), 0.0) << "u=" << u;
            ASSERT_NEAR(d.cdf(x), u, 1e-12) << "u=" << u << " x=" << x;
        }
    }
}

TEST(Tabulated, SingleNonzeroBin) {
    auto m = make_tabulated(-1.0, 1.0, {0, 0, 0, 5, 0, 0, 0});
    ASSERT_TRUE(m.ok());
    const double lo = -1.0 + 2.0 * 3 / 7, hi = -1.0 + 2.0 * 4 / 7;
    Pcg32 rng(505u, 1u);
    for (int i = 0; i < 10000; ++i) {
        double u = rng.next_double();
        double x = m.value.sample(u);
        ASSERT_GE(x, lo - 1e-15);
        ASSERT_LE(x, hi + 1e-15);
        ASSERT_NEAR(x, lo + u * (hi - lo), 1e-14); // linear inside the bin
    }
    EXPECT_NEAR(m.value.pdf(0.0), 3.5, 1e-14);
    EXPECT_EQ(m.value.pdf(-0.9), 0.0);
}

// --- Factory errors --------------------------------------------------------------------

TEST(Distribution1D, FactoriesRejectBadParameters) {
    struct Bad {
        Made<Distribution1D> made;
        const char* expect; // a substring naming the parameter (and where useful its value)
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const Bad bad[] = {
        {make_uniform(1, 0), "a=1, b=0"},
        {make_uniform(nan, 1), "a=nan"},
        {make_uniform(0, inf), "b=inf"},
        {make_uniform(0, 0), "a < b"},
        {make_power(0, 1, -1.5), "k must be finite and > -1, got -1.5"},
        {make_power(0, 1, -1), "k must"},
        {make_power(0, 1, nan), "k must"},
        {make_power(0, 1, inf), "k must"},
        {make_power(2, 1, 1), "a=2, b=1"},
        {make_exponential(0, 1, 0), "rate must be finite and != 0, got 0"},
        {make_exponential(0, 1, nan), "rate"},
        {make_exponential(0, 1, -inf), "rate"},
        {make_exponential(0, 1e-10, 1e-320), "rate"}, // |rate| (b - a) underflows to 0
        {make_exponential(nan, 1, 1), "a=nan"},
        {make_truncated_gaussian(0, 1, 0.5, 0), "sigma must be finite and > 0, got 0"},
        {make_truncated_gaussian(0, 1, 0.5, -1), "sigma"},
        {make_truncated_gaussian(0, 1, 0.5, nan), "sigma"},
        {make_truncated_gaussian(0, 1, nan, 1), "mu must be finite"},
        {make_truncated_gaussian(0, 1, inf, 1), "mu"},
        {make_truncated_gaussian(40, 41, 0, 1), "30 sigma of mu"},
        {make_truncated_gaussian(-41, -40, 0, 1), "30 sigma of mu"},
        {make_truncated_gaussian(1, -1, 0, 1), "a=1, b=-1"},
        {make_cosine(0, 1, 0, 0), "omega must be finite and > 0, got 0"},
        {make_cosine(0, 1, -1, 0), "omega"},
        {make_cosine(0, 1, nan, 0), "omega"},
        {make_cosine(0, 1, 1, nan), "x0 must be finite"},
        {make_cosine(-2, 1, 1, 0), "omega (a - x0) = -2"},
        {make_cosine(0, 2, 1, 0), "omega (b - x0) = 2"},
        {make_cosine(0, inf, 1, 0), "b=inf"},
        {make_tabulated(0, 1, {}), "values must be non-empty"},
        {make_tabulated(0, 1, {1, -1}), "values[1] must be >= 0, got -1"},
        {make_tabulated(0, 1, {1, nan}), "values[1] must be finite"},
        {make_tabulated(0, 1, {inf, 1}), "values[0]"},
        {make_tabulated(0, 1, {0, 0}), "values must not all be zero"},
        {make_tabulated(0, 1, std::vector<double>((1u << 22) + 1, 1.0)), "4194304"},
        {make_tabulated(1e10, 1e10 + 1e-5, std::vector<double>(1000, 1.0)), "too narrow"},
        {make_tabulated(1, 1, {1}), "a=1, b=1"},
    };
    for (const Bad& b : bad) {
        EXPECT_FALSE(b.made.ok()) << "expected an error containing: " << b.expect;
        EXPECT_NE(b.made.error.find(b.expect), std::string::npos)
            << "message: " << b.made.error << "\nexpected to contain: " << b.expect;
    }
    // Boundary values that are valid.
    EXPECT_TRUE(make_power(0, 1, -0.999).ok());
    EXPECT_TRUE(make_cosine(-kPi / 6, kPi / 6, 3.0, 0.0).ok()); // pi/2 up to rounding
    EXPECT_TRUE(make_tabulated(0, 1, std::vector<double>(1u << 22, 1.0)).ok());
    EXPECT_TRUE(make_tabulated(0, 1, {0, 1e-310}).ok());
    EXPECT_TRUE(make_truncated_gaussian(29, 30, 0, 1).ok());
}

// --- Tabulated 2D ----------------------------------------------------------------------

namespace {

constexpr int kNx = 6, kNy = 5;
constexpr double kX0 = -1.0, kX1 = 2.0, kY0 = 0.0, kY1 = 1.0;
// Row 2 is all zero; rows 0, 1 and 4 have zero cells.
const std::vector<double> kTable2D = {
    1,   2, 0, 3, 1, 1, //
    0,   0, 5, 0, 0, 1, //
    0,   0, 0, 0, 0, 0, //
    2,   2, 2, 2, 2, 2, //
    0.5, 0, 0, 0, 0, 4,
};

double table_sum() {
    double s = 0.0;
    for (double v : kTable2D) s += v;
    return s;
}

// The cell of (x, y), computed here by the obvious formula.
int cell_of(double x, double y) {
    int ix = std::min(kNx - 1, int((x - kX0) / (kX1 - kX0) * kNx));
    int iy = std::min(kNy - 1, int((y - kY0) / (kY1 - kY0) * kNy));
    return iy * kNx + ix;
}

TabulatedDistribution2D table_2d() {
    auto m = make_tabulated_2d(kX0, kX1, kY0, kY1, kNx, kNy, kTable2D);
    EXPECT_TRUE(m.ok()) << m.error;
    return m.value;
}

} // namespace

TEST(Tabulated2D, PdfIntegratesToOneAndMatchesValues) {
    TabulatedDistribution2D t = table_2d();
    EXPECT_EQ(t.nx(), kNx);
    EXPECT_EQ(t.ny(), kNy);
    const double dx = (kX1 - kX0) / kNx, dy = (kY1 - kY0) / kNy;
    double integral = 0.0;
    for (int iy = 0; iy < kNy; ++iy)
        for (int ix = 0; ix < kNx; ++ix) {
            double p = t.pdf(kX0 + (ix + 0.5) * dx, kY0 + (iy + 0.5) * dy);
            double expect = kTable2D[size_t(iy * kNx + ix)] / table_sum() / (dx * dy);
            EXPECT_NEAR(p, expect, 1e-14 * expect) << "cell " << ix << "," << iy;
            integral += p * dx * dy;
        }
    EXPECT_NEAR(integral, 1.0, 1e-13);
    EXPECT_EQ(t.pdf(kX0 - 0.1, 0.5), 0.0);
    EXPECT_EQ(t.pdf(0.0, kY1 + 0.1), 0.0);
}

TEST(Tabulated2D, ChiSquareAndZeroCellsNeverSampled) {
    TabulatedDistribution2D t = table_2d();
    std::vector<double> observed(kTable2D.size(), 0.0), expected(kTable2D.size());
    for (size_t i = 0; i < kTable2D.size(); ++i)
        expected[i] = kChiSamples * kTable2D[i] / table_sum();
    Pcg32 rng(606u, 2u);
    const double cell_area = (kX1 - kX0) / kNx * ((kY1 - kY0) / kNy);
    for (int n = 0; n < kChiSamples; ++n) {
        double u1 = rng.next_double(), u2 = rng.next_double();
        double x, y, pdf;
        t.sample(u1, u2, &x, &y, &pdf);
        ASSERT_GE(x, kX0);
        ASSERT_LE(x, kX1);
        ASSERT_GE(y, kY0);
        ASSERT_LE(y, kY1);
        ASSERT_GT(pdf, 0.0) << "u=" << u1 << "," << u2;
        ASSERT_EQ(pdf, t.pdf(x, y));
        int cell = cell_of(x, y);
        ASSERT_GT(kTable2D[size_t(cell)], 0.0) << "x=" << x << " y=" << y;
        ASSERT_NEAR(pdf, kTable2D[size_t(cell)] / table_sum() / cell_area, 1e-13 * pdf);
        observed[size_t(cell)] += 1.0;
    }
    auto r = test::chi_square(observed, expected);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    EXPECT_GE(r.cells, 15); // the 15 nonzero cells; zero cells pool into their neighbours
}

// Convention (distributions.cpp): u2 selects the row through the marginal in y, u1 the point
// within the row through the conditional in x.
TEST(Tabulated2D, InvertAndSampleAreInverses) {
    TabulatedDistribution2D t = table_2d();
    Pcg32 rng(707u, 4u);
    for (int i = 0; i < 5000; ++i) {
        double u1 = rng.next_double(), u2 = rng.next_double();
        double x, y, pdf, v1, v2;
        t.sample(u1, u2, &x, &y, &pdf);
        t.invert(x, y, &v1, &v2);
        ASSERT_NEAR(v1, u1, 1e-12) << "u=" << u1 << "," << u2;
        ASSERT_NEAR(v2, u2, 1e-12) << "u=" << u1 << "," << u2;
        // u2 alone fixes y.
        double x2, y2, pdf2;
        t.sample(rng.next_double(), u2, &x2, &y2, &pdf2);
        ASSERT_EQ(y2, y);
    }
    // Points in cells of nonzero value: sample(invert(p)) = p.
    const double dx = (kX1 - kX0) / kNx, dy = (kY1 - kY0) / kNy;
    for (int i = 0; i < 5000; ++i) {
        int cell = int(rng.next_below(uint32_t(kTable2D.size())));
        if (kTable2D[size_t(cell)] == 0.0) continue;
        double x = kX0 + (cell % kNx + 0.01 + 0.98 * rng.next_double()) * dx;
        double y = kY0 + (cell / kNx + 0.01 + 0.98 * rng.next_double()) * dy;
        double u1, u2, xs, ys, pdf;
        t.invert(x, y, &u1, &u2);
        ASSERT_GE(u1, 0.0);
        ASSERT_LE(u1, 1.0);
        ASSERT_GE(u2, 0.0);
        ASSERT_LE(u2, 1.0);
        t.sample(u1, u2, &xs, &ys, &pdf);
        ASSERT_NEAR(xs, x, 1e-12) << "cell " << cell;
        ASSERT_NEAR(ys, y, 1e-12) << "cell " << cell;
    }
}

namespace {

/// sample_block equals sample() point by point (bit for bit) on n random pairs (u1, u2).
void expect_block_equals_scalar(const TabulatedDistribution2D& t, uint64_t seed, size_t n) {
    Pcg32 rng(seed, 6u);
    std::vector<double> u1(n), u2(n), x(n), y(n), pdf(n);
    for (size_t i = 0; i < n; ++i) {
        u1[i] = rng.next_double();
        u2[i] = rng.next_double();
    }
    t.sample_block(u1.data(), u2.data(), x.data(), y.data(), pdf.data(), n);
    for (size_t i = 0; i < n; ++i) {
        double xs, ys, ps;
        t.sample(u1[i], u2[i], &xs, &ys, &ps);
        ASSERT_EQ(x[i], xs) << "u1=" << u1[i] << " u2=" << u2[i];
        ASSERT_EQ(y[i], ys) << "u1=" << u1[i] << " u2=" << u2[i];
        ASSERT_EQ(pdf[i], ps) << "u1=" << u1[i] << " u2=" << u2[i];
        ASSERT_GT(ps, 0.0);
    }
}

} // namespace

TEST(Tabulated2D, BlockEqualsScalar) {
    expect_block_equals_scalar(table_2d(), 808u, 2000);
}

// The same on a peaked table, where the block loops' guided step often does not settle the bin.
TEST(Tabulated2D, BlockEqualsScalarOnAPeakedTable) {
    std::vector<double> values;
    for (int iy = 0; iy < 24; ++iy)
        for (int ix = 0; ix < 32; ++ix) {
            const double zx = ((ix + 0.5) / 32 - 0.7) / 0.04, zy = ((iy + 0.5) / 24 - 0.2) / 0.05;
            values.push_back(std::exp(-0.5 * (zx * zx + zy * zy)));
        }
    auto made = make_tabulated_2d(0, 1, 0, 1, 32, 24, values);
    ASSERT_TRUE(made.ok()) << made.error;
    expect_block_equals_scalar(made.value, 811u, 5000);
}

TEST(Tabulated2D, SingleRowAndColumn) {
    auto row = make_tabulated_2d(0, 1, 0, 1, 3, 1, {1, 0, 3});
    ASSERT_TRUE(row.ok()) << row.error;
    auto col = make_tabulated_2d(0, 1, 0, 1, 1, 3, {1, 0, 3});
    ASSERT_TRUE(col.ok()) << col.error;
    Pcg32 rng(909u, 8u);
    for (int i = 0; i < 2000; ++i) {
        double u1 = rng.next_double(), u2 = rng.next_double(), x, y, p;
        row.value.sample(u1, u2, &x, &y, &p);
        ASSERT_GT(p, 0.0);
        ASSERT_FALSE(x > 1.0 / 3 && x < 2.0 / 3);
        col.value.sample(u1, u2, &x, &y, &p);
        ASSERT_GT(p, 0.0);
        ASSERT_FALSE(y > 1.0 / 3 && y < 2.0 / 3);
    }
}

TEST(Tabulated2D, FactoryRejectsBadInput) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    struct Bad {
        Made<TabulatedDistribution2D> made;
        const char* expect;
    };
    const Bad bad[] = {
        {make_tabulated_2d(0, 1, 0, 1, 0, 2, {}), "nx and ny must be > 0, got nx=0"},
        {make_tabulated_2d(0, 1, 0, 1, 2, -1, {1, 1}), "ny=-1"},
        {make_tabulated_2d(0, 1, 0, 1, 2, 2, {1, 1, 1}),
         "values.size() must equal nx * ny = 4, got 3"},
        {make_tabulated_2d(0, 1, 0, 1, 2, 1, {1, -2}), "values[1] must be finite and >= 0, got -2"},
        {make_tabulated_2d(0, 1, 0, 1, 2, 1, {nan, 1}), "values[0]"},
        {make_tabulated_2d(0, 1, 0, 1, 2, 1, {0, 0}), "values must not all be zero"},
        {make_tabulated_2d(1, 0, 0, 1, 1, 1, {1}), "x0=1, x1=0"},
        {make_tabulated_2d(0, 1, 0, nan, 1, 1, {1}), "y1=nan"},
        {make_tabulated_2d(0, 1, 0, 1, 1 << 12, 1 << 11, {}), "4194304"},
        {make_tabulated_2d(0, 1, 0, 1, 2, 1, {1e308, 1e308}), "integral"},
    };
    for (const Bad& b : bad) {
        EXPECT_FALSE(b.made.ok()) << "expected an error containing: " << b.expect;
        EXPECT_NE(b.made.error.find(b.expect), std::string::npos)
            << "message: " << b.made.error << "\nexpected to contain: " << b.expect;
    }
}

// floor_to_index (core/float_index.h), the conversion the tabulated and VEGAS kernels use:
// equal to std::floor on [0, 2^31) at integers, one ulp either side of them, halves (where
// round-to-nearest-even would go the wrong way) and random values of every magnitude.
TEST(FloorToIndex, EqualsFloorOnItsRange) {
    auto check = [](double x) {
        ASSERT_EQ(floor_to_index(x), static_cast<uint32_t>(std::floor(x))) << "x = " << x;
    };
    for (double k : {0.0, 1.0, 2.0, 3.0, 15.0, 16.0, 1023.0, 4194303.0, 2147483646.0}) {
        check(k);
        check(std::nextafter(k, 1e300));
        if (k > 0.0) check(std::nextafter(k, 0.0));
        check(k + 0.5);
    }
    check(std::nextafter(2147483648.0, 0.0));
    check(std::numeric_limits<double>::denorm_min());
    Pcg32 rng(7, 11);
    for (int i = 0; i < 1000000; ++i) {
        const double u = rng.next_double();
        check(u);
        check(u * 16.0);
        check(u * 2147483648.0);
        check(std::ldexp(u, -(i % 60)));
    }
}
