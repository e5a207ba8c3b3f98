// Point-set analysis: the L2 discrepancies against exact rational values, a direct O(N^2 d)
// evaluation and the expectation for independent points; minimum distances on grids and hand
// sets, plain and toroidal; the periodogram on a grid (power N at the lattice's dual
// frequencies, 0 elsewhere), against a direct sum, its symmetry, and its mean 1 for
// independent points; results that do not depend on the thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/point_analysis.h"
#include "core/rng.h"

using namespace mcp;

namespace {

/// A set from points given point-major.
PointSet make_set(const std::vector<std::vector<double>>& points) {
    PointSet s;
    s.n = points.size();
    s.dim = static_cast<int>(points.at(0).size());
    s.coords.resize(s.n * uint64_t(s.dim));
    for (uint64_t i = 0; i < s.n; ++i)
        for (int k = 0; k < s.dim; ++k) s.coords[uint64_t(k) * s.n + i] = points[i][size_t(k)];
    return s;
}

PointSet random_set(uint64_t n, int dim, uint64_t seed) {
    Pcg32 rng(seed, 17);
    PointSet s;
    s.n = n;
    s.dim = dim;
    s.coords.resize(n * uint64_t(dim));
    for (uint64_t i = 0; i < n; ++i)
        for (int k = 0; k < dim; ++k) s.coords[uint64_t(k) * n + i] = rng.next_double();
    return s;
}

/// The k^dim points ((i_1 + 1/2)/k, ..., (i_dim + 1/2)/k).
PointSet grid_set(int k, int dim) {
    std::vector<std::vector<double>> pts;
    uint64_t total = 1;
    for (int a = 0; a < dim; ++a) total *= uint64_t(k);
    for (uint64_t m = 0; m < total; ++m) {
        std::vector<double> p;
        uint64_t r = m;
        for (int a = 0; a < dim; ++a, r /= uint64_t(k)) p.push_back((double(r % k) + 0.5) / k);
        pts.push_back(p);
    }
    return make_set(pts);
}

double van_der_corput(uint32_t i) {
    double r = 0.0, f = 0.5;
    for (; i; i >>= 1, f *= 0.5)
        if (i & 1u) r += f;
    return r;
}

// The sets of tests/data/discrepancy_reference.py, built the same way.
PointSet vdc_set(int n) {
    std::vector<std::vector<double>> pts;
    for (int i = 0; i < n; ++i) pts.push_back({van_der_corput(uint32_t(i))});
    return make_set(pts);
}
PointSet hammersley_set(int n) {
    std::vector<std::vector<double>> pts;
    for (int i = 0; i < n; ++i) pts.push_back({double(i) / n, van_der_corput(uint32_t(i))});
    return make_set(pts);
}

/// Direct double sums of the closed forms, in long double, over all ordered pairs: no
/// symmetry, tiles or transformed coordinates.
struct Direct {
    long double star, centered, wrap;
};
Direct direct_discrepancies(const PointSet& s) {
    const int d = s.dim;
    const long double n = static_cast<long double>(s.n);
    long double s_mid = 0, c_mid = 0, s_pair = 0, c_pair = 0, w_pair = 0;
    for (uint64_t i = 0; i < s.n; ++i) {
        long double a = 1, b = 1;
        for (int k = 0; k < d; ++k) {
            const long double x = s.at(i, k), u = std::fabs(x - 0.5L);
            a *= 1 - x * x;
            b *= 1 + u / 2 - u * u / 2;
        }
        s_mid += a;
        c_mid += b;
        for (uint64_t j = 0; j < s.n; ++j) {
            long double p = 1, q = 1, r = 1;
            for (int k = 0; k < d; ++k) {
                const long double x = s.at(i, k), y = s.at(j, k), t = std::fabs(x - y);
                p *= 1 - std::max(x, y);
                q *= 1 + std::fabs(x - 0.5L) / 2 + std::fabs(y - 0.5L) / 2 - t / 2;
                r *= 1.5L - t * (1 - t);
            }
            s_pair += p;
            c_pair += q;
            w_pair += r;
        }
    }
    Direct out;
    out.star = std::pow(3.0L, -d) - std::pow(2.0L, 1 - d) / n * s_mid + s_pair / (n * n);
    out.centered = std::pow(13.0L / 12, d) - 2 / n * c_mid + c_pair / (n * n);
    out.wrap = -std::pow(4.0L / 3, d) + w_pair / (n * n);
    return out;
}

double sq(double x) {
    return x * x;
}

} // namespace

