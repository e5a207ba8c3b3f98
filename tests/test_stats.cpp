// Compensated sums, Welford moments, line fits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "core/stats.h"

using namespace mcp;

TEST(Stats, NeumaierSumRecoversSmallTerms) {
    // 1 + 1e100 + 1 - 1e100 = 2; naive summation gives 0.
    NeumaierSum s;
    for (double x : {1.0, 1e100, 1.0, -1e100}) s.add(x);
    EXPECT_EQ(s.value(), 2.0);
    // 1e7 additions of 0.1: naive double accumulation drifts by ~1e-4 relative-ish.
    NeumaierSum t;
    for (int i = 0; i < 10000000; ++i) t.add(0.1);
    EXPECT_NEAR(t.value(), 1e6, 1e-8);
}

TEST(Stats, WelfordStableWithLargeOffset) {
    // Variance of {1e9 + 4, 1e9 + 7, 1e9 + 13, 1e9 + 16} is 30 exactly; E[x^2] - E[x]^2
    // loses every digit here.
    RunningMoments m;
    for (double x : {4.0, 7.0, 13.0, 16.0}) m.add(1e9 + x);
    EXPECT_DOUBLE_EQ(m.variance(), 30.0);
    EXPECT_DOUBLE_EQ(m.mean(), 1e9 + 10.0);
}

// The third central moment, one value at a time, by blocks and merged, against a two-pass sum
// about the exact mean; on a large offset (1e6) too. Exponential values: skewness 2.
TEST(Stats, SkewnessOneAtATimeByBlocksAndMergedAgree) {
    Pcg32 rng(8, 3);
    std::vector<double> x(100000);
    for (double& v : x) v = 1e6 - std::log(1.0 - rng.next_double());
    RunningMoments single, blocks, left, right;
    for (double v : x) single.add(v);
    for (size_t i = 0; i < x.size(); i += 1000) blocks.add_block(&x[i], 1000);
    left.add_block(x.data(), 30000);
    for (size_t i = 30000; i < x.size(); ++i) right.add(x[i]);
    left.merge(right);
    double mean = 0.0;
    for (double v : x) mean += (v - 1e6) / static_cast<double>(x.size());
    double m2 = 0.0, m3 = 0.0;
    for (double v : x) {
        const double d = (v - 1e6) - mean;
        m2 += d * d;
        m3 += d * d * d;
    }
    const double g1 = std::sqrt(static_cast<double>(x.size())) * m3 / std::pow(m2, 1.5);
    for (const RunningMoments* m : {&single, &blocks, &left}) {
        EXPECT_NEAR(m->sum_cubed_deviations(), m3, 1e-9 * std::fabs(m3));
        EXPECT_NEAR(m->skewness(), g1, 1e-9);
    }
    // The sample skewness of 1e5 exponential values: within 0.15 of 2 (its standard error is
    // about 0.03 here: sqrt(Var g1) ~ sqrt(6 ... + kurtosis terms) / sqrt(n)).
    EXPECT_NEAR(g1, 2.0, 0.15);
    // No spread, no skewness.
    RunningMoments flat;
    for (int i = 0; i < 10; ++i) flat.add(3.0);
    EXPECT_EQ(flat.skewness(), 0.0);
}

TEST(Stats, MergeEqualsSequential) {
    Pcg32 rng(1, 2);
    RunningMoments all, a, b;
    for (int i = 0; i < 1000; ++i) {
        double x = rng.next_double() * 10.0 + 1e6;
        all.add(x);
        (i < 300 ? a : b).add(x);
    }
    a.merge(b);
    EXPECT_EQ(a.count(), all.count());
    EXPECT_NEAR(a.mean(), all.mean(), 1e-9);
    EXPECT_NEAR(a.variance() / all.variance(), 1.0, 1e-9);
}

// A part added by value, variance and count is what a stratum adds by its moments: the same
// estimate, variance and Satterthwaite degrees of freedom; a part of one value leaves no
// variance estimate.
TEST(Stats, StratifiedSumPartsAsStrata) {
    RunningMoments a, b;
    for (double x : {1.0, 2.0, 4.0}) a.add(x);
    for (double x : {0.5, 0.25, 3.0, 9.0, 1.0}) b.add(x);
    StratifiedSum strata, parts;
    strata.add(0.25, a);
    strata.add(0.75, b);
    parts.add_part(0.25 * a.mean(), 0.25 * 0.25 * a.variance() / 3.0, 3);
    parts.add_part(0.75 * b.mean(), 0.75 * 0.75 * b.variance() / 5.0, 5);
    EXPECT_DOUBLE_EQ(parts.estimate(), strata.estimate());
    EXPECT_DOUBLE_EQ(parts.variance(), strata.variance());
    EXPECT_EQ(parts.dof(), strata.dof());
    EXPECT_TRUE(parts.has_variance());
    parts.add_part(1.0, 0.0, 1);
    EXPECT_FALSE(parts.has_variance());
}

