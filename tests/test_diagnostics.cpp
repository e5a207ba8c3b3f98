// Diagnostics as data (estimators/diagnostics.h): the flags real studies raise, with their
// evidence, read directly from the core without going through JSON.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <tuple>

#include "api/report.h"
#include "api/scene.h"
#include "core/rng.h"
#include "core/special.h"
#include "core/stats.h"
#include "estimators/accumulator.h"
#include "estimators/diagnostics.h"

using namespace mcp;

namespace {

StudyResult study(const std::string& scene_name, const Json& options) {
    std::ifstream in(std::string(MCPLAY_SOURCE_DIR) + "/scenes/" + scene_name + ".json");
    std::stringstream ss;
    ss << in.rdbuf();
    Made<Json> j = parse_json(ss.str().c_str(), scene_name.c_str());
    EXPECT_TRUE(j.ok()) << j.error;
    Made<SceneRequest> r = build_request(j.value, options);
    EXPECT_TRUE(r.ok()) << r.error;
    return run_study(r.value.problem, r.value.estimators, r.value.settings);
}

const EstimatorStudy& named(const StudyResult& s, const std::string& name) {
    for (const EstimatorStudy& e : s.estimators)
        if (e.spec.name == name) return e;
    ADD_FAILURE() << "no estimator " << name;
    return s.estimators.at(0);
}

bool has(const std::vector<Flag>& flags, FlagCode code) {
    return std::any_of(flags.begin(), flags.end(), [&](const Flag& f) { return f.code == code; });
}

} // namespace

// The accumulator's top weights (for the tail index) are the kTailWeights largest |w|,
// decreasing, however the blocks bring them: rising weights (each block beats the threshold),
// falling ones, and random ones, in blocks of every size; a merge keeps the largest of both.
TEST(Diagnostics, TopWeightsAreTheLargest) {
    Pcg32 rng(5, 9);
    for (int order = 0; order < 3; ++order) {
        const size_t total = 5 * kTailWeights + 777;
        std::vector<double> f(total), p(total, 1.0), w(total);
        for (size_t i = 0; i < total; ++i)
            f[i] = order == 0 ? static_cast<double>(i)
                              : (order == 1 ? -static_cast<double>(total - i) : rng.next_double());
        WeightAccumulator a, later;
        a.reset(ErrorMethod::Iid, total, 1, false);
        later.reset(ErrorMethod::Iid, total, 1, false);
        const size_t half = total / 2 & ~size_t(1);
        for (size_t first = 0; first < total;) {
            const size_t count =
                std::min<size_t>(2 * (1 + rng.next_below(kBlockSize / 2)), total - first);
            (first < half ? a : later)
                .add_block(first, f.data() + first, p.data() + first, w.data() + first, count);
            first += count;
        }
        a.merge(later);
        std::vector<double> expected(total);
        for (size_t i = 0; i < total; ++i) expected[i] = std::fabs(f[i]);
        std::sort(expected.begin(), expected.end(), std::greater<double>());
        expected.resize(kTailWeights);
        EXPECT_EQ(a.finish(1.0).top, expected) << "order " << order;
    }
}

// x^-0.9 under uniform sampling has weights with tail index 1/0.9 = 1.11: heavy_tail, with the
// estimate and its standard error as evidence; the exact importance pdf raises nothing.
TEST(Diagnostics, HeavyTailCarriesItsEvidence) {
    StudyResult s = study("singular_power_0.9",
                          Json{{"n_min", 1024}, {"n_max", 16384}, {"reps", 16}, {"seed", 3}});
    std::vector<Flag> uniform = estimator_flags(named(s, "uniform"), s.settings);
    ASSERT_TRUE(has(uniform, FlagCode::HeavyTail));
    const Flag& tail = uniform.front();
    EXPECT_EQ(tail.code, FlagCode::HeavyTail);
    EXPECT_EQ(tail.n, 16384u);
    EXPECT_GT(tail.count, 0u);                         // Hill's k
    EXPECT_NEAR(tail.value, 1.0 / 0.9, 4.0 * tail.se); // alpha = 1/0.9 within 4 se
    EXPECT_EQ(tail.threshold, kHeavyTailAlpha);
    const EstimatorStudy& exact = named(s, "importance_exact");
    EXPECT_TRUE(estimator_flags(exact, s.settings).empty());
    for (const LevelStats& l : exact.levels) EXPECT_TRUE(level_flags(l).empty()) << l.n;
}

// A bounded smooth integrand: no alarm (error or warning) for any estimator at any level; only
// notes (info: conservative error bars of stratified runs, a pre-asymptotic tail note).
TEST(Diagnostics, QuietWhereTheAnswerIsFine) {
    StudyResult s = study("exp_1d", Json{{"n_min", 64}, {"n_max", 4096}, {"reps", 16}});
    for (const EstimatorStudy& e : s.estimators) {
        for (const LevelStats& l : e.levels)
            for (const Flag& f : level_flags(l))
                if (f.severity != Severity::Info)
                    ADD_FAILURE() << e.spec.name << " N=" << l.n << ": " << flag_code_name(f.code);
        for (const Flag& f : estimator_flags(e, s.settings))
            if (f.severity != Severity::Info)
                ADD_FAILURE() << e.spec.name << ": " << flag_code_name(f.code);
    }
}

// A pdf that is zero where f is not: pdf_support at the estimator level, with the missed share.
TEST(Diagnostics, ZeroPdfSupportIsAnEstimatorFlag) {
    StudyResult s = study("is_zero_pdf", Json{{"n_min", 256}, {"n_max", 1024}, {"reps", 8}});
    bool found = false;
    for (const EstimatorStudy& e : s.estimators)
        for (const Flag& f : estimator_flags(e, s.settings))
            if (f.code == FlagCode::PdfSupport) {
                found = true;
                EXPECT_GT(f.value, kSupportTolerance) << e.spec.name;
            }
    EXPECT_TRUE(found);
}

// Error bars too small for the replicates' spread, known or unknown exact value: VEGAS's
// iteration average without the even share, across Genz's discontinuity, whose iterations trust
// a map that collapsed the zero region (docs/scene-format.md). The F statistic s^2 / mean se^2
// is far above 1 there; on the smooth peak the same estimator is quiet.
TEST(Diagnostics, ErrorBarsThatUnderstateTheSpreadAreFlagged) {
    const Json options{{"estimators", {"vegas_iterations_no_share"}},
                       {"n_min", 131072},
                       {"n_max", 131072},
                       {"reps", 32},
                       {"seed", 5}};
    StudyResult s = study("miser_discontinuous", options);
    const LevelStats& l = s.estimators[0].levels[0];
    const std::vector<Flag> flags = level_flags(l);
    auto it = std::find_if(flags.begin(), flags.end(),
                           [](const Flag& f) { return f.code == FlagCode::ErrorBarsUnderstate; });
    ASSERT_NE(it, flags.end());
    EXPECT_GT(it->value, 4.0); // s^2 over the mean se^2
    EXPECT_LT(it->p_value, 1e-3);
    EXPECT_EQ(it->dof, 31);
    // The same statistic on a smooth integrand stays near 1: no flag.
    StudyResult q =
        study("vegas_corner_peak", Json{{"estimators", {"vegas", "vegas_plus", "miser"}},
                                        {"n_min", 4096},
                                        {"n_max", 65536},
                                        {"reps", 16}});
    for (const EstimatorStudy& e : q.estimators)
        for (const LevelStats& level : e.levels)
            EXPECT_FALSE(has(level_flags(level), FlagCode::ErrorBarsUnderstate))
                << e.spec.name << " N=" << level.n;
}

// Severities (issue 13): what is wrong is an error, what cannot be trusted at this N a warning,
// what is only worth knowing info; a raised flag carries its code's severity.
TEST(Diagnostics, EveryFlagHasTheSeverityOfWhatItSays) {
    for (FlagCode c :
         {FlagCode::NoEstimate, FlagCode::NonfiniteEstimate, FlagCode::NonfiniteVariance,
          FlagCode::ZeroErrorBar, FlagCode::NonfiniteSamples, FlagCode::ZeroPdfSamples,
          FlagCode::ExactOutsideCi, FlagCode::PdfSupport, FlagCode::IterationsDisagree,
          FlagCode::ErrorBarsUnderstate, FlagCode::PixelErrorBars, FlagCode::ValuesUnderflow})
        EXPECT_EQ(default_severity(c), Severity::Error) << flag_code_name(c);
    for (FlagCode c : {FlagCode::SkewedWeights, FlagCode::LowEss, FlagCode::HeavyTail,
                       FlagCode::LevelDrift, FlagCode::SlowConvergence, FlagCode::ReplicateFarOff,
                       FlagCode::FewPixelErrors, FlagCode::RareLargeErrors})
        EXPECT_EQ(default_severity(c), Severity::Warning) << flag_code_name(c);
    for (FlagCode c : {FlagCode::HeavyTail4, FlagCode::Float32Accumulator,
                       FlagCode::BelowReferenceNoise, FlagCode::ReferenceNoise})
        EXPECT_EQ(default_severity(c), Severity::Info) << flag_code_name(c);
    EXPECT_STREQ(severity_name(Severity::Error), "error");
    EXPECT_STREQ(severity_name(Severity::Warning), "warning");
    EXPECT_STREQ(severity_name(Severity::Info), "info");

    // Raised by a real study: x^-0.9 under uniform sampling (infinite variance: a warning) and
    // a pdf that misses part of f (biased: an error).
    StudyResult s = study("singular_power_0.9",
                          Json{{"n_min", 1024}, {"n_max", 4096}, {"reps", 8}, {"seed", 3}});
    for (const Flag& f : estimator_flags(named(s, "uniform"), s.settings))
        EXPECT_EQ(f.severity, default_severity(f.code)) << flag_code_name(f.code);
    StudyResult z = study("is_zero_pdf", Json{{"n_min", 256}, {"n_max", 1024}, {"reps", 8}});
    int support = 0;
    for (const EstimatorStudy& e : z.estimators)
        for (const Flag& f : estimator_flags(e, z.settings))
            if (f.code == FlagCode::PdfSupport) {
                EXPECT_EQ(f.severity, Severity::Error);
                ++support;
            }
    EXPECT_GT(support, 0);
}