// D^2 from tests/data/discrepancy_reference.py (exact rational arithmetic on the same double
// coordinates), printed by `python3 tests/data/discrepancy_reference.py` from the repository
// root: star, centred, wrap-around. The three terms of each closed form are of order 1 here and
// D^2 of order 1e-3, so a few units of round-off in the terms are ~1e-14 of D^2.
TEST(PointAnalysis, DiscrepanciesMatchExactRationalValues) {
    struct Case {
        const char* name;
        PointSet set;
        double star2, centered2, wrap2;
    };
    const Case cases[] = {
        {"vdc8", vdc_set(8), 5.20833333333333333333333333333e-3, 5.20833333333333333333333333333e-3,
         2.60416666666666666666666666667e-3},
        {"vdc16", vdc_set(16), 1.30208333333333333333333333333e-3,
         1.30208333333333333333333333333e-3, 6.51041666666666666666666666667e-4},
        {"hammersley16", hammersley_set(16), 4.80122036404079861111111111111e-3,
         4.31293911404079861111111111111e-3, 2.71309746636284722222222222222e-3},
        {"hammersley32", hammersley_set(32), 1.48326820797390407986111111111e-3,
         1.23912758297390407986111111111e-3, 7.39230049981011284722222222222e-4},
        {"hand3d",
         make_set({{0.1, 0.7, 0.35}, {0.9, 0.2, 0.55}, {0.5, 0.5, 0.95}, {0.25, 0.999, 0.0}}),
         1.49041268807870352644358739623e-2, 9.38977352792245315186301250508e-2,
         1.22296731563223372697542214255e-1},
        {"single2d", make_set({{0.3, 0.6}}), 9.99111111111111168398619181769e-2,
         2.36411111111111108901767292107e-1, 4.72222222222222222222222222222e-1},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const double star = l2_star_discrepancy(c.set), cen = centered_l2_discrepancy(c.set),
                     wrap = wraparound_l2_discrepancy(c.set);
        EXPECT_NEAR(sq(star), c.star2, 1e-14 * c.star2);
        EXPECT_NEAR(sq(cen), c.centered2, 1e-14 * c.centered2);
        EXPECT_NEAR(sq(wrap), c.wrap2, 1e-14 * c.wrap2);
    }
}

// Several tiles and chunks of rows (700 points: 11 chunks of 64 rows, 3 tiles of 256
// columns), against the direct sums in long double.
TEST(PointAnalysis, DiscrepanciesMatchDirectSums) {
    for (int d : {1, 2, 3, 7}) {
        SCOPED_TRACE(d);
        const PointSet s = random_set(700, d, 40 + uint64_t(d));
        const Direct ref = direct_discrepancies(s);
        // The terms are of order 1 (star: 3^-d); D^2 ~ 1e-3 .. 1e-5: relative 1e-10 of D^2 is
        // far above the round-off of either computation and far below any indexing mistake.
        EXPECT_NEAR(sq(l2_star_discrepancy(s)), double(ref.star), 1e-10 * double(ref.star));
        EXPECT_NEAR(sq(centered_l2_discrepancy(s)), double(ref.centered),
                    1e-10 * double(ref.centered));
        EXPECT_NEAR(sq(wraparound_l2_discrepancy(s)), double(ref.wrap), 1e-10 * double(ref.wrap));
    }
}

TEST(PointAnalysis, ResultsDoNotDependOnThreadCount) {
    const PointSet s = random_set(1500, 3, 9);
    const double star = l2_star_discrepancy(s, 1), cen = centered_l2_discrepancy(s, 1),
                 wrap = wraparound_l2_discrepancy(s, 1), md = min_distance(s, false, 1),
                 mt = min_distance(s, true, 1);
    for (int threads : {2, 3, 7, 0}) {
        SCOPED_TRACE(threads);
        EXPECT_EQ(l2_star_discrepancy(s, threads), star);
        EXPECT_EQ(centered_l2_discrepancy(s, threads), cen);
        EXPECT_EQ(wraparound_l2_discrepancy(s, threads), wrap);
        EXPECT_EQ(min_distance(s, false, threads), md);
        EXPECT_EQ(min_distance(s, true, threads), mt);
    }
}

