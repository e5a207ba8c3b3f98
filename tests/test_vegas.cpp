// VEGAS: the map (identity at the start, concentration where the integrand's marginal has its
// mass), and the frozen-map estimators (unbiased, calibrated error bars, better than uniform
// on a peak; the training counts in N; bad options are named).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <vector>

#include "api/scene.h"
#include "estimators/block_driver.h"
#include "estimators/diagnostics.h"
#include "estimators/study.h"
#include "estimators/vegas.h"
#include "estimators/vegas_train.h"
#include "independent_runs.h"

using namespace mcp;

namespace {

Made<SceneRequest> request(const std::string& scene) {
    Made<Json> j = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(j.ok()) << j.error;
    return build_request(j.value, Json());
}

// A 2-D Gaussian of width sigma at c, on the unit square, with the given estimators.
std::string gaussian_scene(double sigma, const std::string& estimators) {
    return R"({"name": "g", "domain": {"type": "box", "dim": 2},
               "integrand": {"type": "gaussian", "center": [0.3, 0.6], "sigma": )" +
           std::to_string(sigma) + R"(}, "estimators": )" + estimators + "}";
}

// The fraction of the map's probability on [lo, hi] of axis j: y spreads evenly over the
// increments, so it is the share of each increment inside [lo, hi], summed, over K.
double map_probability(const VegasMap& m, int j, double lo, double hi) {
    const double* e = m.edges(j);
    double p = 0.0;
    for (int i = 0; i < m.increments(); ++i) {
        const double a = std::max(e[i], lo), b = std::min(e[i + 1], hi);
        if (b > a) p += (b - a) / (e[i + 1] - e[i]);
    }
    return p / m.increments();
}

} // namespace

TEST(VegasMap, StartsAsTheIdentity) {
    VegasMap m(3, 50);
    PointBlock u;
    u.reset(3, kBlockSize);
    u.n = 7;
    for (int j = 0; j < 3; ++j)
        for (size_t i = 0; i < u.n; ++i) u.coord(j)[i] = (i + 0.25 * j) / 8.0;
    PointBlock y = u;
    std::vector<double> jac(kBlockSize);
    m.apply_block(y, jac.data(), nullptr);
    for (int j = 0; j < 3; ++j)
        for (size_t i = 0; i < u.n; ++i) EXPECT_NEAR(y.coord(j)[i], u.coord(j)[i], 1e-15);
    for (size_t i = 0; i < u.n; ++i) EXPECT_NEAR(jac[i], 1.0, 1e-12);
}

// A separable product peak prod_j 1 / (c^-2 + (x_j - w_j)^2): its marginal on axis j puts
// half its mass (arctan) within 1/c of w_j, here an interval of length 2/c = 0.1. Training
// moves the map's probability there from 0.1 toward that half.
TEST(VegasMap, ConcentratesWhereTheMarginalHasItsMass) {
    const double c = 20.0, w[2] = {0.35, 0.7};
    VegasMap m(2, 200);
    Pcg32 rng(11u, 3u);
    PointBlock u;
    u.reset(2, kBlockSize);
    std::vector<double> jac(kBlockSize), weight(kBlockSize);
    std::vector<uint32_t> bins(2 * kBlockSize);
    for (int iteration = 0; iteration < 10; ++iteration) {
        for (int block = 0; block < 80; ++block) {
            u.n = kBlockSize;
            for (int j = 0; j < 2; ++j)
                for (size_t i = 0; i < u.n; ++i) u.coord(j)[i] = rng.next_double();
            m.apply_block(u, jac.data(), bins.data());
            for (size_t i = 0; i < u.n; ++i) {
                double f = 1.0;
                for (int j = 0; j < 2; ++j) {
                    const double t = u.coord(j)[i] - w[j];
                    f *= 1.0 / (1.0 / (c * c) + t * t);
                }
                weight[i] = f * jac[i];
            }
            m.add_training(bins.data(), weight.data(), u.n);
        }
        m.adapt(0.5, 0.05);
    }
    for (int j = 0; j < 2; ++j) {
        // The marginal's own share of [w - 1/c, w + 1/c] on [0, 1].
        auto marginal_cdf = [&](double x) { return std::atan(c * (x - w[j])); };
        const double half = (marginal_cdf(w[j] + 1 / c) - marginal_cdf(w[j] - 1 / c)) /
                            (marginal_cdf(1.0) - marginal_cdf(0.0));
        const double p = map_probability(m, j, w[j] - 1 / c, w[j] + 1 / c);
        EXPECT_GT(p, 0.6 * half) << "axis " << j << ": marginal share " << half;
        EXPECT_LT(p, 1.2 * half) << "axis " << j;
    }
}

// The map alone's even share is 5% of the whole map: each axis spreads 1 - 0.95^(1/d) of its
// probability evenly (vegas_resolved), so that a point is in the learnt part of every axis
// with probability 0.95, where 0.05 per axis left 0.95^d of them there (0.77 in d = 5); the
// other estimators keep 0.05 per axis. One adaptation of the identity map (K = 1000) to
// training data that is 1 on the first 20% of every axis and 0 elsewhere: [0.3, 1], beyond the
// smoothing's reach, holds 0.7 of the axis's share, up to the map's resolution 1 / K.
TEST(VegasMap, TheMapAlonesEvenShareIsTheWholeMaps) {
    const int k = 1000;
    for (int dim : {1, 2, 5}) {
        const double share =
            vegas_resolved(VegasOptions(), SamplerKind::Independent, false, dim).uniform_share;
        EXPECT_NEAR(std::pow(1.0 - share, dim), 0.95, 1e-12) << "d = " << dim;
        EXPECT_EQ(vegas_resolved(VegasOptions(), SamplerKind::Sobol, false, dim).uniform_share,
                  0.05);
        EXPECT_EQ(vegas_resolved(VegasOptions(), SamplerKind::Independent, true, dim).uniform_share,
                  0.05);
        VegasMap m(dim, k);
        std::vector<uint32_t> bins(static_cast<size_t>(dim) * kBlockSize);
        std::vector<double> weight(kBlockSize);
        for (int first = 0; first < k; first += static_cast<int>(kBlockSize)) {
            const int count = std::min(k - first, static_cast<int>(kBlockSize));
            for (int i = 0; i < count; ++i) {
                for (int j = 0; j < dim; ++j)
                    bins[static_cast<size_t>(j) * kBlockSize + i] =
                        static_cast<uint32_t>(first + i);
                weight[i] = first + i < k / 5 ? 1.0 : 0.0;
            }
            m.add_training(bins.data(), weight.data(), static_cast<size_t>(count));
        }
        m.adapt(1.0, share);
        for (int j = 0; j < dim; ++j)
            EXPECT_NEAR(map_probability(m, j, 0.3, 1.0), 0.7 * share, 1.0 / k)
                << "d = " << dim << ", axis " << j;
    }
    VegasOptions given;
    given.uniform_share = 0.2;
    EXPECT_EQ(vegas_resolved(given, SamplerKind::Independent, false, 5).uniform_share, 0.2);
}