namespace {

// A level of R = 10 runs at N whose R N pooled weights are k ones in every m values (the rest
// zeros): skewness (1 - 2p) / sqrt(p (1 - p)) with p = k / m; the runs' error bars 1 and
// `spread`. The weights are the error bar's units.
LevelStats skewed_level(uint64_t n, uint64_t k, uint64_t m, double spread) {
    LevelStats l;
    l.n = n;
    l.reps = 10;
    l.mean = 0.0;
    l.variance = 1.0;
    l.estimates_spread = true;
    for (uint64_t i = 0; i < 10 * n; ++i) l.diagnostics.weights.add(i % m < k ? 1.0 : 0.0);
    l.diagnostics.error_units = l.diagnostics.weights;
    l.run_std_errors.assign(10, 1.0);
    l.run_std_errors[3] = spread;
    l.ess_mean = static_cast<double>(n);
    return l;
}

// The flag of that code, if raised (a copy: the flags are often a temporary).
std::optional<Flag> find(const std::vector<Flag>& flags, FlagCode code) {
    for (const Flag& f : flags)
        if (f.code == code) return f;
    return std::nullopt;
}

} // namespace

// Cochran's rule both ways on levels built to order: one weight in 1024 non-zero has skewness
// 32.0 and needs N > 25 x 32.0^2 = 25570. Below a quarter of that, a warning; between a quarter
// and the whole, a warning only when the runs' error bars differ by more than a factor 2, else
// info with the N from which the rule holds; above it, nothing. Weights with one in ten
// non-zero (skewness 2.67, N > 178) raise nothing at N = 1024.
TEST(Diagnostics, SkewedWeightsFollowCochransRule) {
    const double p = 1.0 / 1024.0, g1 = (1.0 - 2.0 * p) / std::sqrt(p * (1.0 - p));
    std::optional<Flag> f =
        find(level_flags(skewed_level(4096, 1, 1024, 1.1)), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);
    EXPECT_NEAR(f->value, g1, 1e-9);
    EXPECT_NEAR(f->threshold, 25.0 * g1 * g1, 1e-6);
    f = find(level_flags(skewed_level(16384, 1, 1024, 1.1)), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Info);
    f = find(level_flags(skewed_level(16384, 1, 1024, 2.5)), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);
    EXPECT_NEAR(f->se, 2.5, 1e-12);
    EXPECT_FALSE(find(level_flags(skewed_level(32768, 1, 1024, 2.5)), FlagCode::SkewedWeights));
    EXPECT_FALSE(find(level_flags(skewed_level(1024, 1, 10, 1.1)), FlagCode::SkewedWeights));
}

// Randomized QMC: the rule reads the K batch means, and the weights' skewness over sqrt(N/K)
// when that is larger. K = 16 batch means of 128 points that look symmetric, from weights with
// one point in 128 non-zero (skewness 11.3: a batch mean holds about one hit, skewness 1.0, and
// needs K > 25): flagged. The same batch means from weights with one point in 4 non-zero
// (skewness 1.15, 0.10 per batch mean): not flagged.
TEST(Diagnostics, BatchMeansAreJudgedByTheWeightsTheyAverage) {
    auto rqmc_level = [](uint64_t m) {
        LevelStats l = skewed_level(2048, 1, m, 1.1);
        l.diagnostics.batch_units = true;
        l.diagnostics.error_units = RunningMoments();
        for (int i = 0; i < 10 * 16; ++i) l.diagnostics.error_units.add(i % 2 ? 1.0 : -1.0);
        return l;
    };
    const std::optional<Flag> f = find(level_flags(rqmc_level(128)), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->count, 16u); // batch means per run
    EXPECT_NEAR(f->value, (126.0 / 128.0) / std::sqrt(127.0 / 128.0 / 128.0) / std::sqrt(128.0),
                1e-9);
    EXPECT_FALSE(find(level_flags(rqmc_level(4)), FlagCode::SkewedWeights));
}

// The runs' own error bars: flagged when they differ by more than a factor 4 and Bartlett's test
// says more than their degrees of freedom allow (one of ten runs' se 5 times the others', 1000
// dof each); not for the same spread at 1 dof each (such error bars vary that much by chance),
// nor for error bars that agree to 10%.
TEST(Diagnostics, UnstableErrorBarsNeedBothASpreadAndBartlettsTest) {
    LevelStats l = skewed_level(1024, 1, 2, 1.0); // symmetric weights: no skewness flag
    l.run_dofs.assign(10, 1000);
    l.run_std_errors = {1.0, 1.02, 0.98, 1.01, 0.99, 1.0, 1.03, 0.97, 1.0, 5.0};
    std::optional<Flag> f = find(level_flags(l), FlagCode::ErrorBarsUnstable);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);
    EXPECT_NEAR(f->value, 5.0 / 0.97, 1e-12);
    EXPECT_LT(f->p_value, 1e-3);
    l.run_dofs.assign(10, 1);
    EXPECT_FALSE(find(level_flags(l), FlagCode::ErrorBarsUnstable));
    l.run_dofs.assign(10, 1000);
    l.run_std_errors.back() = 1.1;
    EXPECT_FALSE(find(level_flags(l), FlagCode::ErrorBarsUnstable));
}

// From real studies: Genz's corner peak in d = 2 (c = 75 per axis; f bounded by 1, skewness
// about 120 under uniform sampling) at N = 1024 is flagged skewed_weights as a warning, and its
// tail flag, on weights bounded by what the problem says, is info; exp_1d at N = 1024 raises
// neither; x^-0.9 (unbounded) keeps heavy_tail a warning.
TEST(Diagnostics, BoundedPeaksAreSkewedNotInfiniteVariance) {
    const Json peak = {
        {"name", "corner"},
        {"integrand", {{"type", "genz_corner_peak"}, {"a", {75.0, 75.0}}, {"u", {0.5, 0.5}}}},
        {"estimators", {"uniform"}}};
    Made<SceneRequest> r =
        build_request(peak, Json{{"n_min", 1024}, {"n_max", 4096}, {"reps", 10}, {"seed", 5}});
    ASSERT_TRUE(r.ok()) << r.error;
    StudyResult s = run_study(r.value.problem, r.value.estimators, r.value.settings);
    const EstimatorStudy& e = named(s, "uniform");
    EXPECT_TRUE(e.weights_bounded);
    const std::optional<Flag> skew = find(level_flags(e.levels.front()), FlagCode::SkewedWeights);
    ASSERT_TRUE(skew.has_value());
    EXPECT_EQ(skew->severity, Severity::Warning);
    EXPECT_GT(skew->value, 20.0);
    const std::optional<Flag> bounded_tail =
        find(estimator_flags(e, s.settings), FlagCode::HeavyTail);
    ASSERT_TRUE(bounded_tail.has_value()); // Hill's alpha near 1 at N = 4096: it looks heavy
    EXPECT_EQ(bounded_tail->severity, Severity::Info);

    StudyResult x = study("exp_1d", Json{{"n_min", 1024}, {"n_max", 1024}, {"reps", 10}});
    for (const EstimatorStudy& est : x.estimators) {
        EXPECT_FALSE(find(level_flags(est.levels.front()), FlagCode::SkewedWeights))
            << est.spec.name;
    }

    StudyResult sing = study("singular_power_0.9",
                             Json{{"n_min", 1024}, {"n_max", 4096}, {"reps", 8}, {"seed", 3}});
    const EstimatorStudy& u = named(sing, "uniform");
    EXPECT_FALSE(u.weights_bounded);
    const std::optional<Flag> tail = find(estimator_flags(u, sing.settings), FlagCode::HeavyTail);
    ASSERT_TRUE(tail.has_value());
    EXPECT_EQ(tail->severity, Severity::Warning);
}

// An exact estimator (f/p constant: the matched pdf of a peak of width 1e-8, stratified points
// on disk_quarter) is recognised at every N and raises nothing: its spread, skewness and tail
// are round-off. Points that never see f (uniform on the peak: every estimate 0) are not exact:
// they keep their alarms.
TEST(Diagnostics, ExactEstimatorsAreRecognisedAndQuiet) {
    StudyResult s =
        study("stiff_peak_1e-8", Json{{"n_min", 16}, {"n_max", 4096}, {"reps", 16}, {"seed", 4}});
    const EstimatorStudy& matched = named(s, "importance_matched");
    for (const LevelStats& l : matched.levels) {
        EXPECT_TRUE(l.exact_to_roundoff) << l.n;
        EXPECT_TRUE(level_flags(l).empty()) << l.n;
    }
    EXPECT_TRUE(estimator_flags(matched, s.settings).empty());
    const EstimatorStudy& uniform = named(s, "uniform");
    for (const LevelStats& l : uniform.levels) EXPECT_FALSE(l.exact_to_roundoff) << l.n;
    EXPECT_FALSE(level_flags(uniform.levels.back()).empty());

    StudyResult d = study("disk_quarter", Json{{"n_min", 16}, {"n_max", 1024}, {"reps", 8}});
    for (const LevelStats& l : named(d, "stratified_concentric").levels)
        EXPECT_TRUE(l.exact_to_roundoff) << l.n;
    for (const LevelStats& l : named(d, "uniform").levels) EXPECT_FALSE(l.exact_to_roundoff) << l.n;
}

