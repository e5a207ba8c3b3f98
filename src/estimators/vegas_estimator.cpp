// VEGAS [Lepage78, Lepage21] as an estimator: training iterations adapt a map of the unit cube
// (estimators/vegas.h), then the frozen map warps the spec's sampler's points before the
// proposal's warp, for an ordinary estimate with the sampler's error bar; or, with "report":
// "iterations", the map keeps adapting and the iterations' weighted average is reported.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "estimators/estimator_kind.h"
#include "estimators/vegas_train.h"

namespace mcp {
namespace {

// VEGAS [Lepage21]: training iterations of independent points through the current map adapt
// it; then the map is frozen and N_final points of the spec's sampler, mapped, warped and
// weighted, make an ordinary estimate with an ordinary error bar (iid, strata or
// randomizations): the training points are not in it, so they cannot bias it. The result
// counts all N evaluations.
class VegasEstimator final : public EstimatorAlgorithm, private TrainingPoints {
  public:
    VegasEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec),
          options_(
              vegas_resolved(spec.vegas_options, spec.sampler, false, problem.domain.sample_dim())),
          float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& /*rng*/) override {
        const VegasOptions& o = options_;
        const int dim = problem_.domain.sample_dim();
        total_ = n;
        uint64_t train = static_cast<uint64_t>(o.train_fraction * static_cast<double>(n));
        iterations_ = vegas_training_iterations(o, train);
        if (train < 2) train = 0;
        plan_final(n - train);
        train_ = n - final_;
        if (train_ == 0) iterations_ = 0;
        round_ = 0;
        rounds_done_.clear();
        // The map learns from the training iterations, or from the averaged rounds.
        const uint64_t per_iteration =
            iterations_ > 0 ? train_ / iterations_ : (rounds_ > 1 ? final_ / rounds_ : 0);
        stage_.reset(
            dim, vegas_trainable_increments(o, dim, per_iteration, iterations_ > 0 ? train_ : 0));
        trained_ = false;
        next_ = 0;
        plan_ready_ = false;
        prepared_ = false;
        log_.begin(stage_.map(), iterations_, static_cast<bool>(observer_));
    }

    bool run_block(Pcg32& rng, Workspace& ws) override {
        if (!prepared_) {
            prepare_workspace(problem_.domain, ws);
            prepared_ = true;
        }
        if (!trained_) {
            const TrainingSpent spent = train_map(stage_, options_, problem_, spec_.proposal,
                                                  iterations_, train_, *this, rng, ws, log_);
            if (spent.calls < train_) {
                // Settled early: the calls left go to the estimate. A net's share is rounded
                // to K 2^m again, and what that leaves is one more training iteration.
                plan_final(total_ - spent.calls);
                const uint64_t rest = total_ - spent.calls - final_;
                if (rest > 0)
                    train_map(stage_, budget_options(), problem_, spec_.proposal, 1, rest, *this,
                              rng, ws, log_);
                train_ = total_ - final_;
            }
            trained_ = true;
        }
        if (!plan_ready_) {
            if (final_ == 0 || round_ >= rounds_) return false;
            log_.end_training();
            const uint64_t size = part_of(final_, rounds_, round_);
            plan_ = make_sampler_plan(spec_.sampler, problem_.domain.sample_dim(), size, rng,
                                      spec_.sampler_options());
            accumulator_.reset(sampler_error_method(spec_), plan_, float32_);
            plan_ready_ = true;
            next_ = 0;
            ws.batch.clear();
        }
        const bool averaging = rounds_ > 1; // iteration average: the map keeps learning
        const size_t count =
            static_cast<size_t>(std::min<uint64_t>(kBlockSize, plan_.total - next_));
        auto make = [&](uint64_t at, size_t m) {
            generate_block(plan_, at, m, ws.u);
            stage_.warp(problem_, spec_.proposal, ws, averaging);
        };
        if (averaging) { // the map's bins of this very block are needed: one block at a time
            make(next_, count);
            evaluate_block(problem_.integrand, ws.x, ws.f.data());
        } else { // a frozen map: a caller's function gets the samples in batches
            batched_block(problem_, next_, count, plan_.total, ws, make);
        }
        if (observer_) notify(block_of(ws, next_, count));
        accumulator_.add_block(next_, ws.f.data(), ws.pdf.data(), ws.pdf.data(), count);
        if (averaging) stage_.map().add_training(stage_.bins(), ws.pdf.data(), count); // weights
        next_ += count;
        if (next_ == plan_.total) {
            // One estimation iteration done: keep its result, adapt for the next.
            rounds_done_.push_back(finish_round());
            if (averaging) stage_.map().adapt(options_.alpha, options_.uniform_share);
            ++round_;
            plan_ready_ = false;
        }
        return true;
    }

