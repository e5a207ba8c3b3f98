#include "estimators/estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>

#include "core/special.h"
#include "core/stats.h"
#include "estimators/accumulator.h"
#include "estimators/block_driver.h"

namespace mcp {

void RunDiagnostics::merge(const RunDiagnostics& o) {
    nonfinite += o.nonfinite;
    zero_pdf += o.zero_pdf;
    nonzero += o.nonzero;
    max_weight_share = std::fmax(max_weight_share, o.max_weight_share);
    weights.merge(o.weights);
    error_units.merge(o.error_units);
    batch_units = batch_units || o.batch_units;
}

const char* error_method_name(ErrorMethod m) {
    switch (m) {
    case ErrorMethod::Iid: return "iid";
    case ErrorMethod::CollapsedStrata: return "collapsed_strata";
    case ErrorMethod::PairedStrata: return "paired_strata";
    case ErrorMethod::IidConservative: return "iid_conservative";
    case ErrorMethod::Randomizations: return "randomizations";
    case ErrorMethod::None: return "none";
    case ErrorMethod::PartsSum: return "parts_sum";
    case ErrorMethod::Regression: return "regression";
    }
    return "?";
}

double interval_quantile(int dof) {
    return dof > 0 ? student_t_quantile(0.975, dof) : 1.959963984540054;
}

ErrorMethod error_method_for(const EstimatorSpec& spec) {
    if (spec.miser || (spec.vegas && spec.vegas_options.stratify) || spec.control_variates)
        return ErrorMethod::PartsSum;
    if (spec.mis) {
        if (!spec.mis_options.one_sample) return ErrorMethod::PartsSum;
        return spec.mis_options.optimal ? ErrorMethod::Regression : ErrorMethod::Iid;
    }
    switch (spec.sampler) {
    case SamplerKind::Independent: return ErrorMethod::Iid;
    case SamplerKind::Stratified:
        return spec.per_stratum == 2 ? ErrorMethod::PairedStrata : ErrorMethod::CollapsedStrata;
    case SamplerKind::LatinHypercube: return ErrorMethod::IidConservative;
    case SamplerKind::Sobol:
    case SamplerKind::Halton:
    case SamplerKind::Lattice:
        return spec.randomization == QmcRandomization::None ? ErrorMethod::None
                                                            : ErrorMethod::Randomizations;
    }
    return ErrorMethod::Iid;
}

int hill_order(uint64_t samples) {
    // k grows with the sample (k / n -> 0, k -> infinity, as Hill's estimator needs) but stays
    // small enough for a fixed-size heap: k = min(64, n / 16); below 8 there is no estimate.
    const uint64_t k = std::min<uint64_t>(64, samples / 16);
    return k < 8 ? 0 : static_cast<int>(k);
}

double hill_tail_index(const std::vector<double>& top, int k) {
    if (k < 1 || static_cast<int>(top.size()) < k + 1)
        return std::numeric_limits<double>::quiet_NaN();
    const double xk = top[static_cast<size_t>(k)];
    if (!(xk > 0.0)) return 0.0;
    // Top values equal up to rounding (a constant weight computed along different paths)
    // have no tail: their log spacings are noise of a few ulps, not a power law.
    if (top[0] <= xk * (1.0 + 1e-12)) return std::numeric_limits<double>::infinity();
    double sum = 0.0;
    for (int i = 0; i < k; ++i) sum += std::log(top[static_cast<size_t>(i)] / xk);
    return sum > 0.0 ? k / sum : std::numeric_limits<double>::infinity();
}

void prepare_workspace(const Domain& domain, Workspace& ws) {
    const int sdim = domain.sample_dim(), pdim = domain.point_dim();
    if (ws.u.dim != sdim || ws.u.capacity != kBlockSize) ws.u.reset(sdim, kBlockSize);
    if (ws.x.dim != pdim || ws.x.capacity != kBlockSize) ws.x.reset(pdim, kBlockSize);
    ws.pdf.resize(kBlockSize);
    ws.f.resize(kBlockSize);
}

SampleBlock block_of(Workspace& ws, uint64_t first, size_t count) {
    SampleBlock block;
    block.first = first;
    block.count = count;
    block.u = &ws.u;
    block.x = &ws.x;
    block.pdf = ws.pdf.data();
    block.f = ws.f.data();
    return block;
}

SampleBlock sample_block(const Problem& problem, const Proposal& proposal, const SamplerPlan& plan,
                         uint64_t first, size_t count, Workspace& ws) {
    generate_block(plan, first, count, ws.u);
    warp_block(proposal, problem.domain, ws.u, ws.x, ws.pdf.data());
    evaluate_block(problem.integrand, ws.x, ws.f.data());
    return block_of(ws, first, count);
}

double clock_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

AdaptiveView view_of(const VegasMap& map) {
    AdaptiveView v;
    for (int j = 0; j < map.dim(); ++j)
        v.edges.emplace_back(map.edges(j), map.edges(j) + map.increments() + 1);
    return v;
}

void TrainingLog::begin(const VegasMap& map, int iterations, bool record) {
    record_ = record;
    ended_ = false;
    iterations_ = iterations;
    calls_ = 0;
    start_ = clock_seconds();
    seconds_ = 0.0;
    history_.clear();
    this->record(map, 0);
}

void TrainingLog::adapted(const VegasMap& map, int iteration) {
    record(map, iteration);
}

void TrainingLog::end_training() {
    if (ended_) return;
    ended_ = true;
    seconds_ = clock_seconds() - start_;
}

void TrainingLog::report(RunResult* r) const {
    r->training_n = calls_;
    r->training_seconds = calls_ > 0 ? seconds_ : 0.0;
}

void TrainingLog::record(const VegasMap& map, int iteration) {
    if (!record_) return;
    // Snapshots 0 .. iterations; keep about kViewIterations of them, evenly, and the last.
    const int stride = std::max(1, (iterations_ + kViewIterations - 1) / kViewIterations);
    if (iteration % stride != 0 && iteration != iterations_) return;
    const int k = map.increments();
    const int step = std::max(1, (k + kViewEdges - 1) / kViewEdges);
    std::vector<std::vector<double>> axes;
    for (int j = 0; j < std::min(map.dim(), 2); ++j) {
        std::vector<double> e;
        for (int i = 0; i <= k; i += step) e.push_back(map.edges(j)[i]);
        if ((k % step) != 0) e.push_back(map.edges(j)[k]);
        axes.push_back(e);
    }
    history_.push_back(axes);
}

namespace {

// A fixed estimator: N points from one sampler, warped by one proposal, weighted f/p and summed
// by the weight accumulator: I_N = (1/N) sum f(x_i) / p(x_i).
class FixedEstimator final : public EstimatorAlgorithm {
  public:
    FixedEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec), float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& rng) override {
        plan_ = make_sampler_plan(spec_.sampler, problem_.domain.sample_dim(), n, rng,
                                  spec_.sampler_options());
        accumulator_.reset(error_method_for(spec_), plan_, float32_);
        next_ = 0;
        prepared_ = false;
    }

