// Control variates [Owen13, 8.9]: with the coefficient fitted on the same samples, the
// estimate is unbiased to O(1/N), its variance is (1 - rho^2) of plain Monte Carlo's, and its
// error bar (residuals on N - 1 - m degrees of freedom) is calibrated even at small N.
#include <gtest/gtest.h>

#include <cmath>

#include "api/scene.h"
#include "estimators/block_driver.h"
#include "independent_runs.h"

using namespace mcp;

namespace {

Made<SceneRequest> request(const std::string& estimators, const std::string& domain =
                                                              R"({"type": "interval", "lower": 0,
                                                                  "upper": 1})") {
    const std::string scene = R"({"name": "cv", "domain": )" + domain +
                              R"(, "integrand": "exp(x) ", "estimators": )" + estimators + "}";
    Made<Json> j = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(j.ok()) << j.error;
    return build_request(j.value, Json());
}

// exp(x) on [0, 1] against g = x: Var(e^X) = (e^2 - 1)/2 - (e - 1)^2,
// Cov(e^X, X) = 1 - (e - 1)/2, Var(X) = 1/12.
const double kE = std::exp(1.0);
const double kVarF = (kE * kE - 1.0) / 2.0 - (kE - 1.0) * (kE - 1.0);
const double kRho2 = std::pow(1.0 - (kE - 1.0) / 2.0, 2) / (kVarF / 12.0);

} // namespace

// R = 400 runs at N = 1024: the variance of the estimates is (1 - rho^2) Var(f) / N within the
// chi^2(399) interval [0.80, 1.23] (two-sided p = 0.002), about 61 times below plain Monte
// Carlo's; the mean within 4 standard errors of e - 1, the 95% intervals cover 90-99%.
TEST(ControlVariates, FittedCoefficientGivesTheRegressionVarianceAndHonestIntervals) {
    Made<SceneRequest> r = request(R"([{"name": "cv", "control_variates": [{"g": "x",
                                       "integral": 0.5}]}, {"name": "cv_builtin",
                                       "control_variates": [{"g": {"type": "monomial",
                                       "powers": [1]}}]}])");
    ASSERT_TRUE(r.ok()) << r.error;
    const double exact = kE - 1.0;
    const uint64_t n = 1024;
    const int runs = 400;
    const double expected = (1.0 - kRho2) * kVarF / static_cast<double>(n);
    for (size_t e = 0; e < 2; ++e) {
        const test::IndependentRuns s =
            test::independent_runs(r.value.problem, r.value.estimators[e], n, runs, 7, e, exact);
        EXPECT_TRUE(s.every_n_reported);
        EXPECT_GT(s.variance, 0.80 * expected) << e;
        EXPECT_LT(s.variance, 1.23 * expected) << e;
        EXPECT_LE(std::fabs(s.mean - exact), 4.0 * std::sqrt(expected / runs)) << e;
        EXPECT_GE(s.covered, static_cast<int>(0.90 * runs)) << e;
        EXPECT_LE(s.covered, static_cast<int>(0.99 * runs)) << e;
    }
}

// At N = 16 the coefficient is noisy: fitted on the same samples it biased the estimate by a
// quarter of its standard deviation and the intervals covered 87%; cross-fitted over 4 folds,
// the intervals cover 90-98% of 1000 runs and the mean is within 4 standard errors.
TEST(ControlVariates, ErrorBarAccountsForTheFittedCoefficientAtSmallN) {
    Made<SceneRequest> r = request(R"([{"name": "cv", "control_variates": [{"g": "x",
                                       "integral": 0.5}]}])");
    ASSERT_TRUE(r.ok()) << r.error;
    const int runs = 1000;
    const test::IndependentRuns s =
        test::independent_runs(r.value.problem, r.value.estimators[0], 16, runs, 11, 3, kE - 1.0);
    EXPECT_GE(s.covered, static_cast<int>(0.90 * runs));
    EXPECT_LE(s.covered, static_cast<int>(0.98 * runs));
    EXPECT_LE(std::fabs(s.mean - (kE - 1.0)), 4.0 * std::sqrt(s.variance / runs));
}

