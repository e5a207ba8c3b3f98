#include "estimators/study.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/special.h"

#if defined(__EMSCRIPTEN__) && !defined(__EMSCRIPTEN_PTHREADS__)
#define MCPLAY_HAS_THREADS 0
#else
#define MCPLAY_HAS_THREADS 1
#include <thread>
#endif

namespace mcp {

namespace {
constexpr uint64_t kMaxN = uint64_t(1) << 36;
constexpr int kMaxReps = 100000;
constexpr int kMaxThreads = 256;
constexpr uint64_t kSupportProbes = 1 << 16;
} // namespace

SupportCheck check_support(const Problem& problem, const EstimatorSpec& spec, uint64_t probes,
                           uint64_t seed) {
    SupportCheck check;
    check.probes = probes;
    if (!spec.proposal.importance) return check; // uniform proposals cover the whole domain
    const Domain& d = problem.domain;
    Pcg32 rng(mix64(seed ^ 0x737570706f7274ULL), hash_string(spec.name.c_str())); // "support"
    const Proposal uniform = uniform_proposal(d);
    const SamplerPlan plan =
        make_sampler_plan(SamplerKind::Independent, d.sample_dim(), probes, rng);
    PointBlock u, x;
    u.reset(d.sample_dim(), kBlockSize);
    x.reset(d.point_dim(), kBlockSize);
    std::vector<double> f(kBlockSize), p(kBlockSize);
    NeumaierSum all, missed;
    for (uint64_t first = 0; first < probes; first += kBlockSize) {
        const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, probes - first));
        generate_block(plan, first, count, rng, u);
        warp_block(uniform, d, u, x, p.data());
        evaluate_block(problem.integrand, x, f.data());
        proposal_pdf_block(spec.proposal, d, x, p.data());
        for (size_t i = 0; i < count; ++i) {
            const double a = std::fabs(f[i]);
            if (!(a > 0.0) || !std::isfinite(a)) continue;
            ++check.f_nonzero;
            all.add(a);
            if (!(p[i] > 0.0)) {
                ++check.missed;
                missed.add(a);
            }
        }
    }
    check.missed_fraction = all.value() > 0.0 ? missed.value() / all.value() : 0.0;
    return check;
}

std::string check_settings(const StudySettings& s) {
    if (s.n_min < 1) return "n_min must be >= 1, got " + std::to_string(s.n_min);
    if (s.n_max > kMaxN)
        return "n_max must be <= 2^36 (" + std::to_string(kMaxN) + "), got " +
               std::to_string(s.n_max);
    if (s.n_max < s.n_min)
        return "n_max (" + std::to_string(s.n_max) + ") must be >= n_min (" +
               std::to_string(s.n_min) + ")";
    if (n_ladder(s.n_min, s.n_max).empty())
        return "no power of two lies between n_min = " + std::to_string(s.n_min) +
               " and n_max = " + std::to_string(s.n_max);
    if (s.reps < 2 || s.reps > kMaxReps)
        return "reps must be in 2.." + std::to_string(kMaxReps) +
               " (a variance needs two replicates), got " + std::to_string(s.reps);
    if (s.threads < 0 || s.threads > kMaxThreads)
        return "threads must be in 0.." + std::to_string(kMaxThreads) + " (0 = all cores), got " +
               std::to_string(s.threads);
    return "";
}

std::vector<uint64_t> n_ladder(uint64_t n_min, uint64_t n_max) {
    std::vector<uint64_t> ladder;
    for (uint64_t n = 1; n <= n_max && n != 0; n <<= 1)
        if (n >= n_min) ladder.push_back(n);
    return ladder;
}

uint64_t replicate_stream(uint64_t seed, const std::string& estimator, uint64_t n, int rep) {
    uint64_t h = hash_combine(mix64(seed), hash_string(estimator.c_str()));
    h = hash_combine(h, n);
    return hash_combine(h, static_cast<uint64_t>(rep));
}

