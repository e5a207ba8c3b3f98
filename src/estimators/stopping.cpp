#include "estimators/stopping.h"

#include <chrono>
#include <cmath>

#include "core/special.h"
#include "estimators/diagnostics.h"
#include "estimators/study.h"

namespace mcp {

const char* stop_reason_name(StopReason r) {
    switch (r) {
    case StopReason::ToleranceMet: return "tolerance_met";
    case StopReason::NMax: return "n_max";
    case StopReason::TimeBudget: return "max_seconds";
    case StopReason::NoErrorBar: return "no_error_bar";
    }
    return "?";
}

std::string check_stopping(const Tolerance& tol, const StoppingBudget& budget) {
    if (!(tol.abs >= 0.0) || !std::isfinite(tol.abs))
        return "abs_tol: must be a finite number >= 0";
    if (!(tol.rel >= 0.0) || !std::isfinite(tol.rel))
        return "rel_tol: must be a finite number >= 0";
    if (tol.abs == 0.0 && tol.rel == 0.0) return "abs_tol, rel_tol: at least one must be > 0";
    if (budget.n_start < 2) return "n_min: stopping needs runs of at least 2 samples";
    if (budget.n_max < budget.n_start) return "n_max: must be at least n_min";
    if (!(budget.max_seconds > 0.0)) return "max_seconds: must be > 0";
    return "";
}

namespace {

double t95(int dof) {
    return dof >= 1 ? student_t_quantile(0.975, static_cast<double>(dof))
                    : std::numeric_limits<double>::infinity();
}

// Condition 4: Cochran's rule on the run's weights (N of them). For randomized QMC the error bar
// is the spread of only K batch means, whose skewness one run cannot estimate (its sampling
// sd, sqrt(6 / K), is 0.6 for K = 16); the weights' rule is the conservative stand-in.
// Also the low_ess rule: a run whose sum rests on a handful of weights, or on none (every weight
// 0: no point saw f, and 0 +- 0 says nothing), is not evidence.
bool error_bar_trusted(const RunResult& r) {
    const RunningMoments& u = r.diagnostics.weights;
    const double g1 = u.skewness();
    const double n = static_cast<double>(u.count());
    const bool enough = r.diagnostics.ess >= std::fmin(kLowEss, kLowEssShare * n);
    return enough && std::isfinite(g1) && n >= kSkewnessRule * g1 * g1;
}

} // namespace

StoppingResult run_to_tolerance(const Problem& problem, const EstimatorSpec& spec,
                                const Tolerance& tol, const StoppingBudget& budget, uint64_t seed,
                                int replicate, Workspace& ws, Accumulator accumulator) {
    StoppingResult out;
    for (uint64_t n = budget.n_start;; n *= 2) {
        Pcg32 rng = replicate_rng(seed, spec.name, n, replicate);
        const RunResult r = run_estimate(problem, spec, n, rng, ws, accumulator);
        out.evaluations += r.n;
        out.seconds += r.seconds;
        StoppingStep step;
        step.n = n;
        step.estimate = r.estimate;
        step.std_error = r.std_error;
        step.dof = r.dof;
        step.seconds = r.seconds;
        step.half_width = t95(r.dof) * r.std_error;
        step.trusted = error_bar_trusted(r);
        out.steps.push_back(step);
        const StoppingStep* previous =
            out.steps.size() >= 2 ? &out.steps[out.steps.size() - 2] : nullptr;
        out.answer = r;
        out.half_width = step.half_width;
        out.target = std::fmax(tol.abs, tol.rel * std::fabs(r.estimate));
        if (r.dof < 1 || !std::isfinite(r.std_error)) {
            out.reason = StopReason::NoErrorBar;
            return out;
        }
        const bool meets = step.half_width <= out.target;
        const bool predicted =
            previous && previous->dof >= 1 && previous->half_width / std::sqrt(2.0) <= out.target;
        const bool agree = previous && std::fabs(step.estimate - previous->estimate) <=
                                           t95(std::min(step.dof, previous->dof)) *
                                               std::sqrt(step.std_error * step.std_error +
                                                         previous->std_error * previous->std_error);
        if (meets && predicted && agree && step.trusted) {
            out.met = true;
            out.reason = StopReason::ToleranceMet;
            return out;
        }
        if (n > budget.n_max / 2) {
            out.reason = StopReason::NMax;
            return out;
        }
        if (out.seconds + 2.0 * r.seconds > budget.max_seconds) {
            out.reason = StopReason::TimeBudget;
            return out;
        }
    }
}

Tolerance tolerance_of(const StudySettings& settings) {
    return Tolerance{settings.abs_tol, settings.rel_tol};
}

StoppingBudget budget_of(const StudySettings& settings) {
    StoppingBudget b;
    b.n_start = settings.n_min;
    b.n_max = settings.n_max;
    if (settings.max_seconds > 0.0) b.max_seconds = settings.max_seconds;
    return b;
}

StoppingStudy run_stopping_study(const Problem& problem, const std::vector<EstimatorSpec>& specs,
                                 const StudySettings& settings) {
    const auto start = std::chrono::steady_clock::now();
    StoppingStudy s;
    s.problem = problem;
    s.settings = settings;
    s.specs = specs;
    Workspace ws;
    for (const EstimatorSpec& spec : specs) {
        std::vector<StoppingResult> runs;
        for (int r = 0; r < settings.reps; ++r)
            runs.push_back(run_to_tolerance(problem, spec, tolerance_of(settings),
                                            budget_of(settings), settings.seed, r, ws,
                                            settings.accumulator));
        s.runs.push_back(std::move(runs));
    }
    s.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return s;
}

} // namespace mcp
