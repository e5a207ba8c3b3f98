#include "estimators/stopping.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

#include "core/qmc.h"
#include "core/special.h"
#include "core/walsh_bound.h"
#include "estimators/diagnostics.h"
#include "estimators/registry.h"
#include "estimators/study.h"

namespace mcp {

const char* stop_reason_name(StopReason r) {
    switch (r) {
    case StopReason::ToleranceMet: return "tolerance_met";
    case StopReason::NMax: return "n_max";
    case StopReason::TimeBudget: return "max_seconds";
    case StopReason::NoErrorBar: return "no_error_bar";
    case StopReason::UntrustedErrorBar: return "untrusted_error_bar";
    case StopReason::AllZero: return "all_zero";
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
// A doubling's record: the run at n and its half-width t r.std_error.
StoppingStep step_of(const RunResult& r, uint64_t n, double t) {
    StoppingStep step;
    step.n = n;
    step.estimate = r.estimate;
    step.std_error = r.std_error;
    step.dof = r.dof;
    step.seconds = r.seconds;
    step.half_width = t * r.std_error;
    const RunDiagnostics& d = r.diagnostics;
    step.all_zero =
        r.n > 0 && r.estimate == 0.0 && d.nonzero == 0 && d.nonfinite == 0 && d.zero_pdf == 0;
    return step;
}

bool error_bar_trusted(const RunResult& r) {
    const RunningMoments& u = r.diagnostics.weights;
    const double g1 = u.skewness();
    const double n = static_cast<double>(u.count());
    const bool enough = r.diagnostics.ess >= std::fmin(kLowEss, kLowEssShare * n);
    return enough && std::isfinite(g1) && n >= kSkewnessRule * g1 * g1;
}

// Condition 5: the study's judgement of the answer as a level of one run, without the exact
// value (the rule cannot know it). Returns the flags; *blocking says whether a warning or an
// error is among them.
std::vector<Flag> judge_answer_in(const RunResult& answer, const Problem& problem,
                                  const EstimatorSpec& spec, bool* blocking,
                                  const IntegrandTail* integrand) {
    Problem blind = problem;
    blind.exact.reset();
    LevelStats level = summarise_level({answer}, blind);
    // One run has no spread of replicates: the level's variance is the run's own error bar
    // (what the flags' "are the estimates spread, or exact to round-off" question asks of it).
    const double se = answer.std_error;
    level.variance = se * se;
    level.std_error = se;
    const double roundoff = 64.0 * 2.220446049250313e-16 * std::fabs(level.mean);
    level.estimates_spread = std::isfinite(se) && se > roundoff;
    level.exact_to_roundoff = !level.estimates_spread && std::isfinite(level.mean) &&
                              level.mean != 0.0 && level.diagnostics.nonfinite == 0 &&
                              level.diagnostics.zero_pdf == 0;
    std::vector<Flag> flags = level_flags(level);
    for (const Flag& f : tail_flags(level, weights_bounded(problem, spec), integrand))
        flags.push_back(f);
    *blocking = false;
    for (const Flag& f : flags) {
        // The K batch means of one run: the study's rule (K > 25 g1^2 on R K pooled means)
        // would refuse about 15% of normal runs with K = 16 (a sample skewness of 16 values has
        // sd 0.56); the extended rule's condition 3 judges them instead.
        if (f.code == FlagCode::SkewedWeights && answer.diagnostics.batch_units) continue;
        *blocking = *blocking || f.severity != Severity::Info;
    }
    return flags;
}

// The last two doublings saw f/p = 0 at every point, the last at N >= kAllZeroMinN (a few
// thousand points: a scene's n_min of 16 is no evidence): StopReason::AllZero.
constexpr uint64_t kAllZeroMinN = 4096;
bool zero_twice(const std::vector<StoppingStep>& steps) {
    return steps.size() >= 2 && steps.back().all_zero && steps[steps.size() - 2].all_zero &&
           steps.back().n >= kAllZeroMinN;
}

// The last doubling met the tolerance by its error bar but was not allowed to stop on it.
StopReason unmet_reason(const StoppingResult& out, StopReason budget_reason) {
    return out.half_width <= out.target ? StopReason::UntrustedErrorBar : budget_reason;
}

// The budget ends the doubling: the next N would pass n_max, or the next run (predicted at
// twice this one's seconds) max_seconds. Then out's reason says which (and whether the last
// error bar met the tolerance untrusted).
bool budget_ended(const StoppingBudget& budget, uint64_t n, double run_seconds,
                  StoppingResult* out) {
    if (n > budget.n_max / 2)
        out->reason = unmet_reason(*out, StopReason::NMax);
    else if (out->seconds + 2.0 * run_seconds > budget.max_seconds)
        out->reason = unmet_reason(*out, StopReason::TimeBudget);
    else
        return false;
    return true;
}

// Adaptive estimators (VEGAS, VEGAS+, MISER) learn where f is from their own points: a region
// they have not found is a bias their error bar cannot show, and runs that all missed it agree
// with each other. Their condition 2 asks the run at N/2 to meet the tolerance itself, so that
// the answer stands on two runs that each found enough of f (MISER on a peak of width 1e-3 at
// the bisection point found half of it, 0.5 +- 0.002 at N = 8192, and all of it at 16384).
bool adaptive(const EstimatorSpec& spec) {
    const std::string kind = kind_of(spec).name;
    return kind == "vegas" || kind == "vegas_plus" || kind == "miser";
}

// A doubling's answer recorded in out: the study's flags of it (condition 5), its target and
// step. True when it ends the run: no error bar, or every condition met.
bool record_answer(StoppingStep step, const RunResult& r, const Problem& problem,
                   const EstimatorSpec& spec, const Tolerance& tol, StoppingResult* out) {
    bool blocking = false;
    out->flags = stopping_answer_flags(r, problem, spec, &blocking,
                                       out->integrand.k > 0 ? &out->integrand : nullptr);
    step.flagged = blocking;
    out->steps.push_back(step);
    out->answer = r;
    out->half_width = step.half_width;
    out->target = std::fmax(tol.abs, tol.rel * std::fabs(r.estimate));
    if (!std::isfinite(r.std_error)) {
        out->reason = StopReason::NoErrorBar;
        return true;
    }
    if (zero_twice(out->steps)) {
        out->reason = StopReason::AllZero;
        return true;
    }
    if (step.half_width <= out->target && step.agrees && step.trusted && !blocking) {
        out->met = true;
        out->reason = StopReason::ToleranceMet;
        return true;
    }
    return false;
}

// Randomized QMC by extension (the header's first way): K accumulators, one per randomization,
// each fed the points of its own randomized sequence in order.
StoppingResult extend_to_tolerance(const Problem& problem, const EstimatorSpec& spec,
                                   const Tolerance& tol, const StoppingBudget& budget,
                                   uint64_t seed, int replicate, Workspace& ws) {
    StoppingResult out;
    out.extended = true;
    out.integrand = stopping_integrand_tail(problem, spec, seed);
    const SamplerOptions options = spec.sampler_options();
    const uint64_t k_count = static_cast<uint64_t>(options.randomizations);
    const uint64_t longest = budget.n_max / k_count; // points of each sequence at most
    Pcg32 rng = replicate_rng(seed, spec.name, 0, replicate);
    const SamplerPlan all = make_sampler_plan(spec.sampler, problem.domain.sample_dim(),
                                              longest * k_count, rng, options);
    std::vector<SamplerPlan> plans(static_cast<size_t>(k_count));
    std::vector<WeightAccumulator> acc(static_cast<size_t>(k_count));
    for (size_t k = 0; k < plans.size(); ++k) {
        plans[k].kind = all.kind;
        plans[k].dim = all.dim;
        plans[k].total = longest;
        plans[k].randomizers = {all.randomizers[k]};
        acc[k].reset(ErrorMethod::Iid, plans[k], false);
    }
    prepare_workspace(problem.domain, ws);
    const double scale = quantity_scale(problem);
    const double kd = static_cast<double>(k_count);
    const double tk = t95(static_cast<int>(k_count) - 1);
    std::vector<double> batch(plans.size()), previous_batch;
    for (uint64_t n = budget.n_start;; n *= 2) {
        const auto start = std::chrono::steady_clock::now();
        const uint64_t m = n / k_count, done = out.steps.empty() ? 0 : m / 2;
        for (size_t k = 0; k < plans.size(); ++k)
            for (uint64_t first = done; first < m; first += kBlockSize) {
                const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, m - first));
                const SampleBlock b =
                    sample_block(problem, spec.proposal, plans[k], first, count, ws);
                acc[k].add_block(b.first, b.f, b.pdf, b.pdf, b.count);
            }
        // The answer at N: the K batch means' t interval, the weights' diagnostics pooled.
        RunResult r;
        RunningMoments means;
        std::vector<double> top;
        double abs_sum = 0.0, max_abs = 0.0;
        uint64_t nonfinite = 0;
        for (size_t k = 0; k < plans.size(); ++k) {
            const RunResult rk = acc[k].finish(1.0);
            batch[k] = rk.estimate;
            means.add(rk.estimate);
            r.diagnostics.merge(rk.diagnostics);
            nonfinite += rk.diagnostics.nonfinite;
            top.insert(top.end(), rk.top.begin(), rk.top.end());
            // sum |w| of the batch from its ESS and sum w^2 (Kish: ess = (sum |w|)^2 / sum w^2)
            const RunningMoments& w = rk.diagnostics.weights;
            const double sum_sq =
                w.sum_squared_deviations() + static_cast<double>(w.count()) * w.mean() * w.mean();
            const double batch_abs = std::sqrt(std::fmax(rk.diagnostics.ess, 0.0) * sum_sq);
            abs_sum += batch_abs;
            max_abs = std::fmax(max_abs, rk.diagnostics.max_weight_share * batch_abs);
        }
        std::sort(top.begin(), top.end(), std::greater<double>());
        if (top.size() > kTailWeights) top.resize(kTailWeights);
        r.top = top;
        r.n = n;
        r.estimate = means.mean() * scale;
        r.std_error = std::sqrt(means.variance() / kd) * scale;
        r.dof = static_cast<int>(k_count) - 1;
        r.diagnostics.error_units = means;
        r.diagnostics.batch_units = true;
        r.diagnostics.max_weight_share = abs_sum > 0.0 ? max_abs / abs_sum : 0.0;
        const RunningMoments& w = r.diagnostics.weights;
        const double sum_sq =
            w.sum_squared_deviations() + static_cast<double>(w.count()) * w.mean() * w.mean();
        r.diagnostics.ess = sum_sq > 0.0 ? abs_sum * abs_sum / sum_sq : 0.0;
        if (nonfinite == n) r.estimate = r.std_error = std::numeric_limits<double>::quiet_NaN();
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        out.evaluations = n; // every point of every randomization once
        out.seconds += r.seconds;

        StoppingStep step = step_of(r, n, tk);
        // Condition 3: the batch means' own skewness within three sampling sds of 0. (Cochran's
        // rule on the N weights, in condition 4, is the rule K > 25 (g1_w / sqrt m)^2 on the
        // skewness a batch mean of m weights would have from the weights' [Cochran77, 2.15].)
        const double g1 = means.skewness();
        step.trusted = error_bar_trusted(r) &&
                       (!std::isfinite(g1) || std::fabs(g1) <= 3.0 * std::sqrt(6.0 / kd));
        if (!previous_batch.empty()) {
            RunningMoments d;
            for (size_t k = 0; k < batch.size(); ++k) d.add(batch[k] - previous_batch[k]);
            step.agrees = std::fabs(d.mean()) <= tk * std::sqrt(d.variance() / kd);
        }
        if (record_answer(step, r, problem, spec, tol, &out)) return out;
        previous_batch = batch;
        if (budget_ended(budget, n, r.seconds, &out) || problem_stopped(problem)) return out;
    }
}

// One linearly scrambled Sobol' sequence with the Walsh bound (the header's third way): each
// doubling evaluates points [N/2, N) of the sequence (the next net) and extends the bound.
StoppingResult walsh_to_tolerance(const Problem& problem, const EstimatorSpec& spec,
                                  const Tolerance& tol, const StoppingBudget& budget, uint64_t seed,
                                  int replicate, Workspace& ws) {
    StoppingResult out;
    out.extended = true;
    out.integrand = stopping_integrand_tail(problem, spec, seed);
    Pcg32 rng = replicate_rng(seed, spec.name, 0, replicate);
    const SamplerPlan plan = make_sampler_plan(spec.sampler, problem.domain.sample_dim(),
                                               budget.n_max, rng, spec.sampler_options());
    WeightAccumulator acc; // the weights' moments and diagnostics; the bound is the Walsh one
    acc.reset(ErrorMethod::Iid, plan, false);
    prepare_workspace(problem.domain, ws);
    const double scale = quantity_scale(problem);
    WalshBound walsh;
    std::vector<double> natural; // the new points' weights in the net's natural order
    for (uint64_t n = budget.n_start;; n *= 2) {
        const auto start = std::chrono::steady_clock::now();
        const uint64_t done = out.steps.empty() ? 0 : n / 2;
        natural.assign(static_cast<size_t>(n - done), 0.0);
        for (uint64_t first = done; first < n; first += kBlockSize) {
            const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, n - first));
            const SampleBlock b = sample_block(problem, spec.proposal, plan, first, count, ws);
            acc.add_block(b.first, b.f, b.pdf, b.pdf, b.count); // weights overwrite p
            for (size_t i = 0; i < b.count; ++i)
                natural[static_cast<size_t>(gray_natural_index(first + i) - done)] = b.pdf[i];
        }
        if (done == 0)
            walsh.start(natural.data(), n);
        else
            walsh.extend(natural.data());
        RunResult r = acc.finish(scale);
        r.n = n;
        const double bound = walsh.bound() * scale;
        if (std::isfinite(r.estimate)) {
            r.std_error = bound / kNormal975;
            r.dof = 1000000; // a bound reported as a 95% half-width: the normal quantile
        }
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        out.evaluations = n;
        out.seconds += r.seconds;