// A biased estimator's flat MSE: bias_dominates (info) from the first N where the bias outgrows
// the spread, with an MSE order near 0 under a variance order near -1; the unbiased uniform
// estimator raises neither. Conservative error bars (Latin hypercube's iid bound on a smooth
// integrand, variance ~ N^-3 under an N^-1 bound) are info; uniform's are not flagged.
TEST(Diagnostics, BiasDominatesAndConservativeErrorBarsAreInfo) {
    StudyResult z =
        study("is_zero_pdf", Json{{"n_min", 256}, {"n_max", 16384}, {"reps", 16}, {"seed", 6}});
    const EstimatorStudy& gap = named(z, "importance_gap");
    const std::optional<Flag> bias =
        find(estimator_flags(gap, z.settings), FlagCode::BiasDominates);
    ASSERT_TRUE(bias.has_value());
    EXPECT_EQ(bias->severity, Severity::Info);
    EXPECT_EQ(bias->n, 256u);
    ASSERT_TRUE(gap.mse_fit.valid && gap.fit.valid);
    EXPECT_NEAR(gap.mse_fit.order, 0.0, 4.0 * gap.mse_fit.order_se);
    EXPECT_LT(gap.fit.order, -0.5);
    const EstimatorStudy& uniform = named(z, "uniform");
    EXPECT_FALSE(find(estimator_flags(uniform, z.settings), FlagCode::BiasDominates));
    ASSERT_TRUE(uniform.mse_fit.valid);
    EXPECT_NEAR(uniform.mse_fit.order, -1.0, 4.0 * uniform.mse_fit.order_se);

    StudyResult x = study("exp_1d", Json{{"n_min", 1024}, {"n_max", 4096}, {"reps", 16}});
    for (const LevelStats& l : named(x, "latin_hypercube").levels) {
        const std::optional<Flag> wide = find(level_flags(l), FlagCode::ConservativeErrorBars);
        ASSERT_TRUE(wide.has_value()) << l.n;
        EXPECT_EQ(wide->severity, Severity::Info);
        EXPECT_GT(wide->value, 10.0) << l.n; // N^-3 against an N^-1 bound: far too wide
    }
    for (const LevelStats& l : named(x, "uniform").levels)
        EXPECT_FALSE(find(level_flags(l), FlagCode::ConservativeErrorBars)) << l.n;
}

namespace {

/// A ladder of 7 levels whose means are averages of R normal replicates around `truth` (plus
/// `shift` standard deviations on level 3), with the standard errors those replicates give.
std::vector<LevelStats> normal_ladder(Pcg32& rng, int reps, double shift) {
    std::vector<LevelStats> levels(7);
    for (size_t k = 0; k < levels.size(); ++k) {
        const double sigma = 1.0 / std::sqrt(double(uint64_t(1) << k)); // as for N = 2^k
        RunningMoments m;
        for (int r = 0; r < reps; ++r) {
            // Box-Muller from two 53-bit uniforms
            const double u1 = 1.0 - rng.next_double(), u2 = rng.next_double();
            const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
            m.add(1.0 + sigma * (z + (k == 3 ? shift / std::sqrt(double(reps)) : 0.0)));
        }
        levels[k].reps = reps;
        levels[k].mean = m.mean();
        levels[k].std_error = std::sqrt(m.variance() / reps);
        levels[k].estimates_spread = true;
    }
    return levels;
}

} // namespace

// The level-consistency test (level_drift) both ways: on ladders whose levels agree, R = 10
// replicates each, p < 1e-3 must be as rare as 1e-3 says (t-distributed z's summed as if normal
// fired on 1.7% of them); a level shifted by 10 of its standard errors must be caught (6 is
// within what t with 9 degrees of freedom allows once in a few thousand).
TEST(Diagnostics, LevelDriftIsRareOnConsistentLaddersAndCatchesAShift) {
    Pcg32 rng(2026, 13);
    const int ladders = 4000;
    int false_alarms = 0;
    for (int i = 0; i < ladders; ++i)
        false_alarms += level_consistency(normal_ladder(rng, 10, 0.0)).p_value < kLevelDriftP;
    // Expected 4 at p = 1e-3; 14 is about 5 binomial standard deviations above that.
    EXPECT_LE(false_alarms, 14) << "of " << ladders;
    int caught = 0;
    for (int i = 0; i < 200; ++i)
        caught += level_consistency(normal_ladder(rng, 10, 10.0)).p_value < kLevelDriftP;
    EXPECT_GE(caught, 150) << "of 200";
}

namespace {

// A level of R replicates with error bars 1 (dof 1000) about the exact value 0: replicate i's
// estimate is z[i]. Its weights are skewed (one in 1024 non-zero: Cochran's rule needs
// N > 25570) so that skewed_weights fires on the weights alone at N = 4096.
LevelStats replicates_level(const std::vector<double>& z, bool with_exact) {
    const int r = static_cast<int>(z.size());
    LevelStats l;
    l.n = 4096;
    l.reps = r;
    l.estimates_spread = true;
    l.has_exact = with_exact;
    l.exact = with_exact ? 0.0 : std::numeric_limits<double>::quiet_NaN();
    for (uint64_t i = 0; i < uint64_t(r) * l.n; ++i)
        l.diagnostics.weights.add(i % 1024 == 0 ? 1.0 : 0.0);
    l.diagnostics.error_units = l.diagnostics.weights;
    l.estimates = z;
    l.run_std_errors.assign(z.size(), 1.0);
    l.run_dofs.assign(z.size(), 1000);
    l.ess_mean = 4096.0;
    RunningMoments m;
    for (double x : z) m.add(x);
    l.mean = m.mean();
    l.variance = m.variance();
    l.mean_run_variance = 1.0;
    l.run_dof_total = 1000.0 * r;
    return l;
}

// n replicates spread like honest N(0, 1) errors (normal quantiles at (i + 1/2) / n, shuffled
// by a fixed stride): their misses beyond 1.96 are the 5% that honest intervals give.
std::vector<double> honest_errors(int n) {
    std::vector<double> z(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) z[size_t((i * 7) % n)] = normal_quantile((i + 0.5) / n);
    return z;
}

} // namespace

// The replicates' own evidence overrules a warning that rests on the weights alone, once there
// are enough of them (20): with 32 replicates whose intervals miss as honest ones do (2 of 32;
// up to 3 allowed, P(Bin(32, 0.05) >= 4) = 0.077 < 0.1), skewed_weights is info and carries the
// counts; with 5 misses or more (P(Bin(32, 0.05) >= 5) = 0.026) it stays a warning; with 10
// replicates (too few to tell 80% coverage from 95%) the weights' rule stands alone.
// error_bars_unstable follows the same rule.
TEST(Diagnostics, ReplicatesThatCoverOverruleWarningsFromTheWeights) {
    LevelStats covered = replicates_level(honest_errors(32), true);
    std::optional<Flag> f = find(level_flags(covered), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Info);
    EXPECT_EQ(f->replicates_judged, 32);
    EXPECT_EQ(f->replicate_misses, 2);
    EXPECT_EQ(f->miss_allowance, 3);
    EXPECT_FALSE(find(level_flags(covered), FlagCode::ReplicateFarOff));

    std::vector<double> missing = honest_errors(32);
    for (int i = 0; i < 4; ++i) missing[size_t(i)] = 2.5 + 0.1 * i; // 5 or 6 misses in all
    f = find(level_flags(replicates_level(missing, true)), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);
    EXPECT_GE(f->replicate_misses, 5);

    f = find(level_flags(replicates_level(honest_errors(10), true)), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);

    // Unstable error bars (one run's se 5 times the others', Bartlett p < 1e-3): info when the
    // replicates cover, a warning when they do not.
    LevelStats unstable = replicates_level(honest_errors(32), true);
    unstable.diagnostics.weights = RunningMoments();
    for (int i = 0; i < 1000; ++i) unstable.diagnostics.weights.add(i % 2 ? 1.0 : -1.0);
    unstable.diagnostics.error_units = unstable.diagnostics.weights;
    unstable.run_std_errors[5] = 5.0;
    f = find(level_flags(unstable), FlagCode::ErrorBarsUnstable);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Info);
    for (int i = 0; i < 5; ++i) unstable.estimates[size_t(10 + i)] = 3.0;
    f = find(level_flags(unstable), FlagCode::ErrorBarsUnstable);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);
}

// Blind, replicates cannot vouch for strongly skewed weights when one weight rules a run
// (max |w| / sum |w| of 0.3 >= kRulingShare): the runs that missed such weights make the others'
// mean, so 32 honest-looking replicates keep skewed_weights a warning. The other way: the same
// replicates demote it where no weight rules (share 0.05), or where the exact value judges them.
TEST(Diagnostics, BlindReplicatesDoNotVouchForAMeanRuledByAFewWeights) {
    LevelStats ruled = replicates_level(honest_errors(32), false);
    ruled.diagnostics.max_weight_share = 0.3;
    std::optional<Flag> f = find(level_flags(ruled), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);
    EXPECT_EQ(f->replicate_misses, 2); // the replicates look honest: the weights decide

    LevelStats spread = ruled;
    spread.diagnostics.max_weight_share = 0.05;
    f = find(level_flags(spread), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Info);

    LevelStats judged = replicates_level(honest_errors(32), true);
    judged.diagnostics.max_weight_share = 0.3;
    f = find(level_flags(judged), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Info);

    // Mildly skewed weights (warning only because the runs' error bars disagree) are demoted by
    // blind replicates even when one weight rules: the rule is for strongly skewed means.
    LevelStats mild = ruled;
    mild.n = 16384; // N in [25 g1^2 / 4, 25 g1^2) = [6393, 25570): the mean's skewness 0.25
    mild.diagnostics.weights = RunningMoments();
    for (uint64_t i = 0; i < 32 * mild.n; ++i) mild.diagnostics.weights.add(i % 1024 ? 0.0 : 1.0);
    mild.diagnostics.error_units = mild.diagnostics.weights;
    mild.run_std_errors[3] = 2.5; // runs' error bars 2.5 apart: unsettled, a warning
    f = find(level_flags(mild), FlagCode::SkewedWeights);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Info);
}