TEST(VegasMap, AnAxisWithoutDataKeepsItsEdges) {
    VegasMap m(1, 10);
    std::vector<uint32_t> bins(kBlockSize, 3);
    std::vector<double> zero(kBlockSize, 0.0);
    m.add_training(bins.data(), zero.data(), 100);
    m.adapt(0.5, 0.05);
    for (int i = 0; i <= 10; ++i) EXPECT_NEAR(m.edges(0)[i], i / 10.0, 1e-15);
}

// Frozen-map estimates: R independent runs at N = 65536; the mean of the runs within 4 of its
// standard errors of the exact value, the 95% intervals covering it in [0.88, 0.995] of the
// runs (R = 200: 3.2 binomial standard deviations below 0.95), and a variance below uniform's.
TEST(VegasEstimator, UnbiasedCalibratedAndBetterThanUniform) {
    Made<SceneRequest> r = request(gaussian_scene(0.05, R"(["uniform", "vegas", "vegas_sobol"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    ASSERT_TRUE(problem.exact.has_value());
    const double exact = *problem.exact;
    const int runs = 200;
    double variance[3] = {0, 0, 0};
    for (size_t e = 0; e < 3; ++e) {
        const EstimatorSpec& spec = r.value.estimators[e];
        const test::IndependentRuns runs_of =
            test::independent_runs(problem, spec, 65536, runs, 2024, 7 + e, exact);
        EXPECT_TRUE(runs_of.every_n_reported) << spec.name; // training counts in N
        variance[e] = runs_of.variance;
        EXPECT_LE(std::fabs(runs_of.mean - exact), 4.0 * std::sqrt(variance[e] / runs))
            << spec.name;
        if (e > 0) {
            EXPECT_GE(runs_of.covered, static_cast<int>(0.88 * runs)) << spec.name;
            EXPECT_LE(runs_of.covered, static_cast<int>(0.995 * runs)) << spec.name;
        }
    }
    // Uniform's variance over the map's is F-distributed under equal variances; with
    // 199 and 199 degrees of freedom a ratio above 2 has p ~ 1e-6.
    EXPECT_GT(variance[0] / variance[1], 2.0);
    EXPECT_GT(variance[1] / variance[2], 2.0); // the same map on scrambled nets
}

// Genz's discontinuous family (f = exp(a . x) below u on every axis, 0 above): f is largest at
// the cut, and a map that let the region where f = 0 collapse into one increment reaching
// across the cut gave rare huge weights: error bars that miss (coverage 0.38 for vegas_sobol
// at N = 2^20) with no flag. The evenly spread share of increments keeps them honest.
TEST(VegasEstimator, HonestAcrossADiscontinuity) {
    for (const char* estimator : {"vegas", "vegas_sobol"}) {
        Made<SceneRequest> r = request(
            R"({"name": "d", "integrand": {"type": "genz_discontinuous", "a": [12, 8],
                "u": [0.2, 0.4]}, "estimators": [")" +
            std::string(estimator) + R"("]})");
        ASSERT_TRUE(r.ok()) << r.error;
        const test::IndependentRuns runs_of = test::independent_runs(
            r.value.problem, r.value.estimators[0], 1 << 18, 64, 77, 3, *r.value.problem.exact);
        const int covered = runs_of.covered;
        // Binomial(64, 0.95): 55 or fewer has probability 0.003.
        EXPECT_GE(covered, 56) << estimator;
    }
}

// The iteration average, as vegas and GSL report it: on a smooth peak its iterations agree (the
// pooled chi^2 raises no flag) and its mean is within 4 standard errors of the exact value;
// across a discontinuity with the even share turned off, the iterations disagree, and the flag
// says so where the frozen map's runs only show a heavy tail (the training pinned to the
// settings of 2026-12-02, alpha 0.5 and 10 whole iterations, whose map misjudges the cut).
TEST(VegasIterations, AgreeOnAPeakAndDisagreeAcrossACut) {
    StudySettings settings;
    settings.n_min = settings.n_max = 1 << 18;
    settings.reps = 32;
    settings.seed = 5;
    settings.threads = 2;
    Made<SceneRequest> peak =
        request(gaussian_scene(0.02, R"([{"name": "it", "vegas": {"report": "iterations"}}])"));
    ASSERT_TRUE(peak.ok()) << peak.error;
    StudyResult s = run_study(peak.value.problem, peak.value.estimators, settings);
    const LevelStats& l = s.estimators[0].levels[0];
    EXPECT_EQ(l.iteration_dof, 32 * 4); // 5 iterations per run
    EXPECT_LE(std::fabs(l.bias), 4.0 * l.std_error);
    for (const Flag& f : level_flags(l)) ADD_FAILURE() << flag_code_name(f.code);

    Made<SceneRequest> cut = request(
        R"({"name": "d", "integrand": {"type": "genz_discontinuous", "a": [12, 8],
            "u": [0.2, 0.4]}, "estimators": [{"name": "it",
            "vegas": {"report": "iterations", "uniform_share": 0, "alpha": 0.5,
                      "train_iterations": 10, "train_stop": "budget"}}]})");
    ASSERT_TRUE(cut.ok()) << cut.error;
    s = run_study(cut.value.problem, cut.value.estimators, settings);
    bool flagged = false;
    for (const Flag& f : level_flags(s.estimators[0].levels[0]))
        flagged = flagged || f.code == FlagCode::IterationsDisagree;
    EXPECT_TRUE(flagged);
}

