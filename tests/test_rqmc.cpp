// Randomized quasi-Monte Carlo estimators (sobol, halton, lattice samplers) through the scene
// API and the study runner: unbiased, error bars from independent randomizations that cover
// as often as they say, variance rates, 53-bit points, and clear errors for what a sequence
// cannot do.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "api/scene.h"
#include "core/special.h"
#include "estimators/diagnostics.h"

using namespace mcp;

namespace {

Made<SceneRequest> request(const Json& scene, const Json& options = Json()) {
    return build_request(scene, options);
}

SceneRequest must(const Json& scene, const Json& options = Json()) {
    Made<SceneRequest> r = request(scene, options);
    EXPECT_TRUE(r.ok()) << r.error;
    return r.value;
}

Json genz_scene(const std::string& family, int dim, uint64_t seed, const Json& estimators) {
    return Json{{"name", family + "_" + std::to_string(dim)},
                {"integrand", {{"type", "genz_" + family}, {"dim", dim}, {"seed", seed}}},
                {"estimators", estimators}};
}

const char* const kFamilies[] = {"oscillatory", "product_peak", "corner_peak",
                                 "gaussian",    "continuous",   "discontinuous"};

} // namespace

// Coverage of the runs' own 95% t intervals (K = 16 randomizations, 15 degrees of freedom) on
// the Genz families at the project's random parameters: within [0.90, 0.99] over 200 runs
// (binomial standard error of a coverage of 0.95: 1.5%). Corner peak is tested below.
TEST(RqmcErrorBars, CoverageOfGenzFamiliesIsNinetyFivePercent) {
    for (const char* sampler : {"sobol", "halton", "lattice"}) {
        for (const char* family : kFamilies) {
            if (std::string(family) == "corner_peak") continue;
            for (int dim : {2, 5}) {
                SceneRequest req =
                    must(genz_scene(family, dim, 7, Json::array({sampler})), Json{{"n_min", 4096},
                                                                                  {"n_max", 4096},
                                                                                  {"reps", 200},
                                                                                  {"seed", 11},
                                                                                  {"threads", 2}});
                StudyResult s = run_study(req.problem, req.estimators, req.settings);
                const LevelStats& l = s.estimators[0].levels[0];
                EXPECT_GE(l.coverage, 0.90) << sampler << " " << family << " d=" << dim;
                EXPECT_LE(l.coverage, 0.99) << sampler << " " << family << " d=" << dim;
                EXPECT_EQ(s.estimators[0].error_method, ErrorMethod::Randomizations);
                // The mean of 200 unbiased estimates lies within 4 of its standard errors.
                EXPECT_LE(std::fabs(l.mean - *req.problem.exact),
                          4.0 * l.std_error + 1e-13 * std::fabs(*req.problem.exact))
                    << sampler << " " << family << " d=" << dim;
            }
        }
    }
}

// Corner peak at the standard difficulty (sum a = 600 / d^2: f falls from 1 at the corner to
// 10^-5 of it across the cube) is pre-asymptotic at these N for every method, plain Monte
// Carlo included: the batch means are skewed and t intervals undercover. Where they do, the
// estimator must say so (a flag on the level or the estimator), never look fine.
TEST(RqmcErrorBars, UndercoverageOnTheCornerPeakIsFlagged) {
    for (const char* sampler : {"sobol", "halton", "lattice"}) {
        for (int dim : {2, 5}) {
            SceneRequest req = must(
                genz_scene("corner_peak", dim, 7, Json::array({sampler})),
                Json{
                    {"n_min", 1024}, {"n_max", 4096}, {"reps", 200}, {"seed", 11}, {"threads", 2}});
            StudyResult s = run_study(req.problem, req.estimators, req.settings);
            const EstimatorStudy& e = s.estimators[0];
            bool flagged = !estimator_flags(e, s.settings).empty();
            for (const LevelStats& l : e.levels) flagged = flagged || !level_flags(l).empty();
            for (const LevelStats& l : e.levels) {
                if (l.coverage < 0.90) {
                    EXPECT_TRUE(flagged) << sampler << " d=" << dim << " N=" << l.n << ": coverage "
                                         << l.coverage << " and no flag";
                }
            }
        }
    }
}

