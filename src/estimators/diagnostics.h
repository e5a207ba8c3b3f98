// Diagnostics as data: which flags a level or an estimator raises, with the thresholds and the
// evidence behind each. The study, the renderer, stopping rules and the tests read these; the
// API only turns them into sentences (src/api/report.cpp).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "estimators/study.h"

namespace mcp {

enum class FlagCode {
    NoEstimate,            ///< every sample of some run was NaN/Inf
    NonfiniteEstimate,     ///< the mean of the replicates overflowed
    NonfiniteVariance,     ///< the variance across replicates is not a finite number >= 0
    ZeroErrorBar,          ///< runs reported se = 0 although the replicates differ
    NonfiniteSamples,      ///< samples with NaN/Inf f/p were dropped (biased)
    ZeroPdfSamples,        ///< samples with f != 0 where p = 0 were dropped (biased)
    SkewedWeights,         ///< the weights too skewed for a normal error bar at this N
    LowEss,                ///< Kish's effective sample size is a handful
    ExactOutsideCi,        ///< the replicates' mean misses the exact value
    HeavyTail,             ///< tail index within 2 standard errors of 2 (or below)
    HeavyTail4,            ///< tail index below 4
    PdfSupport,            ///< the pdf is zero where f is not
    LevelDrift,            ///< the level means disagree beyond their error bars
    Float32Accumulator,    ///< naive single-precision sums (teaching mode)
    IterationsDisagree,    ///< an iteration average's iterations disagree beyond their error bars
    ErrorBarsUnderstate,   ///< the replicates spread more than their own error bars allow
    ErrorBarsUnstable,     ///< the replicates' own error bars disagree far beyond their dof
    BiasDominates,         ///< from some N on the bias, not the variance, makes the MSE
    ConservativeErrorBars, ///< the replicates spread far less than their error bars say
    // Render studies (render/render_study.h: render_flags).
    BelowReferenceNoise, ///< a level's relative MSE is below the reference's own noise
    ReferenceNoise,      ///< some levels lie below the reference's noise (left out of the fit)
    SlowConvergence,     ///< relative MSE falls clearly slower than 1/spp
    PixelErrorBars,      ///< too few pixels' 95% intervals cover the reference
    FewPixelErrors,      ///< a level's relative MSE rests on a few (pixel, image) errors
    RareLargeErrors,     ///< some levels rest on a few pixel errors: rare large errors
    // Added with issue 37 (kept after the render codes: codes are names in results, the enum
    // order is not).
    ValuesUnderflow, ///< the estimates are below 1e-150: their squares underflow
    ReplicateFarOff, ///< a replicate lies beyond 5 (t-widened) of its own standard errors
};

/// The stable code of a flag in results ("no_estimate", "heavy_tail", ...).
const char* flag_code_name(FlagCode code);

/// How much a flag matters, most first:
/// - Error: the estimate or its error bar is wrong (samples dropped, mass the pdf misses, an
///   exact value far outside the interval, error bars the replicates contradict);
/// - Warning: the error bar cannot be trusted at this N (evidence of infinite variance, too
///   few effective samples, drift across N);
/// - Info: worth knowing, nothing is wrong (a finite-variance heavy tail, teaching modes).
enum class Severity { Error, Warning, Info };

/// "error", "warning", "info".
const char* severity_name(Severity severity);

/// The severity of a code when its evidence says nothing more.
Severity default_severity(FlagCode code);

/// One raised flag and its evidence. Fields a flag does not use stay NaN / 0. Built from its
/// code, with the code's default severity.
struct Flag {
    explicit Flag(FlagCode c) : code(c), severity(default_severity(c)) {}
    FlagCode code;
    Severity severity;
    uint64_t n = 0; ///< the level's N (0 for an estimator-wide flag)
    double value = std::numeric_limits<double>::quiet_NaN();     ///< the statistic
    double se = std::numeric_limits<double>::quiet_NaN();        ///< its standard error
    double threshold = std::numeric_limits<double>::quiet_NaN(); ///< what it was compared with
    uint64_t count = 0, of = 0; ///< e.g. runs or samples concerned, out of how many
    int dof = 0;                ///< chi-square degrees of freedom (level drift)
    double p_value = std::numeric_limits<double>::quiet_NaN();
    /// The replicates' own evidence (ReplicateCheck), where a flag's severity rests on it:
    /// replicates judged (0: not consulted), how many missed their 95% interval, and how many
    /// misses honest intervals give in 9 of 10 studies.
    int replicates_judged = 0, replicate_misses = 0, miss_allowance = 0;
    /// The replicates' studentized skewness where the flag rests on it (replicate_far_off from
    /// the skew's signature, ReplicateCheck::skewed_index), NaN otherwise.
    double skewness = std::numeric_limits<double>::quiet_NaN();
};

/// Each replicate against its own 95% interval: its estimate's distance from the exact value
/// (when known) or from the mean of the other replicates (leave-one-out, with that mean's own
/// uncertainty added), in its own standard errors, widened to normal-equivalent units by
/// widened_limit. Replicates without a finite, positive error bar are not judged.
struct ReplicateCheck {
    int judged = 0;
    int misses = 0;           ///< outside their t_0.975(dof) interval
    int far = 0;              ///< beyond widened_limit(kFarOffZ, dof)
    int worst_index = -1;     ///< the replicate farthest off (-1: none judged)
    double worst_z = 0.0;     ///< its distance in its own standard errors
    double worst_limit = 0.0; ///< widened_limit(kFarOffZ, its degrees of freedom)
    int allowance = 0;        ///< misses that honest 95% intervals exceed in < 1 study in 10
    /// Without the exact value: the skewness of t_i = (x_i - mean of the others) / se_i, and
    /// the replicate farthest off on the side it points to when |skewness| > kSkewSignature and
    /// |t_i| > widened_limit(kSkewedFarZ, dof) (-1: none).
    double skewness = std::numeric_limits<double>::quiet_NaN();
    int skewed_index = -1;
    double skewed_z = 0.0, skewed_limit = 0.0;
};
ReplicateCheck check_replicates(const LevelStats& level);

/// The replicates against their own error bars, one by one: Q = sum_i z_i^2, z_i the distance
/// of replicate i from the exact value (when known) or from the replicates' plain mean (over
/// the sd of that difference, sqrt(se_i^2 (1 - 2/R) + sum_j se_j^2 / R^2)), each z_i taken from
/// Student t with the run's dof to the normal quantile of the same tail. Q has mean R and is
/// about chi^2_R under honest error bars (Cochran's Q of a meta-analysis [Cochran54]). Unlike
/// the F test of the mean se^2, it sees runs with tiny error bars that scatter far beyond them
/// beside a few runs with large ones. Replicates without a finite, positive error bar and a
/// dof >= 1 are left out; fewer than 4: not judged (judged = 0, p NaN).
struct ScatterTest {
    int judged = 0;
    double q = 0.0;
    double p_value = std::numeric_limits<double>::quiet_NaN();
};
ScatterTest replicate_scatter(const LevelStats& level);

// Thresholds (see the functions' comments for why).
constexpr double kSkewnessRule = 25.0; ///< skewed_weights below N = 25 g1^2 [Cochran77]
/// One weight carrying this share of a run's sum: the run rests on a few weights (its Kish ESS
/// is at most 1 / share^2), too few for replicates judged blind to vouch for its interval.
constexpr double kRulingShare = 0.1;
constexpr double kErrorBarSpread = 2.0; ///< runs' max se / min se above this: unsettled
/// error_bars_unstable: runs' max se / min se above this (some run's error bar is off by a
/// factor 2 or more from the others' middle: enough to show a 2.5-SE error as 5 SE), and
/// Bartlett's test at p < kLevelDriftP.
constexpr double kUnstableSpread = 4.0;
constexpr double kLowEss = 10.0; ///< mean ESS below this (and below N/4) flags
constexpr double kLowEssShare = 0.25;
constexpr double kExactOutsideZ = 5.0;  ///< |mean - exact| beyond this many standard errors
constexpr double kLevelDriftP = 1e-3;   ///< chi-square p-value below this flags
constexpr double kHeavyTailAlpha = 2.0; ///< infinite variance below this tail index
constexpr double kHeavyTail4Alpha = 4.0;
/// A replicate this many (t-widened: widened_limit) standard errors off has an error bar far too
/// small.
constexpr double kFarOffZ = 5.0;
/// Skewed weights make a run's studentized error skewed, -2 g1 / sqrt(N) for weights of
/// skewness g1 [Hall92]: a low estimate comes with a small error bar. The replicates'
/// deviations from the others' mean in their own error bars skewing beyond this (3 standard
/// errors of a sample skewness of 32 normal values) ...
constexpr double kSkewSignature = 1.2;
/// ... with one of them this many (t-widened) standard errors off on the side they skew toward
/// is a replicate whose error bar is far too small (honest: 32 replicates reach it in fewer than
/// 1 cell in 500).
constexpr double kSkewedFarZ = 4.0;
/// From this many judged replicates their misses are evidence enough to overrule a warning
/// that rests on the weights alone (skewed_weights, error_bars_unstable): with 20, an
/// estimator whose intervals cover 85% shows more than the allowance in 6 studies of 10.
constexpr int kEvidenceReplicates = 20;
/// The allowance: the most misses that honest 95% intervals exceed with probability < 0.1.
constexpr double kMissAllowanceP = 0.1;

/// The flags of one level, from its replicates' statistics: no estimate (then nothing else),
/// a non-finite mean or variance, wrong zero error bars, dropped samples, weights too skewed
/// for the normal approximation at this N (N < 25 g1^2: a warning below a quarter of that or
/// when the runs' error bars differ by more than a factor 2, else info), a low effective sample
/// size (< 10 and < N/4), and, with the
/// exact value known, a mean more than 5 standard errors (+ 1e-12 relative) away from it;
/// for iteration averages, iterations that disagree: the chi^2 summed over the runs has
/// p < 1e-3 (pooled, so that the 1 run in 100 with p < 0.01 by chance raises nothing).
std::vector<Flag> level_flags(const LevelStats& level);

/// Hill's tail index alpha, P(|x| > t) ~ t^-alpha, read at the deepest level (the pooled sample
/// reaches furthest into the tail): heavy_tail when alpha = 2 is within two standard errors
/// (alpha / sqrt(k)) or above alpha, heavy_tail_4 when alpha < 4 [Hill75]. With `bounded`
/// weights (every moment finite) heavy_tail is info: a pre-asymptotic tail, whose effect on the
/// error bars skewed_weights judges, with the N from which they hold. Nothing when alpha is 0:
/// fewer than k + 1 weights are non-zero (points that never saw f), and the tail is undefined.
/// With `integrand` measured (an estimator whose variance follows the integrand's,
/// variance_follows_integrand), the tail index is the integrand's at its uniform probes
/// instead (the flag's `of` says how many probes): an adaptive estimator's own weights can look
/// light-tailed under an infinite variance, or heavy under a finite one. Where f's form makes
/// int f^2 finite (IntegrandTail::square_integrable), heavy_tail from that index is info.
std::vector<Flag> tail_flags(const LevelStats& deepest, bool bounded = false,
                             const IntegrandTail* integrand = nullptr);

/// Whether the estimator has a known source of bias: the support check found mass the pdf
/// misses (pdf_support, a probe with f != 0 where p = 0, or a missed mass by quadrature that is
/// not finite), or some level dropped samples (f != 0 where p = 0, or f/p not finite).
bool known_bias_source(const EstimatorStudy& e);

/// The flags of an estimator over the whole study: the tail index at the deepest level, the
/// support check, the consistency of the level means (p < 1e-3), float32 accumulation, and
/// with an exact value a bias that dominates the MSE from some N to the largest (bias^2 above
/// the variance of one estimate and |bias| beyond 3 of its standard errors at every such N).
/// bias_dominates is not raised under an infinite variance (heavy_tail as a warning) without a
/// known source of bias (known_bias_source): the mean of an unbiased estimator with infinite
/// variance falls short of the integral in most studies, which is the heavy tail's doing.
std::vector<Flag> estimator_flags(const EstimatorStudy& e, const StudySettings& settings);

} // namespace mcp