        StoppingStep step = step_of(r, n, t95(r.dof));
        // The bound of a net that never saw f (every weight 0 on a spike it missed) is 0 too:
        // the low_ess rule of condition 4. Cochran's rule is not asked: the bound is not a
        // normal approximation.
        step.trusted = error_bar_trusted(r);
        // The bounds of the last kWalshLag doublings must hold the answer (within the answer's
        // own bound): the integral lies in each of them if the integrand is in the cone, and a
        // bound the sequence's later points contradict says it is not (a corner peak in d = 8
        // broke half its bounds this way, and a rule that looked at N/2 alone stopped on them).
        // Older bounds are not asked: the first nets' bounds fail on peaks the later ones
        // resolve (a product peak in d = 2 broke its 2^10 bound once, then held 14 doublings).
        step.agrees = !out.steps.empty();
        const size_t from = out.steps.size() > size_t(kWalshLag) ? out.steps.size() - kWalshLag : 0;
        for (size_t j = from; j < out.steps.size(); ++j)
            step.agrees = step.agrees && std::fabs(step.estimate - out.steps[j].estimate) <=
                                             step.half_width + out.steps[j].half_width;
        if (record_answer(step, r, problem, spec, tol, &out)) return out;
        if (budget_ended(budget, n, r.seconds, &out) || problem_stopped(problem)) return out;
    }
}

} // namespace