    bool run_block(Pcg32& rng, Workspace& ws) override {
        if (next_ >= plan_.total) return false;
        if (!prepared_) {
            prepare_workspace(problem_.domain, ws);
            prepared_ = true;
        }
        const size_t count =
            static_cast<size_t>(std::min<uint64_t>(kBlockSize, plan_.total - next_));
        const SampleBlock b = sample_block(problem_, spec_.proposal, plan_, next_, count, ws);
        notify(b);
        accumulator_.add_block(b.first, b.f, b.pdf, b.pdf, b.count); // weights overwrite p
        next_ += count;
        return true;
    }

    RunResult result() const override {
        const double scale = quantity_scale(problem_);
        RunResult r = accumulator_.finish(scale);
        r.n = plan_.total;
        return r;
    }

  private:
    const Problem& problem_;
    const EstimatorSpec& spec_;
    bool float32_;
    SamplerPlan plan_;
    WeightAccumulator accumulator_;
    uint64_t next_ = 0;
    bool prepared_ = false;
};

// VEGAS [Lepage21]: training iterations of independent points through the current map adapt
// it; then the map is frozen and N_final points of the spec's sampler, mapped, warped and
// weighted, make an ordinary estimate with an ordinary error bar (iid, strata or
// randomizations): the training points are not in it, so they cannot bias it. The result
// counts all N evaluations.
class VegasEstimator final : public EstimatorAlgorithm {
  public:
    VegasEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec), float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& /*rng*/) override {
        const VegasOptions& o = spec_.vegas_options;
        const int dim = problem_.domain.sample_dim();
        total_ = n;
        uint64_t train = static_cast<uint64_t>(o.train_fraction * static_cast<double>(n));
        iterations_ = vegas_training_iterations(o, train);
        if (train < 2) train = 0;
        final_ = n - train;
        // A net's randomizations are full nets when each holds a power of two points: the
        // estimation share is rounded down to K 2^m, and training takes the rest.
        const uint64_t k = static_cast<uint64_t>(std::max(spec_.randomizations, 1));
        if (spec_.sampler == SamplerKind::Sobol && train > 0 && final_ >= k) {
            uint64_t per = 1; // per k <= final_ throughout
            while (2 * per * k <= final_) per *= 2;
            final_ = per * k;
        }
        train_ = n - final_;
        if (train_ == 0) iterations_ = 0;
        // Iteration average: the estimation share in `iterations` parts (each at least 2 points).
        rounds_ = 1;
        if (o.report == VegasReport::Iterations)
            rounds_ = static_cast<int>(std::max<uint64_t>(
                1,
                std::min<uint64_t>(static_cast<uint64_t>(std::max(o.iterations, 1)), final_ / 2)));
        round_ = 0;
        rounds_done_.clear();
        const uint64_t per_iteration = iterations_ > 0 ? train_ / iterations_ : 0;
        map_ = VegasMap(dim, spec_.vegas_options.increments > 0
                                 ? spec_.vegas_options.increments
                                 : vegas_increments(dim, per_iteration));
        iteration_ = 0;
        next_ = 0;
        plan_ready_ = false;
        prepared_ = false;
        log_.begin(map_, iterations_, static_cast<bool>(observer_));
        jacobian_.assign(kBlockSize, 1.0);
        bins_.assign(static_cast<size_t>(dim) * kBlockSize, 0);
    }

    bool run_block(Pcg32& rng, Workspace& ws) override {
        if (!prepared_) {
            prepare_workspace(problem_.domain, ws);
            prepared_ = true;
        }
        const bool training = iteration_ < iterations_;
        if (!plan_ready_) {
            const int dim = problem_.domain.sample_dim();
            if (training) {
                const uint64_t size = part_of(train_, iterations_, iteration_);
                plan_ = make_sampler_plan(SamplerKind::Independent, dim, size, rng, {});
            } else {
                if (final_ == 0 || round_ >= rounds_) return false;
                log_.end_training();
                const uint64_t size = part_of(final_, rounds_, round_);
                plan_ = make_sampler_plan(spec_.sampler, dim, size, rng, spec_.sampler_options());
                accumulator_.reset(error_method_for(spec_), plan_, float32_);
            }
            plan_ready_ = true;
            next_ = 0;
        }
        const bool averaging = rounds_ > 1; // iteration average: the map keeps learning
        const size_t count =
            static_cast<size_t>(std::min<uint64_t>(kBlockSize, plan_.total - next_));
        generate_block(plan_, next_, count, ws.u);
        map_.apply_block(ws.u, jacobian_.data(), training || averaging ? bins_.data() : nullptr);
        warp_block(spec_.proposal, problem_.domain, ws.u, ws.x, ws.pdf.data());
        for (size_t i = 0; i < count; ++i) ws.pdf[i] /= jacobian_[i]; // p(x) / J(y)
        evaluate_block(problem_.integrand, ws.x, ws.f.data());
        if (training) {
            for (size_t i = 0; i < count; ++i) jacobian_[i] = ws.f[i] / ws.pdf[i]; // weights
            map_.add_training(bins_.data(), jacobian_.data(), count);
            next_ += count;
            log_.trained(count);
            if (next_ == plan_.total) {
                map_.adapt(spec_.vegas_options.alpha, spec_.vegas_options.uniform_share);
                ++iteration_;
                log_.adapted(map_, iteration_);
                plan_ready_ = false;
            }
            return true;
        }
        if (observer_) notify(block_of(ws, next_, count));
        accumulator_.add_block(next_, ws.f.data(), ws.pdf.data(), ws.pdf.data(), count);
        if (averaging) map_.add_training(bins_.data(), ws.pdf.data(), count); // the weights
        next_ += count;
        if (next_ == plan_.total) {
            // One estimation iteration done: keep its result, adapt for the next.
            rounds_done_.push_back(finish_round());
            if (averaging) map_.adapt(spec_.vegas_options.alpha, spec_.vegas_options.uniform_share);
            ++round_;
            plan_ready_ = false;
        }
        return true;
    }

    RunResult result() const override {
        RunResult r = rounds_done_.size() == 1 ? rounds_done_[0] : average(rounds_done_);
        r.n = total_;
        log_.report(&r);
        return r;
    }

    AdaptiveView adaptive_view() const override {
        AdaptiveView v = view_of(map_);
        log_.add_history(&v);
        return v;
    }

  private:
    RunResult finish_round() const {
        const double scale = quantity_scale(problem_);
        return accumulator_.finish(scale);
    }

    /// The weighted average of the iterations, weights 1 / se_i^2, its standard error
    /// (sum 1 / se_i^2)^-1/2, and chi^2 = sum (I_i - I)^2 / se_i^2 on (iterations - 1) degrees
    /// of freedom [Lepage78]. An iteration without a positive finite error bar (an exact or
    /// empty one) makes the weights meaningless: then the plain mean, and no chi^2.
    static RunResult average(const std::vector<RunResult>& rounds) {
        RunResult r;
        if (rounds.empty()) {
            r.estimate = r.std_error = std::numeric_limits<double>::quiet_NaN();
            return r;
        }
        bool weighted = true;
        for (const RunResult& x : rounds)
            weighted = weighted && std::isfinite(x.estimate) && std::isfinite(x.std_error) &&
                       x.std_error > 0.0;
        NeumaierSum sum_w, sum_wi, sum_se2;
        long dof = 0;
        for (const RunResult& x : rounds) {
            const double w = weighted ? 1.0 / (x.std_error * x.std_error) : 1.0;
            sum_w.add(w);
            sum_wi.add(w * x.estimate);
            sum_se2.add(x.std_error * x.std_error);
            dof += x.dof;
            const double ess = r.diagnostics.ess + x.diagnostics.ess;
            r.diagnostics.merge(x.diagnostics);
            r.diagnostics.ess = ess;
            r.top.insert(r.top.end(), x.top.begin(), x.top.end());
        }
        const double m = static_cast<double>(rounds.size());
        r.estimate = sum_wi.value() / sum_w.value();
        r.std_error = weighted ? 1.0 / std::sqrt(sum_w.value()) : std::sqrt(sum_se2.value()) / m;
        r.dof = static_cast<int>(std::min<long>(dof, 1000000));
        std::sort(r.top.begin(), r.top.end(), std::greater<double>());
        if (r.top.size() > kTopWeights) r.top.resize(kTopWeights);
        if (weighted && rounds.size() > 1) {
            NeumaierSum chi2;
            for (const RunResult& x : rounds) {
                const double z = (x.estimate - r.estimate) / x.std_error;
                chi2.add(z * z);
            }
            r.iteration_chi2 = chi2.value();
            r.iteration_dof = static_cast<int>(rounds.size()) - 1;
        }
        return r;
    }

  public:
  private:
    const Problem& problem_;
    const EstimatorSpec& spec_;
    bool float32_;
    uint64_t total_ = 0, train_ = 0, final_ = 0, next_ = 0;
    TrainingLog log_;
    int iterations_ = 0, iteration_ = 0; // training iterations
    int rounds_ = 1, round_ = 0;         // estimation iterations (1 unless averaging)
    std::vector<RunResult> rounds_done_;
    bool plan_ready_ = false, prepared_ = false;
    VegasMap map_;
    SamplerPlan plan_;
    WeightAccumulator accumulator_;
    std::vector<double> jacobian_;
    std::vector<uint32_t> bins_;
};

} // namespace

std::unique_ptr<EstimatorAlgorithm>
make_estimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator) {
    if (spec.mis) return make_mis_estimator(problem, spec, accumulator);
    if (spec.control_variates) return make_control_variate_estimator(problem, spec, accumulator);
    if (spec.miser) return make_miser_estimator(problem, spec, accumulator);
    if (spec.vegas && spec.vegas_options.stratify)
        return make_vegas_plus_estimator(problem, spec, accumulator);
    if (spec.vegas) return std::make_unique<VegasEstimator>(problem, spec, accumulator);
    return std::make_unique<FixedEstimator>(problem, spec, accumulator);
}

RunResult run_estimate(const Problem& problem, const EstimatorSpec& spec, uint64_t n, Pcg32& rng,
                       Workspace& ws, Accumulator accumulator) {
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<EstimatorAlgorithm> estimator = make_estimator(problem, spec, accumulator);
    estimator->begin(n, rng);
    while (estimator->run_block(rng, ws)) {
    }
    RunResult result = estimator->result();
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace mcp
