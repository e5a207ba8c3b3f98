// Antithetic variates [Owen13, 8.2]: the points come in pairs u and 1 - u of the unit cube, each
// warped by the proposal, and each pair's mean weight
//   y_i = (w(u_i) + w(1 - u_i)) / 2,   w = f / p,
// is one unit: I = (1/m) sum y_i over m = floor(N/2) independent pairs (N = 2m evaluations),
// with the error bar s_y / sqrt(m) on m - 1 degrees of freedom (iid over the pairs). Both points
// of a pair have the proposal's density, so each y_i is unbiased; when w is monotone in each
// coordinate, w(u) and w(1 - u) are negatively correlated and Var(y) <= Var(w) / 2: N antithetic
// evaluations beat N independent ones [Owen13, 8.2]. The weight accumulator sees the pair means,
// so its diagnostics (largest weights, tail, effective sample size) are of the pairs.
#include <algorithm>
#include <limits>

#include "estimators/estimator_kind.h"

namespace mcp {
namespace {

constexpr size_t kPairsPerBlock = kBlockSize / 2;

class AntitheticEstimator final : public EstimatorAlgorithm {
  public:
    AntitheticEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec), float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& rng) override {
        pairs_ = std::max<uint64_t>(n / 2, 1);
        plan_ = make_sampler_plan(SamplerKind::Independent, problem_.domain.sample_dim(), pairs_,
                                  rng, {});
        accumulator_.reset(ErrorMethod::Iid, plan_, float32_);
        ones_.assign(kPairsPerBlock, 1.0);
        means_.assign(kPairsPerBlock, 0.0);
        units_.assign(kPairsPerBlock, 0.0);
        next_ = 0;
        prepared_ = false;
    }

    bool run_block(Pcg32& /*rng*/, Workspace& ws) override {
        if (next_ >= pairs_) return false;
        if (!prepared_) {
            prepare_workspace(problem_.domain, ws);
            prepared_ = true;
        }
        const size_t m = static_cast<size_t>(std::min<uint64_t>(kPairsPerBlock, pairs_ - next_));
        // u_i into the first m slots, then spread to u_i, 1 - u_i from the back, so that no
        // u_i is overwritten before it is read.
        generate_block(plan_, next_, m, ws.u);
        for (int j = 0; j < ws.u.dim; ++j) {
            double* c = ws.u.coord(j);
            for (size_t i = m; i-- > 0;) {
                const double v = c[i];
                c[2 * i] = v;
                c[2 * i + 1] = below_one(1.0 - v);
            }
        }
        ws.u.n = 2 * m;
        warp_block(spec_.proposal, problem_.domain, ws.u, ws.x, ws.pdf.data());
        evaluate_block(problem_.integrand, ws.x, ws.f.data());
        notify(block_of(ws, 2 * next_, 2 * m));
        // A point with p = 0 and f != 0 makes its pair's mean infinite: the accumulator drops
        // the pair and counts it as non-finite (p = 0 with f = 0 weighs 0, as everywhere).
        const double inf = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < m; ++i) {
            const double p0 = ws.pdf[2 * i], p1 = ws.pdf[2 * i + 1];
            const double f0 = ws.f[2 * i], f1 = ws.f[2 * i + 1];
            const double w0 = p0 > 0.0 ? f0 / p0 : (f0 == 0.0 ? 0.0 : inf);
            const double w1 = p1 > 0.0 ? f1 / p1 : (f1 == 0.0 ? 0.0 : inf);
            means_[i] = 0.5 * (w0 + w1);
        }
        accumulator_.add_block(next_, means_.data(), ones_.data(), units_.data(), m);
        next_ += m;
        return true;
    }

    RunResult result() const override {
        RunResult r = accumulator_.finish(quantity_scale(problem_));
        r.n = 2 * pairs_;
        return r;
    }

  private:
    const Problem& problem_;
    const EstimatorSpec& spec_;
    bool float32_;
    uint64_t pairs_ = 0, next_ = 0;
    bool prepared_ = false;
    SamplerPlan plan_; // the run's points
    WeightAccumulator accumulator_;
    std::vector<double> ones_, means_, units_; // per block: p = 1, the pair means, their weights
};

} // namespace

const EstimatorKind& antithetic_estimator_kind() {
    static const EstimatorKind kind{
        "antithetic",
        "antithetic pairs u and 1 - u: the mean of each pair's f/p, independent over the pairs",
        [](const EstimatorSpec&) { return "antithetic"; },
        [](const EstimatorSpec&) { return ErrorMethod::Iid; }, // iid over the pairs
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<AntitheticEstimator>(problem, spec, accumulator);
        },
        // Pairs: the first k points' mean is the estimate at even k, but the independent
        // points' error bar is not its error.
        [](const EstimatorSpec&) { return false; },
        false,
    };
    return kind;
}

} // namespace mcp
