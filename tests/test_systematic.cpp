// Systematic sampling (estimators/systematic.cpp), a kind that draws and randomizes its own
// points: the preset builds it, its runs are unbiased with honest error bars from the spread of
// its 16 shifted grids, its variance is the shifted grid's (analytic on exp) and far below
// uniform's, it refuses the N it cannot split and the dimensions too high for a grid, and the
// reports and the sample view describe its points in its own words [Owen13, ch. 10]. Fixed seeds;
// tolerances in standard errors.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "api/mcplay.h"
#include "api/scene.h"
#include "estimators/registry.h"
#include "independent_runs.h"

using namespace mcp;

namespace {

Made<SceneRequest> request(const std::string& scene, const std::string& options = "") {
    Made<Json> j = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(j.ok()) << j.error;
    Json o;
    if (!options.empty()) o = parse_json(options.c_str(), "options").value;
    return build_request(j.value, o);
}

const char* kExp = R"J({"f": "exp(x)", "exact": 1.718281828459045,
                        "estimators": ["uniform", "systematic"]})J";
const double kExact = std::exp(1.0) - 1.0;

// A box of `dim` dimensions with a smooth integrand, for the checks on N and dimension.
std::string box(int dim, uint64_t n_min, uint64_t n_max, const char* extra = "") {
    return R"J({"domain": {"type": "box", "dim": )J" + std::to_string(dim) +
           R"J(}, "f": "exp(x)", "estimators": ["systematic"], "n_min": )J" +
           std::to_string(n_min) + R"J(, "n_max": )J" + std::to_string(n_max) + extra + "}";
}

} // namespace

TEST(Systematic, ThePresetMakesTheKindWithItsOwnWords) {
    Made<SceneRequest> r = request(kExp);
    ASSERT_TRUE(r.ok()) << r.error;
    const EstimatorSpec& s = r.value.estimators[1];
    EXPECT_STREQ(kind_of(s).name, "systematic");
    EXPECT_STREQ(estimator_method(s), "systematic");
    EXPECT_EQ(error_method_for(s), ErrorMethod::Randomizations);
    EXPECT_FALSE(kind_of(s).replay_is_estimate(s));
    const PointWords words = point_words(s);
    EXPECT_STREQ(words.sampler, "systematic");
    EXPECT_STREQ(words.randomization, "random_shift");
    EXPECT_EQ(words.randomizations, 16);
    // and a kind without words of its own keeps its sampler's
    EXPECT_STREQ(point_words(r.value.estimators[0]).sampler, "independent");
    EXPECT_EQ(point_words(r.value.estimators[0]).randomizations, 0);
}

TEST(Systematic, ARunIsSixteenShiftedGridsWithTheirSpreadAsErrorBar) {
    Made<SceneRequest> r = request(box(2, 256, 256));
    ASSERT_TRUE(r.ok()) << r.error;
    const EstimatorSpec& s = r.value.estimators[0];
    std::unique_ptr<EstimatorAlgorithm> e = make_estimator(r.value.problem, s, {});
    std::vector<double> u0, u1;
    e->observe([&](const SampleBlock& b) {
        for (size_t i = 0; i < b.count; ++i) {
            u0.push_back(b.u->coord(0)[i]);
            u1.push_back(b.u->coord(1)[i]);
        }
    });
    Pcg32 rng(3, 5);
    Workspace ws;
    e->begin(256, rng);
    const PointDesign design = e->design();
    EXPECT_EQ(design.randomizations, 16u);
    EXPECT_EQ(design.strata, (std::vector<uint64_t>{4, 4}));
    while (e->run_block(rng, ws)) {
    }
    const RunResult run = e->result();
    EXPECT_EQ(run.n, 256u);
    EXPECT_EQ(run.dof, 15); // K - 1
    EXPECT_GT(run.std_error, 0.0);
    ASSERT_EQ(u0.size(), 256u);
    // Each batch of 16 is a 4 x 4 grid under one shift: one point per cell, all at one offset.
    for (size_t k = 0; k < 16; ++k) {
        int cells[16] = {};
        const double ox = std::fmod(4 * u0[16 * k], 1.0), oy = std::fmod(4 * u1[16 * k], 1.0);
        for (size_t i = 16 * k; i < 16 * k + 16; ++i) {
            ++cells[static_cast<int>(4 * u0[i]) + 4 * static_cast<int>(4 * u1[i])];
            EXPECT_NEAR(std::fmod(4 * u0[i], 1.0), ox, 1e-12);
            EXPECT_NEAR(std::fmod(4 * u1[i], 1.0), oy, 1e-12);
        }
        for (int c : cells) EXPECT_EQ(c, 1);
    }
}