LevelStats summarise_level(const std::vector<RunResult>& runs, const Problem& problem) {
    LevelStats s;
    s.reps = static_cast<int>(runs.size());
    if (runs.empty()) return s;
    s.n = runs[0].n;
    RunningMoments est, se;
    NeumaierSum sq_err, time;
    int covered = 0, se_count = 0;
    s.has_exact = problem.exact.has_value();
    const double exact = s.has_exact ? *problem.exact : 0.0;
    // Every run keeps its kTopWeights largest |w|, so the largest of the pooled tops are the
    // largest weights of all R N samples: the tail index uses them all.
    std::vector<double> pooled;
    double nonzero = 0.0, ess = 0.0;
    for (const RunResult& r : runs) {
        ess += r.diagnostics.ess;
        pooled.insert(pooled.end(), r.top.begin(), r.top.end());
        nonzero += static_cast<double>(r.diagnostics.nonzero);
        est.add(r.estimate);
        time.add(r.seconds);
        s.diagnostics.merge(r.diagnostics);
        s.estimates.push_back(r.estimate);
        s.run_std_errors.push_back(r.std_error);
        if (std::isfinite(r.std_error)) {
            se.add(r.std_error);
            ++se_count;
        }
        if (s.has_exact) {
            const double e = r.estimate - exact;
            sq_err.add(e * e);
            if (std::isfinite(r.std_error) && std::fabs(e) <= 1.959963984540054 * r.std_error)
                ++covered;
        }
    }
    const double R = static_cast<double>(s.reps);
    s.nonzero_per_run = nonzero / R;
    s.ess_mean = ess / R;
    std::sort(pooled.begin(), pooled.end(), std::greater<double>());
    s.tail_k = hill_order(s.n * static_cast<uint64_t>(s.reps));
    s.tail_index = hill_tail_index(pooled, s.tail_k);
    s.mean = est.mean();
    s.variance = est.variance();
    // s^2 / sigma^2 ~ chi^2_{R-1} for normal estimates.
    const double dof = R - 1.0;
    s.variance_lo = dof * s.variance / chi_square_quantile(0.975, dof);
    s.variance_hi = dof * s.variance / chi_square_quantile(0.025, dof);
    s.std_error = std::sqrt(s.variance / R);
    const double t = student_t_quantile(0.975, dof);
    s.ci_lo = s.mean - t * s.std_error;
    s.ci_hi = s.mean + t * s.std_error;
    s.mean_run_se = se_count ? se.mean() : std::numeric_limits<double>::quiet_NaN();
    s.time_total = time.value();
    s.time_mean = s.time_total / R;
    s.efficiency = s.variance > 0.0 && s.time_mean > 0.0 ? 1.0 / (s.variance * s.time_mean)
                                                         : std::numeric_limits<double>::infinity();
    if (s.has_exact) {
        s.bias = s.mean - exact;
        s.mse = sq_err.value() / R;
        s.rmse = std::sqrt(s.mse);
        s.coverage = static_cast<double>(covered) / R;
        s.error = s.rmse;
    } else {
        s.error = std::sqrt(s.variance);
    }
    return s;
}

ConvergenceFit fit_convergence(const std::vector<LevelStats>& levels) {
    ConvergenceFit fit;
    std::vector<double> x, y;
    int reps = 0, skipped = 0;
    for (const LevelStats& l : levels) {
        // A variance at the round-off level of the mean (an exact estimator such as a pdf
        // proportional to f) carries no convergence information.
        const double roundoff = 64.0 * 2.220446049250313e-16 * std::fabs(l.mean);
        if (l.variance > roundoff * roundoff && std::isfinite(l.variance)) {
            x.push_back(std::log(static_cast<double>(l.n)));
            y.push_back(std::log(l.variance));
            reps = l.reps;
        } else {
            ++skipped;
        }
    }
    fit.levels_used = static_cast<int>(x.size());
    if (skipped)
        fit.note = std::to_string(skipped) + " level(s) with zero (round-off) variance left out";
    if (x.size() < 3) {
        fit.note = x.empty() && skipped ? "variance is zero at every N (an exact estimator?)"
                                        : "fewer than 3 levels with a variance: no fit" +
                                              (fit.note.empty() ? "" : "; " + fit.note);
        return fit;
    }
    LineFit line = fit_line(x, y);
    fit.valid = true;
    fit.order = line.slope;
    fit.intercept = line.intercept;
    const double noise = reps > 1 ? trigamma(0.5 * (reps - 1)) : 0.0;
    fit.order_se = std::sqrt(std::fmax(line.residual_variance, noise) / line.sxx);
    return fit;
}

LevelConsistency level_consistency(const std::vector<LevelStats>& levels) {
    LevelConsistency c;
    double wsum = 0.0, wmean = 0.0;
    for (const LevelStats& l : levels)
        if (l.std_error > 0.0 && std::isfinite(l.std_error) && std::isfinite(l.mean)) {
            const double w = 1.0 / (l.std_error * l.std_error);
            wsum += w;
            wmean += w * l.mean;
        }
    if (wsum == 0.0) return c;
    wmean /= wsum;
    int used = 0;
    for (const LevelStats& l : levels)
        if (l.std_error > 0.0 && std::isfinite(l.std_error) && std::isfinite(l.mean)) {
            const double z = (l.mean - wmean) / l.std_error;
            c.chi2 += z * z;
            ++used;
        }
    c.dof = used - 1;
    c.p_value = c.dof > 0 ? chi_square_sf(c.chi2, c.dof) : 1.0;
    return c;
}