// A real blind study: stratified sampling of Genz's corner peak in d = 3 (a = 4.9, 36.5, 25.2,
// the fresh battery's seed 48401) at N = 8192, where one corner cell's jittered point carries up
// to a third of a run's sum and the intervals cover about 76% of the time (400 runs, judged
// against the exact value). Told nothing of the exact value, the study keeps skewed_weights a
// warning whatever the 32 replicates look like: seeds 13 and 20 are two of the 6 in 1..40
// whose replicates look covering blind, where replicates alone would demote it.
TEST(Diagnostics, AStratifiedCornerPeakRuledByOneCellStaysAWarningBlind) {
    const Json peak = {{"name", "corner3"},
                       {"integrand",
                        {{"type", "genz_corner_peak"},
                         {"a", {4.90452, 36.5253, 25.2368}},
                         {"u", {0.5, 0.5, 0.5}}}},
                       {"exact", nullptr}, // as a user's own integrand runs
                       {"estimators", {"stratified"}}};
    for (uint64_t seed : {13, 20}) {
        Made<SceneRequest> r = build_request(
            peak, Json{{"n_min", 8192}, {"n_max", 8192}, {"reps", 32}, {"seed", seed}});
        ASSERT_TRUE(r.ok()) << r.error;
        const StudyResult s = run_study(r.value.problem, r.value.estimators, r.value.settings);
        const LevelStats& l = named(s, "stratified").levels.front();
        EXPECT_FALSE(l.has_exact);
        EXPECT_GE(l.diagnostics.max_weight_share, kRulingShare) << seed;
        const std::optional<Flag> f = find(level_flags(l), FlagCode::SkewedWeights);
        ASSERT_TRUE(f.has_value()) << seed;
        EXPECT_EQ(f->severity, Severity::Warning) << seed;
    }
}

// A replicate beyond 5 of its own standard errors (widened by t_0.975(dof) / 1.96 for few
// degrees of freedom) is an alarm by itself, against the exact value or, without one, against
// the other replicates' mean: 5.6 with 1000 dof is raised, 4.5 is not; with 15 dof (16
// randomizations) the limit is 5 x 2.13 / 1.96 = 5.44; with 3 dof (4 randomizations) it is t_3's
// quantile crossed as rarely as 5.44 is at 15 (about 32, not 5 x 3.18 / 1.96 = 8.1), so 16.5 is
// not raised and 60 is.
TEST(Diagnostics, AReplicateFarOutsideItsIntervalIsAnAlarm) {
    std::vector<double> z = honest_errors(32);
    z[7] = 5.6;
    std::optional<Flag> f = find(level_flags(replicates_level(z, true)), FlagCode::ReplicateFarOff);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);
    EXPECT_EQ(f->dof, 7); // which replicate
    EXPECT_NEAR(f->value, 5.6, 1e-12);
    EXPECT_NEAR(f->threshold, 5.0 * student_t_quantile(0.975, 1000.0) / 1.959963984540054, 1e-9);
    z[7] = 4.5;
    EXPECT_FALSE(find(level_flags(replicates_level(z, true)), FlagCode::ReplicateFarOff));

    // Without the exact value: the other 31 replicates' mean (about 0) and their spread.
    z[7] = 6.5;
    f = find(level_flags(replicates_level(z, false)), FlagCode::ReplicateFarOff);
    ASSERT_TRUE(f.has_value());
    EXPECT_GT(f->value, 5.5);
    EXPECT_LT(f->value, 6.5);

    LevelStats default_dof = replicates_level(honest_errors(32), true);
    default_dof.run_dofs.assign(32, 15);
    default_dof.estimates[7] = 5.6;
    f = find(level_flags(default_dof), FlagCode::ReplicateFarOff);
    ASSERT_TRUE(f.has_value());
    EXPECT_NEAR(f->threshold, 5.0 * student_t_quantile(0.975, 15.0) / 1.959963984540054, 1e-9);

    LevelStats few_dof = replicates_level(honest_errors(32), true);
    few_dof.run_dofs.assign(32, 3);
    few_dof.estimates[7] = 16.5;
    EXPECT_FALSE(find(level_flags(few_dof), FlagCode::ReplicateFarOff));
    few_dof.estimates[7] = 60.0;
    f = find(level_flags(few_dof), FlagCode::ReplicateFarOff);
    ASSERT_TRUE(f.has_value());
    EXPECT_NEAR(student_t_sf(f->threshold, 3.0),
                student_t_sf(5.0 * 2.131449546 / 1.959963985, 15.0), 1e-9);
}

// The other way, at few degrees of freedom: replicates whose errors are Student t with 1 degree
// of freedom in their own error bars (2 randomizations, honest) cross 5 x 12.7 / 1.96 = 32.4 in
// 2% of draws, so the old limit raised replicate_far_off on about half of all cells of 32. Now a
// replicate crosses the limit with probability 6.9e-5 (0.2% of cells); 200 cells, against the
// exact value and blind, stay under Poisson bounds at p < 1e-3 (4 and 8 cells).
TEST(Diagnostics, HonestReplicatesWithOneDegreeOfFreedomAreNoAlarm) {
    Pcg32 rng(20261207, 3);
    int flagged_exact = 0, flagged_blind = 0;
    for (int cell = 0; cell < 200; ++cell) {
        std::vector<double> z(32);
        for (double& x : z) x = std::tan(kPi * (rng.next_double() - 0.5)); // t_1: Cauchy
        for (bool with_exact : {true, false}) {
            LevelStats l = replicates_level(z, with_exact);
            l.run_dofs.assign(32, 1);
            if (find(level_flags(l), FlagCode::ReplicateFarOff))
                ++(with_exact ? flagged_exact : flagged_blind);
        }
    }
    EXPECT_LE(flagged_exact, 4);
    EXPECT_LE(flagged_blind, 8);
    // ... and a replicate 10^5 of its error bars off is still raised at 1 degree of freedom.
    std::vector<double> z = honest_errors(32);
    z[3] = 1e5;
    LevelStats l = replicates_level(z, true);
    l.run_dofs.assign(32, 1);
    EXPECT_TRUE(find(level_flags(l), FlagCode::ReplicateFarOff));
}

// The skew's signature, blind: skewed weights give the runs that miss the rare large ones a low
// estimate and a small error bar [Hall92]. 26 runs honour error bars of 1, 4 have error bars of
// 8, and two low runs have error bars of 0.2: the leave-one-out check, whose spread the wide
// runs inflate, finds nothing beyond 5, yet the low runs lie about 5 of their own error bars
// below the others' mean, on the side the studentized deviations skew toward. That raises
// replicate_far_off and keeps skewed_weights a warning. The other way: the same runs with one
// low and one high (no skew), with both low runs 3.5 error bars off (skewness -1), and honest
// runs raise nothing and leave skewed_weights info; the mirror image (high runs) is flagged.
TEST(Diagnostics, ReplicatesSkewedWithTheirErrorBarsAreAnAlarm) {
    const std::vector<double> z = honest_errors(32);
    auto level = [&](double low_a, double low_b, double sign) {
        LevelStats l = replicates_level(z, false);
        RunningMoments m, se2;
        for (size_t i = 0; i < z.size(); ++i) {
            l.run_std_errors[i] = i % 8 == 3 ? 8.0 : 1.0;
            l.estimates[i] = sign * l.run_std_errors[i] * z[i];
        }
        l.run_std_errors[5] = l.run_std_errors[20] = 0.2;
        l.estimates[5] = sign * low_a;
        l.estimates[20] = sign * low_b;
        for (size_t i = 0; i < z.size(); ++i) {
            m.add(l.estimates[i]);
            se2.add(l.run_std_errors[i] * l.run_std_errors[i]);
        }
        l.mean = m.mean();
        l.variance = m.variance();
        l.mean_run_variance = se2.mean();
        return l;
    };
    for (double sign : {1.0, -1.0}) {
        const LevelStats skewed = level(-1.0, -0.95, sign);
        const ReplicateCheck c = check_replicates(skewed);
        EXPECT_EQ(c.far, 0); // the leave-one-out check alone passes them
        EXPECT_LT(sign * c.skewness, -kSkewSignature);
        const std::vector<Flag> flags = level_flags(skewed);
        const std::optional<Flag> f = find(flags, FlagCode::ReplicateFarOff);
        ASSERT_TRUE(f.has_value()) << sign;
        EXPECT_EQ(f->severity, Severity::Warning);
        EXPECT_TRUE(f->dof == 5 || f->dof == 20) << f->dof;
        EXPECT_GT(f->value, f->threshold);
        EXPECT_NEAR(f->threshold, kSkewedFarZ * student_t_quantile(0.975, 1000.0) / 1.96, 1e-3);
        const std::optional<Flag> w = find(flags, FlagCode::SkewedWeights);
        ASSERT_TRUE(w.has_value());
        EXPECT_EQ(w->severity, Severity::Warning); // no demotion by replicates that only seem to
        const Json level_json = level_to_json(skewed);
        std::string said;
        for (const Json& m : level_json["warnings"])
            if (m["code"] == "replicate_far_off") said = m["message"].get<std::string>();
        EXPECT_NE(said.find(sign > 0 ? "a low estimate" : "a high estimate"), std::string::npos)
            << said;
    }
    EXPECT_LT(std::fabs(check_replicates(level(-1.0, 1.0, 1.0)).skewness), kSkewSignature);
    for (const LevelStats& fine :
         {level(-1.0, 1.0, 1.0), level(-0.7, -0.7, 1.0), replicates_level(z, false)}) {
        const std::vector<Flag> flags = level_flags(fine);
        EXPECT_FALSE(find(flags, FlagCode::ReplicateFarOff));
        const std::optional<Flag> w = find(flags, FlagCode::SkewedWeights);
        ASSERT_TRUE(w.has_value());
        EXPECT_EQ(w->severity, Severity::Info);
    }
}