// E[D^2] = (E K(x, x) - int int K) / N for independent uniform points: the mean of D^2 over
// 200 independent sets of 64 points within 4 standard errors of the closed form.
TEST(PointAnalysis, MeanSquaredDiscrepancyOfIndependentPointsMatchesClosedForm) {
    const int reps = 200;
    const uint64_t n = 64;
    for (int d : {2, 5}) {
        SCOPED_TRACE(d);
        std::vector<double> star(reps), cen(reps), wrap(reps);
        for (int r = 0; r < reps; ++r) {
            const PointSet s = random_set(n, d, 1000 * uint64_t(d) + uint64_t(r));
            star[size_t(r)] = sq(l2_star_discrepancy(s));
            cen[size_t(r)] = sq(centered_l2_discrepancy(s));
            wrap[size_t(r)] = sq(wraparound_l2_discrepancy(s));
        }
        auto check = [&](const std::vector<double>& v, double expected, const char* what) {
            double mean = 0.0;
            for (double x : v) mean += x;
            mean /= reps;
            double ss = 0.0;
            for (double x : v) ss += (x - mean) * (x - mean);
            const double se = std::sqrt(ss / (reps - 1) / reps);
            EXPECT_NEAR(mean, expected, 4.0 * se) << what << ": se " << se;
        };
        check(star, expected_l2_star_squared_iid(n, d), "star");
        check(cen, expected_centered_squared_iid(n, d), "centred");
        check(wrap, expected_wraparound_squared_iid(n, d), "wrap-around");
    }
}

TEST(PointAnalysis, ExpectationsAreTheClosedForms) {
    for (int d : {1, 2, 5, 17, 64}) {
        SCOPED_TRACE(d);
        const double n = 10.0;
        EXPECT_NEAR(expected_l2_star_squared_iid(10, d),
                    (std::pow(2.0, -d) - std::pow(3.0, -d)) / n, 1e-15 * std::pow(2.0, -d) / n);
        EXPECT_NEAR(expected_wraparound_squared_iid(10, d),
                    (std::pow(1.5, d) - std::pow(4.0 / 3.0, d)) / n, 1e-14 * std::pow(1.5, d) / n);
        EXPECT_NEAR(expected_centered_squared_iid(10, d),
                    (std::pow(1.25, d) - std::pow(13.0 / 12.0, d)) / n,
                    1e-14 * std::pow(1.25, d) / n);
    }
    // d = 1: each is 1/(6 N).
    EXPECT_DOUBLE_EQ(expected_l2_star_squared_iid(4, 1), 1.0 / 24.0);
    EXPECT_DOUBLE_EQ(expected_wraparound_squared_iid(4, 1), 1.0 / 24.0);
    EXPECT_DOUBLE_EQ(expected_centered_squared_iid(4, 1), 1.0 / 24.0);
}

// The wrap-around discrepancy depends only on differences modulo 1.
TEST(PointAnalysis, WraparoundDiscrepancyIsShiftInvariant) {
    const PointSet s = random_set(300, 3, 5);
    PointSet shifted = s;
    const double shift[3] = {0.25, 0.5, 0.875};
    for (int k = 0; k < 3; ++k)
        for (uint64_t i = 0; i < s.n; ++i) {
            double& x = shifted.coords[uint64_t(k) * s.n + i];
            x += shift[k];
            if (x >= 1.0) x -= 1.0;
        }
    const double a = wraparound_l2_discrepancy(s), b = wraparound_l2_discrepancy(shifted);
    EXPECT_NEAR(a, b, 1e-10 * a);
    // The star discrepancy is not shift invariant.
    EXPECT_GT(std::fabs(l2_star_discrepancy(s) - l2_star_discrepancy(shifted)), 1e-4);
}