int resolve_threads(int requested) {
#if MCPLAY_HAS_THREADS
    if (requested > 0) return requested;
    unsigned hw = std::thread::hardware_concurrency();
    return hw > 0 ? static_cast<int>(hw) : 1;
#else
    (void)requested;
    return 1;
#endif
}

StudyResult run_study(const Problem& problem, const std::vector<EstimatorSpec>& estimators,
                      const StudySettings& settings, const StudyProgress& progress) {
    const auto start = std::chrono::steady_clock::now();
    StudyResult result;
    result.problem = problem;
    result.settings = settings;
    result.threads_used = resolve_threads(settings.threads);
    for (const EstimatorSpec& spec : estimators) {
        EstimatorStudy es;
        es.spec = spec;
        es.error_method = error_method_for(spec);
        es.support = check_support(problem, spec, kSupportProbes, settings.seed);
        result.estimators.push_back(es);
    }
    const std::vector<uint64_t> ladder = n_ladder(settings.n_min, settings.n_max);
    const size_t n_est = estimators.size();
    const size_t reps = static_cast<size_t>(settings.reps);
    const uint64_t seed_state = mix64(settings.seed ^ 0x6d63706c6179ULL); // "mcplay"

    for (size_t level = 0; level < ladder.size(); ++level) {
        const uint64_t n = ladder[level];
        const size_t tasks = n_est * reps;
        std::vector<RunResult> runs(tasks);
        std::atomic<size_t> next{0};
        auto worker = [&]() {
            Workspace ws;
            for (size_t t = next++; t < tasks; t = next++) {
                const size_t e = t / reps;
                const int r = static_cast<int>(t % reps);
                Pcg32 rng(seed_state, replicate_stream(settings.seed, estimators[e].name, n, r));
                runs[t] = run_estimate(problem, estimators[e], n, rng, ws, settings.accumulator);
            }
        };
        const int threads =
            static_cast<int>(std::min<size_t>(static_cast<size_t>(result.threads_used), tasks));
#if MCPLAY_HAS_THREADS
        if (threads > 1) {
            std::vector<std::thread> pool;
            for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
            for (std::thread& th : pool) th.join();
        } else {
            worker();
        }
#else
        (void)threads;
        worker();
#endif
        for (size_t e = 0; e < n_est; ++e) {
            std::vector<RunResult> level_runs(runs.begin() + static_cast<long>(e * reps),
                                              runs.begin() + static_cast<long>((e + 1) * reps));
            EstimatorStudy& es = result.estimators[e];
            es.levels.push_back(summarise_level(level_runs, problem));
            es.fit = fit_convergence(es.levels);
            es.consistency = level_consistency(es.levels);
        }
        result.wall_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (progress && !progress(result, level)) {
            result.cancelled = level + 1 < ladder.size();
            break;
        }
    }
    result.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace mcp

namespace mcp {

SampleDump dump_samples(const Problem& problem, const EstimatorSpec& spec, uint64_t n,
                        uint64_t seed) {
    SampleDump dump;
    const Domain& d = problem.domain;
    dump.sample_dim = d.sample_dim();
    dump.point_dim = d.point_dim();
    // The same stream and seeding as replicate 0 of the study at this N.
    Pcg32 rng(mix64(seed ^ 0x6d63706c6179ULL), replicate_stream(seed, spec.name, n, 0));
    const SamplerPlan plan =
        make_sampler_plan(spec.sampler, dump.sample_dim, n, rng, spec.per_stratum);
    dump.strata = plan.strata;
    dump.per_stratum = plan.per_stratum;
    PointBlock u, x;
    u.reset(dump.sample_dim, kBlockSize);
    x.reset(dump.point_dim, kBlockSize);
    std::vector<double> p(kBlockSize), f(kBlockSize);
    for (uint64_t first = 0; first < n; first += kBlockSize) {
        const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, n - first));
        generate_block(plan, first, count, rng, u);
        warp_block(spec.proposal, d, u, x, p.data());
        evaluate_block(problem.integrand, x, f.data());
        for (size_t i = 0; i < count; ++i) {
            for (int j = 0; j < dump.sample_dim; ++j) dump.u.push_back(u.coord(j)[i]);
            for (int j = 0; j < dump.point_dim; ++j) dump.x.push_back(x.coord(j)[i]);
            dump.pdf.push_back(p[i]);
            dump.f.push_back(f[i]);
            dump.weight.push_back(p[i] > 0.0 ? f[i] / p[i] : (f[i] == 0.0 ? 0.0 : NAN));
        }
    }
    return dump;
}

} // namespace mcp