// The allocation by largest remainders against its definition: the whole parts, then one point
// more to each of the `left` largest remainders, ties to the lower index (a sort of pairs).
TEST(Stats, LargestRemaindersAsDefined) {
    Pcg32 rng(17, 3);
    for (int trial = 0; trial < 40; ++trial) {
        const size_t n = 1 + rng.next_below(20000);
        std::vector<double> share(n);
        // Some trials draw shares from a few values only, so that many remainders tie.
        const uint32_t levels = trial % 2 ? 3 : 0;
        double total = 0.0;
        for (double& s : share) {
            s = levels ? static_cast<double>(1 + rng.next_below(levels)) : rng.next_double();
            total += s;
        }
        for (double& s : share) s /= total;
        const uint64_t points = rng.next_below(static_cast<uint32_t>(8 * n)) + (trial % 5);
        std::vector<uint64_t> counts(n, 2), expected(n, 2);
        allocate_largest_remainders(points, share, &counts);
        uint64_t given = 0;
        std::vector<std::pair<double, size_t>> remainders(n);
        for (size_t h = 0; h < n; ++h) {
            const double exact = static_cast<double>(points) * share[h];
            const uint64_t whole = std::min(points - given, static_cast<uint64_t>(exact));
            expected[h] += whole;
            given += whole;
            remainders[h] = {exact - static_cast<double>(whole), h};
        }
        std::sort(remainders.begin(), remainders.end(), [](const auto& a, const auto& b) {
            return a.first != b.first ? a.first > b.first : a.second < b.second;
        });
        for (size_t k = 0; given < points; k = (k + 1) % n, ++given)
            ++expected[remainders[k].second];
        ASSERT_EQ(counts, expected) << "trial " << trial << ", n " << n << ", points " << points;
    }
}

TEST(Stats, LineFitExactAndUncertainty) {
    std::vector<double> x{0, 1, 2, 3, 4}, y;
    for (double v : x) y.push_back(3.0 - 2.0 * v);
    LineFit f = fit_line(x, y);
    EXPECT_NEAR(f.slope, -2.0, 1e-14);
    EXPECT_NEAR(f.intercept, 3.0, 1e-14);
    EXPECT_NEAR(f.slope_se, 0.0, 1e-12);
    // Noisy line: the true slope lies within 4 standard errors of the fit.
    Pcg32 rng(9, 9);
    std::vector<double> xs, ys;
    for (int i = 0; i < 200; ++i) {
        xs.push_back(i * 0.05);
        ys.push_back(1.0 + 0.5 * xs.back() + (rng.next_double() - 0.5));
    }
    LineFit g = fit_line(xs, ys);
    EXPECT_LT(std::fabs(g.slope - 0.5), 4.0 * g.slope_se);
    EXPECT_GT(g.slope_se, 0.0);
}

TEST(Stats, WeightedLineFit) {
    // Four points on y = 1 - x with sd 0.1 and one far off with sd 1e3: the fit follows the four.
    std::vector<double> x{0, 1, 2, 3, 4}, y{1, 0, -1, -2, 100}, sd{0.1, 0.1, 0.1, 0.1, 1e3};
    LineFit f = fit_weighted_line(x, y, sd);
    EXPECT_NEAR(f.slope, -1.0, 1e-3);
    EXPECT_NEAR(f.intercept, 1.0, 1e-3);
    // Residuals within the stated sd: the slope's error is the sd's, 1 / sqrt(S_xx^w) (the far
    // point adds almost nothing to S_xx^w = 100 (sum of (x - 1.5)^2 over the four) = 500).
    EXPECT_NEAR(f.slope_se, 1.0 / std::sqrt(500.0), 1e-4);
    // Points scattered 10x beyond their stated sd: the error grows by about sqrt(chi^2 / dof).
    std::vector<double> ys{1.5, -0.5, -0.5, -2.5}, xs{0, 1, 2, 3}, sds{0.1, 0.1, 0.1, 0.1};
    LineFit g = fit_weighted_line(xs, ys, sds);
    LineFit u = fit_line(xs, ys);
    EXPECT_NEAR(g.slope, u.slope, 1e-12);       // equal weights: the unweighted slope
    EXPECT_NEAR(g.slope_se, u.slope_se, 1e-12); // and, residuals dominating, its error
    EXPECT_GT(g.residual_variance, 1.0);
    // An unknown sd falls back to the unweighted fit.
    LineFit h = fit_weighted_line(xs, ys, {0.1, 0.0, 0.1, 0.1});
    EXPECT_EQ(h.slope, u.slope);
    EXPECT_EQ(h.slope_se, u.slope_se);
}

// The median's order-statistic interval [DavidNagaraja03, 7.1]: for n = 10, [x_(2), x_(9)] at
// level 1 - 2 * 11/1024; for n = 5 the whole range, at its own level 1 - 2/32; unsorted input.
TEST(Stats, MedianIntervalFromOrderStatistics) {
    std::vector<double> ten{10, 9, 8, 7, 6, 5, 4, 3, 2, 1};
    const MedianInterval m = median_interval(ten);
    EXPECT_DOUBLE_EQ(m.median, 5.5);
    EXPECT_DOUBLE_EQ(m.lo, 2.0);
    EXPECT_DOUBLE_EQ(m.hi, 9.0);
    EXPECT_NEAR(m.level, 1.0 - 22.0 / 1024.0, 1e-15);
    std::vector<double> five{3, 1, 5, 2, 4};
    const MedianInterval s = median_interval(five);
    EXPECT_DOUBLE_EQ(s.median, 3.0);
    EXPECT_DOUBLE_EQ(s.lo, 1.0);
    EXPECT_DOUBLE_EQ(s.hi, 5.0);
    EXPECT_NEAR(s.level, 1.0 - 2.0 / 32.0, 1e-15);
    std::vector<double> none;
    EXPECT_EQ(median_interval(none).level, 0.0);
}