TEST(PointAnalysis, EdgeCases) {
    // One point in one dimension: D*^2 = x^2 - x + 1/3, wrap-around 3/2 - 4/3 = 1/6.
    const PointSet one = make_set({{0.25}});
    EXPECT_NEAR(sq(l2_star_discrepancy(one)), 0.0625 - 0.25 + 1.0 / 3.0, 1e-16);
    EXPECT_NEAR(sq(wraparound_l2_discrepancy(one)), 1.0 / 6.0, 1e-16);
    EXPECT_EQ(min_distance(one, false), std::numeric_limits<double>::infinity());
    EXPECT_EQ(min_distance(one, true), std::numeric_limits<double>::infinity());
    // 64 dimensions: finite, positive and equal to the direct sums; the star discrepancy of
    // points spread in many dimensions is about sqrt(2^-d / N) (the empty-box part).
    const PointSet wide = random_set(40, 64, 3);
    const Direct ref = direct_discrepancies(wide);
    EXPECT_NEAR(sq(l2_star_discrepancy(wide)), double(ref.star), 1e-10 * double(ref.star));
    EXPECT_NEAR(sq(centered_l2_discrepancy(wide)), double(ref.centered),
                1e-10 * double(ref.centered));
    EXPECT_NEAR(sq(wraparound_l2_discrepancy(wide)), double(ref.wrap), 1e-10 * double(ref.wrap));
    EXPECT_GT(min_distance(wide, false), 0.0);
    // No points: NaN, not a crash.
    PointSet empty;
    empty.dim = 2;
    EXPECT_TRUE(std::isnan(l2_star_discrepancy(empty)));
}

TEST(PointAnalysis, PairwiseAffordableBound) {
    EXPECT_TRUE(pairwise_affordable(0, 3));
    EXPECT_TRUE(pairwise_affordable(1, 64));
    EXPECT_TRUE(pairwise_affordable(16384, 8)); // 1.07e9 pair-coordinates
    // n (n - 1) / 2 <= 2^33 exactly up to n = 131072 in one dimension.
    EXPECT_TRUE(pairwise_affordable(131072, 1));
    EXPECT_FALSE(pairwise_affordable(131073, 1));
    EXPECT_FALSE(pairwise_affordable(kMaxAnalysisPoints, 1));
    EXPECT_DOUBLE_EQ(pair_coordinates(4, 3), 18.0);
}

TEST(PointAnalysis, MinDistanceOfGridsAndHandSets) {
    for (int k : {4, 10}) {
        const PointSet g = grid_set(k, 2);
        EXPECT_NEAR(min_distance(g, false), 1.0 / k, 1e-15);
        EXPECT_NEAR(min_distance(g, true), 1.0 / k, 1e-15);
    }
    const PointSet g3 = grid_set(5, 3);
    EXPECT_NEAR(min_distance(g3, true), 0.2, 1e-15);
    // The closest pair is (0.4, 0.5)-(0.35, 0.45).
    const PointSet hand = make_set({{0.1, 0.1}, {0.4, 0.5}, {0.9, 0.9}, {0.35, 0.45}, {0.6, 0.1}});
    EXPECT_NEAR(min_distance(hand, false), std::hypot(0.05, 0.05), 1e-15);
    // Near opposite edges: 0.95 apart in the square, 0.05 on the torus.
    const PointSet edges = make_set({{0.02, 0.5}, {0.97, 0.5}, {0.5, 0.2}});
    EXPECT_NEAR(min_distance(edges, false), std::hypot(0.47, 0.3), 1e-15);
    EXPECT_NEAR(min_distance(edges, true), 0.05, 1e-15);
    // A corner pair: close on the torus through both edges at once.
    const PointSet corners = make_set({{0.01, 0.01}, {0.98, 0.99}, {0.5, 0.5}});
    EXPECT_NEAR(min_distance(corners, true), std::hypot(0.03, 0.02), 1e-15);
    // A repeated point.
    EXPECT_EQ(min_distance(make_set({{0.3, 0.3}, {0.7, 0.1}, {0.3, 0.3}}), false), 0.0);
}

