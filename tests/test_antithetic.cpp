// Antithetic variates (estimators/antithetic.cpp), a kind added as one file: the preset builds
// it, its runs are unbiased with honest error bars, and on a monotone integrand its variance is
// below that of as many independent points [Owen13, 8.2]. Fixed seeds; tolerances in standard
// errors.
#include <gtest/gtest.h>

#include <cmath>

#include "api/scene.h"
#include "estimators/registry.h"
#include "independent_runs.h"

using namespace mcp;

namespace {

Made<SceneRequest> request(const std::string& scene) {
    Made<Json> j = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(j.ok()) << j.error;
    return build_request(j.value, Json());
}

// exp(x) on [0, 1]: monotone, I = e - 1, Var(e^U) = (e^2 - 1)/2 - (e - 1)^2.
const char* kExp = R"J({"f": "exp(x)", "exact": 1.718281828459045,
                        "estimators": ["uniform", "antithetic"]})J";
const double kExact = std::exp(1.0) - 1.0;

} // namespace

TEST(Antithetic, ThePresetMakesTheKind) {
    Made<SceneRequest> r = request(kExp);
    ASSERT_TRUE(r.ok()) << r.error;
    const EstimatorSpec& a = r.value.estimators[1];
    EXPECT_STREQ(kind_of(a).name, "antithetic");
    EXPECT_STREQ(estimator_method(a), "antithetic");
    EXPECT_EQ(error_method_for(a), ErrorMethod::Iid);
    EXPECT_FALSE(kind_of(a).replay_is_estimate(a));
    EXPECT_FALSE(kind_of(a).adaptive);
    EXPECT_EQ(find_estimator_kind("antithetic"), &kind_of(a));
}

TEST(Antithetic, PairsOfOneRunAreItsEvaluationsAndItsDegreesOfFreedom) {
    Made<SceneRequest> r = request(kExp);
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    Pcg32 rng(3, 5);
    const RunResult run = run_estimate(r.value.problem, r.value.estimators[1], 4096, rng, ws);
    EXPECT_EQ(run.n, 4096u);
    EXPECT_EQ(run.dof, 2047); // m - 1 over m = N/2 pairs
    EXPECT_TRUE(std::isfinite(run.estimate));
    EXPECT_GT(run.std_error, 0.0);
}

TEST(Antithetic, UnbiasedWithHonestErrorBarsAndBelowUniformOnAMonotoneIntegrand) {
    Made<SceneRequest> r = request(kExp);
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const int runs = 400;
    const uint64_t n = 256;
    const test::IndependentRuns uniform =
        test::independent_runs(problem, r.value.estimators[0], n, runs, 11, 1, kExact);
    const test::IndependentRuns anti =
        test::independent_runs(problem, r.value.estimators[1], n, runs, 11, 2, kExact);
    EXPECT_TRUE(anti.every_n_reported);
    // Unbiased: the mean of 400 runs within 5 of its standard errors.
    EXPECT_LT(std::fabs(anti.mean - kExact), 5.0 * std::sqrt(anti.variance / runs));
    // Honest 95% intervals: 400 runs cover 0.95 +- 4 binomial standard errors (0.906 .. 0.994).
    const double se = std::sqrt(0.95 * 0.05 / runs);
    EXPECT_GE(anti.covered, static_cast<int>(std::floor((0.95 - 4 * se) * runs)));
    EXPECT_LE(anti.covered, static_cast<int>(std::ceil((0.95 + 4 * se) * runs)));
    // Uniform's variance is Var(e^U)/N; antithetic's Var((e^U + e^(1-U))/2)/(N/2), about 1/30
    // of it. The sample variances of 400 runs are within 25% (3.5 of their relative standard
    // errors, sqrt(2/399)), so "below half" cannot fail by chance and still says much.
    const double var_u = (std::exp(2.0) - 1.0) / 2.0 - kExact * kExact;
    EXPECT_NEAR(uniform.variance, var_u / n, 0.25 * var_u / n);
    EXPECT_LT(anti.variance, 0.5 * uniform.variance);
    // and the antithetic variance is the pairs' own: Var(y) = ((e^2 - 1) + 2e)/4 - (e - 1)^2.
    const double var_y = (std::exp(2.0) - 1.0 + 2.0 * std::exp(1.0)) / 4.0 - kExact * kExact;
    EXPECT_NEAR(anti.variance, var_y / (n / 2), 0.25 * var_y / (n / 2));
}
