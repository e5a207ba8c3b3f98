// One Monte Carlo estimate: N points from a sampler, warped by a proposal density p,
// weighted f/p and averaged: I_N = (1/N) sum f(x_i) / p(x_i). Streaming, block by block.
#pragma once

#include <cstdint>
#include <vector>

#include "core/points.h"
#include "core/rng.h"
#include "core/stats.h"
#include "estimators/problem.h"

namespace mcp {

/// Sample-level problems found during a run. A dropped sample contributes 0 to the sum
/// (the estimate is then biased, and the count says by how many samples).
struct RunDiagnostics {
    uint64_t nonfinite = 0;        ///< f/p was NaN or infinite (f itself NaN/Inf): dropped
    uint64_t zero_pdf = 0;         ///< f != 0 where p = 0 at a sampled point: dropped
    uint64_t nonzero = 0;          ///< samples with f/p != 0 (few: a narrow peak was missed)
    double max_weight_share = 0.0; ///< max |w_i| / sum |w_i|: near 1 means one sample rules
    double ess = 0.0;              ///< Kish's effective sample size (sum |w|)^2 / sum w^2
    /// The weights' moments (mean, variance, third moment), pooled when runs merge: their
    /// skewness says from which N the normal approximation behind an error bar holds.
    RunningMoments weights;
    /// The values whose spread is the run's error bar, pooled when runs merge: the weights, or
    /// for K randomizations the K batch means. Cochran's rule reads their skewness.
    RunningMoments error_units;
    bool batch_units = false; ///< error_units are batch means (randomized QMC), not weights
    void merge(const RunDiagnostics& o);
};

/// How the per-run standard error is estimated.
enum class ErrorMethod {
    Iid,             ///< s^2 / N from the sample variance (independent samples)
    CollapsedStrata, ///< neighbouring strata paired [Cochran77, 5A.12]: conservative
    PairedStrata,    ///< two points per stratum: unbiased [Cochran77, 5.4]
    IidConservative, ///< s^2 / N for Latin hypercube: >= its variance up to N/(N-1) [Owen97]
    Randomizations,  ///< spread of the K batch means of independent randomizations, t with K-1
                     ///< degrees of freedom [LEcuyerLemieux02]
    None,            ///< one deterministic point set: no error bar
    /// A sum of independent parts (MISER's leaves, VEGAS+'s hypercubes, MIS techniques,
    /// control-variate folds): the sum of their variances, Satterthwaite's dof [Satterthwaite46]
    PartsSum,
    /// One-sample optimal MIS: residuals of the samples' own regression, N - K dof
    Regression,
    /// One randomized Sobol' sequence (linear scramble or digital shift), N = 2^m: the bound
    /// fudge(m) S_{m-4,m} from its own Walsh coefficients [HickernellJimenezRugama16], reported as
    /// a 95% half-width (std_error = bound / 1.96, normal quantile). It holds for integrands whose
    /// Walsh coefficients decay predictably (a cone); its coverage is measured, not promised.
    WalshBound,
};
const char* error_method_name(ErrorMethod m);
/// Whether the method's error bars are wider than the estimator's spread by design (collapsed
/// strata, the iid formula for Latin hypercubes): their coverage stays above 95%.
bool error_method_conservative(ErrorMethod m);
/// The error method of the spec's sampler and its options: the fixed estimators' and the frozen
/// VEGAS map's (the spec's own, whatever its kind, is error_method_for in estimators/registry.h).
ErrorMethod sampler_error_method(const EstimatorSpec& spec);

/// How the weights are summed. Float32 is a teaching mode: a naive single-precision running
/// sum, to show where naive accumulation stalls (the error bar stays in double).
enum class Accumulator { Compensated, Float32 };

struct RunResult {
    uint64_t n = 0;
    double estimate = 0.0;  ///< NaN when every sample was NaN/Inf (no estimate)
    double std_error = 0.0; ///< NaN when it cannot be estimated (N = 1, or no estimate)
    /// Degrees of freedom of the error bar's variance estimate (its 95% interval is
    /// estimate +- t_dof se): N - 1 for independent points, the number of differences for
    /// strata, K - 1 for K randomizations; 0 when there is no error bar. Capped at 10^6.
    int dof = 0;
    double seconds = 0.0;
    RunDiagnostics diagnostics;
    std::vector<double> top; ///< the kTailWeights largest |w|, decreasing (for the tail index)
    /// Estimators that average iterations (VEGAS's iteration average): chi^2 of the iteration
    /// estimates about their weighted mean, on iteration_dof = iterations - 1 degrees of
    /// freedom (0: not such an estimator).
    double iteration_chi2 = 0.0;
    int iteration_dof = 0;
    /// Adaptive estimators: the integrand calls and the time spent learning rather than
    /// estimating (VEGAS's training iterations, MISER's probes); they count in n and seconds.
    uint64_t training_n = 0;
    double training_seconds = 0.0;
};

/// The 97.5% quantile behind a run's 95% interval: Student t with dof degrees of freedom
/// (1.96 for dof = 0, where there is no variance estimate to be unsure of).
double interval_quantile(int dof);

/// Largest weights a render image keeps for the tail index (enough for Hill's k = 64).
constexpr size_t kTopWeights = 65;

/// Hill order for a render image's pool of `samples` values: k = min(64, samples / 16), 0 below 8.
int hill_order(uint64_t samples);

/// Hill's largest order for an integration level. With k = 64 the standard error alpha / 8
/// cannot tell a finite variance (alpha = 2.2: x^-0.45) from an infinite one (alpha = 1.8); with
/// k = 2048 (alpha / 45) 2.2 lies 4.5 standard errors above 2. The top of R N uniform points'
/// weights on a power singularity is an exact Pareto tail, so the larger k adds no bias there;
/// where it is not (stable_tail_index), a smaller k is used.
constexpr int kTailOrder = 2048;
/// Largest |w| each integration run keeps: enough for Hill's k = kTailOrder.
constexpr size_t kTailWeights = kTailOrder + 1;

/// Hill order for an integration pool of `samples` weights: k = min(kTailOrder, samples / 16),
/// 0 below 8.
int tail_order(uint64_t samples);

/// Hill's estimate at the largest order k <= k_max the tail supports. An adaptive estimator
/// (MISER's boxes, a VEGAS map) reshapes the weights: only the top few are Pareto, from the few
/// points near a singularity, and a larger k reaches into the body, where the log spacings
/// shrink and the estimate rises (x^-0.55 y^-0.1 z^-0.1 under MISER: 1.7 at k = 64, 3.1 at
/// k = 2048). The orders k = 64, 128, ..., k_max are tried in turn and the last kept is the
/// one before the first rise beyond chance: by Renyi's representation 1/alpha_k is the mean of
/// k independent Exp(1) / alpha, so for nested k1 < k2 the difference 1/alpha_k1 - 1/alpha_k2
/// has sd (1/alpha) sqrt(1/k1 - 1/k2); a rise of more than 3 of those ends the search
/// [Hill75, Renyi53]. *k gets the order used (0: none).
double stable_tail_index(const std::vector<double>& top_descending, int k_max, int* k);

/// Hill's estimator of the tail index alpha from the k+1 largest values, sorted in
/// decreasing order (standard error about alpha / sqrt(k)): k / sum_{i<k} log(x_i / x_k) [Hill75].
/// P(|w| > t) ~ t^-alpha, so alpha < 2 means infinite variance. Infinite when the top values are
/// all equal (to 1e-12 relative), 0 when x_k is 0 (fewer than k+1 non-zero weights).
double hill_tail_index(const std::vector<double>& top_descending, int k);

/// Buffers reused across runs (estimators/block_driver.h).
struct Workspace;

/// Runs one estimate of the problem with n samples, all randomness drawn from rng: the spec's
/// kind's algorithm (estimators/registry.cpp), run to completion.
RunResult run_estimate(const Problem& problem, const EstimatorSpec& spec, uint64_t n, Pcg32& rng,
                       Workspace& ws, Accumulator accumulator = Accumulator::Compensated);

} // namespace mcp