IntegrandTail stopping_integrand_tail(const Problem& problem, const EstimatorSpec& spec,
                                      uint64_t seed) {
    if (!variance_follows_integrand(spec) || weights_bounded(problem, spec)) return {};
    return integrand_tail(problem, kTailProbes, seed);
}

std::vector<Flag> stopping_answer_flags(const RunResult& answer, const Problem& problem,
                                        const EstimatorSpec& spec, bool* blocking,
                                        const IntegrandTail* integrand) {
    return judge_answer_in(answer, problem, spec, blocking, integrand);
}

bool stopping_extends(const EstimatorSpec& spec, const StoppingBudget& budget,
                      Accumulator accumulator) {
    const SamplerOptions options = spec.sampler_options();
    const uint64_t k = static_cast<uint64_t>(std::max(options.randomizations, 1));
    return accumulator == Accumulator::Compensated && kind_of(spec).name == std::string("fixed") &&
           is_qmc(spec.sampler) && error_method_for(spec) == ErrorMethod::Randomizations &&
           k >= 8 && budget.n_start % k == 0 && budget.n_start / k >= 2 &&
           budget.n_max / k <= qmc_max_points(qmc_kind_of(spec.sampler));
}

StoppingResult run_to_tolerance(const Problem& problem, const EstimatorSpec& spec,
                                const Tolerance& tol, const StoppingBudget& budget, uint64_t seed,
                                int replicate, Workspace& ws, Accumulator accumulator) {
    if (stopping_extends(spec, budget, accumulator))
        return extend_to_tolerance(problem, spec, tol, budget, seed, replicate, ws);
    if (error_method_for(spec) == ErrorMethod::WalshBound) {
        // N = 2^m from 2^5 to 2^24 (the scene reader refuses other ladders with a message).
        StoppingBudget walsh = budget;
        walsh.n_start = uint64_t(1) << kWalshMinLog2;
        while (walsh.n_start < budget.n_start) walsh.n_start *= 2;
        walsh.n_max = std::min<uint64_t>(budget.n_max, uint64_t(1) << kWalshMaxLog2);
        walsh.n_max = std::max(walsh.n_max, walsh.n_start);
        return walsh_to_tolerance(problem, spec, tol, walsh, seed, replicate, ws);
    }
    StoppingResult out;
    out.integrand = stopping_integrand_tail(problem, spec, seed);
    for (uint64_t n = budget.n_start;; n *= 2) {
        Pcg32 rng = replicate_rng(seed, spec.name, n, replicate);
        const RunResult r = run_estimate(problem, spec, n, rng, ws, accumulator);
        out.evaluations += r.n;
        out.seconds += r.seconds;
        StoppingStep step = step_of(r, n, t95(r.dof));
        step.trusted = error_bar_trusted(r);
        bool blocking = false;
        out.flags = stopping_answer_flags(r, problem, spec, &blocking,
                                          out.integrand.k > 0 ? &out.integrand : nullptr);
        step.flagged = blocking;
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
        if (zero_twice(out.steps)) {
            out.reason = StopReason::AllZero;
            return out;
        }
        const bool meets = step.half_width <= out.target;
        const double previous_width =
            previous ? previous->half_width / (adaptive(spec) ? 1.0 : std::sqrt(2.0)) : 0.0;
        const bool predicted = previous && previous->dof >= 1 && previous_width <= out.target;
        const bool agree = previous && std::fabs(step.estimate - previous->estimate) <=
                                           t95(std::min(step.dof, previous->dof)) *
                                               std::sqrt(step.std_error * step.std_error +
                                                         previous->std_error * previous->std_error);
        out.steps.back().agrees = agree;
        if (meets && predicted && agree && step.trusted && !blocking) {
            out.met = true;
            out.reason = StopReason::ToleranceMet;
            return out;
        }
        if (budget_ended(budget, n, r.seconds, &out) || problem_stopped(problem)) return out;
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
        for (int r = 0; r < settings.reps && !problem_stopped(problem); ++r)
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