// VEGAS+: hypercubes with points allocated by sigma_h^0.75 on top of the map. On a peak of
// width 0.05 it beats the map alone (F test as above), and its stratified error bar (per
// hypercube variances, Satterthwaite's degrees of freedom) covers as it should.
TEST(VegasPlus, UnbiasedCalibratedAndBetterThanTheMapAlone) {
    Made<SceneRequest> r = request(gaussian_scene(0.05, R"(["vegas", "vegas_plus"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const double exact = *problem.exact;
    const int runs = 200;
    double variance[2] = {0, 0};
    for (size_t e = 0; e < 2; ++e) {
        const test::IndependentRuns runs_of =
            test::independent_runs(problem, r.value.estimators[e], 65536, runs, 4048, 9 + e, exact);
        EXPECT_TRUE(runs_of.every_n_reported);
        variance[e] = runs_of.variance;
        EXPECT_LE(std::fabs(runs_of.mean - exact), 4.0 * std::sqrt(variance[e] / runs));
        EXPECT_GE(runs_of.covered, static_cast<int>(0.88 * runs)) << e;
        EXPECT_LE(runs_of.covered, static_cast<int>(0.995 * runs)) << e;
    }
    EXPECT_GT(variance[0] / variance[1], 2.0);
}

TEST(VegasPlus, OnePointRunHasNoErrorBar) {
    Made<SceneRequest> r = request(gaussian_scene(0.1, R"(["vegas_plus"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    Pcg32 rng(5u, 2u);
    const RunResult run = run_estimate(r.value.problem, r.value.estimators[0], 1, rng, ws);
    EXPECT_EQ(run.n, 1u);
    EXPECT_TRUE(std::isfinite(run.estimate));
    EXPECT_TRUE(std::isnan(run.std_error));
}

// The sample view: the points the frozen map's estimate is made from (not the training ones),
// and the map's edges, increasing from 0 to 1 on each axis.
TEST(VegasEstimator, SampleDumpShowsTheEstimatePointsAndTheMap) {
    Made<SceneRequest> r = request(gaussian_scene(0.05, R"(["vegas"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    const SampleDump d = dump_samples(r.value.problem, r.value.estimators[0], 4096, 1);
    EXPECT_EQ(d.weight.size(), 4096u - 1024u); // a quarter trains the map
    ASSERT_EQ(d.adaptive.edges.size(), 2u);
    for (const std::vector<double>& e : d.adaptive.edges) {
        ASSERT_GE(e.size(), 3u);
        EXPECT_EQ(e.front(), 0.0);
        EXPECT_EQ(e.back(), 1.0);
        for (size_t i = 1; i < e.size(); ++i) EXPECT_LE(e[i - 1], e[i]);
    }
    for (double w : d.weight) EXPECT_TRUE(std::isfinite(w));
}

// The map's history for the animation: asked to show 256 points of a run of 2^16 calls, the
// dump holds 256 estimate points and the map before training and after each of its 10
// training iterations, on 2 axes, thinned to at most 65 edges; the first snapshot is the
// identity, the last is the frozen map's edges thinned, and the peak at 0.3 draws edges in.
TEST(VegasEstimator, SampleDumpKeepsTheMapOfEveryTrainingIteration) {
    Made<SceneRequest> r = request(gaussian_scene(0.05, R"(["vegas", "vegas_plus"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    for (const EstimatorSpec& spec : r.value.estimators) {
        const SampleDump d = dump_samples(r.value.problem, spec, 256, 1, 65536);
        EXPECT_EQ(d.weight.size(), 256u) << spec.name;
        const auto& h = d.adaptive.history;
        // The identity and one map per training iteration: 3 to 20 of them (settled early).
        ASSERT_GE(h.size(), 4u) << spec.name;
        ASSERT_LE(h.size(), 21u) << spec.name;
        for (const auto& snapshot : h) {
            ASSERT_EQ(snapshot.size(), 2u);
            for (const std::vector<double>& e : snapshot) {
                ASSERT_GE(e.size(), 3u);
                EXPECT_LE(e.size(), 65u);
                EXPECT_EQ(e.front(), 0.0);
                EXPECT_EQ(e.back(), 1.0);
            }
        }
        const size_t m = h[0][0].size() - 1;
        for (size_t i = 0; i <= m; ++i) EXPECT_NEAR(h[0][0][i], double(i) / m, 1e-12);
        const std::vector<double>& frozen = d.adaptive.edges[0];
        const size_t step = (frozen.size() - 1) / m;
        for (size_t i = 0; i <= m; ++i) EXPECT_EQ(h.back()[0][i], frozen[i * step]);
        // Share of the thinned edges within 0.1 of the peak (0.3 on axis 0): 0.2 for the
        // identity, at least twice that once trained (vegas_plus's nested map has K = 10 here:
        // 11 edges, 5 of them near the peak).
        auto near_peak = [](const std::vector<double>& e) {
            int c = 0;
            for (double v : e) c += std::fabs(v - 0.3) < 0.1;
            return static_cast<double>(c) / e.size();
        };
        EXPECT_GT(near_peak(h.back()[0]), 0.4) << spec.name;
    }
}

// Runs of 1 to 40 calls (the sample view asks for as few as 1): every preset finishes, reports
// its n, and estimates; vegas_sobol's net rounding never asks for more points than n.
TEST(VegasEstimator, TinyRunsFinish) {
    Made<SceneRequest> r =
        request(gaussian_scene(0.1, R"(["vegas", "vegas_sobol", "vegas_plus"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    for (const EstimatorSpec& spec : r.value.estimators)
        for (uint64_t n = 1; n <= 40; ++n) {
            Pcg32 rng(5u, n);
            const RunResult run = run_estimate(r.value.problem, spec, n, rng, ws);
            EXPECT_EQ(run.n, n) << spec.name;
            EXPECT_TRUE(std::isfinite(run.estimate)) << spec.name << " n=" << n;
        }
}

// The calls and time spent learning are reported (the time plot draws them): with
// "train_stop": "budget", a quarter of N trains vegas and vegas_plus, half of 2^16 trains
// vegas_sobol (its estimate takes K 2^m points), as by default; at most that;
// MISER's probes are some of N, a fixed estimator learns nothing.
TEST(VegasEstimator, TrainingCallsAndTimeAreReported) {
    Made<SceneRequest> r =
        request(gaussian_scene(0.1, R"([{"name": "vb", "vegas": {"train_stop": "budget"}},
                 {"name": "vsb", "sampler": "sobol", "vegas": {"train_stop": "budget"}},
                 {"name": "vpb", "vegas": {"stratify": true, "train_stop": "budget"}},
                 "vegas", "vegas_sobol", "vegas_plus", "miser", "uniform"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    const uint64_t n = 65536;
    const uint64_t expected[] = {n / 4, n / 2, n / 4, n / 4, n / 2, n / 4};
    for (size_t e = 0; e < r.value.estimators.size(); ++e) {
        Pcg32 rng(8u, e);
        const RunResult run = run_estimate(r.value.problem, r.value.estimators[e], n, rng, ws);
        const std::string& name = r.value.estimators[e].name;
        EXPECT_EQ(run.n, n) << name;
        if (e < 3) {
            EXPECT_EQ(run.training_n, expected[e]) << name;
        } else if (e < 6) {
            EXPECT_GT(run.training_n, 0u) << name;
            EXPECT_LE(run.training_n, expected[e]) << name;
        }
        if (name == "miser") {
            EXPECT_GT(run.training_n, 0u);
            EXPECT_LT(run.training_n, n);
        }
        if (name == "uniform") {
            EXPECT_EQ(run.training_n, 0u);
        }
        EXPECT_GE(run.training_seconds, 0.0) << name;
        EXPECT_LE(run.training_seconds, run.seconds) << name;
        EXPECT_EQ(run.training_seconds > 0.0, run.training_n > 0) << name;
    }
}

TEST(VegasOptions, BadValuesAreNamed) {
    struct Case {
        const char* options;
        const char* field;
    } cases[] = {
        {R"({"alpha": -1})", "vegas.alpha"},
        {R"({"train_fraction": 0.95})", "vegas.train_fraction"},
        {R"({"train_iterations": 0})", "vegas.train_iterations"},
        {R"({"increments": 3000000})", "vegas.increments"},
        {R"({"increments": 0})", "vegas.increments"},
        {R"({"uniform_share": 1.5})", "vegas.uniform_share"},
        {R"({"report": "average"})", "vegas.report"},
        {R"({"report": "iterations", "iterations": 1})", "vegas.iterations"},
        {R"({"beta": 3})", "vegas.beta"},
        {R"({"stratify": 1})", "vegas.stratify"},
        {R"({"stratify": true, "report": "iterations"})", "vegas.report"},
        {R"({"bins": 4})", "unknown field 'bins'"},
        {R"({"train_stop": "never"})", "vegas.train_stop"},
    };
    for (const Case& c : cases) {
        Made<SceneRequest> r = request(
            gaussian_scene(0.1, std::string(R"([{"name": "v", "vegas": )") + c.options + "}]"));
        ASSERT_FALSE(r.ok()) << c.options;
        EXPECT_NE(r.error.find(c.field), std::string::npos) << r.error;
    }
}

namespace {

// Genz's product peak prod_j 1 / (a^-2 + (x_j - u_j)^2), every a_j = a, in d dimensions.
std::string product_peak_scene(double a, int d, const std::string& estimators) {
    std::string as, us;
    for (int j = 0; j < d; ++j) {
        as += (j ? ", " : "") + std::to_string(a);
        us += (j ? ", " : "") + std::to_string(0.2 + 0.6 * j / std::max(1, d - 1));
    }
    return R"({"name": "pp", "integrand": {"type": "genz_product_peak", "a": [)" + as +
           R"(], "u": [)" + us + R"(]}, "estimators": )" + estimators + "}";
}

} // namespace

// The unit test of the rule: a variance and a movement that keep falling never settle; flat
// ones with agreeing estimates settle on the third iteration; flat ones whose estimates
// disagree by 10 standard errors do not; a non-finite variance never settles.
TEST(VegasTraining, TrainingStopRule) {
    TrainingStop falling;
    for (int i = 0; i < 30; ++i)
        EXPECT_FALSE(falling.settled(1.0, std::pow(0.8, i), 1000, std::pow(0.8, i)));
    TrainingStop flat;
    EXPECT_FALSE(flat.settled(1.0, 1.0, 1000, 0.01));
    EXPECT_FALSE(flat.settled(1.0, 0.97, 1000, 0.0099));
    EXPECT_TRUE(flat.settled(1.01, 0.99, 1000, 0.0101));
    TrainingStop disagree; // se = sqrt(1 / 1000) = 0.032 per iteration
    EXPECT_FALSE(disagree.settled(1.0, 1.0, 1000, 0.01));
    EXPECT_FALSE(disagree.settled(1.0, 1.0, 1000, 0.01));
    EXPECT_FALSE(disagree.settled(1.45, 1.0, 1000, 0.01));
    TrainingStop broken;
    for (int i = 0; i < 5; ++i) EXPECT_FALSE(broken.settled(1.0, std::nan(""), 1000, 0.01));
}

// A variance that jumps above kVegasSettleRise times its least (the iteration's points found a
// peak the map had under-sampled; its few large weights also make the estimates "agree" within
// their wide error bars) counts as the map still changing: two more flat iterations are needed.
TEST(VegasTraining, AVarianceThatRisesIsNotSettled) {
    TrainingStop stop;
    EXPECT_FALSE(stop.settled(1.0, 1.0, 1000, 0.01));
    EXPECT_FALSE(stop.settled(1.0, 0.99, 1000, 0.01));
    EXPECT_FALSE(stop.settled(1.5, 30.0, 1000, 0.01)); // flat M, agreeing: settled without the rise
    EXPECT_FALSE(stop.settled(1.0, 1.0, 1000, 0.01));
    EXPECT_TRUE(stop.settled(1.0, 1.0, 1000, 0.01));
    TrainingStop noise; // within the factor: stalled as before
    EXPECT_FALSE(noise.settled(1.0, 1.0, 1000, 0.01));
    EXPECT_FALSE(noise.settled(1.0, 1.0, 1000, 0.01));
    EXPECT_TRUE(noise.settled(1.0, 1.9, 1000, 0.01));
}

// The defaults per estimator (vegas_resolved): the map alone (independent points, frozen)
// trains with damping 1 for up to 20 iterations until settled; stratified or QMC points after
// the map, VEGAS+ and the iteration average keep vegas's 0.5 and 10 whole iterations; a field
// the scene sets is kept, and a "vegas" object that leaves train_stop out gets the default.
TEST(VegasOptions, DefaultsPerEstimator) {
    Made<SceneRequest> r = request(gaussian_scene(0.1, R"(["vegas", "vegas_sobol", "vegas_plus",
                 {"name": "it", "vegas": {"report": "iterations"}},
                 {"name": "strata", "sampler": "stratified", "vegas": {}},
                 {"name": "a07", "vegas": {"alpha": 0.7}},
                 {"name": "sobol_settled", "sampler": "sobol",
                  "vegas": {"train_stop": "settled", "train_iterations": 30}}])"));
    ASSERT_TRUE(r.ok()) << r.error;
    struct Want {
        double alpha;
        int iterations;
        VegasTrainStop stop;
    } want[] = {{1.0, 20, VegasTrainStop::Settled}, {0.5, 10, VegasTrainStop::Budget},
                {0.5, 10, VegasTrainStop::Budget},  {0.5, 10, VegasTrainStop::Budget},
                {0.5, 10, VegasTrainStop::Budget},  {0.7, 20, VegasTrainStop::Settled},
                {0.5, 30, VegasTrainStop::Settled}};
    ASSERT_EQ(r.value.estimators.size(), 7u);
    for (size_t e = 0; e < 7; ++e) {
        const EstimatorSpec& spec = r.value.estimators[e];
        const bool plus = std::string(spec.kind->name) == "vegas_plus";
        const VegasOptions o = vegas_resolved(spec.vegas_options, spec.sampler, plus, 2);
        EXPECT_EQ(o.alpha, want[e].alpha) << spec.name;
        EXPECT_EQ(o.train_iterations, want[e].iterations) << spec.name;
        EXPECT_TRUE(o.train_stop == want[e].stop) << spec.name;
        const bool alone = want[e].stop == VegasTrainStop::Settled && want[e].alpha > 0.5;
        EXPECT_DOUBLE_EQ(o.uniform_share, alone ? 1.0 - std::sqrt(0.95) : 0.05) << spec.name;
    }
}

// The default increments are sized by the training share split in kVegasSizingIterations
// (about 100 points per increment there), not by the actual iterations: 20 iterations of
// 13107 points in d = 2 keep the 262 increments of 10 iterations; at most 1/10 of an
// iteration's points, and the caps of vegas_increments, still hold.
TEST(VegasOptions, IncrementsSizedByTheTrainingShare) {
    const VegasOptions o;
    EXPECT_EQ(vegas_trainable_increments(o, 2, 13107, 262144), 262);
    EXPECT_EQ(vegas_trainable_increments(o, 2, 13107), 131);
    EXPECT_EQ(vegas_trainable_increments(o, 2, 1000, 100000), 100); // 10 per increment
    EXPECT_EQ(vegas_trainable_increments(o, 6, 100000, 4000000), 500);
    VegasOptions given;
    given.increments = 50;
    EXPECT_EQ(vegas_trainable_increments(given, 2, 13107, 262144), 50);
}

// Error bars on a sharp product peak (a = 200, d = 4) cover: 100 seeded runs of 2^16 calls for
// vegas and vegas_plus; under honest 95% intervals Binomial(100, 0.95) is 87 or fewer with
// probability 0.0043, and the mean is within 4 standard errors of the exact value.
TEST(VegasTraining, ErrorBarsCoverOnASharpPeak) {
    Made<SceneRequest> r = request(product_peak_scene(200.0, 4, R"(["vegas", "vegas_plus"])"));
    ASSERT_TRUE(r.ok()) << r.error;
    const double exact = *r.value.problem.exact;
    const int runs = 100;
    for (size_t e = 0; e < 2; ++e) {
        const EstimatorSpec& spec = r.value.estimators[e];
        const test::IndependentRuns of =
            test::independent_runs(r.value.problem, spec, 1 << 16, runs, 4242, 11 + e, exact);
        EXPECT_GE(of.covered, 88) << spec.name;
        EXPECT_LE(std::fabs(of.mean - exact), 4.0 * std::sqrt(of.variance / runs)) << spec.name;
    }
}

// The map alone's defaults (alpha 1, up to 20 iterations until settled, 5% of the whole map
// spread evenly) against vegas's settings (the defaults before 2026-12-04: 0.5, 10 whole
// iterations, 0.05 on each axis) on a sharp product peak, a = 500 in d = 6, 64 seeded runs of
// 2^17 calls each: the variance falls by far more than the factor 3.5 that has probability
// about 1e-6 under equal variances (F with 63 and 63 degrees of freedom), the mean is within 4
// standard errors of the exact value and the intervals cover (Binomial(64, 0.95): 55 or fewer
// has probability 0.003).
TEST(VegasTraining, TheMapAlonesDefaultsWinOnASharpPeak) {
    Made<SceneRequest> r = request(
        product_peak_scene(500.0, 6, R"(["vegas", {"name": "vegas_settings", "vegas": {"alpha": 0.5,
            "train_iterations": 10, "train_stop": "budget", "uniform_share": 0.05}}])"));
    ASSERT_TRUE(r.ok()) << r.error;
    const double exact = *r.value.problem.exact;
    const int runs = 64;
    double variance[2] = {0, 0};
    for (size_t e = 0; e < 2; ++e) {
        const EstimatorSpec& spec = r.value.estimators[e];
        const test::IndependentRuns of =
            test::independent_runs(r.value.problem, spec, 1 << 17, runs, 500, 6 + e, exact);
        variance[e] = of.variance;
        if (e == 0) {
            EXPECT_GE(of.covered, 56) << spec.name;
            EXPECT_LE(std::fabs(of.mean - exact), 4.0 * std::sqrt(of.variance / runs));
        }
    }
    EXPECT_GT(variance[1] / variance[0], 3.5);
}

// 64-D with 65536 increments per axis used to collapse: 1,250 training points per iteration
// could not train them, the map followed the noise, and the product of 64 noisy Jacobian
// factors gave estimates of 1e-164. The run caps the increments at what its iterations can
// train (kVegasPointsPerIncrement points each) and estimates within 5 standard errors; a study
// whose largest N cannot train them is refused, naming the field.
TEST(VegasTraining, HighDimensionalMapDoesNotCollapse) {
    Made<SceneRequest> r = request(
        R"({"name": "g64", "integrand": {"type": "genz_gaussian", "dim": 64, "seed": 3},
            "estimators": ["vegas"]})");
    ASSERT_TRUE(r.ok()) << r.error;
    const double exact = *r.value.problem.exact;
    EstimatorSpec spec = r.value.estimators[0];
    spec.vegas_options.increments = 65536;
    Workspace ws;
    for (uint64_t seed = 0; seed < 4; ++seed) {
        Pcg32 rng(64u, seed);
        const RunResult run = run_estimate(r.value.problem, spec, 100000, rng, ws);
        ASSERT_TRUE(std::isfinite(run.estimate) && std::isfinite(run.std_error));
        EXPECT_LE(std::fabs(run.estimate - exact), 5.0 * run.std_error) << "seed " << seed;
        EXPECT_LT(run.std_error, 0.1 * exact) << "seed " << seed;
    }
    EXPECT_EQ(vegas_trainable_increments(spec.vegas_options, 64, 1250), 125);
    Made<SceneRequest> refused = request(
        R"({"name": "g64", "integrand": {"type": "genz_gaussian", "dim": 64, "seed": 3},
            "n_max": 100000, "estimators": [{"name": "v", "vegas": {"increments": 65536}}]})");
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error.find("vegas.increments = 65536"), std::string::npos) << refused.error;
    Made<SceneRequest> fine = request(
        R"({"name": "g64", "integrand": {"type": "genz_gaussian", "dim": 64, "seed": 3},
            "n_max": 100000, "estimators": [{"name": "v", "vegas": {"increments": 100}}]})");
    EXPECT_TRUE(fine.ok()) << fine.error;
}

// VEGAS+'s hypercubes per axis: the largest m with m^d hypercubes of about 4 points each, at
// most 2^20 of them. The estimate sizes its own grid this way from its own points (a multiple of
// the training grid's), where it once kept the training iteration's (about 30 points per
// hypercube at the default 10 training iterations).
TEST(VegasPlus, HypercubesPerAxisHoldAboutFourPointsEach) {
    for (int dim : {1, 2, 3, 6}) {
        for (uint64_t points : {uint64_t(1), uint64_t(7), uint64_t(65536), uint64_t(750000)}) {
            const uint64_t m = vegas_plus_per_axis(dim, points);
            ASSERT_GE(m, 1u);
            const double cubes = std::pow(static_cast<double>(m), dim);
            const double more = std::pow(static_cast<double>(m + 1), dim);
            if (m > 1) {
                EXPECT_LE(4.0 * cubes, static_cast<double>(points)) << dim << " " << points;
            }
            EXPECT_TRUE(4.0 * more > static_cast<double>(points) ||
                        more > static_cast<double>(kVegasMaxHypercubes))
                << "m + 1 would still fit: dim " << dim << ", points " << points;
        }
    }
    EXPECT_EQ(vegas_plus_per_axis(2, 750000), 433u); // 433^2 * 4 = 749,956
    EXPECT_EQ(vegas_plus_per_axis(1, uint64_t(1) << 30), kVegasMaxHypercubes);
}

// The siblings' median without one of them (VEGAS+'s pilot share must not depend on a
// hypercube's own pilot points): against sorting the others, for every value of groups of 2 to
// 9 values with and without ties, and the median of all n left at first + n / 2. A median
// that kept the value itself fails on either side of it: the largest value's others have a
// median below the group's, the smallest's above it (n = 4: 1 2 | 3 4).
TEST(VegasPlus, MedianWithoutOneLeavesTheValueOut) {
    Pcg32 rng(4901, 58);
    for (int n = 2; n <= 9; ++n) {
        for (int trial = 0; trial < 50; ++trial) {
            std::vector<double> group(static_cast<size_t>(n));
            for (double& v : group) // few distinct values in half the trials: ties
                v = trial % 2 ? std::floor(4.0 * rng.next_double()) : rng.next_double();
            std::vector<double> work = group;
            const MedianWithoutOne m = median_without_one(work.data(), work.data() + n);
            std::vector<double> sorted = group;
            std::sort(sorted.begin(), sorted.end());
            EXPECT_EQ(work[static_cast<size_t>(n / 2)], sorted[static_cast<size_t>(n / 2)]);
            for (int i = 0; i < n; ++i) {
                std::vector<double> others = group;
                others.erase(others.begin() + i);
                std::sort(others.begin(), others.end());
                EXPECT_EQ(m.of(group[static_cast<size_t>(i)]), others[others.size() / 2])
                    << "n " << n << ", trial " << trial << ", value " << i;
            }
        }
    }
    double four[] = {3.0, 1.0, 4.0, 2.0};
    const MedianWithoutOne m = median_without_one(four, four + 4);
    EXPECT_EQ(m.of(4.0), 2.0); // others 1 2 3
    EXPECT_EQ(m.of(1.0), 3.0); // others 2 3 4
    EXPECT_EQ(four[2], 3.0);   // the median of all four: the sorted value 2
}

// A power singularity at a corner, x^-0.45 y^-0.2 (finite variance: 2 * 0.45 < 1): VEGAS and
// VEGAS+ stay unbiased (the mean of 100 seeded runs within 4 standard errors) and their error
// bars cover. The weights' tail is heavy (w^2 has a tail index near 1.1), so a run's error bar
// is a little short more often than a Gaussian's: coverage of the nominal 95% intervals at or
// above 85 of 100 (a fair 95% coin gives 85 or fewer with probability 3e-4), and not every run
// covering at 95% either way (100 of 100 has probability 0.006).
TEST(VegasPlus, HonestOnACornerSingularity) {
    Made<SceneRequest> r = request(R"({"name": "corner", "domain": {"type": "box", "dim": 2},
        "integrand": {"type": "monomial", "powers": [-0.45, -0.2]},
        "estimators": ["vegas", "vegas_plus"]})");
    ASSERT_TRUE(r.ok()) << r.error;
    const double exact = *r.value.problem.exact;
    EXPECT_NEAR(exact, 1.0 / (0.55 * 0.8), 1e-12);
    const int runs = 100;
    for (const EstimatorSpec& spec : r.value.estimators) {
        const test::IndependentRuns of =
            test::independent_runs(r.value.problem, spec, 1 << 16, runs, 4949, 49, exact);
        EXPECT_TRUE(of.every_n_reported) << spec.name;
        EXPECT_LE(std::fabs(of.mean - exact), 4.0 * std::sqrt(of.variance / runs)) << spec.name;
        EXPECT_GE(of.covered, 85) << spec.name;
        EXPECT_LT(of.covered, 100) << spec.name;
    }
}

// VEGAS+ trains its map on the errors where its hypercubes are at least as fine as the map's
// increments (1-D here: 2^18 calls, a training iteration's 1638 hypercubes, 26 in each of K = 63):
// a point counts with its squared deviation from its hypercube's mean, as GSL's stratified mode
// does. At x^-0.45 the increments then pile into the singular corner far below the width of
// the first increment of the map with equal mass per increment, K^(-1/(1-a)) (the optimum of
// the map alone, whose increments hold equal shares of f): the variance there comes from
// within the first hypercubes, which shrink until it is spent. Judged both ways: at x^2, which
// vanishes at 0 with its slope, the first increment stays wider than the even 1/K (not x^0.45:
// its slope is singular at 0, and with alpha 1.5 the error-trained map narrows there too).
TEST(VegasPlus, MapTrainedOnTheErrorsPilesIntoASingularCorner) {
    for (const double a : {0.45, -2.0}) {
        const std::string power = std::to_string(-a);
        Made<SceneRequest> r = request(R"({"name": "c", "domain": {"type": "box", "dim": 1},
            "integrand": {"type": "monomial", "powers": [)" +
                                       power + R"(]}, "estimators": ["vegas_plus"]})");
        ASSERT_TRUE(r.ok()) << r.error;
        const SampleDump d = dump_samples(r.value.problem, r.value.estimators[0], 256, 1, 1 << 18);
        ASSERT_EQ(d.adaptive.edges.size(), 1u);
        const std::vector<double>& e = d.adaptive.edges[0];
        const double k = static_cast<double>(e.size() - 1);
        ASSERT_GE(k, 32.0);
        if (a > 0) { // singular: far below the equal-mass map's first edge
            EXPECT_LT(e[1], 0.01 * std::pow(k, -1.0 / (1.0 - a))) << "K " << k;
        } else {
            EXPECT_GT(e[1], 1.0 / k) << "K " << k;
        }
    }
}

// VEGAS+'s nested mode (GSL's stratified mode): where a training iteration has at least
// kVegasPlusNestedAxis hypercubes per axis and the training runs kVegasSizingIterations
// iterations, the default increments are cut to a whole number of hypercubes each, and the map
// trains on the hypercubes' errors with damping kVegasNestedAlpha, the training's hypercubes
// then of 2 points each. Judged both ways on the map's size: 2-D at 2^18 calls (40 hypercubes
// per axis of 4 points in each of 10 training iterations of 6553 points, where the default K
// would be 65) gets K = 57, the hypercubes per axis at 2 points each; 4-D (8 per axis) and 2-D
// at 2^15 (8 training iterations) keep the default K, trained on w^2.
TEST(VegasPlus, NestedModeWhereHypercubesAreFineEnough) {
    struct Case {
        int dim;
        uint64_t n;
        bool nested;
    };
    for (const Case c : {Case{2, uint64_t(1) << 18, true}, Case{4, uint64_t(1) << 18, false},
                         Case{2, uint64_t(1) << 15, false}}) {
        Made<SceneRequest> r = request(R"({"name": "c", "domain": {"type": "box", "dim": )" +
                                       std::to_string(c.dim) + R"(},
            "integrand": {"type": "gaussian", "center": )" +
                                       (c.dim == 2 ? "[0.3, 0.6]" : "[0.3, 0.6, 0.4, 0.5]") +
                                       R"(, "sigma": 0.2},
            "estimators": ["vegas_plus"]})");
        ASSERT_TRUE(r.ok()) << r.error;
        const SampleDump d = dump_samples(r.value.problem, r.value.estimators[0], 16, 1, c.n);
        ASSERT_EQ(d.adaptive.edges.size(), static_cast<size_t>(c.dim));
        const size_t k = d.adaptive.edges[0].size() - 1;
        const VegasOptions defaults;
        const uint64_t train = c.n / 4;
        const int iterations = vegas_training_iterations(
            vegas_resolved(defaults, SamplerKind::Independent, true, c.dim), train);
        const uint64_t per_iteration = train / static_cast<uint64_t>(iterations);
        const size_t k_default = vegas_trainable_increments(defaults, c.dim, per_iteration, train);
        const uint64_t m = vegas_plus_per_axis(c.dim, per_iteration);
        if (c.nested) {
            ASSERT_GE(m, kVegasPlusNestedAxis);
            ASSERT_EQ(iterations, kVegasSizingIterations);
            const uint64_t m2 = vegas_plus_per_axis(c.dim, 2 * per_iteration); // 2 points each
            ASSERT_NE(m2 % k_default, 0u); // else K could not tell M from the default
            EXPECT_EQ(m2 % k, 0u) << "K " << k << " M " << m2;
            EXPECT_EQ(m2 / k, (m2 + k_default - 1) / k_default) << "K " << k << " M " << m2;
            EXPECT_NE(m % k, 0u) << "K " << k << " M at 4 points " << m;
            EXPECT_LT(k, k_default);
        } else {
            EXPECT_TRUE(m < kVegasPlusNestedAxis || iterations < kVegasSizingIterations);
            EXPECT_EQ(k, k_default) << "d " << c.dim << " n " << c.n;
        }
    }
}

// The nested mode against the map trained on w^2 with the default increments (what VEGAS+ did
// before; an explicit K keeps it): on x^-0.45 y^-0.2 at 2^18 calls the estimates' variance over
// 30 seeded runs each falls more than 4-fold (measured 35-fold at R = 40; under equal variances
// the ratio of two 30-run variances exceeds 3.1 with probability 0.001), both unbiased (4
// standard errors).
TEST(VegasPlus, NestedModeLowersTheVarianceOnACornerSingularity) {
    Made<SceneRequest> r = request(R"({"name": "corner", "domain": {"type": "box", "dim": 2},
        "integrand": {"type": "monomial", "powers": [-0.45, -0.2]},
        "estimators": ["vegas_plus",
                       {"name": "w2", "vegas": {"stratify": true, "increments": 65}}]})");
    ASSERT_TRUE(r.ok()) << r.error;
    const double exact = *r.value.problem.exact;
    const int runs = 30;
    std::vector<test::IndependentRuns> of;
    for (const EstimatorSpec& spec : r.value.estimators) {
        of.push_back(test::independent_runs(r.value.problem, spec, 1 << 18, runs, 5151, 51, exact));
        EXPECT_LE(std::fabs(of.back().mean - exact), 4.0 * std::sqrt(of.back().variance / runs))
            << spec.name;
    }
    EXPECT_LT(4.0 * of[0].variance, of[1].variance)
        << "nested " << of[0].variance << ", w^2-trained " << of[1].variance;
}

// 64 seeded vegas_plus runs of each integrand at 2^16 calls on the unit box of `dim`: at least 56
// covered by the t interval and the mean within 4 standard errors of the exact value.
void expect_vegas_plus_honest(int dim, std::initializer_list<const char*> integrands, uint64_t seed,
                              uint64_t stream) {
    for (const char* integrand : integrands) {
        Made<SceneRequest> r = request(
            R"({"name": "honest", "domain": {"type": "box", "dim": )" + std::to_string(dim) +
            R"(}, "integrand": )" + std::string(integrand) + R"(, "estimators": ["vegas_plus"]})");
        ASSERT_TRUE(r.ok()) << r.error;
        const int runs = 64;
        const test::IndependentRuns of =
            test::independent_runs(r.value.problem, r.value.estimators[0], 1 << 16, runs, seed,
                                   stream, *r.value.problem.exact);
        EXPECT_GE(of.covered, 56) << integrand;
        EXPECT_LE(std::fabs(of.mean - *r.value.problem.exact), 4.0 * std::sqrt(of.variance / runs))
            << integrand;
    }
}

// VEGAS+'s error bars in 1-D where one hypercube holds the variance (issue 49): a cut (Genz's
// discontinuous family) and a corner singularity x^-0.43 (finite variance). The estimate's
// hypercubes are finer than the training's; sized by sigma_h inherited from their parents,
// the child holding the cut got 2 points, missed it, and the error bar missed by 100+ standard
// errors (45 and 51 of 64 runs covered at 2^16 calls, 2026-12-07). The pilot that measures the
// finer hypercubes first keeps both honest: of 64 seeded runs at least 56 covered by the t
// interval (a fair 95% coin gives 55 or fewer with probability 0.003, 2.8 binomial standard
// errors of 1.74 below its mean 60.8), and the mean within 4 standard errors of the exact value.
TEST(VegasPlus, HonestIn1DOnACutAndASingularity) {
    expect_vegas_plus_honest(1,
                             {R"({"type": "genz_discontinuous", "a": [5], "u": [0.37]})",
                              R"({"type": "monomial", "powers": [-0.43]})"},
                             777, 5);
}

// In d >= 2 the pilot's points count in VEGAS+'s estimate, with a share per hypercube that its
// own pilot points do not set (min(0.25, 2 / (2 + n_h)), n_h from its neighbours' means and its
// siblings' variances), and the hypercubes' sigma_h are at least their siblings' median (issue
// 49). Both must leave the estimate unbiased and its
// error bar honest where the variance sits in few hypercubes: a cut and a corner singularity
// x^-0.45 y^-0.2, as above.
TEST(VegasPlus, PilotInTheEstimateHonestIn2D) {
    expect_vegas_plus_honest(2,
                             {R"({"type": "genz_discontinuous", "a": [5, 3], "u": [0.37, 0.61]})",
                              R"({"type": "monomial", "powers": [-0.45, -0.2]})"},
                             5353, 53);
}