// Every run finishes with its N, from 1 point (no error bar) through the in-sample fit
// (N < 4 (m + 1)) to the folds.
TEST(ControlVariates, RunsOfOneToFortyPointsFinish) {
    Made<SceneRequest> r = request(R"([{"name": "cv", "control_variates": [{"g": "x",
                                       "integral": 0.5}, {"g": "x^2", "integral": 0.3333333333333333}]}])");
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    for (uint64_t n = 1; n <= 40; ++n) {
        Pcg32 rng(n, 2u);
        const RunResult run = run_estimate(r.value.problem, r.value.estimators[0], n, rng, ws);
        EXPECT_EQ(run.n, n);
        EXPECT_TRUE(std::isfinite(run.estimate)) << n;
        EXPECT_EQ(std::isfinite(run.std_error), n >= 4) << n;
    }
}

// A given coefficient: unbiased for any c; c = 0 is plain Monte Carlo's variance Var(f) / N,
// and on a mean over [0, 2] the estimate is scaled by 1/2 with the integral G of g.
TEST(ControlVariates, GivenCoefficientsAndMeansAreUnbiased) {
    Made<SceneRequest> r = request(R"([{"name": "c0", "control_variates": [{"g": "x",
                                       "integral": 0.5}], "coefficients": [0]}, {"name": "c3",
                                       "control_variates": [{"g": "x", "integral": 0.5}],
                                       "coefficients": [3]}])");
    ASSERT_TRUE(r.ok()) << r.error;
    const int runs = 400;
    const uint64_t n = 256;
    const test::IndependentRuns c0 =
        test::independent_runs(r.value.problem, r.value.estimators[0], n, runs, 13, 0, kE - 1.0);
    EXPECT_GT(c0.variance, 0.80 * kVarF / n);
    EXPECT_LT(c0.variance, 1.23 * kVarF / n);
    const test::IndependentRuns c3 =
        test::independent_runs(r.value.problem, r.value.estimators[1], n, runs, 13, 1, kE - 1.0);
    EXPECT_LE(std::fabs(c3.mean - (kE - 1.0)), 4.0 * std::sqrt(c3.variance / runs));
    EXPECT_GE(c3.covered, static_cast<int>(0.90 * runs));

    Made<Json> j = parse_json(R"({"name": "m", "domain": {"type": "interval", "lower": 0,
        "upper": 2}, "integrand": "exp(x) ", "quantity": "mean", "estimators": [{"name": "cv",
        "control_variates": [{"g": "x", "integral": 2}]}]})",
                              "scene");
    ASSERT_TRUE(j.ok()) << j.error;
    Made<SceneRequest> m = build_request(j.value, Json());
    ASSERT_TRUE(m.ok()) << m.error;
    const double mean = (std::exp(2.0) - 1.0) / 2.0;
    const test::IndependentRuns mr =
        test::independent_runs(m.value.problem, m.value.estimators[0], 1024, runs, 19, 0, mean);
    EXPECT_LE(std::fabs(mr.mean - mean), 4.0 * std::sqrt(mr.variance / runs));
    EXPECT_GE(mr.covered, static_cast<int>(0.90 * runs));
}

// g that is not finite somewhere (1/x at x = 0 is never drawn, but log(x - 0.5) is NaN on half
// the interval): those samples are dropped and counted, never silently used.
TEST(ControlVariates, NonFiniteControlValuesAreCounted) {
    Made<SceneRequest> r = request(R"([{"name": "bad", "control_variates": [{"g":
                                       "log(x - 0.5) ", "integral": 0}]}])");
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    Pcg32 rng(1u, 1u);
    const RunResult run = run_estimate(r.value.problem, r.value.estimators[0], 1000, rng, ws);
    EXPECT_GT(run.diagnostics.nonfinite, 400u);
    EXPECT_LT(run.diagnostics.nonfinite, 600u);
}