// Replicates judged one by one against their own error bars (Cochran's Q, replicate_scatter),
// without the exact value: 28 runs whose error bars are 14 times too small (se 1, estimates
// spread 14) beside 4 runs with error bars of 60 that cover. The 4 large se^2 carry the mean
// se^2 (450, the replicates' variance about 640): the F test sees an F of 1.4 and nothing, and
// the leave-one-out check of each replicate finds none beyond 5 standard errors. Q does, and
// error_bars_unstable is not demoted by replicates that only seem to cover. The other way: the
// same error bars with estimates that honour them raise no understatement.
TEST(Diagnostics, ReplicatesScatteringBeyondTheirOwnErrorBarsAreAnAlarm) {
    const std::vector<double> z = honest_errors(32);
    LevelStats l = replicates_level(z, false);
    for (size_t i = 0; i < z.size(); ++i) {
        const bool wide = i % 8 == 3;
        l.run_std_errors[i] = wide ? 60.0 : 1.0;
        l.estimates[i] = (wide ? 60.0 : 14.0) * z[i];
    }
    auto summarise = [](LevelStats* level) {
        RunningMoments m, se2;
        for (double x : level->estimates) m.add(x);
        for (double s : level->run_std_errors) se2.add(s * s);
        level->mean = m.mean();
        level->variance = m.variance();
        level->mean_run_variance = se2.mean();
    };
    summarise(&l);
    EXPECT_LT(l.variance / l.mean_run_variance, 2.0); // the F test's ratio: nothing there
    const ScatterTest scatter = replicate_scatter(l);
    EXPECT_EQ(scatter.judged, 32);
    EXPECT_LT(scatter.p_value, 1e-6);
    std::vector<Flag> flags = level_flags(l);
    std::optional<Flag> f = find(flags, FlagCode::ErrorBarsUnderstate);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Error);
    EXPECT_EQ(f->count, 32u); // the replicate-by-replicate test, not the F test
    EXPECT_NEAR(f->value, scatter.q / 32.0, 1e-12);
    f = find(flags, FlagCode::ErrorBarsUnstable);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Warning);

    // The same error bars, honoured: Q near its mean 32 (p >= 0.05, no sign of scatter), no
    // understatement, and Bartlett's finding that the error bars lie 60 times apart is info:
    // the replicates show they hold.
    for (size_t i = 0; i < z.size(); ++i) l.estimates[i] = l.run_std_errors[i] * z[i];
    summarise(&l);
    EXPECT_GT(replicate_scatter(l).p_value, 0.05);
    flags = level_flags(l);
    EXPECT_FALSE(find(flags, FlagCode::ErrorBarsUnderstate));
    f = find(flags, FlagCode::ErrorBarsUnstable);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->severity, Severity::Info);
    // Against an exact value honest replicates pass and scattered ones do not.
    for (size_t i = 0; i < z.size(); ++i) l.estimates[i] = l.run_std_errors[i] * z[i];
    l.has_exact = true;
    l.exact = 0.0;
    EXPECT_GT(replicate_scatter(l).p_value, 0.05);
    for (size_t i = 0; i < z.size(); ++i) l.estimates[i] = 3.0 * l.run_std_errors[i] * z[i];
    EXPECT_LT(replicate_scatter(l).p_value, 1e-6);
}

// heavy_tail judged both ways on products of powers, for estimators whose sampling density is
// bounded above and below (their variance is finite exactly where int f^2 is): x^-0.45 y^-0.2
// (tail index 1 / 0.45 = 2.22, a finite variance) raised heavy_tail at warning in 6 of 8 cells
// from the weights' Hill index at k = 64 (standard error 0.28); x^-0.55 y^-0.1 z^-0.1 (1.82, an
// infinite variance) went unflagged by MISER at one N of two, its boxes making the weights' tail
// look light. The integrand's tail at 2^15 uniform points, Hill's k = 2048 (standard error
// 0.05), tells them apart at every N, for every such estimator.
TEST(Diagnostics, HeavyTailFollowsTheIntegrandWhereTheDensityIsBounded) {
    auto product = [](std::vector<double> powers) {
        double exact = 1.0;
        for (double a : powers) exact /= 1.0 + a;
        return Json{{"name", "product"},
                    {"domain", {{"type", "box"}, {"dim", powers.size()}}},
                    {"integrand", {{"type", "monomial"}, {"powers", powers}}},
                    {"exact", exact},
                    {"estimators", {"uniform", "sobol", "miser", "vegas", "vegas_plus"}}};
    };
    auto run = [](const Json& scene, uint64_t n) {
        Made<SceneRequest> r = build_request(
            scene, Json{{"n_min", n}, {"n_max", n}, {"reps", 32}, {"seed", 5}, {"threads", 1}});
        EXPECT_TRUE(r.ok()) << r.error;
        return run_study(r.value.problem, r.value.estimators, r.value.settings);
    };
    for (uint64_t n : {uint64_t(4096), uint64_t(16384)}) {
        const StudyResult finite = run(product({-0.45, -0.2}), n);
        for (const EstimatorStudy& e : finite.estimators) {
            const std::optional<Flag> f =
                find(estimator_flags(e, finite.settings), FlagCode::HeavyTail);
            EXPECT_FALSE(f.has_value())
                << e.spec.name << " N = " << n << ": tail index " << (f ? f->value : 0.0);
            const double se = 2.22 / std::sqrt(2048.0);
            EXPECT_NEAR(e.integrand.alpha, 1.0 / 0.45, 4.0 * se) << e.spec.name;
        }
        const StudyResult infinite = run(product({-0.55, -0.1, -0.1}), n);
        for (const EstimatorStudy& e : infinite.estimators) {
            const std::optional<Flag> f =
                find(estimator_flags(e, infinite.settings), FlagCode::HeavyTail);
            ASSERT_TRUE(f.has_value()) << e.spec.name << " N = " << n;
            EXPECT_EQ(f->severity, Severity::Warning) << e.spec.name;
            EXPECT_EQ(f->of, kTailProbes); // judged on the integrand's uniform probes
        }
    }
}

// A bounded peak is not a heavy tail: 1 + x + a Gaussian of sigma 0.01 on [0, 1] (bounded by
// 41) reads a Hill index near 0.6 at k = 2048 of 2^15 uniform probes, because the top k span the
// plateau and the peak; its top is far more compressed than a power tail of that index gives
// (the largest log-excess 3 where Pareto puts it near 13), so the integrand has no tail and
// uniform sampling raises no heavy_tail. The other way: x^-0.9 and x^-0.5 (infinite variance)
// keep their finite index and their warning, and their top passes the same test.
TEST(Diagnostics, ABoundedPeakHasNoTail) {
    auto run = [](const Json& integrand) {
        const Json scene = {{"name", "t"},
                            {"domain", {{"type", "interval"}, {"lower", 0}, {"upper", 1}}},
                            {"integrand", integrand},
                            {"exact", nullptr},
                            {"estimators", {"uniform"}}};
        Made<SceneRequest> r =
            build_request(scene, Json{{"n_min", 4096}, {"n_max", 4096}, {"reps", 8}, {"seed", 3}});
        EXPECT_TRUE(r.ok()) << r.error;
        return run_study(r.value.problem, r.value.estimators, r.value.settings);
    };
    const StudyResult peak =
        run("1 + x + exp(-0.5 * ((x - 0.3) / 0.01)^2) / (0.01 * sqrt(2 * pi))");
    const EstimatorStudy& p = named(peak, "uniform");
    EXPECT_TRUE(std::isinf(p.integrand.alpha));
    EXPECT_LT(p.integrand.top_log_p, std::log(kBoundedTopP));
    EXPECT_FALSE(find(estimator_flags(p, peak.settings), FlagCode::HeavyTail));
    for (const char* singular : {"x^-0.9", "x^-0.5"}) {
        const StudyResult s = run(singular);
        const EstimatorStudy& u = named(s, "uniform");
        EXPECT_TRUE(std::isfinite(u.integrand.alpha)) << singular;
        EXPECT_GT(u.integrand.top_log_p, std::log(0.01)) << singular;
        const std::optional<Flag> f = find(estimator_flags(u, s.settings), FlagCode::HeavyTail);
        ASSERT_TRUE(f.has_value()) << singular;
        EXPECT_EQ(f->severity, Severity::Warning) << singular;
    }
}

