// MISER [PressFarrar90]: unbiased with calibrated error bars, far below uniform's variance on a
// peak, calls where the integrand varies, the whole budget spent, bad options named.
#include <gtest/gtest.h>

#include <cmath>

#include "api/scene.h"
#include "estimators/block_driver.h"
#include "estimators/miser.h"
#include "estimators/study.h"
#include "independent_runs.h"

using namespace mcp;

namespace {

Made<SceneRequest> request(const std::string& estimators, double cx = 0.3) {
    const std::string scene =
        R"({"name": "g", "domain": {"type": "box", "dim": 2},
            "integrand": {"type": "gaussian", "center": [)" +
        std::to_string(cx) + R"(, 0.6], "sigma": 0.05}, "estimators": )" + estimators + "}";
    Made<Json> j = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(j.ok()) << j.error;
    return build_request(j.value, Json());
}

} // namespace

// R = 200 runs at N = 65536: the mean within 4 standard errors of the exact value, coverage of
// the 95% intervals in [0.88, 0.995], and uniform's variance over MISER's above 4 (F(199, 199):
// p ~ 1e-20 under equal variances; the true ratio is above 100).
TEST(Miser, UnbiasedCalibratedAndBelowUniform) {
    Made<SceneRequest> r = request(R"(["uniform", "miser", {"name": "dithered", "miser":
                                      {"dither": 0.1}}])");
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const double exact = *problem.exact;
    const int runs = 200;
    double variance[3] = {0, 0, 0};
    for (size_t e = 0; e < 3; ++e) {
        const test::IndependentRuns runs_of =
            test::independent_runs(problem, r.value.estimators[e], 65536, runs, 99, 4 + e, exact);
        EXPECT_TRUE(runs_of.every_n_reported);
        variance[e] = runs_of.variance;
        EXPECT_LE(std::fabs(runs_of.mean - exact), 4.0 * std::sqrt(variance[e] / runs)) << e;
        EXPECT_GE(runs_of.covered, static_cast<int>(0.88 * runs)) << e;
        EXPECT_LE(runs_of.covered, static_cast<int>(0.995 * runs)) << e;
    }
    EXPECT_GT(variance[0] / variance[1], 4.0);
    EXPECT_GT(variance[0] / variance[2], 4.0);
}

// A peak at x = 0.75: the half x < 0.5 holds e^-12.5 of it, so MISER gives it little beyond its
// probes' minimum; the leaves partition the unit square.
TEST(Miser, CallsFollowTheVariance) {
    Made<SceneRequest> r = request(R"(["miser"])", 0.75);
    ASSERT_TRUE(r.ok()) << r.error;
    Pcg32 rng(3u, 3u);
    const uint64_t n = 1 << 18;
    const std::vector<MiserBox> leaves =
        miser_leaves(r.value.problem, r.value.estimators[0], n, rng, 1 << 20);
    ASSERT_FALSE(leaves.empty());
    double area = 0.0;
    uint64_t calls = 0, left = 0;
    for (const MiserBox& b : leaves) {
        area += (b.hi[0] - b.lo[0]) * (b.hi[1] - b.lo[1]);
        calls += b.calls;
        if (b.hi[0] <= 0.5) left += b.calls;
    }
    EXPECT_NEAR(area, 1.0, 1e-12);
    // The probes are spent too: 10% of every region's calls at each of about
    // log2(N / 512) = 9 levels of cuts leaves 0.9^9 = 39% for the leaves.
    EXPECT_LT(calls, n);
    EXPECT_GT(calls, n / 4);
    EXPECT_LT(left, calls / 20); // uniform would give half
}

// The sample view: the leaves' points (not the probes) and the leaf boxes, which tile the square.
TEST(Miser, SampleDumpShowsTheLeavesAndTheirPoints) {
    Made<SceneRequest> r = request(R"(["miser"])", 0.75);
    ASSERT_TRUE(r.ok()) << r.error;
    const SampleDump d = dump_samples(r.value.problem, r.value.estimators[0], 4096, 1);
    ASSERT_FALSE(d.adaptive.box_lo.empty());
    ASSERT_EQ(d.adaptive.box_lo.size(), d.adaptive.box_hi.size());
    double area = 0.0;
    for (size_t b = 0; b < d.adaptive.box_lo.size(); ++b)
        area += (d.adaptive.box_hi[b][0] - d.adaptive.box_lo[b][0]) *
                (d.adaptive.box_hi[b][1] - d.adaptive.box_lo[b][1]);
    EXPECT_NEAR(area, 1.0, 1e-12);
    EXPECT_GT(d.weight.size(), 0u);
    EXPECT_LT(d.weight.size(), 4096u); // the probes are not shown
}

TEST(Miser, TinyRunsArePlainMonteCarlo) {
    Made<SceneRequest> r = request(R"(["miser"])");
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    for (uint64_t n : {1u, 2u, 100u}) {
        Pcg32 rng(1u, 1u);
        const RunResult run = run_estimate(r.value.problem, r.value.estimators[0], n, rng, ws);
        EXPECT_EQ(run.n, n);
        EXPECT_TRUE(std::isfinite(run.estimate));
        EXPECT_EQ(std::isnan(run.std_error), n == 1) << n;
    }
}

TEST(Miser, BadOptionsAreNamed) {
    struct Case {
        const char* options;
        const char* field;
    } cases[] = {
        {R"({"estimate_fraction": 0.7})", "miser.estimate_fraction"},
        {R"({"estimate_fraction": 0})", "miser.estimate_fraction"},
        {R"({"min_calls": 1})", "miser.min_calls"},
        {R"({"alpha": -1})", "miser.alpha"},
        {R"({"dither": 0.5})", "miser.dither"},
        {R"({"depth": 3})", "unknown field 'depth'"},
    };
    for (const Case& c : cases) {
        Made<SceneRequest> r =
            request(std::string(R"([{"name": "m", "miser": )") + c.options + "}]");
        ASSERT_FALSE(r.ok()) << c.options;
        EXPECT_NE(r.error.find(c.field), std::string::npos) << r.error;
    }
    Made<SceneRequest> both = request(R"([{"name": "m", "miser": {}, "vegas": {}}])");
    ASSERT_FALSE(both.ok());
    Made<SceneRequest> sobol = request(R"([{"name": "m", "miser": {}, "sampler": "sobol"}])");
    ASSERT_FALSE(sobol.ok());
    EXPECT_NE(sobol.error.find("sampler"), std::string::npos) << sobol.error;
}