TEST(Systematic, UnbiasedWithHonestErrorBarsAndTheShiftedGridsVariance) {
    Made<SceneRequest> r = request(kExp);
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const int runs = 400;
    const uint64_t n = 256, k = 16, m = n / k;
    const test::IndependentRuns uniform =
        test::independent_runs(problem, r.value.estimators[0], n, runs, 21, 1, kExact);
    const test::IndependentRuns sys =
        test::independent_runs(problem, r.value.estimators[1], n, runs, 21, 2, kExact);
    EXPECT_TRUE(sys.every_n_reported);
    // Unbiased: the mean of 400 runs within 5 of its standard errors.
    EXPECT_LT(std::fabs(sys.mean - kExact), 5.0 * std::sqrt(sys.variance / runs));
    // Honest 95% intervals (t on 15 dof): 400 runs cover 0.95 +- 4 binomial standard errors.
    const double se = std::sqrt(0.95 * 0.05 / runs);
    EXPECT_GE(sys.covered, static_cast<int>(std::floor((0.95 - 4 * se) * runs)));
    EXPECT_LE(sys.covered, static_cast<int>(std::ceil((0.95 + 4 * se) * runs)));
    // One grid of m points shifted by s: b(s) = A e^(s/m), A = (e - 1) / (m (e^(1/m) - 1)), so
    // Var b = A^2 (m/2 (e^(2/m) - 1) - m^2 (e^(1/m) - 1)^2) and a run's variance is Var b / K.
    // 400 runs' sample variance is within 25% (3.5 of its relative standard errors).
    const double md = static_cast<double>(m), e1 = std::expm1(1.0 / md);
    const double a = kExact / (md * e1);
    const double var_b = a * a * (md / 2.0 * std::expm1(2.0 / md) - md * md * e1 * e1);
    const double var_run = var_b / static_cast<double>(k);
    EXPECT_NEAR(sys.variance, var_run, 0.25 * var_run);
    // and below as many independent points', Var(e^U) / N: in 1D, for a smooth f, Var b falls
    // as m^-2 (about (e - 1)^2 / (12 m^2)), here a sixteenth of uniform's; "below a fifth" holds
    // with both sample variances 25% off.
    const double var_u = (std::exp(2.0) - 1.0) / 2.0 - kExact * kExact;
    EXPECT_NEAR(uniform.variance, var_u / n, 0.25 * var_u / n);
    EXPECT_LT(var_run, var_u / n / 12.0);
    EXPECT_LT(sys.variance, 0.2 * uniform.variance);
}

TEST(Systematic, RefusesNItCannotSplitAndDimensionsTooHighForAGrid) {
    // 16 grids need N >= 16: n_min = 8 is refused (in one line), 16 is not.
    Made<SceneRequest> low = request(box(3, 8, 1024));
    ASSERT_FALSE(low.ok());
    EXPECT_EQ(low.error, "scene: estimator 'systematic': systematic sampling runs 16 shifted grids "
                         "of N/16 points: n_min must be at least 16, got 8");
    EXPECT_TRUE(request(box(3, 16, 1024)).ok());
    // Given by the options, the message says so.
    Made<SceneRequest> opt = request(box(3, 16, 1024), R"({"n_min": 4})");
    ASSERT_FALSE(opt.ok());
    EXPECT_EQ(opt.error.rfind("options: estimator 'systematic': ", 0), 0u) << opt.error;
    // 3 axes cut twice need 16 x 2^3 = 128 points at n_max: 64 is refused, naming the dimension.
    Made<SceneRequest> high = request(box(3, 16, 64));
    ASSERT_FALSE(high.ok());
    EXPECT_NE(high.error.find("in 3 dimensions that takes N >= 16 x 2^3 = 128, beyond n_max = 64"),
              std::string::npos)
        << high.error;
    EXPECT_EQ(high.error.find('\n'), std::string::npos);
    EXPECT_TRUE(request(box(3, 16, 128)).ok());
    Made<SceneRequest> twelve = request(box(12, 16, 16384));
    ASSERT_FALSE(twelve.ok());
    EXPECT_NE(twelve.error.find("in 12 dimensions"), std::string::npos) << twelve.error;
    // Stopping at a tolerance doubles N from n_min: it must be a multiple of 16.
    Made<SceneRequest> odd = request(box(1, 40, 4096, R"J(, "rel_tol": 0.01)J"));
    ASSERT_FALSE(odd.ok());
    EXPECT_NE(odd.error.find("n_min must be a multiple of 16, got 40"), std::string::npos)
        << odd.error;
    EXPECT_TRUE(request(box(1, 48, 4096, R"J(, "rel_tol": 0.01)J")).ok());
}

TEST(Systematic, ReportsAndTheSampleViewUseItsWords) {
    const std::string scene = box(2, 256, 512, R"J(, "reps": 4, "seed": 3)J");
    char* out = nullptr;
    ASSERT_EQ(mcp_study_run(scene.c_str(), nullptr, nullptr, nullptr, &out), MCP_OK)
        << mcp_last_error();
    const nlohmann::json result = nlohmann::json::parse(out);
    mcp_free(out);
    const nlohmann::json& e = result["estimators"][0];
    EXPECT_EQ(e["sampler"], "systematic");
    EXPECT_EQ(e["randomization"], "random_shift");
    EXPECT_EQ(e["randomizations"], 16);
    EXPECT_EQ(e["error_method"], "randomizations");
    EXPECT_EQ(e["levels"][0]["run_dof"], 15);
    ASSERT_EQ(mcp_study_samples(scene.c_str(), R"({"n": 256})", &out), MCP_OK) << mcp_last_error();
    const nlohmann::json dump = nlohmann::json::parse(out);
    mcp_free(out);
    const nlohmann::json& d = dump["estimators"][0];
    EXPECT_EQ(d["sampler"], "systematic");
    EXPECT_EQ(d["randomizations"], 16);
    EXPECT_EQ(d["strata"], nlohmann::json::array({4, 4}));
    EXPECT_EQ(d["weight"].size(), 256u);
}
