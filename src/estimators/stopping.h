// Stopping at a requested accuracy: double N until an estimate's 95% error bar meets an absolute
// or relative tolerance, or a budget (largest N, seconds) ends.
//
// Stopping when an error bar first dips below the target picks the runs whose error bars
// happen to be small, and their intervals then cover less than they say. The rule asks for
// evidence beyond the error bar itself before it stops at N, in one of two ways.
//
// Randomized quasi-Monte Carlo of the fixed kind (sobol, halton, lattice: K randomizations of a
// point sequence, the Randomizations error method) EXTENDS its runs: the K randomized
// sequences are drawn once for the largest N, and doubling evaluates only points [N/2K, N/K) of
// each (the first 2^m points of a scrambled Sobol' sequence, or of a lattice sequence in
// radical-inverse order, are a randomized net or lattice of their own [Owen95, Hickernell00]).
// A run costs its final N evaluations, and the estimate at N/2 comes for free. It stops at N when
//  1. the K-randomization t interval meets the tolerance: t_{K-1} s_b / sqrt K <= tol,
//     tol = max(abs, rel |I_N|) [LEcuyerLemieux02];
//  2. the N/2 and N estimates agree, judged with their dependence: they share the first half of
//     every randomization, so the differences d_k = b_k(N) - b_k(N/2) of the K batch means are
//     K independent draws, and |mean d| <= t_{K-1} sd(d) / sqrt K;
//  3. the K batch means are not too skewed for a t interval: |g1| <= 3 sqrt(6 / K) (three
//     sampling standard deviations of a normal sample's skewness), K >= 8 randomizations;
//  4. the run's weights pass condition 4 below, and the study's flags raise nothing (5).
// One Sobol' sequence with the Walsh bound (error_bar "walsh", core/walsh_bound.h) EXTENDS its one
// sequence from 2^10 points: each doubling evaluates the next net, points [N/2, N), and updates
// the bound [HickernellJimenezRugama16]. It stops at N when the bound meets the tolerance, the
// intervals of the last four doublings hold the answer (within the answer's bound: a bound the
// later points contradict means the integrand is outside the bound's cone), condition 4 holds
// and the flags of condition 5 raise nothing.
// Every N is a fresh run otherwise (its own replicate stream, so the evidence at N/2 is
// independent of the answer at N; the cost is at most twice the answer's evaluations):
//  1. the run at N meets the tolerance: t_0.975(dof) se <= tol, tol = max(abs, rel |I_N|);
//  2. the independent run at N/2 predicts it: its half-width over sqrt 2 (the 1/sqrt(N) rate of
//     Monte Carlo, conservative for faster estimators) meets the tolerance too; for the
//     adaptive estimators (VEGAS, VEGAS+, MISER), whose runs can all miss a region of f and
//     agree on it, its half-width itself meets it;
//  3. the two runs agree: |I_N - I_{N/2}| <= t_0.975 sqrt(se_N^2 + se_{N/2}^2);
//  4. the run's error bar can be trusted at its size: Cochran's rule on its weights,
//     N > 25 g1^2 [Cochran77] (the rule of the skewed_weights flag), and an effective sample
//     size of at least min(10, N/4) (the low_ess rule: not 0 +- 0 from points that never saw f).
// In every way (5) the answer carries the judgement a study level gets: level_flags and
// tail_flags (estimators/diagnostics.h) of the answer as a level of one run, without the exact
// value (a stopping rule cannot know it). A warning or an error among them (a heavy tail that
// may mean infinite variance, too few effective samples, dropped samples) means the error bar
// cannot be trusted, and the run does not stop "met": it doubles on, and if the budget ends with
// the error bar meeting the tolerance but untrusted, the reason is untrusted_error_bar.
// For estimators whose density is bounded above and below (variance_follows_integrand) the
// heavy_tail of (5) judges the integrand's tail at uniform points, not the answer's weights
// (a VEGAS+ map makes them look light-tailed under an infinite variance). Two doublings in a row
// that saw f/p = 0 at every point stop the run unmet (StopReason::AllZero).
// Any estimator with an error bar can be run this way (fixed, RQMC, VEGAS, MISER, MIS, control
// variates: each N is a complete run of it); one without an error bar (a point set with no
// randomization) cannot, and stops at once with StopReason::NoErrorBar.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "estimators/block_driver.h"
#include "estimators/diagnostics.h"
#include "estimators/estimator.h"
#include "estimators/problem.h"
#include "estimators/study.h"