// Across tiles and chunks, against all pairs by hand (the same sums in the same order).
TEST(PointAnalysis, MinDistanceMatchesAllPairs) {
    const PointSet s = random_set(900, 3, 12);
    double plain = 1e300, torus = 1e300;
    for (uint64_t i = 0; i < s.n; ++i)
        for (uint64_t j = i + 1; j < s.n; ++j) {
            double a = 0.0, b = 0.0;
            for (int k = 0; k < 3; ++k) {
                const double t = std::fabs(s.at(i, k) - s.at(j, k)), u = std::min(t, 1.0 - t);
                a += t * t;
                b += u * u;
            }
            plain = std::min(plain, a);
            torus = std::min(torus, b);
        }
    EXPECT_EQ(min_distance(s, false), std::sqrt(plain));
    EXPECT_EQ(min_distance(s, true), std::sqrt(torus));
}

namespace {

double spectrum_at(const PowerSpectrum& p, int kx, int ky) {
    return p.power[size_t(ky + p.size / 2) * size_t(p.size) + size_t(kx + p.size / 2)];
}

} // namespace

// A k x k grid: sum_j exp(-2 pi i kx x_j) over one axis is k exp(-pi i kx / k) where k | kx and
// 0 elsewhere, so P = k^4 / N = N at kx, ky both multiples of k (the axes included) and 0
// elsewhere.
TEST(PointSpectrum, GridHasPowerNAtMultiplesOfItsResolution) {
    for (int k : {4, 8, 6}) {
        SCOPED_TRACE(k);
        const PointSet g = grid_set(k, 2);
        const double n = double(g.n);
        const int size = 32;
        const PowerSpectrum p = power_spectrum(g, 0, 1, size);
        ASSERT_EQ(p.size, size);
        ASSERT_EQ(p.power.size(), size_t(size * size));
        EXPECT_EQ(spectrum_at(p, 0, 0), n);
        for (int ky = -size / 2; ky < size / 2; ++ky)
            for (int kx = -size / 2; kx < size / 2; ++kx) {
                const bool peak = kx % k == 0 && ky % k == 0;
                const double v = spectrum_at(p, kx, ky);
                if (peak) {
                    EXPECT_NEAR(v, n, 1e-9 * n) << kx << "," << ky;
                } else {
                    EXPECT_LT(v, 1e-9 * n) << kx << "," << ky;
                }
            }
    }
}

// Against the definition summed directly with std::cos and std::sin, on axes 2 and 0 of a
// 3-D set; the odd number of points also exercises the padding of the last group of four.
TEST(PointSpectrum, MatchesDirectSum) {
    const PointSet s = random_set(131, 3, 21);
    const int size = 18;
    const PowerSpectrum p = power_spectrum(s, 2, 0, size);
    ASSERT_EQ(p.size, size);
    EXPECT_EQ(p.axis_a, 2);
    EXPECT_EQ(p.axis_b, 0);
    EXPECT_EQ(p.n, s.n);
    const double two_pi = 6.283185307179586;
    double worst = 0.0;
    for (int ky = -size / 2; ky < size / 2; ++ky)
        for (int kx = -size / 2; kx < size / 2; ++kx) {
            double re = 0.0, im = 0.0;
            for (uint64_t j = 0; j < s.n; ++j) {
                const double phase = two_pi * (kx * s.at(j, 2) + ky * s.at(j, 0));
                re += std::cos(phase);
                im -= std::sin(phase);
            }
            const double direct = (re * re + im * im) / double(s.n);
            worst = std::max(worst, std::fabs(spectrum_at(p, kx, ky) - direct));
        }
    EXPECT_LT(worst, 1e-11);
}

TEST(PointSpectrum, SymmetricWithPowerNAtZero) {
    const PointSet s = random_set(777, 2, 4);
    const int size = 64;
    const PowerSpectrum p = power_spectrum(s, 0, 1, size);
    EXPECT_EQ(spectrum_at(p, 0, 0), 777.0);
    for (int ky = -size / 2 + 1; ky < size / 2; ++ky)
        for (int kx = -size / 2 + 1; kx < size / 2; ++kx)
            EXPECT_NEAR(spectrum_at(p, kx, ky), spectrum_at(p, -kx, -ky), 1e-12);
    // Threads take fixed rows: the same numbers with any count.
    const PowerSpectrum p1 = power_spectrum(s, 0, 1, size, 1),
                        p3 = power_spectrum(s, 0, 1, size, 3);
    EXPECT_EQ(p1.power, p3.power);
}

