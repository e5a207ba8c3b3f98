// Resampled importance sampling (estimators/ris.cpp) [Talbot05]: the presets and the "ris" object
// build the kind; M = 1 is importance sampling with the source density p; with a target g that
// covers f it is unbiased with honest error bars, and its variance falls with M on a peaked
// integrand; a target that misses part of f's support is flagged (the support check and the
// zero-pdf samples), and the run then estimates the integral over {g > 0} alone. Fixed seeds;
// tolerances in standard errors.
#include <gtest/gtest.h>

#include <cmath>

#include "api/scene.h"
#include "estimators/registry.h"
#include "estimators/study.h"
#include "independent_runs.h"

using namespace mcp;

namespace {

Made<SceneRequest> request(const std::string& scene) {
    Made<Json> j = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(j.ok()) << j.error;
    return build_request(j.value, Json());
}

// A peak of width 0.05 at 0.5 on [0, 1]; the targets: the uniform candidates resampled by |f|,
// or by a wider normal pdf (a cheap proxy of f, positive everywhere).
const char* kPeak = R"J({"domain": {"type": "interval", "lower": 0, "upper": 1},
    "integrand": {"type": "gaussian", "center": [0.5], "sigma": 0.05},
    "estimators": ["uniform", "ris_m1", "ris_m8",
        {"name": "importance_normal", "pdf": {"type": "gaussian", "mu": 0.45, "sigma": 0.08}},
        {"name": "ris_f_from_normal", "ris": {"candidates": 1, "target": "f"},
         "pdf": {"type": "gaussian", "mu": 0.45, "sigma": 0.08}},
        {"name": "ris1_normal", "ris": {"candidates": 1},
         "pdf": {"type": "gaussian", "mu": 0.45, "sigma": 0.08}},
        {"name": "ris4_normal", "ris": {"candidates": 4},
         "pdf": {"type": "gaussian", "mu": 0.45, "sigma": 0.08}},
        {"name": "ris16_normal", "ris": {"candidates": 16},
         "pdf": {"type": "gaussian", "mu": 0.45, "sigma": 0.08}}]})J";
enum { kUniform, kRisM1, kRisM8, kImportance, kRisFromNormal, kRis1, kRis4, kRis16 };

// e^x on [0, 1] with tabulated targets: one zero on [0, 0.25) (it misses part of f's support),
// one positive everywhere.
const char* kGap = R"J({"f": "exp(x)",
    "estimators": [
        {"name": "ris_gap", "ris": {"candidates": 4},
         "pdf": {"type": "tabulated", "values": [0, 1, 1.5, 2]}},
        {"name": "ris_cover", "ris": {"candidates": 4},
         "pdf": {"type": "tabulated", "values": [0.5, 1, 1.5, 2]}}]})J";

std::string error_of(const std::string& estimator) {
    const std::string scene = R"J({"f": "x", "estimators": [)J" + estimator + "]}";
    Made<SceneRequest> r = request(scene);
    return r.ok() ? "" : r.error;
}

double exact_of(const Problem& problem) {
    EXPECT_TRUE(problem.exact.has_value());
    return problem.exact.value_or(0.0);
}

} // namespace

TEST(Ris, PresetsAndObjectsMakeTheKind) {
    Made<SceneRequest> r = request(kPeak);
    ASSERT_TRUE(r.ok()) << r.error;
    const EstimatorSpec& m8 = r.value.estimators[kRisM8];
    EXPECT_STREQ(kind_of(m8).name, "ris");
    EXPECT_STREQ(estimator_method(m8), "ris");
    EXPECT_EQ(error_method_for(m8), ErrorMethod::Iid);
    EXPECT_TRUE(kind_of(m8).replay_is_estimate(m8));
    EXPECT_FALSE(kind_of(m8).adaptive);
    EXPECT_EQ(m8.ris_options.candidates, 8);
    EXPECT_FALSE(m8.ris_options.target_pdf);
    EXPECT_FALSE(m8.proposal.importance);
    const EstimatorSpec& normal = r.value.estimators[kRis4];
    EXPECT_EQ(normal.ris_options.candidates, 4);
    EXPECT_TRUE(normal.ris_options.target_pdf); // the pdf is the target, the candidates uniform
    EXPECT_TRUE(normal.ris_options.target.importance);
    EXPECT_FALSE(normal.proposal.importance);
    const EstimatorSpec& from = r.value.estimators[kRisFromNormal];
    EXPECT_FALSE(from.ris_options.target_pdf); // "target": "f": the pdf is the source
    EXPECT_TRUE(from.proposal.importance);
    for (const char* name : {"ris_m1", "ris_m2", "ris_m4", "ris_m8", "ris_m16"})
        EXPECT_NE(find_preset(name), nullptr) << name;
}