// A product of d powers near -1/3 has a finite variance (tail index 1 / max a_i ~ 3) but a
// slowly varying tail, P(f > t) ~ t^-3 (log t)^(d-1), that Hill's index at 2^15 uniform points
// reads near or below 2 (1.9-2.0 for d = 10 in the fresh battery: 30-34 false heavy_tail
// warnings). Where f's form says int f^2 is finite (every power above -1/2) heavy_tail is info;
// an infinite one (a power at or below -1/2) stays a warning, and so does an expression (form
// unknown) with the same values.
TEST(Diagnostics, HeavyTailKnowsTheSquareIntegralFromTheIntegrandsForm) {
    auto scene = [](const Json& integrand, int dim) {
        return Json{{"name", "product"},
                    {"domain", {{"type", "box"}, {"dim", dim}}},
                    {"integrand", integrand},
                    {"estimators", {"uniform", "miser"}}};
    };
    auto heavy_tail = [](const Json& sc) {
        Made<SceneRequest> r = build_request(
            sc, Json{{"n_min", 1024}, {"n_max", 1024}, {"reps", 8}, {"seed", 3}, {"threads", 1}});
        EXPECT_TRUE(r.ok()) << r.error;
        const StudyResult s = run_study(r.value.problem, r.value.estimators, r.value.settings);
        std::vector<std::optional<Flag>> out;
        for (const EstimatorStudy& e : s.estimators)
            out.push_back(find(estimator_flags(e, s.settings), FlagCode::HeavyTail));
        return out;
    };
    std::vector<double> finite(10, -0.34), infinite(10, -0.34);
    infinite[0] = -0.55;
    std::string expr = "1";
    for (int j = 1; j <= 10; ++j) expr += "*x" + std::to_string(j) + "^-0.34";
    for (const std::optional<Flag>& f :
         heavy_tail(scene({{"type", "monomial"}, {"powers", finite}}, 10))) {
        ASSERT_TRUE(f.has_value()); // Hill's index reads below 2 + 2 se ...
        EXPECT_LT(f->value, 2.0 + 2.0 * f->se);
        EXPECT_EQ(f->severity, Severity::Info); // ... but int f^2 is finite
        const std::string said =
            tail_warning(*f, 0, TailWording{"w", "w", "N", "v"})["message"].get<std::string>();
        EXPECT_NE(said.find("int f^2 finite"), std::string::npos) << said;
    }
    for (const std::optional<Flag>& f :
         heavy_tail(scene({{"type", "monomial"}, {"powers", infinite}}, 10))) {
        ASSERT_TRUE(f.has_value());
        EXPECT_EQ(f->severity, Severity::Warning);
    }
    for (const std::optional<Flag>& f :
         heavy_tail(scene({{"type", "expression"}, {"f", expr}}, 10))) {
        ASSERT_TRUE(f.has_value());
        EXPECT_EQ(f->severity, Severity::Warning); // the form unknown: the tail alone speaks
    }
    // The rule itself: int_0 x^(2p) dx is finite iff 2p > -1; a box away from 0 bounds x^p.
    auto monomial = [](std::vector<double> p) {
        const size_t d = p.size();
        return make_integrand(IntegrandKind::Monomial, static_cast<int>(d), 1.0, std::move(p), {},
                              1.0)
            .value;
    };
    const std::vector<double> lo2{0.0, 0.0}, hi2{1.0, 1.0}, away{0.5, 0.0};
    EXPECT_EQ(integrand_square_integrable(monomial({-0.45, -0.2}), lo2, hi2), true);
    EXPECT_EQ(integrand_square_integrable(monomial({-0.5, 0.0}), lo2, hi2), false);
    EXPECT_EQ(integrand_square_integrable(monomial({-0.2, -0.55}), lo2, hi2), false);
    EXPECT_EQ(integrand_square_integrable(monomial({-0.9, -0.2}), away, hi2), true);
    EXPECT_EQ(
        integrand_square_integrable(make_expression_integrand("x1^-0.3", 1).value, {0.0}, {1.0}),
        std::nullopt);
}

// Agreement is not exactness. A deterministic point set (Sobol' without randomization) gives
// the same wrong answer in every replicate: not exact, and with the exact value known an error.
// Values whose squares underflow (1e-170 x) agree in their variances (0) while the estimates
// differ: not exact, and flagged values_underflow (an error). A stated exact value that the
// replicates agree on to round-off (the matched density of a narrow peak) stays exact; the same
// estimator with a wrong stated value is not, and misses it.
TEST(Diagnostics, AgreementIsNotExactness) {
    auto run = [](const Json& scene) {
        Made<SceneRequest> r =
            build_request(scene, Json{{"n_min", 64}, {"n_max", 128}, {"reps", 8}, {"seed", 2}});
        EXPECT_TRUE(r.ok()) << r.error;
        return run_study(r.value.problem, r.value.estimators, r.value.settings);
    };
    const Json box = {{"type", "box"}, {"dim", 1}};
    StudyResult det = run(Json{
        {"name", "det"},
        {"domain", box},
        {"integrand", {{"type", "expression"}, {"f", "x^2"}}},
        {"exact", 1.0 / 3.0},
        {"estimators", {{{"name", "fixed"}, {"sampler", "sobol"}, {"randomization", "none"}}}}});
    for (const LevelStats& l : det.estimators[0].levels) {
        EXPECT_TRUE(l.deterministic) << l.n;
        EXPECT_FALSE(l.exact_to_roundoff) << l.n;
        EXPECT_TRUE(has(level_flags(l), FlagCode::ExactOutsideCi)) << l.n;
    }
    StudyResult tiny = run(Json{{"name", "tiny"},
                                {"domain", box},
                                {"integrand", {{"type", "expression"}, {"f", "1e-170*x"}}},
                                {"estimators", {"uniform"}}});
    for (const LevelStats& l : tiny.estimators[0].levels) {
        EXPECT_TRUE(l.values_underflow) << l.n;
        EXPECT_FALSE(l.exact_to_roundoff) << l.n;
        const std::optional<Flag> f = find(level_flags(l), FlagCode::ValuesUnderflow);
        ASSERT_TRUE(f.has_value());
        EXPECT_EQ(f->severity, Severity::Error);
    }
    StudyResult scaled = run(Json{{"name", "scaled"},
                                  {"domain", box},
                                  {"integrand", {{"type", "expression"}, {"f", "1e-100*x"}}},
                                  {"estimators", {"uniform"}}});
    for (const LevelStats& l : scaled.estimators[0].levels) {
        EXPECT_FALSE(l.values_underflow) << l.n;
        EXPECT_TRUE(l.estimates_spread) << l.n;
        EXPECT_FALSE(has(level_flags(l), FlagCode::ValuesUnderflow)) << l.n;
    }
    // The matched density of x^2 on [0, 1] is 3 x^2: f/p = 1/3 at every point.
    const Json matched = {
        {"name", "m"},
        {"domain", box},
        {"integrand", {{"type", "monomial"}, {"powers", {2.0}}}},
        {"exact", 1.0 / 3.0},
        {"estimators", {{{"name", "matched"}, {"pdf", {{"type", "power"}, {"k", 2.0}}}}}}};
    StudyResult right = run(matched);
    Json wrong_exact = matched;
    wrong_exact["exact"] = 0.34;
    StudyResult wrong = run(wrong_exact);
    for (size_t i = 0; i < right.estimators[0].levels.size(); ++i) {
        EXPECT_TRUE(right.estimators[0].levels[i].exact_to_roundoff);
        EXPECT_FALSE(wrong.estimators[0].levels[i].exact_to_roundoff);
        EXPECT_TRUE(has(level_flags(wrong.estimators[0].levels[i]), FlagCode::ExactOutsideCi));
    }
}

// The same rules on real studies of 32 replicates, both ways. A product of x^-0.3 in d = 4 (finite
// variance, an infinite fourth moment: the sample skewness is erratic) at N = 16384, whose
// intervals cover: no warning (skewness and unstable error bars are info, with the counts).
// Genz's corner peak in d = 2 (c = 75 per axis) at N = 2048, where a run sees a handful of
// points in the peak: the intervals fail, and skewed_weights stays a warning.
TEST(Diagnostics, TheReplicatesDecideOnSkewedRealStudies) {
    auto run = [](const Json& scene, uint64_t n, uint64_t seed) {
        Made<SceneRequest> r =
            build_request(scene, Json{{"n_min", n}, {"n_max", n}, {"reps", 32}, {"seed", seed}});
        EXPECT_TRUE(r.ok()) << r.error;
        return run_study(r.value.problem, r.value.estimators, r.value.settings);
    };
    const double a = 0.3;
    const Json product = {{"name", "product"},
                          {"domain", {{"type", "box"}, {"dim", 4}}},
                          {"integrand", {{"type", "monomial"}, {"powers", {-a, -a, -a, -a}}}},
                          {"exact", std::pow(1.0 / (1.0 - a), 4)},
                          {"estimators", {"uniform", "sobol"}}};
    StudyResult fine = run(product, 16384, 2);
    for (const EstimatorStudy& e : fine.estimators) {
        std::vector<Flag> flags = level_flags(e.levels.front());
        for (const Flag& f : estimator_flags(e, fine.settings)) flags.push_back(f);
        for (const Flag& f : flags)
            EXPECT_EQ(f.severity, Severity::Info) << e.spec.name << " " << flag_code_name(f.code);
    }
    const Json peak = {
        {"name", "corner"},
        {"integrand", {{"type", "genz_corner_peak"}, {"a", {75.0, 75.0}}, {"u", {0.5, 0.5}}}},
        {"estimators", {"uniform", "sobol"}}};
    StudyResult failing = run(peak, 2048, 1);
    for (const EstimatorStudy& e : failing.estimators) {
        const std::optional<Flag> skew =
            find(level_flags(e.levels.front()), FlagCode::SkewedWeights);
        ASSERT_TRUE(skew.has_value()) << e.spec.name;
        EXPECT_EQ(skew->severity, Severity::Warning) << e.spec.name;
        EXPECT_GT(skew->replicate_misses, skew->miss_allowance) << e.spec.name;
    }
}

// --- Goodness of fit of the power-law fits (fit, mse_fit: chi2, dof, p_value, suffix) ---------

namespace {

// A variance ladder N = 16 .. 65536 (13 levels) whose sample variances follow factor(k) / N with
// the noise of R normal replicates: (R - 1) s^2 / sigma^2 is chi-square with R - 1 degrees of
// freedom, drawn here as a sum of R - 1 squared normals.
std::vector<LevelStats> variance_ladder(Pcg32& rng, int reps, double (*factor)(size_t)) {
    std::vector<LevelStats> levels(13);
    for (size_t k = 0; k < levels.size(); ++k) {
        double chi2 = 0.0;
        for (int r = 0; r + 1 < reps; ++r) {
            const double u1 = 1.0 - rng.next_double(), u2 = rng.next_double();
            const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
            chi2 += z * z;
        }
        LevelStats& l = levels[k];
        l.n = uint64_t(16) << k;
        l.reps = reps;
        l.mean = 1.0;
        l.variance = factor(k) / static_cast<double>(l.n) * chi2 / (reps - 1);
        l.std_error = std::sqrt(l.variance / reps);
        l.estimates_spread = true;
    }
    return levels;
}

double no_jump(size_t) {
    return 1.0;
}
// Two jumps by 100: at level 3 (N = 128) and at level 6 (N = 1024).
double two_jumps(size_t k) {
    return k < 3 ? 1.0 : k < 6 ? 100.0 : 10000.0;
}

} // namespace