    AdaptiveView adaptive_view() const override {
        AdaptiveView v = view_of(stage_.map());
        log_.add_history(&v);
        return v;
    }

    RunResult result() const override {
        RunResult r = rounds_done_.size() == 1 ? rounds_done_[0] : average(rounds_done_);
        r.n = total_;
        log_.report(&r);
        return r;
    }

  private:
    // The estimation share: `left` calls, a net's rounded down to K 2^m (randomizations of
    // full nets; the rest trains), split into the rounds of the iteration average.
    void plan_final(uint64_t left) {
        const VegasOptions& o = options_;
        final_ = left;
        const uint64_t k = static_cast<uint64_t>(std::max(spec_.randomizations, 1));
        if (spec_.sampler == SamplerKind::Sobol && left < total_ && final_ >= k) {
            uint64_t per = 1; // per k <= final_ throughout
            while (2 * per * k <= final_) per *= 2;
            final_ = per * k;
        }
        // Iteration average: the estimation share in `iterations` parts (each at least 2).
        rounds_ = 1;
        if (o.report == VegasReport::Iterations)
            rounds_ = static_cast<int>(std::max<uint64_t>(
                1,
                std::min<uint64_t>(static_cast<uint64_t>(std::max(o.iterations, 1)), final_ / 2)));
    }
    VegasOptions budget_options() const {
        VegasOptions o = options_;
        o.train_stop = VegasTrainStop::Budget;
        return o;
    }

    // The training points (TrainingPoints, for train_map): independent points of the unit
    // cube, a fresh plan per iteration; their weights f / p as they are.
    void start(uint64_t calls, Pcg32& rng) override {
        plan_ = make_sampler_plan(SamplerKind::Independent, problem_.domain.sample_dim(), calls,
                                  rng, {});
        next_ = 0;
    }
    size_t next(PointBlock& u) override {
        const size_t count =
            static_cast<size_t>(std::min<uint64_t>(kBlockSize, plan_.total - next_));
        if (count == 0) return 0;
        generate_block(plan_, next_, count, u);
        next_ += count;
        return count;
    }
    const double* weigh(const Workspace& ws, size_t count, double* weights) override {
        for (size_t i = 0; i < count; ++i) weights[i] = ws.f[i] / ws.pdf[i];
        return nullptr; // uniform y
    }

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
        if (r.top.size() > kTailWeights) r.top.resize(kTailWeights);
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

    const Problem& problem_;
    const EstimatorSpec& spec_;
    const VegasOptions options_; // spec_'s, the defaults filled in
    bool float32_;
    uint64_t total_ = 0, train_ = 0, final_ = 0, next_ = 0;
    TrainingLog log_;
    int iterations_ = 0; // training iterations
    bool trained_ = false;
    int rounds_ = 1, round_ = 0; // estimation iterations (1 unless averaging)
    std::vector<RunResult> rounds_done_;
    bool plan_ready_ = false, prepared_ = false;
    MapStage stage_;   // the map and its buffers
    SamplerPlan plan_; // the training iteration's, then the estimation round's
    WeightAccumulator accumulator_;
};

} // namespace

const EstimatorKind& vegas_estimator_kind() {
    static const EstimatorKind kind{
        "vegas",
        "a VEGAS map trained on a share of N, then frozen for the sampler's points",
        [](const EstimatorSpec&) { return "vegas"; },
        sampler_error_method, // the frozen map's points are the sampler's, mapped
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<VegasEstimator>(problem, spec, accumulator);
        },
        [](const EstimatorSpec&) { return false; }, // a learnt map: the first points are training
        true,
    };
    return kind;
}

} // namespace mcp
