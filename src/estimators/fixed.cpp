// Fixed estimators: N points from one sampler (independent, stratified, Latin hypercube or a
// randomized quasi-Monte Carlo set), warped by one proposal, weighted f/p and summed by the
// weight accumulator: I_N = (1/N) sum f(x_i) / p(x_i) [Owen13, ch. 2, 10, 17]. The kind "fixed"
// covers the methods uniform, importance, stratified, stratified_importance, latin_hypercube,
// qmc, rqmc and rqmc_walsh (the spec's sampler, proposal and error bar say which).
#include <algorithm>

#include "estimators/estimator_kind.h"

namespace mcp {
namespace {

class FixedEstimator final : public EstimatorAlgorithm {
  public:
    FixedEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec), float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& rng) override {
        plan_ = make_sampler_plan(spec_.sampler, problem_.domain.sample_dim(), n, rng,
                                  spec_.sampler_options());
        accumulator_.reset(sampler_error_method(spec_), plan_, float32_);
        next_ = 0;
        prepared_ = false;
    }

    bool run_block(Pcg32& rng, Workspace& ws) override {
        if (next_ >= plan_.total) return false;
        if (!prepared_) {
            prepare_workspace(problem_.domain, ws);
            ws.batch.clear();
            prepared_ = true;
        }
        const size_t count =
            static_cast<size_t>(std::min<uint64_t>(kBlockSize, plan_.total - next_));
        const SampleBlock b =
            sample_block_batched(problem_, spec_.proposal, plan_, next_, count, ws);
        notify(b);
        accumulator_.add_block(b.first, b.f, b.pdf, b.pdf, b.count); // weights overwrite p
        next_ += count;
        return true;
    }

    PointDesign design() const override {
        return {plan_.strata, plan_.per_stratum, plan_.batches()};
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

const char* fixed_method(const EstimatorSpec& spec) {
    if (is_qmc(spec.sampler)) {
        if (spec.randomization == QmcRandomization::None) return "qmc";
        return spec.walsh_bound ? "rqmc_walsh" : "rqmc";
    }
    const bool importance = spec.proposal.importance;
    switch (spec.sampler) {
    case SamplerKind::Stratified: return importance ? "stratified_importance" : "stratified";
    case SamplerKind::LatinHypercube: return "latin_hypercube";
    default: return importance ? "importance" : "uniform";
    }
}

} // namespace

const EstimatorKind& fixed_estimator_kind() {
    static const EstimatorKind kind{
        "fixed",
        "one sampler's points warped by one proposal, weighted f/p and averaged",
        fixed_method,
        sampler_error_method,
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<FixedEstimator>(problem, spec, accumulator);
        },
        // Independent points: any first k of them are k independent points. Strata, Latin
        // hypercubes and nets are designs of all N.
        [](const EstimatorSpec& spec) { return spec.sampler == SamplerKind::Independent; },
        false,
    };
    return kind;
}

} // namespace mcp