// Ladders that follow N^-1 with the noise of R = 32 normal replicates: the chi-square of the
// log-log line is nearly chi-square with 11 degrees of freedom (log s^2 is nearly normal, with
// variance psi'((R - 1) / 2)). Its slight left skew makes p < 0.01 on 1.14% of ladders and
// p < 1e-3 on 0.13% (20000 ladders of this generator). Of 400: 4.6 expected below 0.01, and 12
// or more has binomial probability 0.005 (P(Bin(400, 0.0125) >= 12)); 0.5 expected below 1e-3,
// 5 or more has probability 2.4e-4. Where the whole range passes, no suffix is looked for.
TEST(PowerLawFit, LaddersThatFollowAPowerLawPass) {
    Pcg32 rng(38, 1);
    const int ladders = 400;
    int rejected = 0, failed_whole = 0;
    for (int i = 0; i < ladders; ++i) {
        const ConvergenceFit fit = fit_convergence(variance_ladder(rng, 32, no_jump));
        ASSERT_TRUE(fit.valid);
        EXPECT_EQ(fit.dof, 11);
        EXPECT_EQ(fit.n_first, 16u);
        EXPECT_EQ(fit.n_last, 65536u);
        EXPECT_NEAR(fit.p_value, chi_square_sf(fit.chi2, 11), 1e-15);
        rejected += fit.p_value < 0.01;
        failed_whole += fit.p_value < kPowerLawP;
        if (fit.p_value >= kPowerLawP) {
            EXPECT_FALSE(fit.suffix.has_value());
        }
    }
    EXPECT_LE(rejected, 11) << "of " << ladders;
    EXPECT_LE(failed_whole, 4) << "of " << ladders; // 0.4 expected; P(>= 5) = 8e-4
}

// Two jumps by 100 (at N = 128 and N = 1024): no power law (p < 1e-6), and the longest suffix
// that is one starts after the second jump, at N = 1024, with the order -1 of the levels there.
TEST(PowerLawFit, JumpsFailAndTheSuffixStartsAfterThem) {
    Pcg32 rng(38, 2);
    for (int i = 0; i < 20; ++i) {
        const ConvergenceFit fit = fit_convergence(variance_ladder(rng, 32, two_jumps));
        ASSERT_TRUE(fit.valid);
        EXPECT_LT(fit.p_value, 1e-6);
        ASSERT_TRUE(fit.suffix.has_value()) << i;
        const PowerLawSegment& tail = *fit.suffix;
        EXPECT_EQ(tail.n_first, 1024u) << i;
        EXPECT_EQ(tail.n_last, 65536u);
        EXPECT_EQ(tail.levels_used, 7) << i;
        EXPECT_EQ(tail.dof, 5) << i;
        EXPECT_GE(tail.p_value, kSuffixP);
        EXPECT_NEAR(tail.order, -1.0, 4.0 * tail.order_se) << i;
    }
    // A ladder with no run of 4 levels on one line: every level 30x off its neighbours.
    std::vector<FitPoint> zigzag;
    for (int k = 0; k < 10; ++k) zigzag.push_back({uint64_t(16) << k, k % 2 ? 30.0 : 1.0, 0.25});
    const ConvergenceFit none = fit_power_law(zigzag, LevelMeasure::Variance);
    ASSERT_TRUE(none.valid);
    EXPECT_LT(none.p_value, 1e-6);
    EXPECT_FALSE(none.suffix.has_value());
    // Unknown noise (sd_log 0: unit weights): no chi-square, no p-value, no suffix.
    for (FitPoint& p : zigzag) p.sd_log = 0.0;
    const ConvergenceFit unweighted = fit_power_law(zigzag, LevelMeasure::Variance);
    ASSERT_TRUE(unweighted.valid);
    EXPECT_TRUE(std::isnan(unweighted.chi2) && std::isnan(unweighted.p_value));
    EXPECT_FALSE(unweighted.suffix.has_value());
}