// The per-run error bar estimates the spread of the runs: mean reported variance over the
// replicate variance is 1 within its sampling noise (400 runs, 15 dof each: a few percent).
TEST(RqmcErrorBars, ReportedVarianceMatchesReplicateSpread) {
    SceneRequest req = must(genz_scene("gaussian", 4, 3, Json::array({"sobol", "lattice"})),
                            Json{{"n_min", 4096}, {"n_max", 4096}, {"reps", 400}, {"seed", 5}});
    StudyResult s = run_study(req.problem, req.estimators, req.settings);
    for (const EstimatorStudy& e : s.estimators) {
        const LevelStats& l = e.levels[0];
        double reported = 0.0;
        for (double se : l.run_std_errors) reported += se * se;
        reported /= static_cast<double>(l.run_std_errors.size());
        // The replicate variance of 400 runs is within about 3 x sqrt(2/399) = 21% of the
        // truth (heavier tails than normal allowed for); the reported one averages 400 runs.
        EXPECT_NEAR(reported / l.variance, 1.0, 0.25) << e.spec.name;
    }
}

// Few randomizations (K = 4 and 2: 3 and 1 degrees of freedom) still make honest intervals:
// the t quantile widens them as the K batch means, near normal for smooth f [Loh03], ask.
// Coverage over 400 runs within 3.5 binomial standard errors of 95% (sqrt(0.95 x 0.05 / 400)
// = 1.1%: [0.912, 0.988]), on smooth families at parameters the rules were not tuned on.
TEST(RqmcErrorBars, FewRandomizationsStillCoverNinetyFivePercent) {
    const double se = std::sqrt(0.95 * 0.05 / 400.0);
    for (int k : {4, 2}) {
        for (const char* family : {"oscillatory", "gaussian", "continuous"}) {
            for (int dim : {3, 5}) {
                Json sobol_k = {{"name", "sobol"}, {"randomizations", k}};
                SceneRequest req =
                    must(genz_scene(family, dim, 52, Json::array({sobol_k})), Json{{"n_min", 1024},
                                                                                   {"n_max", 1024},
                                                                                   {"reps", 400},
                                                                                   {"seed", 49},
                                                                                   {"threads", 2}});
                ASSERT_EQ(req.estimators[0].randomizations, k);
                StudyResult s = run_study(req.problem, req.estimators, req.settings);
                const LevelStats& l = s.estimators[0].levels[0];
                EXPECT_EQ(l.run_dofs[0], k - 1);
                EXPECT_NEAR(l.coverage, 0.95, 3.5 * se)
                    << "K=" << k << " " << family << " d=" << dim;
            }
        }
    }
}

// At a fixed N, fewer randomizations mean larger nets: Owen-scrambled nets of n points have
// variance O(n^-3 (log n)^(d-1)) on smooth f [Owen97b], so K nets of N/K points have
// O(K^2 N^-3) up to logarithms, and the variance falls with K. Over R = 300 runs the log of a
// ratio of two replicate variances has standard error about sqrt(2/(R-1) + 2/(R-1)) = 0.116;
// each step 16 -> 4 -> 2 must lower it by more than 4 of those (a factor above 1.6), the
// direction theory gives and plain Monte Carlo (whose variance ignores K) would not.
TEST(RqmcVariance, FewerRandomizationsAtFixedNLowerTheVariance) {
    const int reps = 300;
    const double log_ratio_se = std::sqrt(4.0 / (reps - 1.0));
    Json estimators = Json::array();
    for (int k : {16, 4, 2})
        estimators.push_back(Json{
            {"name", "sobol_k" + std::to_string(k)}, {"sampler", "sobol"}, {"randomizations", k}});
    Json scene{{"name", "smooth_3d"},
               {"domain", {{"type", "box"}, {"lower", {0, 0, 0}}, {"upper", {1, 1, 1}}}},
               {"integrand", {{"type", "exponential"}, {"rates", {1.0, -0.7, 0.4}}}},
               {"estimators", estimators}};
    SceneRequest req =
        must(scene,
             Json{{"n_min", 4096}, {"n_max", 4096}, {"reps", reps}, {"seed", 49}, {"threads", 2}});
    StudyResult s = run_study(req.problem, req.estimators, req.settings);
    ASSERT_EQ(s.estimators.size(), 3u);
    for (size_t i = 0; i + 1 < s.estimators.size(); ++i) {
        const double more = s.estimators[i].levels[0].variance;
        const double fewer = s.estimators[i + 1].levels[0].variance;
        ASSERT_GT(fewer, 0.0);
        EXPECT_GT(std::log(more / fewer), 4.0 * log_ratio_se)
            << s.estimators[i].spec.name << " variance " << more << ", "
            << s.estimators[i + 1].spec.name << " " << fewer;
        // The error bars follow: the runs' mean reported variance falls by a like factor.
        EXPECT_LT(s.estimators[i + 1].levels[0].mean_run_variance,
                  s.estimators[i].levels[0].mean_run_variance);
    }
}