namespace mcp {

/// The requested accuracy: the 95% half-width at most max(abs, rel |estimate|); at least one of
/// the two is > 0.
struct Tolerance {
    double abs = 0.0;
    double rel = 0.0;
};

/// The largest N of a stopping run when nothing else says (the study ladder's default is 65536).
constexpr uint64_t kStoppingDefaultNMax = uint64_t(1) << 24;

/// Where doubling starts and what ends it.
struct StoppingBudget {
    uint64_t n_start = 1024;
    uint64_t n_max = uint64_t(1) << 24;
    double max_seconds = std::numeric_limits<double>::infinity();
};

/// UntrustedErrorBar: the budget ended while the error bar met the tolerance but a flag (or
/// the agreement with earlier doublings) said it cannot be trusted. AllZero: two doublings in a
/// row, the last at N >= 4096, saw f/p = 0 at every point: the estimate is 0 +- 0, which meets
/// no relative tolerance (the target rel |0| is 0) and cannot show that f is 0 where no point
/// fell, so doubling on would only repeat it (to n_max: 2^25 evaluations by default).
enum class StopReason { ToleranceMet, NMax, TimeBudget, NoErrorBar, UntrustedErrorBar, AllZero };

/// "tolerance_met", "n_max", "max_seconds", "no_error_bar", "untrusted_error_bar", "all_zero".
const char* stop_reason_name(StopReason r);

/// One doubling: the run at n.
struct StoppingStep {
    uint64_t n = 0;
    double estimate = 0.0, std_error = 0.0, half_width = 0.0, seconds = 0.0;
    int dof = 0;
    bool trusted = false;  ///< condition 4 (Cochran's rule on the run's weights, ESS) and 3
                           ///< (skewness of the batch means) for extended runs
    bool agrees = false;   ///< condition 2 (extended) or 3 (fresh runs): agrees with earlier N
    bool flagged = false;  ///< a warning or error flag of the study's judgement (condition 5)
    bool all_zero = false; ///< every point's f/p was 0 (none dropped): the estimate is 0 +- 0
};

struct StoppingResult {
    RunResult answer;        ///< the last run: the reported estimate and error bar
    double half_width = 0.0; ///< its t_0.975(dof) std_error
    double target = 0.0;     ///< max(abs, rel |estimate|) at the answer
    bool met = false;
    StopReason reason = StopReason::NMax;
    uint64_t evaluations = 0; ///< over every doubling (reused points counted once)
    bool extended = false;    ///< the doublings extended one set of K randomized sequences
    /// The study's flags of the answer (level_flags and tail_flags of it as a level of one
    /// run, without the exact value); the run is not "met" with a warning or error among them.
    std::vector<Flag> flags;
    double seconds = 0.0; ///< over every doubling
    std::vector<StoppingStep> steps;
    /// The integrand's tail at kTailProbes uniform points (not counted in evaluations), for
    /// estimators whose variance follows the integrand's (variance_follows_integrand).
    IntegrandTail integrand;
};

/// Condition 5: the study's judgement of a stopping answer as a level of one run, without the
/// exact value; *blocking says whether a warning or an error among the flags keeps it from
/// "met" (a merge of split stopping runs recomputes the flags with it).
/// With `integrand` (the integrand's tail at uniform points, measured by run_to_tolerance
/// when variance_follows_integrand), heavy_tail judges it rather than the answer's weights.
std::vector<Flag> stopping_answer_flags(const RunResult& answer, const Problem& problem,
                                        const EstimatorSpec& spec, bool* blocking,
                                        const IntegrandTail* integrand = nullptr);

/// The integrand's tail that run_to_tolerance judges heavy_tail by: integrand_tail at
/// kTailProbes uniform points from `seed` when variance_follows_integrand(spec) and the weights
/// are not bounded, else not measured (probes 0). The same for every replicate and part.
IntegrandTail stopping_integrand_tail(const Problem& problem, const EstimatorSpec& spec,
                                      uint64_t seed);

/// "" when the tolerance and budget can be used, else a message naming the field.
std::string check_stopping(const Tolerance& tol, const StoppingBudget& budget);

/// Whether run_to_tolerance extends the spec's runs (randomized QMC of the fixed kind with at
/// least 8 randomizations, compensated sums, n_start a multiple of K and the sequences long
/// enough for n_max / K points).
bool stopping_extends(const EstimatorSpec& spec, const StoppingBudget& budget,
                      Accumulator accumulator = Accumulator::Compensated);

/// Runs the estimator at N = n_start, 2 n_start, ... (each run from
/// replicate_rng(seed, spec.name, N, replicate); extended runs draw their K randomizations from
/// replicate_rng(seed, spec.name, 0, replicate)) until the rule above stops it or the budget
/// ends (the next N above n_max, or the next run, predicted at twice the last one's time,
/// past max_seconds).
StoppingResult run_to_tolerance(const Problem& problem, const EstimatorSpec& spec,
                                const Tolerance& tol, const StoppingBudget& budget, uint64_t seed,
                                int replicate, Workspace& ws,
                                Accumulator accumulator = Accumulator::Compensated);

/// Every estimator run to the tolerance `settings.reps` times (replicate r from its own
/// streams), one estimate at a time on one thread, so that each one's seconds are its own.
struct StoppingStudy {
    Problem problem;
    StudySettings settings;
    std::vector<EstimatorSpec> specs;
    std::vector<std::vector<StoppingResult>> runs; ///< per estimator, per replicate
    double wall_seconds = 0.0;
};

/// The tolerance and budget of study settings (settings.stopping() must hold).
Tolerance tolerance_of(const StudySettings& settings);
StoppingBudget budget_of(const StudySettings& settings);

StoppingStudy run_stopping_study(const Problem& problem, const std::vector<EstimatorSpec>& specs,
                                 const StudySettings& settings);

} // namespace mcp
