// Stopping at a requested accuracy: double N until an estimate's 95% error bar meets an absolute
// or relative tolerance, or a budget (largest N, seconds) ends.
//
// Stopping when an error bar first dips below the target picks the runs whose error bars
// happen to be small, and their intervals then cover less than they say. The rule here keeps
// its promise by asking for agreement of independent evidence before it stops at N:
//  1. the run at N meets the tolerance: t_0.975(dof) se <= tol, tol = max(abs, rel |I_N|);
//  2. the independent run at N/2 predicts it: its half-width over sqrt 2 (the 1/sqrt(N) rate of
//     Monte Carlo, conservative for faster estimators) meets the tolerance too;
//  3. the two runs agree: |I_N - I_{N/2}| <= t_0.975 sqrt(se_N^2 + se_{N/2}^2);
//  4. the run's error bar can be trusted at its size: Cochran's rule on its weights,
//     N > 25 g1^2 [Cochran77] (the rule of the skewed_weights flag), and an effective sample
//     size of at least min(10, N/4) (the low_ess rule: not 0 +- 0 from points that never saw f).
// Every N is a fresh run with its own replicate stream, so the evidence at N/2 is independent of
// the answer at N; the answer is the run at N, and the cost is at most twice its evaluations.
// Any estimator with an error bar can be run this way (fixed, RQMC, VEGAS, MISER, MIS, control
// variates: each N is a complete run of it); one without an error bar (a point set with no
// randomization) cannot, and stops at once with StopReason::NoErrorBar.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "estimators/block_driver.h"
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

enum class StopReason { ToleranceMet, NMax, TimeBudget, NoErrorBar };

/// "tolerance_met", "n_max", "max_seconds", "no_error_bar".
const char* stop_reason_name(StopReason r);

/// One doubling: the run at n.
struct StoppingStep {
    uint64_t n = 0;
    double estimate = 0.0, std_error = 0.0, half_width = 0.0, seconds = 0.0;
    int dof = 0;
    bool trusted = false; ///< condition 4 (Cochran's rule on the run's error units)
};

struct StoppingResult {
    RunResult answer;        ///< the last run: the reported estimate and error bar
    double half_width = 0.0; ///< its t_0.975(dof) std_error
    double target = 0.0;     ///< max(abs, rel |estimate|) at the answer
    bool met = false;
    StopReason reason = StopReason::NMax;
    uint64_t evaluations = 0; ///< over every doubling
    double seconds = 0.0;     ///< over every doubling
    std::vector<StoppingStep> steps;
};

/// "" when the tolerance and budget can be used, else a message naming the field.
std::string check_stopping(const Tolerance& tol, const StoppingBudget& budget);

/// Runs the estimator at N = n_start, 2 n_start, ... (each run from
/// replicate_rng(seed, spec.name, N, replicate)) until the rule above stops it or the budget
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