// Owen-scrambled Sobol' points on a smooth 2-D integrand: the variance falls at least as N^-2
// (theory: N^-3 for smooth f [Owen97b]); plain Monte Carlo falls as N^-1.
TEST(RqmcRates, SobolOnASmoothIntegrandFallsFasterThanNToMinus2) {
    Json scene{{"name", "smooth_2d"},
               {"domain", {{"type", "box"}, {"lower", {0, 0}}, {"upper", {1, 1}}}},
               {"integrand", {{"type", "exponential"}, {"rates", {1.0, 0.5}}}},
               {"estimators", {"sobol", "halton", "lattice", "uniform"}}};
    SceneRequest req =
        must(scene, Json{{"n_min", 256}, {"n_max", 65536}, {"reps", 24}, {"seed", 3}});
    StudyResult s = run_study(req.problem, req.estimators, req.settings);
    for (const EstimatorStudy& e : s.estimators) {
        ASSERT_TRUE(e.fit.valid) << e.spec.name << ": " << e.fit.note;
        if (e.spec.name == "uniform") {
            EXPECT_NEAR(e.fit.order, -1.0, 4.0 * e.fit.order_se);
        } else if (e.spec.name == "sobol") {
            // Scrambled nets: N^-3 (up to logarithms) for smooth f; clearly steeper than N^-2.
            EXPECT_LT(e.fit.order + 3.0 * e.fit.order_se, -2.0)
                << e.spec.name << " order " << e.fit.order << " +- " << e.fit.order_se;
        } else {
            // A shifted lattice on a non-periodic f and scrambled Halton: N^-2 (up to
            // logarithms), never significantly slower.
            EXPECT_LT(e.fit.order - 3.0 * e.fit.order_se, -2.0)
                << e.spec.name << " order " << e.fit.order << " +- " << e.fit.order_se;
        }
    }
}

// Every randomization of every point set is unbiased on a discontinuous integrand (Genz's
// discontinuous family, d = 3).
TEST(RqmcUnbiased, EveryRandomizationOnAnIndicator) {
    const std::pair<const char*, const char*> kinds[] = {
        {"sobol", "owen"},  {"sobol", "lms_shift"},    {"sobol", "digital_shift"},
        {"halton", "owen"}, {"halton", "permutation"}, {"lattice", "random_shift"}};
    for (auto [sampler, randomization] : kinds) {
        Json scene = genz_scene(
            "discontinuous", 3, 4,
            Json::array({{{"name", "q"}, {"sampler", sampler}, {"randomization", randomization}}}));
        Made<SceneRequest> r = request(scene, Json{{"n_min", 512}, {"n_max", 512}, {"reps", 256}});
        ASSERT_TRUE(r.ok()) << r.error;
        StudyResult s = run_study(r.value.problem, r.value.estimators, r.value.settings);
        const LevelStats& l = s.estimators[0].levels[0];
        ASSERT_TRUE(r.value.problem.exact.has_value());
        EXPECT_LE(std::fabs(l.mean - *r.value.problem.exact), 4.0 * l.std_error)
            << sampler << " " << randomization;
        EXPECT_GT(l.std_error, 0.0);
    }
}

