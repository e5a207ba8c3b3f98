// Convergence study: every estimator at every N of a ladder of powers of two, R independent
// replicates each, summarised by level (variance of the estimator, bias, RMSE, coverage,
// time, efficiency) and by a fitted convergence order. The ladder, the replicate keys, the
// thread pool and the fit are the machinery of integration and render studies alike
// (run_ladder, replicate_rng, fit_power_law; render/render_study.h measures images with them).
//
// Randomness: replicate r of estimator e at level N draws from its own PCG32 generator, whose
// state and stream both derive from a hash of (seed, name of e, N, r). Results are therefore
// identical whatever the thread count, and running a subset of the estimators does not change the
// ones that remain.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "core/stats.h"
#include "estimators/block_driver.h"
#include "estimators/estimator.h"

namespace mcp {

struct StudySettings {
    uint64_t n_min = 16;
    uint64_t n_max = 65536;
    int reps = 32;
    uint64_t seed = 1;
    int threads = 0; ///< 0: all hardware threads
    Accumulator accumulator = Accumulator::Compensated;
    /// Stopping at a requested accuracy (estimators/stopping.h) instead of the N ladder: either
    /// tolerance > 0 asks for it; N then doubles from n_min to at most n_max, each estimate for
    /// at most max_seconds (0: no limit).
    double abs_tol = 0.0, rel_tol = 0.0, max_seconds = 0.0;
    bool stopping() const { return abs_tol > 0.0 || rel_tol > 0.0; }
};

/// Checks the settings; returns an error message naming the setting, or "".
std::string check_settings(const StudySettings& s);

/// Largest study: integrand evaluations summed over the ladder, sum_N N x reps x estimators
/// (about 3 hours at 1e8 evaluations per second), and replicate results kept (levels x reps x
/// estimators: each is held in memory and written to the result).
constexpr uint64_t kMaxStudyEvaluations = uint64_t(1) << 40;
constexpr uint64_t kMaxReplicateResults = uint64_t(1) << 21;

/// Integrand evaluations of a study: sum over its N ladder of N x reps x estimators
/// (saturates at UINT64_MAX).
uint64_t study_evaluations(const StudySettings& s, size_t estimators);

/// Checks the size of a study before any work: kMaxStudyEvaluations and kMaxReplicateResults.
/// Returns an error message naming n_max, reps and the estimators, or "".
std::string check_study_size(const StudySettings& s, size_t estimators);

/// The N ladder: powers of two from the first >= n_min up to n_max.
std::vector<uint64_t> n_ladder(uint64_t n_min, uint64_t n_max);

/// What a level's `variance` (with variance_lo/hi and efficiency) and its study's fitted order
/// measure.
enum class LevelMeasure {
    Variance,    ///< integrals: the variance of the estimate across replicates
    Mse,         ///< integrals with an exact value: the replicates' mean squared error
    RelativeMse, ///< renders: the images' relative MSE against the reference (render_study.h)
};
/// "variance", "mse", "relative_mse".
const char* level_measure_name(LevelMeasure m);

/// Below this magnitude the squares of estimates and weights underflow double precision
/// (sqrt(DBL_MIN) is 1.5e-154): variances and error bars of such values are 0 or wrong.
constexpr double kUnderflowScale = 1e-150;

struct LevelStats {
    uint64_t n = 0;
    int reps = 0;
    LevelMeasure measure = LevelMeasure::Variance; ///< what `variance` is
    double mean = 0.0;                             ///< mean of the R estimates
    double variance = 0.0;    ///< unbiased variance of the estimator across replicates
    double variance_lo = 0.0; ///< 95% interval of the variance (chi-square, normal estimates)
    double variance_hi = 0.0;
    double std_error = 0.0;          ///< standard error of `mean`, sqrt(variance / R)
    double ci_lo = 0.0, ci_hi = 0.0; ///< 95% t interval of the mean over the R replicates
    bool has_exact = false;
    double bias = 0.0; ///< mean - exact
    double mse = 0.0;  ///< mean of (estimate - exact)^2
    double rmse = 0.0;
    double coverage = 0.0;          ///< share of replicates whose own 95% interval covers exact
    double mean_run_se = 0.0;       ///< average per-run standard error reported by the runs
    double mean_run_variance = 0.0; ///< average of the runs' se^2 (finite ones)
    double run_dof_total = 0.0;     ///< the runs' error-bar degrees of freedom, summed
    int run_dof = 0;                ///< degrees of freedom of the runs' error bars (RunResult::dof)
    double time_mean = 0.0;         ///< seconds per estimate
    double time_std = 0.0;          ///< their standard deviation over the replicates
    double time_median = 0.0;       ///< the replicates' median seconds per estimate
    double time_median_lo = 0.0, time_median_hi = 0.0; ///< its 95% interval (order statistics)
    double time_total = 0.0;
    /// Adaptive estimators: mean share of the calls and mean seconds per estimate spent
    /// training (VEGAS) or probing (MISER), included in n and time_mean.
    double training_share = 0.0;
    double training_time_mean = 0.0;
    double efficiency = 0.0;      ///< 1 / (variance * time_mean)
    double error = 0.0;           ///< rmse when exact is known, else sqrt(variance)
    RunDiagnostics diagnostics;   ///< summed over replicates
    double tail_index = 0.0;      ///< Hill tail index of |w| pooled over the replicates (NaN: none)
    int tail_k = 0;               ///< its order k (standard error ~ tail_index / sqrt(k))
    double nonzero_per_run = 0.0; ///< mean number of non-zero weights per run
    double ess_mean = 0.0;        ///< mean effective sample size per run
    int no_estimate_runs = 0;     ///< runs whose every sample was NaN/Inf: then the level has no
                                  ///< estimate (mean, variance and what derives from them are NaN)
    /// Iteration averages (VEGAS): chi^2 of every run's iterations about their weighted mean,
    /// summed over the runs, and its degrees of freedom (0: no such runs). Under consistent
    /// iterations the sum is chi-square on the summed degrees of freedom.
    double iteration_chi2 = 0.0;
    int iteration_dof = 0;
    int zero_error_runs = 0; ///< runs whose own standard error is 0 (to round-off, 64 eps |I_N|)
    bool estimates_spread = false; ///< the replicates differ beyond round-off (max - min >
                                   ///< 64 eps max |estimate|): a zero error bar is then wrong
    /// An exact estimator at this N: the replicates agree to round-off (not estimates_spread)
    /// on a non-zero, finite mean with no dropped sample (f/p constant, as a matched importance
    /// density or an area by its own uniform density gives). Its z-scores, skewness and tail
    /// are round-off: no statistical flag applies, and tables show "exact".
    bool exact_to_roundoff = false;
    /// Every run is one deterministic point set (no error bar): replicates agree by design,
    /// which says nothing about the error (never exact_to_roundoff).
    bool deterministic = false;
    /// The estimates are so small that their squares underflow double precision (|estimate|
    /// below kUnderflowScale): variances and error bars computed from them are 0 or wrong.
    bool values_underflow = false;
    double exact = std::numeric_limits<double>::quiet_NaN(); ///< the exact value when known
    std::vector<double> estimates, run_std_errors;           ///< per replicate
    std::vector<int> run_dofs; ///< per replicate: the degrees of freedom of its error bar
};

/// A power law fitted over a run of levels, and how well it fits: chi2 is the sum of the
/// squared residuals of log value over their sd_log, chi-square with dof = levels - 2 degrees
/// of freedom when the levels follow a power law with the noise sd_log says; p_value is its
/// upper tail (NaN, like chi2, when some level's sd_log is unknown). n_first and n_last are
/// the smallest and largest N of the levels used.
struct PowerLawSegment {
    double order = 0.0;    ///< slope of log value against log N
    double order_se = 0.0; ///< its standard error (inflated by the residuals, as in the fit)
    double intercept = 0.0;
    int levels_used = 0;
    double chi2 = std::numeric_limits<double>::quiet_NaN();
    int dof = 0;
    double p_value = std::numeric_limits<double>::quiet_NaN();
    uint64_t n_first = 0, n_last = 0;
};

/// Goodness of fit of the whole range: below this p-value the levels do not follow one power
/// law (the CLI says "not a power law"), and a suffix that does is looked for.
constexpr double kPowerLawP = 1e-3;
/// A suffix of the levels passes from this p-value on, with at least kSuffixLevels levels.
constexpr double kSuffixP = 0.01;
constexpr int kSuffixLevels = 4;

struct ConvergenceFit {
    bool valid = false;
    LevelMeasure measure = LevelMeasure::Variance; ///< what was fitted against N
    double order = 0.0;    ///< slope of log variance (or the measure) against log N
    double order_se = 0.0; ///< its standard error
    double intercept = 0.0;
    int levels_used = 0;
    std::string note; ///< why the fit is missing or partial
    /// The goodness of fit over the levels used (PowerLawSegment), when valid.
    double chi2 = std::numeric_limits<double>::quiet_NaN();
    int dof = 0;
    double p_value = std::numeric_limits<double>::quiet_NaN();
    uint64_t n_first = 0, n_last = 0;
    /// When the whole range fails (p_value < kPowerLawP): the longest run of at least
    /// kSuffixLevels levels ending at the largest N whose own fit has p_value >= kSuffixP.
    /// Empty when the whole range passes, its p-value is unknown, or no such run exists.
    std::optional<PowerLawSegment> suffix;
};

/// One level in a convergence fit: value (> 0) at n, and the standard deviation of log value
/// (0 when unknown).
struct FitPoint {
    uint64_t n = 0;
    double value = 0.0;
    double sd_log = 0.0;
};

/// The one convergence fit of the project: order and intercept of value ~ n^order by weighted
/// least squares of log value on log n (weights 1 / sd_log^2; the slope's standard error from
/// them, inflated by the residuals when they exceed them; unit weights and the residuals alone
/// when an sd_log is unknown). Needs 3 points at 2 distinct n; levels_used = points.size().
/// With every sd_log known it also gives the chi-square goodness of fit (PowerLawSegment) and,
/// when that rejects a power law over the whole range, the suffix that follows one.
ConvergenceFit fit_power_law(const std::vector<FitPoint>& points, LevelMeasure measure);

/// Least-squares fit of log variance against log N over the levels with a positive finite
/// variance (fit_power_law). Every level's log s^2 has the sampling noise of R normal
/// replicates, variance psi'((R-1)/2) [trigamma], so the weights are equal and the slope's
/// standard error is the larger of the residual estimate and that noise.
ConvergenceFit fit_convergence(const std::vector<LevelStats>& levels);
/// With an exact value: the order of the MSE (bias^2 + variance) against N, from the levels
/// with an MSE above round-off; sd of log MSE from R replicates as for a variance. A flat MSE
/// under a falling variance is a bias that dominates (bias_dominates).
ConvergenceFit fit_mse(const std::vector<LevelStats>& levels);

/// Does the proposal cover the integrand's support? Checked once per estimator: where f != 0
/// but p = 0 the estimator cannot sample, and is biased by the integral over that region,
/// which no run's own samples can reveal.
///
/// Where the zero set Z of p is known (zero bins of a 1D table, zero cells of a 2D table, a
/// product of 1D factors on a 1- or 2-dimensional box, each factor's zero set found from its
/// bins or, for analytic factors, by bisection of where the density underflows; the cosine
/// hemisphere, zero only on the null set z = 0), the missed mass M = int_Z |f| is integrated by
/// adaptive Gauss-Kronrod quadrature [Piessens83] over each piece of Z, graded geometrically
/// toward its edges (features that touch an edge of Z down to 2^-40 of its width are found),
/// nested on 2D rectangles. The check flags when M > kSupportTolerance x int |f|, with
/// int |f| = M + the probes' estimate of int |f| over the support. Everywhere else (a product
/// in 3 or more dimensions, a quadrature budget exceeded) it rests on the uniform probes, and
/// its note says how far it looked. The uniform probes always run (counts below).
constexpr double kSupportTolerance = 1e-9;

struct SupportCheck {
    uint64_t probes = 0;
    uint64_t f_nonzero = 0;       ///< probes with f != 0
    uint64_t missed = 0;          ///< probes with f != 0 and p = 0
    double missed_fraction = 0.0; ///< share of int |f| where p = 0 (quadrature) or of the
                                  ///< probes' sum |f| (probes)
    /// "none" (a uniform pdf covers the domain), "quadrature" (zero set known, M integrated),
    /// or "probes" (uniform probes only).
    std::string method = "none";
    double zero_measure = 0.0; ///< quadrature: share of the domain's measure where p = 0
    double missed_mass = 0.0;  ///< quadrature: M = int_{p=0} |f| (inf/NaN: |f| not finite there)
    double abs_integral = 0.0; ///< int |f| over the domain (M + the probes' estimate elsewhere)
    int quadrature_evaluations = 0; ///< calls of f by the quadrature
    bool flagged = false;           ///< the estimator misses mass (see above)
    std::string note;               ///< how the check looked, in a sentence
};

/// Runs the support check with `probes` uniform points (its own random stream), plus the
/// quadrature of |f| over the zero set of p where that set is known.
SupportCheck check_support(const Problem& problem, const EstimatorSpec& spec, uint64_t probes,
                           uint64_t seed);

/// Do the level means agree with each other? Every level estimates the same number, so
/// chi2 = sum_l (mean_l - m)^2 / se_l^2 about their weighted mean m is chi-square with L-1
/// degrees of freedom when the error bars are right. A tiny p-value says they are not
/// (heavy tails, too few samples at small N), even when the exact value is unknown. Levels
/// whose replicates agree to round-off are left out (nothing to test).
struct LevelConsistency {
    double chi2 = 0.0;
    int dof = 0;
    double p_value = 1.0;
};
LevelConsistency level_consistency(const std::vector<LevelStats>& levels);

/// Hill's tail index of |f| at uniform points of the domain (integrand_tail). For an estimator
/// whose sampling density is bounded above and below (variance_follows_integrand) the variance
/// of f/p is finite exactly when int f^2 is, that is when this index exceeds 2 (for a power
/// law), whatever the estimator does with its points: its own weights' tail, reshaped by
/// MISER's boxes or a VEGAS map, can look light at any N (x^-0.55 y^-0.1 z^-0.1 under MISER,
/// 1/sqrt|x - 0.3| under VEGAS+) or heavy. Uniform points give the exact Pareto tail of a power
/// singularity, so Hill's order can be large (kTailOrder) and its standard error small.
struct IntegrandTail {
    uint64_t probes = 0; ///< uniform points (0: not measured)
    double alpha = std::numeric_limits<double>::quiet_NaN();
    int k = 0; ///< Hill's order
    /// Whether int f^2 over the domain is finite, where f's form says so
    /// (integrand_square_integrable, box domains): then the variance's finiteness is known, and a
    /// low Hill index is a slowly varying tail read too heavy (x^-0.3 y^-0.3 ... z^-0.3: P(f > t) ~
    /// t^-3.3 (log t)^(d-1)), not an infinite variance.
    std::optional<bool> square_integrable;
    /// log P(the largest log-excess is this small) under Hill's power tail (NaN: not tested);
    /// below log(kBoundedTopP) the top has an upper end and alpha is set infinite.
    double top_log_p = std::numeric_limits<double>::quiet_NaN();
};
/// A top of the probes more compressed than a power tail gives with this probability: bounded.
constexpr double kBoundedTopP = 1e-3;
/// Uniform points probed for the integrand's tail: Hill's order k = min(kTailOrder, probes / 16)
/// reaches kTailOrder.
constexpr uint64_t kTailProbes = uint64_t(1) << 15;
IntegrandTail integrand_tail(const Problem& problem, uint64_t probes, uint64_t seed);

struct EstimatorStudy {
    EstimatorSpec spec;
    LevelConsistency consistency;
    ErrorMethod error_method = ErrorMethod::Iid;
    SupportCheck support;
    /// The weights are bounded by what the problem and estimator say (weights_bounded): every
    /// moment is finite, and a heavy-looking tail is pre-asymptotic.
    bool weights_bounded = false;
    /// The integrand's tail at uniform points, measured when variance_follows_integrand.
    IntegrandTail integrand;
    std::vector<LevelStats> levels;
    ConvergenceFit fit;     ///< of the variance
    ConvergenceFit mse_fit; ///< of the MSE, with an exact value (else not valid)
};

struct StudyResult {
    Problem problem;
    StudySettings settings;
    int threads_used = 1;
    double wall_seconds = 0.0;
    bool cancelled = false;
    std::vector<EstimatorStudy> estimators;
};

/// Called after each completed level (all estimators at that N); returning false cancels
/// the study after that level.
using StudyProgress = std::function<bool(const StudyResult& partial, size_t level_index)>;

/// Summarises the R runs of one level.
LevelStats summarise_level(const std::vector<RunResult>& runs, const Problem& problem);

/// The key of one replicate (see the header comment).
uint64_t replicate_stream(uint64_t seed, const std::string& estimator, uint64_t n, int rep);
/// The generator of one replicate: state and stream both derived from its key.
Pcg32 replicate_rng(uint64_t seed, const std::string& estimator, uint64_t n, int rep);

/// An estimator's study before its first level: its spec, error method, support check and
/// whether its weights are bounded (what run_study and a merge of study parts start from).
/// `shared_tail`: the integrand's tail at uniform points, measured once a study (it depends on
/// the problem and the seed alone) by the first estimator that needs it; null measures anew.
EstimatorStudy begin_estimator_study(const Problem& problem, const EstimatorSpec& spec,
                                     const StudySettings& settings,
                                     IntegrandTail* shared_tail = nullptr);
/// Appends the level of these runs (replicate r at index r) and recomputes the estimator's
/// fits and level consistency: what run_study does after each level, and a merge of parts.
void add_level(EstimatorStudy& es, const std::vector<RunResult>& runs, const Problem& problem);

StudyResult run_study(const Problem& problem, const std::vector<EstimatorSpec>& estimators,
                      const StudySettings& settings, const StudyProgress& progress = {});

/// The study loop of integrals and renders: for each N of the ladder in turn, replicate r of
/// estimator e (task e * reps + r) runs as results[task] = run(e, N, r, worker) on the thread
/// pool (`threads` workers, each with its index for its own scratch space), then
/// end_level(level_index, results) summarises the level; it returns false to stop the study.
/// Results are placed by task, so they do not depend on the thread count or the order the
/// tasks finish in. Returns false when end_level stopped it before the last level.
template <class Result, class Run, class EndLevel>
bool run_ladder(const std::vector<uint64_t>& ladder, size_t estimators, int reps, int threads,
                Run&& run, EndLevel&& end_level) {
    const size_t r = static_cast<size_t>(reps > 0 ? reps : 0), tasks = estimators * r;
    for (size_t level = 0; level < ladder.size(); ++level) {
        std::vector<Result> results(tasks);
        std::atomic<size_t> next{0};
        const int workers = static_cast<int>(
            std::max<size_t>(1, std::min<size_t>(threads > 0 ? size_t(threads) : 1, tasks)));
        run_workers(workers, [&](int worker) {
            for (size_t t = next++; t < tasks; t = next++)
                results[t] = run(t / r, ladder[level], static_cast<int>(t % r), worker);
        });
        if (!end_level(level, results)) return level + 1 == ladder.size();
    }
    return true;
}

/// Threads the study will use for a requested count (0 = hardware); 1 where the build
/// has no threads (WebAssembly without pthreads).
int resolve_threads(int requested);

/// What a study will cost, before it runs: its evaluations, and seconds predicted from a timed
/// pilot of kPilotSamples samples per estimator (two runs when the first is short, the second
/// timed, so that a cold first call does not count).
constexpr uint64_t kPilotSamples = 4096;

struct EstimatorPlan {
    std::string name;
    uint64_t evaluations = 0;
    double seconds_per_evaluation = 0.0; ///< from the pilot
    double predicted_seconds = 0.0;      ///< on one thread
};

struct StudyPlan {
    std::vector<uint64_t> levels;   ///< the N ladder
    uint64_t evaluations = 0;       ///< sum over levels of N x reps x estimators
    int threads = 1;                ///< threads the study would use
    double predicted_seconds = 0.0; ///< wall time: the estimators' seconds / threads
    double pilot_seconds = 0.0;     ///< time the pilot took
    std::vector<EstimatorPlan> estimators;
};

/// Plans a study whose settings passed check_settings and check_study_size.
StudyPlan plan_study(const Problem& problem, const std::vector<EstimatorSpec>& estimators,
                     const StudySettings& settings);

} // namespace mcp