// For independent uniform points E P(k) = 1 at every k != 0, with P(k) close to exponentially
// distributed (variance 1), and P(k), P(k') nearly uncorrelated except P(-k) = P(k): each ring
// of c frequencies holds about c / 2 independent values.
TEST(PointSpectrum, IndependentPointsAverageOne) {
    const PointSet s = random_set(2048, 2, 77);
    const PowerSpectrum p = power_spectrum(s, 0, 1, 64);
    const RadialSpectrum r = radial_average(p);
    ASSERT_EQ(r.frequency.size(), 31u);
    ASSERT_EQ(r.power.size(), 31u);
    ASSERT_EQ(r.count.size(), 31u);
    double total = 0.0;
    uint64_t count = 0;
    for (size_t m = 0; m < r.frequency.size(); ++m) {
        EXPECT_EQ(r.frequency[m], double(m + 1));
        total += r.power[m] * double(r.count[m]);
        count += r.count[m];
        const double se = 1.0 / std::sqrt(0.5 * double(r.count[m]));
        if (r.count[m] >= 40) {
            EXPECT_NEAR(r.power[m], 1.0, 5.0 * se) << "ring " << m + 1;
        }
    }
    // Ring 1: |k|^2 = 1, 2 (4 + 4 frequencies); ring 2: |k|^2 = 4, 5 (4 + 8).
    EXPECT_EQ(r.count[0], 8u);
    EXPECT_EQ(r.count[1], 12u);
    const double mean = total / double(count);
    EXPECT_NEAR(mean, 1.0, 4.0 / std::sqrt(0.5 * double(count)));
}

TEST(PointSpectrum, OnePointAndOneDimension) {
    // One point: |exp(...)|^2 = 1 everywhere.
    const PowerSpectrum single = power_spectrum(make_set({{0.3, 0.81}}), 0, 1, 16);
    for (double v : single.power) EXPECT_NEAR(v, 1.0, 1e-14);
    // A 1-D grid of 8 points: N at multiples of 8, 0 elsewhere, the same on every row.
    const PointSet line = grid_set(8, 1);
    const PowerSpectrum p = power_spectrum(line, 0, 5, 32);
    ASSERT_EQ(p.size, 32);
    EXPECT_EQ(p.axis_b, -1);
    for (int ky = -16; ky < 16; ++ky)
        for (int kx = -16; kx < 16; ++kx) {
            const double v = spectrum_at(p, kx, ky);
            if (kx % 8 == 0) {
                EXPECT_NEAR(v, 8.0, 1e-12);
            } else {
                EXPECT_LT(v, 1e-12);
            }
        }
    const RadialSpectrum r = radial_average(p);
    ASSERT_EQ(r.count.size(), 15u);
    for (size_t m = 0; m < r.count.size(); ++m) {
        EXPECT_EQ(r.count[m], 2u);
        EXPECT_NEAR(r.power[m], (m + 1) % 8 == 0 ? 8.0 : 0.0, 1e-12);
    }
    // 64 dimensions, the last two axes.
    const PowerSpectrum wide = power_spectrum(random_set(50, 64, 8), 62, 63, 8);
    EXPECT_EQ(wide.size, 8);
    EXPECT_EQ(spectrum_at(wide, 0, 0), 50.0);
}

TEST(PointSpectrum, RejectsInvalidArguments) {
    const PointSet s = random_set(10, 2, 1);
    EXPECT_EQ(power_spectrum(s, 0, 1, 7).size, 0);    // odd
    EXPECT_EQ(power_spectrum(s, 0, 1, 0).size, 0);    // too small
    EXPECT_EQ(power_spectrum(s, 0, 1, 2048).size, 0); // too large
    EXPECT_EQ(power_spectrum(s, 0, 0, 8).size, 0);    // same axis
    EXPECT_EQ(power_spectrum(s, 0, 2, 8).size, 0);    // no such axis
    EXPECT_EQ(power_spectrum(PointSet{}, 0, 1, 8).size, 0);
    EXPECT_TRUE(radial_average(PowerSpectrum{}).power.empty());
}