// Points carry 53 random bits: x^-0.9 on (0, 1] (10% of its integral below 2^-32) is
// estimated without bias by every randomized point set, as plain Monte Carlo estimates it.
TEST(RqmcUnbiased, SingularIntegrandNearZeroIsSampledFinely) {
    Json scene{{"name", "x^-0.9"},
               {"domain", {{"type", "interval"}, {"lower", 0}, {"upper", 1}}},
               {"integrand", {{"type", "monomial"}, {"powers", {-0.9}}}},
               {"estimators", {"sobol", "halton", "lattice"}}};
    // Heavy tails: the mean over 2000 runs still converges (tail index 1.1), slowly; compare
    // on the smallest 2^-40 of the domain instead: the share of runs that saw a point there.
    SceneRequest req = must(scene, Json{{"n_min", 4096}, {"n_max", 4096}, {"reps", 64}});
    for (const EstimatorSpec& spec : req.estimators) {
        SampleDump dump = dump_samples(req.problem, spec, 1u << 16, 1);
        double smallest = 1.0;
        for (double u : dump.u) smallest = std::fmin(smallest, u);
        EXPECT_GT(smallest, 0.0) << spec.name;
        // 2^16 points that carry 53 bits: the smallest lies near 2^-16, far below a 32-bit
        // grid's floor only by chance; what matters is that it is not on a 2^-32 grid.
        const double scaled = std::ldexp(smallest, 32);
        EXPECT_NE(scaled, std::floor(scaled)) << spec.name << ": point on a 32-bit grid";
    }
}

// Without randomization the points are one deterministic set: no error bar, said so.
TEST(RqmcErrorBars, NoRandomizationMeansNoErrorBar) {
    Json scene{{"name", "exp"},
               {"domain", {{"type", "interval"}, {"lower", 0}, {"upper", 1}}},
               {"integrand", {{"type", "exponential"}, {"rates", {1}}}},
               {"estimators",
                {{{"name", "plain_sobol"}, {"sampler", "sobol"}, {"randomization", "none"}}}}};
    SceneRequest req = must(scene, Json{{"n_min", 64}, {"n_max", 256}, {"reps", 2}});
    EXPECT_EQ(req.estimators[0].randomizations, 1);
    StudyResult s = run_study(req.problem, req.estimators, req.settings);
    EXPECT_EQ(s.estimators[0].error_method, ErrorMethod::None);
    for (const LevelStats& l : s.estimators[0].levels) {
        EXPECT_TRUE(std::isnan(l.run_std_errors[0]));
        // Deterministic: both replicates give the same number, close to e - 1.
        EXPECT_EQ(l.estimates[0], l.estimates[1]);
        EXPECT_NEAR(l.estimates[0], std::exp(1.0) - 1.0, 4.0 / static_cast<double>(l.n));
    }
}

TEST(RqmcStudy, IdenticalWithOneAndTwoThreads) {
    Json base = genz_scene("oscillatory", 3, 2, Json::array({"sobol", "halton", "lattice"}));
    Json one{{"n_min", 16}, {"n_max", 1024}, {"reps", 5}, {"threads", 1}};
    Json two = one;
    two["threads"] = 2;
    SceneRequest a = must(base, one), b = must(base, two);
    StudyResult sa = run_study(a.problem, a.estimators, a.settings);
    StudyResult sb = run_study(b.problem, b.estimators, b.settings);
    for (size_t e = 0; e < sa.estimators.size(); ++e)
        for (size_t l = 0; l < sa.estimators[e].levels.size(); ++l) {
            EXPECT_EQ(sa.estimators[e].levels[l].estimates, sb.estimators[e].levels[l].estimates);
            EXPECT_EQ(sa.estimators[e].levels[l].run_std_errors,
                      sb.estimators[e].levels[l].run_std_errors);
        }
}

// Replicates are independent: at N = K (one point per randomization) an RQMC run is plain
// Monte Carlo with a t error bar, and its replicates' estimates are uncorrelated.
TEST(RqmcStudy, ReplicatesDifferAndAreUncorrelated) {
    SceneRequest req = must(genz_scene("gaussian", 2, 1, Json::array({"sobol"})),
                            Json{{"n_min", 16}, {"n_max", 16}, {"reps", 400}});
    StudyResult s = run_study(req.problem, req.estimators, req.settings);
    const std::vector<double>& x = s.estimators[0].levels[0].estimates;
    double mean = 0.0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    double c0 = 0.0, c1 = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
        c0 += (x[i] - mean) * (x[i] - mean);
        if (i + 1 < x.size()) c1 += (x[i] - mean) * (x[i + 1] - mean);
    }
    // Lag-1 autocorrelation of independent values: about N(0, 1/400), |r| < 4 / 20.
    EXPECT_LT(std::fabs(c1 / c0), 0.2);
}