namespace mcp {

/// The points behind one small run, for looking at them: unit-cube points u (where strata
/// are drawn), domain points x, densities p and values f, and the weights f/p.
struct SampleDump {
    int sample_dim = 0, point_dim = 0;
    std::vector<double> u, x; ///< point-major: u[i * sample_dim + j], x[i * point_dim + j]
    std::vector<double> pdf, f, weight;
    std::vector<uint64_t> strata; ///< stratified: cells per axis of the unit cube
    uint64_t per_stratum = 1;
    size_t randomizations = 0; ///< quasi-Monte Carlo: batches, each its own randomization
    AdaptiveView adaptive;     ///< VEGAS's frozen map, MISER's leaves
};

/// Runs replicate 0's estimate at N = n (the points are those of the study's first replicate
/// at that N) and records the points the estimate is made from: all n for fixed estimators,
/// the estimation share for VEGAS (not its training points), the leaves' points for MISER
/// (not its probes). Adaptive estimators (VEGAS, MISER) run at N = max(n, adaptive_n) instead,
/// so that they learn what a real run learns, and the first n of their estimate's points are
/// recorded.
SampleDump dump_samples(const Problem& problem, const EstimatorSpec& spec, uint64_t n,
                        uint64_t seed, uint64_t adaptive_n = 0);

} // namespace mcp