TEST(Ris, BadOptionsAreOneLineErrorsNamingTheField) {
    EXPECT_EQ(error_of(R"J({"name": "r", "ris": {"candidates": 8}})J"), "");
    const struct {
        const char* estimator;
        const char* says;
    } bad[] = {
        {R"J({"name": "r", "ris": {"candidates": 0}})J", "ris.candidates: must be in [1, 256]"},
        {R"J({"name": "r", "ris": {"candidates": 257}})J", "got 257"},
        {R"J({"name": "r", "ris": {"target": "g"}})J", "ris.target: expected \"pdf\""},
        {R"J({"name": "r", "ris": {"target": "pdf"}})J", "needs the estimator's \"pdf\""},
        {R"J({"name": "r", "ris": {"m": 3}})J", "ris"},
        {R"J({"name": "r", "ris": 4})J", "ris: expected an object"},
        {R"J({"name": "r", "sampler": "stratified", "ris": {}})J", "independent sampler"},
    };
    for (const auto& b : bad) {
        const std::string e = error_of(b.estimator);
        EXPECT_NE(e.find(b.says), std::string::npos) << b.estimator << " -> " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

TEST(Ris, OneCandidateIsImportanceSamplingWithTheSource) {
    Made<SceneRequest> r = request(kPeak);
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    Workspace ws;
    // The same rng gives the same points: Y = f/p exactly, whatever the target.
    const std::pair<int, int> same[] = {
        {kRisM1, kUniform}, {kRis1, kUniform}, {kRisFromNormal, kImportance}};
    for (auto [ris, plain] : same) {
        for (uint64_t seed : {1u, 2u, 3u}) {
            Pcg32 a(seed, 9), b(seed, 9);
            const RunResult x = run_estimate(problem, r.value.estimators[ris], 1000, a, ws);
            const RunResult y = run_estimate(problem, r.value.estimators[plain], 1000, b, ws);
            EXPECT_EQ(x.n, y.n);
            EXPECT_EQ(x.estimate, y.estimate) << r.value.estimators[ris].name;
            EXPECT_EQ(x.std_error, y.std_error) << r.value.estimators[ris].name;
        }
    }
}

TEST(Ris, UnbiasedWithHonestErrorBarsWhereTheTargetCoversF) {
    Made<SceneRequest> r = request(kPeak);
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const double exact = exact_of(problem);
    const int runs = 400;
    const double se = std::sqrt(0.95 * 0.05 / runs);
    for (int e : {kRisM8, kRis4, kRis16}) {
        const EstimatorSpec& spec = r.value.estimators[e];
        const test::IndependentRuns x =
            test::independent_runs(problem, spec, 128, runs, 5, 3, exact);
        EXPECT_TRUE(x.every_n_reported) << spec.name;
        EXPECT_LT(std::fabs(x.mean - exact), 5.0 * std::sqrt(x.variance / runs)) << spec.name;
        // 400 runs' 95% intervals cover 0.95 +- 4 binomial standard errors.
        EXPECT_GE(x.covered, static_cast<int>(std::floor((0.95 - 4 * se) * runs))) << spec.name;
        EXPECT_LE(x.covered, static_cast<int>(std::ceil((0.95 + 4 * se) * runs))) << spec.name;
        const SupportCheck support = check_support(problem, spec, 1 << 14, 7);
        EXPECT_FALSE(support.flagged) << spec.name;
        EXPECT_EQ(support.missed, 0u) << spec.name;
    }
}

TEST(Ris, VarianceFallsWithTheCandidatesOnAPeak) {
    Made<SceneRequest> r = request(kPeak);
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const double exact = exact_of(problem);
    const int runs = 400;
    const uint64_t n = 128;
    auto variance = [&](int e) {
        return test::independent_runs(problem, r.value.estimators[e], n, runs, 21, 4, exact)
            .variance;
    };
    // With g = |f| (f > 0) a point's Y is the mean of M uniform weights: Var = Var_u / (M N),
    // Var_u = int f^2 - I^2 (f^2 is the same peak at sigma / sqrt 2). 400 runs' sample variance
    // is within 25% (3.5 of its relative standard errors, sqrt(2/399)).
    const double sigma = 0.05, pi = std::acos(-1.0);
    const double f2 = sigma * std::sqrt(pi) * std::erf(0.5 / sigma);
    const double var_u = f2 - exact * exact;
    EXPECT_NEAR(variance(kUniform), var_u / n, 0.25 * var_u / n);
    EXPECT_NEAR(variance(kRisM8), var_u / (8 * n), 0.25 * var_u / (8 * n));
    // With the normal pdf as the target the variance falls from uniform's (M = 1) towards that of
    // importance sampling with the normal pdf as M grows (here about 1/3 from M = 1 to 4, 1/2
    // from 4 to 16, and M = 16 at 1.4 times the limit): the bounds are each over 3 standard
    // errors of a ratio of two such variances (10%) away.
    const double v1 = variance(kRis1), v4 = variance(kRis4), v16 = variance(kRis16);
    const double v_is = variance(kImportance);
    EXPECT_LT(v4, 0.5 * v1);
    EXPECT_LT(v16, 0.75 * v4);
    EXPECT_GT(v16, v_is); // the limit is importance sampling with the target
}

TEST(Ris, ATargetThatMissesFIsFlaggedAndEstimatesItsSupportAlone) {
    Made<SceneRequest> r = request(kGap);
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const EstimatorSpec& gap = r.value.estimators[0];
    const EstimatorSpec& cover = r.value.estimators[1];
    // The support check sees the target's zero on [0, 0.25); the covering target passes.
    EXPECT_TRUE(check_support(problem, gap, 1 << 14, 7).flagged);
    EXPECT_FALSE(check_support(problem, cover, 1 << 14, 7).flagged);
    // So do the samples: a point whose 4 candidates all fall where g = 0 (probability 1/256)
    // looks at one, and f != 0 there counts as a zero-pdf sample.
    Workspace ws;
    Pcg32 rng(11, 2);
    EXPECT_GT(run_estimate(problem, gap, 1 << 14, rng, ws).diagnostics.zero_pdf, 0u);
    EXPECT_EQ(run_estimate(problem, cover, 1 << 14, rng, ws).diagnostics.zero_pdf, 0u);
    // The estimate is the integral over {g > 0}: e - e^0.25, not e - 1.
    const double e = std::exp(1.0), on_support = e - std::exp(0.25);
    const int runs = 200;
    const test::IndependentRuns x =
        test::independent_runs(problem, gap, 1024, runs, 31, 6, on_support);
    const double se = std::sqrt(x.variance / runs);
    EXPECT_LT(std::fabs(x.mean - on_support), 5.0 * se);
    EXPECT_GT(std::fabs(x.mean - (e - 1.0)), 20.0 * se);
}

TEST(Ris, TheStudyFlagsATargetThatMissesF) {
    Made<SceneRequest> r = request(kGap);
    ASSERT_TRUE(r.ok()) << r.error;
    StudySettings s = r.value.settings;
    s.n_min = 1024;
    s.n_max = 4096;
    s.reps = 4;
    s.threads = 1;
    const StudyResult study = run_study(r.value.problem, r.value.estimators, s, {});
    ASSERT_EQ(study.estimators.size(), 2u);
    EXPECT_TRUE(study.estimators[0].support.flagged);
    EXPECT_FALSE(study.estimators[1].support.flagged);
}

// tests/test_estimators.cpp: no replicate beyond 5 of its standard errors with nothing flagged.
void expect_no_confident_wrong_answer(const char* scene, const Json& options);

// The presets (|f| over M uniform candidates: a point is the mean of M uniform weights) on the
// stiff one-dimensional scenes: peaks missed, singularities of finite and infinite variance, a
// step, a large offset.
TEST(Ris, NoConfidentWrongAnswerOnTheStiffScenes) {
    for (const char* scene :
         {"stiff_peak_1e-8", "singular_power_0.3", "singular_power_0.5", "singular_power_0.9",
          "step_1d", "heavy_tail_abs", "oscillatory_cos1000", "offset_1e8_sin"})
        expect_no_confident_wrong_answer(scene, Json{{"n_min", 16},
                                                     {"n_max", 16384},
                                                     {"reps", 16},
                                                     {"seed", 49},
                                                     {"estimators", {"ris_m4", "ris_m16"}}});
}