TEST(RqmcScene, ClearErrorsForWhatASequenceCannotDo) {
    auto error_of = [](const Json& estimator, const Json& options = Json()) {
        Json scene = genz_scene("gaussian", 2, 1, Json::array({estimator}));
        Made<SceneRequest> r = build_request(scene, options);
        return r.ok() ? std::string("(accepted)") : r.error;
    };
    EXPECT_NE(error_of({{"name", "q"}, {"sampler", "sobol"}, {"randomization", "permutation"}})
                  .find("scene.estimators[0].randomization: randomization 'permutation' does not "
                        "apply to sobol"),
              std::string::npos);
    EXPECT_NE(error_of({{"name", "q"}, {"sampler", "sobol"}, {"randomization", "scrambled"}})
                  .find("unknown randomization 'scrambled'"),
              std::string::npos);
    EXPECT_NE(error_of({{"name", "q"}, {"sampler", "halton"}, {"randomizations", 12}})
                  .find("scene.estimators[0].randomizations: must be a power of two"),
              std::string::npos);
    EXPECT_NE(error_of({{"name", "q"}, {"sampler", "halton"}, {"randomizations", 1}})
                  .find("must be a power of two"),
              std::string::npos);
    EXPECT_NE(error_of({{"name", "q"}, {"sampler", "stratified"}, {"randomization", "owen"}})
                  .find("applies to the quasi-Monte Carlo samplers only"),
              std::string::npos);
    EXPECT_NE(
        error_of(
            {{"name", "q"}, {"sampler", "sobol"}, {"randomization", "none"}, {"randomizations", 4}})
            .find("randomizations = 1"),
        std::string::npos);
    // N must hold one point per randomization; a lattice is built for 2^20 points.
    EXPECT_NE(error_of("sobol", Json{{"n_min", 8}, {"n_max", 64}})
                  .find("options: estimator 'sobol': 16 randomizations need n_min >= 16"),
              std::string::npos);
    EXPECT_NE(error_of("lattice", Json{{"n_min", 16}, {"n_max", uint64_t(1) << 25}})
                  .find("beyond the 1048576 the lattice points are built for"),
              std::string::npos);
    EXPECT_EQ(error_of("lattice", Json{{"n_min", 16}, {"n_max", uint64_t(1) << 24}}), "(accepted)");
    EXPECT_EQ(error_of({{"name", "q"},
                        {"sampler", "sobol"},
                        {"randomization", "lms_shift"},
                        {"randomizations", 32}},
                       Json{{"n_min", 32}}),
              "(accepted)");
}

// Quasi-Monte Carlo points warp through every pdf as independent points do: importance
// sampling with Sobol' points is unbiased and beats plain Sobol' on a peaked integrand.
TEST(RqmcImportance, SobolPointsThroughAPdf) {
    Json scene{{"name", "exp_rate"},
               {"domain", {{"type", "interval"}, {"lower", 0}, {"upper", 1}}},
               {"integrand", {{"type", "exponential"}, {"rates", {4}}}},
               {"estimators",
                {"sobol",
                 {{"name", "sobol_importance"},
                  {"sampler", "sobol"},
                  {"pdf", {{"type", "exponential"}, {"rate", -3}}}}}}};
    SceneRequest req = must(scene, Json{{"n_min", 1024}, {"n_max", 1024}, {"reps", 64}});
    StudyResult s = run_study(req.problem, req.estimators, req.settings);
    const LevelStats& plain = s.estimators[0].levels[0];
    const LevelStats& is = s.estimators[1].levels[0];
    EXPECT_LE(std::fabs(is.mean - *req.problem.exact), 4.0 * is.std_error + 1e-13);
    EXPECT_LT(is.variance, plain.variance);
}
