// Resampled importance sampling [Talbot05]: each of the N points is chosen among M candidates
// x_1..x_M drawn from the proposal (source) density p, candidate j kept with probability
// w_j / W, w_j = g(x_j) / p(x_j), W = sum_j w_j, for a target g; the point y's unit is
//   Y = f(y) / g(y) * W / M,
// and I = (1/N) sum Y_i with the error bar s_Y / sqrt(N) on N - 1 degrees of freedom (iid over
// the N points). E[Y] = (1/M) sum_j E[w_j f(x_j) / g(x_j)] = the integral of f over {g > 0}
// [Talbot05]: unbiased when g > 0 wherever f != 0, whatever M. M = 1 is importance sampling
// with p (Y = f/p); as M grows y approaches a draw from g / int g, so Y's variance falls towards
// that of importance sampling with g while a point costs M candidates. g is the estimator's pdf
// (a cheap proxy of |f|: M density evaluations and one f per point) or |f| itself (M calls of f
// per point: then Y = sign f(y) * mean |f|/p, plain importance sampling with M N calls).
// Where g misses f (every candidate at g = 0), one candidate is drawn uniformly and its f is
// evaluated: f != 0 there counts as a zero-pdf sample (the support check's flag) and weighs 0,
// as its Y does.
#include <algorithm>
#include <cmath>
#include <limits>

#include "estimators/estimator_kind.h"

namespace mcp {
namespace {

class RisEstimator final : public EstimatorAlgorithm {
  public:
    RisEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), options_(spec.ris_options), source_(spec.proposal),
          m_(static_cast<size_t>(
              std::clamp(spec.ris_options.candidates, 1, RisOptions::kMaxCandidates))),
          float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& rng) override {
        total_ = n;
        // Candidates i M .. i M + M - 1 are point i's; the plan is drawn first, so that M = 1
        // takes the importance sampler's very points from the same rng.
        plan_ = make_sampler_plan(SamplerKind::Independent, problem_.domain.sample_dim(), n * m_,
                                  rng, {});
        const uint64_t seed = rng.next_u32() | (uint64_t(rng.next_u32()) << 32);
        pick_ = Pcg32(seed, 0x726973); // "ris": the resampling's draws
        accumulator_.reset(ErrorMethod::Iid, plan_, float32_);
        picked_u_.reset(problem_.domain.sample_dim(), kBlockSize);
        picked_x_.reset(problem_.domain.point_dim(), kBlockSize);
        for (std::vector<double>* v : {&g_, &f_, &density_, &weight_}) v->assign(kBlockSize, 0.0);
        picked_.assign(kBlockSize, 0);
        next_ = 0;
    }

    bool run_block(Pcg32& /*rng*/, Workspace& ws) override {
        if (next_ >= total_) return false;
        if (next_ == 0) prepare_workspace(problem_.domain, ws);
        const size_t points =
            static_cast<size_t>(std::min<uint64_t>(kBlockSize / m_, total_ - next_));
        const size_t count = points * m_;
        generate_block(plan_, next_ * m_, count, ws.u);
        warp_block(source_, problem_.domain, ws.u, ws.x, ws.pdf.data());
        if (options_.target_pdf) {
            proposal_pdf_block(options_.target, problem_.domain, ws.x, g_.data());
        } else {
            evaluate_block(problem_.integrand, ws.x, ws.f.data());
            for (size_t i = 0; i < count; ++i) g_[i] = std::fabs(ws.f[i]);
        }
        for (size_t k = 0; k < points; ++k) resample(k, ws);
        picked_u_.n = picked_x_.n = points;
        for (size_t k = 0; k < points; ++k) {
            for (int j = 0; j < ws.u.dim; ++j) picked_u_.coord(j)[k] = ws.u.coord(j)[picked_[k]];
            for (int j = 0; j < ws.x.dim; ++j) picked_x_.coord(j)[k] = ws.x.coord(j)[picked_[k]];
        }
        if (options_.target_pdf) {
            evaluate_block(problem_.integrand, picked_x_, f_.data());
        } else {
            for (size_t k = 0; k < points; ++k) f_[k] = ws.f[picked_[k]];
        }
        for (size_t k = 0; k < points; ++k)
            if (std::isnan(density_[k])) f_[k] = density_[k]; // a NaN target: Y is NaN
        // Seen as a sample of density f / Y: its weight is its Y.
        notify(SampleBlock{next_, points, &picked_u_, &picked_x_, density_.data(), f_.data()});
        accumulator_.add_block(next_, f_.data(), density_.data(), weight_.data(), points);
        next_ += points;
        return true;
    }

    RunResult result() const override {
        RunResult r = accumulator_.finish(quantity_scale(problem_));
        r.n = total_; // points; each cost M candidates
        return r;
    }

  private:
    /// Picks point k's candidate (picked_[k], an index into the block) with probability
    /// w_j / W and sets density_[k] = f / Y's denominator p(y) M w_y / W (0 when every w_j is 0,
    /// NaN when W is not finite).
    void resample(size_t k, const Workspace& ws) {
        const size_t base = k * m_;
        double cumulative[RisOptions::kMaxCandidates];
        double sum = 0.0;
        for (size_t j = 0; j < m_; ++j) {
            const double p = ws.pdf[base + j];
            sum += p > 0.0 ? g_[base + j] / p : 0.0;
            cumulative[j] = sum;
        }
        const double u = pick_.next_double();
        if (!std::isfinite(sum)) {
            picked_[k] = base;
            density_[k] = std::numeric_limits<double>::quiet_NaN();
            return;
        }
        if (!(sum > 0.0)) { // g = 0 at every candidate: look at one of them
            picked_[k] = base + std::min(m_ - 1, static_cast<size_t>(u * static_cast<double>(m_)));
            density_[k] = 0.0;
            return;
        }
        const double t = u * sum;
        size_t j = 0;
        while (j + 1 < m_ && !(cumulative[j] > t)) ++j;
        while (j > 0 && cumulative[j] == cumulative[j - 1]) --j; // round-off: keep w_j > 0
        const double w = cumulative[j] - (j ? cumulative[j - 1] : 0.0);
        picked_[k] = base + j;
        // p M w / W: exactly p at M = 1 (w / W = 1), so that Y = f / p there.
        density_[k] = ws.pdf[base + j] * (static_cast<double>(m_) * w / sum);
    }

    const Problem& problem_;
    const RisOptions& options_;
    const Proposal& source_;
    size_t m_;
    bool float32_;
    uint64_t total_ = 0, next_ = 0;
    SamplerPlan plan_; // outlives the accumulator's use of it
    Pcg32 pick_;
    WeightAccumulator accumulator_;
    PointBlock picked_u_, picked_x_;
    std::vector<double> g_, f_, density_, weight_;
    std::vector<size_t> picked_;
};

} // namespace

const EstimatorKind& ris_estimator_kind() {
    static const EstimatorKind kind{
        "ris",
        "resampled importance sampling: M candidates per point, one kept in proportion to a "
        "target g over their density, weighted f/g times their mean g/p",
        [](const EstimatorSpec&) { return "ris"; },
        [](const EstimatorSpec&) { return ErrorMethod::Iid; }, // iid over the N points
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<RisEstimator>(problem, spec, accumulator);
        },
        // Independent points, each seen at the density f / Y: the first k points' mean is the
        // estimate at N = k.
        [](const EstimatorSpec&) { return true; },
        false,
    };
    return kind;
}

} // namespace mcp