// Real estimators: uniform sampling of a smooth 1-D integrand follows N^-1 (p >= 1e-3 at this
// seed), stratified sampling of x^-0.9 (infinite variance) does not, and the JSON and the
// table say so.
TEST(PowerLawFit, RealEstimatorsAndTheirReports) {
    const Json options{{"n_min", 16}, {"n_max", 65536}, {"reps", 32}, {"seed", 1}};
    const StudyResult smooth = study("exp_1d", options);
    const ConvergenceFit& uniform = named(smooth, "uniform").fit;
    ASSERT_TRUE(uniform.valid);
    EXPECT_GE(uniform.p_value, kPowerLawP);
    EXPECT_FALSE(uniform.suffix.has_value());
    EXPECT_EQ(uniform.n_first, 16u);
    EXPECT_EQ(uniform.n_last, 65536u);
    const StudyResult heavy = study("singular_power_0.9", options);
    const ConvergenceFit& stratified = named(heavy, "stratified").fit;
    ASSERT_TRUE(stratified.valid);
    EXPECT_LT(stratified.p_value, 1e-6);

    const Json j = fit_to_json(uniform);
    for (const char* key : {"chi2", "dof", "p_value", "n_first", "n_last", "suffix"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j["suffix"].is_null());
    EXPECT_EQ(j["dof"], 11);
    const std::string smooth_table = format_table(study_to_json(smooth));
    const std::string heavy_table = format_table(study_to_json(heavy));
    EXPECT_EQ(smooth_table.find("not a power law"), std::string::npos);
    EXPECT_NE(heavy_table.find("not a power law: chi^2 p = "), std::string::npos) << heavy_table;
    // An invalid fit has nulls, not numbers.
    const Json invalid = fit_to_json(ConvergenceFit{});
    for (const char* key : {"chi2", "dof", "p_value", "n_first", "n_last", "suffix"})
        EXPECT_TRUE(invalid[key].is_null()) << key;
}

// --- Messages never say "p = 0" ----------------------------------------------------------------

// The one formatter of p-values in sentences: a p-value below 1e-300 (or 0 from underflow) is
// "p < 1e-300", never "p = 0"; others keep their significant digits.
TEST(PValueText, NeverZero) {
    EXPECT_EQ(p_value_text(0.0), "p < 1e-300");
    EXPECT_EQ(p_value_text(1e-310), "p < 1e-300"); // subnormal
    EXPECT_EQ(p_value_text(1e-300), "p = 1e-300");
    EXPECT_EQ(p_value_text(3.14159e-5), "p = 3.1e-05");
    EXPECT_EQ(p_value_text(0.25, 3), "p = 0.25");
    EXPECT_EQ(p_value_text(0.123456, 4), "p = 0.1235");
    EXPECT_EQ(p_value_text(std::nan("")), "p = -");
    EXPECT_EQ(p_value_text(chi_square_sf(5000.0, 3)), "p < 1e-300");
}

// Latin hypercube's iid bound on exp_1d is hundreds of times too wide: the F test's lower tail
// underflows to 0, and the message says "p < 1e-300".
TEST(PValueText, UnderflowedPValuesInMessages) {
    const StudyResult s = study("exp_1d", Json{{"n_min", 256},
                                               {"n_max", 1024},
                                               {"reps", 32},
                                               {"seed", 1},
                                               {"estimators", {"latin_hypercube"}}});
    const std::optional<Flag> wide =
        find(level_flags(s.estimators[0].levels.front()), FlagCode::ConservativeErrorBars);
    ASSERT_TRUE(wide.has_value());
    EXPECT_EQ(wide->p_value, 0.0); // underflowed: the message must not print it as it is
    const std::string text = study_to_json(s).dump();
    EXPECT_EQ(text.find("p = 0)"), std::string::npos);
    EXPECT_EQ(text.find("p = 0,"), std::string::npos);
    EXPECT_NE(text.find("(F test, p < 1e-300)"), std::string::npos);
}

// --- bias_dominates is not a heavy tail's shortfall --------------------------------------------

namespace {

// Five levels whose mean falls 0.1 short of the exact value 1, 10 standard errors away, with a
// tail index `alpha` (64 weights) at the largest N; `misses_mass`: the support check found
// mass the pdf misses.
EstimatorStudy falling_short(double alpha, bool misses_mass) {
    EstimatorStudy e;
    for (int k = 0; k < 5; ++k) {
        LevelStats l;
        l.n = uint64_t(1024) << k;
        l.reps = 32;
        l.has_exact = true;
        l.exact = 1.0;
        l.mean = 0.9;
        l.bias = -0.1;
        l.variance = 1e-4;
        l.std_error = std::sqrt(l.variance / l.reps);
        l.mse = l.bias * l.bias + l.variance;
        l.estimates_spread = true;
        l.tail_index = alpha;
        l.tail_k = 64;
        e.levels.push_back(l);
    }
    if (misses_mass) {
        e.support.flagged = true;
        e.support.missed = 12;
        e.support.f_nonzero = 60000;
    }
    return e;
}

} // namespace

// Both ways on levels built to order: with an infinite variance (heavy_tail as a warning: tail
// index 1.2) and no source of bias, no bias_dominates; the same shortfall with mass the pdf
// misses, with dropped samples, with a finite-variance tail (5), or with bounded weights
// (heavy_tail as info) keeps it.
TEST(Diagnostics, BiasDominatesIsNotAHeavyTailsShortfall) {
    const StudySettings settings;
    const std::vector<Flag> heavy = estimator_flags(falling_short(1.2, false), settings);
    ASSERT_TRUE(find(heavy, FlagCode::HeavyTail).has_value());
    EXPECT_EQ(find(heavy, FlagCode::HeavyTail)->severity, Severity::Warning);
    EXPECT_FALSE(find(heavy, FlagCode::BiasDominates).has_value());

    EXPECT_TRUE(find(estimator_flags(falling_short(1.2, true), settings), FlagCode::BiasDominates));
    EstimatorStudy dropped = falling_short(1.2, false);
    dropped.levels[2].diagnostics.zero_pdf = 3;
    EXPECT_TRUE(known_bias_source(dropped));
    EXPECT_TRUE(find(estimator_flags(dropped, settings), FlagCode::BiasDominates));
    EXPECT_TRUE(
        find(estimator_flags(falling_short(5.0, false), settings), FlagCode::BiasDominates));
    EstimatorStudy bounded = falling_short(1.2, false);
    bounded.weights_bounded = true;
    const std::vector<Flag> info = estimator_flags(bounded, settings);
    EXPECT_EQ(find(info, FlagCode::HeavyTail)->severity, Severity::Info);
    EXPECT_TRUE(find(info, FlagCode::BiasDominates));

    // Real studies: x^-0.9 sampled uniformly, stratified or by x^-0.45 is unbiased with an
    // infinite variance: no bias_dominates; a pdf that misses a quarter of the support
    // (is_zero_pdf's importance_gap) keeps it.
    const StudyResult s = study("singular_power_0.9",
                                Json{{"n_min", 16}, {"n_max", 65536}, {"reps", 32}, {"seed", 1}});
    for (const char* name : {"uniform", "stratified", "importance_half"}) {
        const EstimatorStudy& e = named(s, name);
        const std::vector<Flag> flags = estimator_flags(e, s.settings);
        EXPECT_TRUE(find(flags, FlagCode::HeavyTail)) << name;
        EXPECT_FALSE(find(flags, FlagCode::BiasDominates)) << name;
        EXPECT_FALSE(known_bias_source(e)) << name;
    }
    const StudyResult z =
        study("is_zero_pdf", Json{{"n_min", 256}, {"n_max", 16384}, {"reps", 16}, {"seed", 6}});
    EXPECT_TRUE(known_bias_source(named(z, "importance_gap")));
    EXPECT_TRUE(
        find(estimator_flags(named(z, "importance_gap"), z.settings), FlagCode::BiasDominates));
}

// --- heavy_tail needs a tail ----------------------------------------------------------------

// Points that never saw the peak of width 1e-8 (uniform): every weight is 0, Hill's index is 0
// (fewer than k + 1 non-zero weights) and undefined, so no heavy_tail; the level's own flags
// say what is wrong. A real tail index of 1.2 still raises it.
TEST(Diagnostics, NoHeavyTailFromWeightsThatAreAllZero) {
    LevelStats zero;
    zero.n = 65536;
    zero.tail_k = 64;
    zero.tail_index = 0.0;
    EXPECT_TRUE(tail_flags(zero).empty());
    EXPECT_TRUE(tail_flags(zero, true).empty());
    LevelStats heavy = zero;
    heavy.tail_index = 1.2;
    ASSERT_EQ(tail_flags(heavy).size(), 1u);
    EXPECT_EQ(tail_flags(heavy)[0].code, FlagCode::HeavyTail);

    const StudyResult s =
        study("stiff_peak_1e-8", Json{{"n_min", 16}, {"n_max", 65536}, {"reps", 32}, {"seed", 1}});
    for (const char* name : {"uniform", "stratified"}) {
        const EstimatorStudy& e = named(s, name);
        EXPECT_EQ(e.levels.back().tail_index, 0.0) << name;
        const std::vector<Flag> flags = estimator_flags(e, s.settings);
        EXPECT_FALSE(find(flags, FlagCode::HeavyTail)) << name;
        EXPECT_FALSE(find(flags, FlagCode::HeavyTail4)) << name;
        const std::vector<Flag> deepest = level_flags(e.levels.back());
        EXPECT_TRUE(find(deepest, FlagCode::ExactOutsideCi)) << name;
        EXPECT_TRUE(find(deepest, FlagCode::LowEss)) << name;
    }
}

namespace {

/// A level of 32 replicates of stiff_peak_1e-8 (scenes/), as `mcplay run stiff_peak_1e-8`
/// (seed 1) gave it: every estimate 0 but those listed (replicate index, estimate, its standard
/// error), the exact value 2.5066282746310004e-08.
LevelStats stiff_level(uint64_t n, const std::vector<std::tuple<int, double, double>>& hits,
                       bool underflow, double mean, double variance, double std_error) {
    LevelStats l;
    l.n = n;
    l.reps = 32;
    l.has_exact = true;
    l.exact = 2.5066282746310004e-08;
    l.estimates.assign(32, 0.0);
    l.run_std_errors.assign(32, 0.0);
    l.run_dofs.assign(32, int(n - 1));
    for (const auto& [i, estimate, se] : hits) {
        l.estimates[size_t(i)] = estimate;
        l.run_std_errors[size_t(i)] = se;
    }
    l.zero_error_runs = 0;
    for (double se : l.run_std_errors) l.zero_error_runs += se == 0.0;
    l.estimates_spread = !hits.empty();
    l.values_underflow = underflow;
    l.mean = mean;
    l.variance = variance;
    l.std_error = std_error;
    l.bias = mean - l.exact;
    l.mean_run_variance = variance;
    l.ess_mean = 1.0;
    for (uint64_t i = 0; i < n; ++i) l.diagnostics.weights.add(0.0);
    l.diagnostics.error_units = l.diagnostics.weights;
    return l;
}

std::string message(const LevelStats& l, const char* code) {
    const Json level = level_to_json(l);
    for (const Json& w : level["warnings"])
        if (w["code"] == code) return w["message"].get<std::string>();
    return "";
}

} // namespace

// Issue 48: the sentences never contradict themselves. stiff_peak_1e-8's uniform level at N =
// 65536 (three replicates hit the peak's tail with estimates near 1e-213 whose squares
// underflow) said "32 of 32 replicates reported a standard error of 0 ... although the
// replicates differ (standard deviation 0)"; its stratified level at N = 65536 (one replicate
// with an error bar) said "replicate 8 of 1 lies 1745710461143661828018334957940699564960403746
// 193408.0 of its own standard errors". Now the standard deviation is the true one (computed in
// long double here, whose range holds these squares), the count is of all 32, and numbers beyond
// 1e6 are in scientific notation. Replicates that do not differ raise no zero_error_bar.
TEST(Diagnostics, StiffPeakSentencesDoNotContradictThemselves) {
    const LevelStats uniform = stiff_level(65536,
                                           {{7, 2.4832149768102067e-243, 0.0},
                                            {11, 2.256226285920717e-213, 0.0},
                                            {25, 5.1702390876908826e-284, 0.0}},
                                           true, 7.050707143502241e-215, 0.0, 0.0);
    std::optional<Flag> f = find(level_flags(uniform), FlagCode::ZeroErrorBar);
    ASSERT_TRUE(f.has_value());
    long double sum = 0.0L, squares = 0.0L;
    for (double x : uniform.estimates) sum += x;
    const long double mean = sum / 32.0L;
    for (double x : uniform.estimates) squares += (x - mean) * (x - mean);
    const double sd = double(std::sqrt(squares / 31.0L));
    EXPECT_NEAR(f->value, sd, 1e-12 * sd);
    const std::string zero = message(uniform, "zero_error_bar");
    EXPECT_NE(zero.find("32 of 32 replicates reported a standard error of 0 at N = 65536 although "
                        "the replicates differ (standard deviation 3.99e-214, from 0 to "
                        "2.26e-213): their error bars are wrong (the squares of values this "
                        "small underflow"),
              std::string::npos)
        << zero;
    EXPECT_EQ(zero.find("standard deviation 0)"), std::string::npos) << zero;

    const LevelStats stratified =
        stiff_level(65536, {{7, 1.4358676345789038e-59, 1.435878589504952e-59}}, false,
                    4.4870863580590745e-61, 6.442862075097552e-120, 4.4870863580590745e-61);
    const std::string far = message(stratified, "replicate_far_off");
    EXPECT_NE(far.find("replicate 8 of 32 (1 of the 32 had an error bar to judge) lies 1.7e+51 "
                       "of its own standard errors from the exact value at N = 65536"),
              std::string::npos)
        << far;
    const std::string outside = message(stratified, "exact_outside_ci");
    EXPECT_NE(outside.find("misses the exact value by 5.6e+52 standard errors"), std::string::npos)
        << outside;

    // Both ways: all 32 replicates judged print no count of the judged; every replicate 0 (they
    // do not differ) raises no zero_error_bar.
    std::vector<double> z = honest_errors(32);
    z[7] = 5.6;
    EXPECT_NE(message(replicates_level(z, true), "replicate_far_off")
                  .find("replicate 8 of 32 lies 5.6 of its own standard errors"),
              std::string::npos);
    EXPECT_FALSE(
        find(level_flags(stiff_level(65536, {}, false, 0.0, 0.0, 0.0)), FlagCode::ZeroErrorBar));
}

// Every sentence writes a number beyond 1e6 or below 1e-4 (not 0) in scientific notation.
TEST(Diagnostics, SentencesWriteLargeAndSmallNumbersInScientificNotation) {
    EXPECT_EQ(fmt("%.1f", 1745710461143661828018334957940699564960403746193408.0), "1.7e+51");
    EXPECT_EQ(fmt("%.1f", 999999.94), "999999.9");
    EXPECT_EQ(fmt("%.1f", 1e6), "1.0e+06");
    EXPECT_EQ(fmt("%.1f", 5e-5), "5.0e-05");
    EXPECT_EQ(fmt("%.1f", 0.0), "0.0");
    EXPECT_EQ(fmt("%.3g%%", 12.5), "12.5%");
    EXPECT_EQ(fmt("%.2f%%", 2e7), "2.00e+07%");
}
