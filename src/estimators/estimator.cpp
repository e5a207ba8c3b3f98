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
}

const char* error_method_name(ErrorMethod m) {
    switch (m) {
    case ErrorMethod::Iid: return "iid";
    case ErrorMethod::CollapsedStrata: return "collapsed_strata";
    case ErrorMethod::PairedStrata: return "paired_strata";
    case ErrorMethod::IidConservative: return "iid_conservative";
    case ErrorMethod::Randomizations: return "randomizations";
    case ErrorMethod::None: return "none";
    }
    return "?";
}

double interval_quantile(int dof) {
    return dof > 0 ? student_t_quantile(0.975, dof) : 1.959963984540054;
}

ErrorMethod error_method_for(const EstimatorSpec& spec) {
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

SampleBlock sample_block(const Problem& problem, const Proposal& proposal, const SamplerPlan& plan,
                         uint64_t first, size_t count, Workspace& ws) {
    generate_block(plan, first, count, ws.u);
    warp_block(proposal, problem.domain, ws.u, ws.x, ws.pdf.data());
    evaluate_block(problem.integrand, ws.x, ws.f.data());
    SampleBlock block;
    block.first = first;
    block.count = count;
    block.u = &ws.u;
    block.x = &ws.x;
    block.pdf = ws.pdf.data();
    block.f = ws.f.data();
    return block;
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
        accumulator_.add_block(b.first, b.f, b.pdf, b.pdf, b.count); // weights overwrite p
        next_ += count;
        return true;
    }

    RunResult result() const override {
        const double scale =
            problem_.quantity == Quantity::Mean ? 1.0 / problem_.domain.measure() : 1.0;
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

} // namespace

std::unique_ptr<EstimatorAlgorithm>
make_estimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator) {
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
