// MISER recursive stratified sampling [PressFarrar90]: a region with enough calls left is
// probed with a share of them, cut in two along the axis whose halves' spreads sigma_a, sigma_b
// make sigma_a^(2/(1+alpha)) + sigma_b^(2/(1+alpha)) smallest, and the rest of its calls go to
// the halves in proportion to those powers; a region with few calls is plain Monte Carlo. The
// probes are not in the estimate (they only decide the cuts), so given the cuts each leaf is an
// independent plain estimate:
//   I = sum_leaves V_l mean_l(w),   var(I) = sum_leaves V_l^2 s_l^2 / n_l.
// MISER runs on the unit cube of the sampler, before the pdf's warp: w = f / p of the warped
// point, so any domain and pdf works.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/stats.h"
#include "estimators/estimator_kind.h"
#include "estimators/miser.h"

namespace mcp {
namespace {

class MiserEstimator final : public EstimatorAlgorithm {
  public:
    MiserEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec), float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& rng) override {
        dim_ = problem_.domain.sample_dim();
        const MiserOptions& o = spec_.miser_options;
        min_calls_ = o.min_calls > 0 ? o.min_calls : 16 * static_cast<uint64_t>(dim_);
        // A cut leaves both halves min_calls after the probes: at least 4 min_calls to cut.
        min_bisect_ =
            std::max(4 * min_calls_,
                     o.min_calls_per_bisection > 0 ? o.min_calls_per_bisection : 32 * min_calls_);
        total_ = n;
        const uint64_t seed = (uint64_t(rng.next_u32()) << 32) | rng.next_u32();
        const uint64_t stream = (uint64_t(rng.next_u32()) << 32) | rng.next_u32();
        points_ = Pcg32(seed, stream);
        done_ = false;
        view_ = AdaptiveView();
    }

    bool run_block(Pcg32& /*rng*/, Workspace& ws) override {
        if (done_) return false;
        prepare_workspace(problem_.domain, ws);
        ws_ = &ws;
        plan_ = SamplerPlan(); // the accumulator's iid error method reads no plan data
        plan_.dim = dim_;
        plan_.total = total_;
        accumulator_.reset(ErrorMethod::Iid, plan_, float32_);
        strata_ = StratifiedSum();
        accumulated_ = 0;
        probed_n_ = 0;
        probe_seconds_ = 0.0;
        // Depth first: a region is probed and cut, or sampled as a leaf, before the next.
        region(std::vector<double>(static_cast<size_t>(dim_), 0.0),
               std::vector<double>(static_cast<size_t>(dim_), 1.0), total_, 0);
        const double unit = quantity_scale(problem_);
        result_ = accumulator_.finish(unit);
        result_.estimate = unit * strata_.estimate();
        result_.std_error = strata_.has_variance() ? unit * std::sqrt(strata_.variance())
                                                   : std::numeric_limits<double>::quiet_NaN();
        result_.dof = strata_.dof();
        done_ = true;
        return true;
    }

    RunResult result() const override {
        RunResult r = result_;
        r.n = total_;
        r.training_n = probed_n_;
        r.training_seconds = probe_seconds_;
        return r;
    }

    AdaptiveView adaptive_view() const override { return view_; }

    /// Records the leaves (at most `limit`) of the runs that follow.
    void record_leaves(std::vector<MiserBox>* out, size_t limit) {
        recorded_ = out;
        record_limit_ = limit;
    }

  private:
    /// Points uniform in the box [lo, hi) of the unit cube, n of them in blocks: warped,
    /// evaluated, and handed to consume(block, weights) with the weights f / p (dropped as 0
    /// where not finite, as the weight accumulator drops them).
    template <class Consume>
    void sample_box(const std::vector<double>& lo, const std::vector<double>& hi, uint64_t n,
                    Consume&& consume) {
        Workspace& ws = *ws_;
        double w[kBlockSize];
        for (uint64_t done = 0; done < n; done += kBlockSize) {
            const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, n - done));
            ws.u.n = count;
            for (size_t i = 0; i < count; ++i)
                for (int j = 0; j < dim_; ++j)
                    ws.u.coord(j)[i] = below_one(lo[j] + (hi[j] - lo[j]) * points_.next_double());
            warp_block(spec_.proposal, problem_.domain, ws.u, ws.x, ws.pdf.data());
            evaluate_block(problem_.integrand, ws.x, ws.f.data());
            for (size_t i = 0; i < count; ++i) {
                const double wi = ws.f[i] / ws.pdf[i];
                w[i] = std::isfinite(wi) && !(ws.pdf[i] == 0.0 && ws.f[i] != 0.0) ? wi : 0.0;
            }
            const SampleBlock b = block_of(ws, done, count);
            consume(b, static_cast<const double*>(w));
        }
    }

    /// A leaf: n plain Monte Carlo points in [lo, hi) of volume V, added to the estimate
    /// (V mean(w)) and its variance (V^2 s^2 / n).
    void leaf(const std::vector<double>& lo, const std::vector<double>& hi, double volume,
              uint64_t n) {
        if (n == 0) return;
        if (recorded_ && recorded_->size() < record_limit_) recorded_->push_back({lo, hi, n});
        RunningMoments m;
        // Weights scaled by V N / n for the accumulator, which keeps the diagnostics (dropped
        // samples, the largest weights, the effective sample size: all scale-free).
        const double scale = volume * static_cast<double>(total_) / static_cast<double>(n);
        if (observer_ && view_.box_lo.size() < kViewBoxes) {
            view_.box_lo.push_back(lo);
            view_.box_hi.push_back(hi);
        }
        sample_box(lo, hi, n, [&](const SampleBlock& b, const double* w) {
            m.add_block(w, b.count);
            if (observer_) {
                SampleBlock seen = b;
                seen.first = accumulated_;
                notify(seen);
            }
            for (size_t i = 0; i < b.count; ++i) b.pdf[i] /= scale;
            accumulator_.add_block(accumulated_, b.f, b.pdf, b.pdf, b.count);
            accumulated_ += b.count;
        });
        strata_.add(volume, m);
    }

    /// The region [lo, hi) with n calls: a leaf, or probed, cut and recursed into.
    void region(std::vector<double> lo, std::vector<double> hi, uint64_t n, int depth) {
        double volume = 1.0;
        for (int j = 0; j < dim_; ++j) volume *= hi[j] - lo[j];
        // Few calls (or a depth no double box can be cut to): plain Monte Carlo.
        if (n < min_bisect_ || depth >= kMaxDepth) {
            leaf(lo, hi, volume, n);
            return;
        }
        const MiserOptions& o = spec_.miser_options;
        const uint64_t probes = std::max<uint64_t>(
            min_calls_, static_cast<uint64_t>(o.estimate_fraction * static_cast<double>(n)));
        // The cut: the middle, moved by +-dither of the width (one random sign per region).
        const double cut = 0.5 + (points_.next_u32() & 1u ? o.dither : -o.dither);
        std::vector<double> mid(static_cast<size_t>(dim_));
        for (int j = 0; j < dim_; ++j) mid[j] = lo[j] + cut * (hi[j] - lo[j]);
        // Spread of the weights on each side of each axis's cut, from the probes (shifted by
        // the first weight against cancellation).
        std::vector<RunningMoments> below(static_cast<size_t>(dim_)),
            above(static_cast<size_t>(dim_));
        const double probe_start = clock_seconds();
        sample_box(lo, hi, probes, [&](const SampleBlock& b, const double* w) {
            for (int j = 0; j < dim_; ++j) {
                const double* u = b.u->coord(j);
                for (size_t i = 0; i < b.count; ++i)
                    (u[i] < mid[j] ? below[j] : above[j]).add(w[i]);
            }
        });
        probe_seconds_ += clock_seconds() - probe_start;
        probed_n_ += probes;
        const double power = 2.0 / (1.0 + o.alpha);
        int axis = -1;
        double best = std::numeric_limits<double>::infinity(), share_below = 0.5;
        for (int j = 0; j < dim_; ++j) {
            if (below[j].count() < 2 || above[j].count() < 2) continue;
            const double a = std::pow(std::sqrt(below[j].variance()), power);
            const double b = std::pow(std::sqrt(above[j].variance()), power);
            if (a + b < best) {
                best = a + b;
                axis = j;
                share_below = a + b > 0.0 ? a / (a + b) : 0.5;
            }
        }
        if (axis < 0) { // no axis had two probes on each side: a random one, calls halved
            axis = static_cast<int>(points_.next_u32() % static_cast<uint32_t>(dim_));
            share_below = 0.5;
        }
        const uint64_t rest = n - probes;
        uint64_t n_below = static_cast<uint64_t>(share_below * static_cast<double>(rest));
        n_below = std::min(std::max(n_below, min_calls_), rest - min_calls_);
        std::vector<double> lo_above = lo, hi_below = hi;
        hi_below[axis] = mid[axis];
        lo_above[axis] = mid[axis];
        region(lo, hi_below, n_below, depth + 1);
        region(lo_above, hi, rest - n_below, depth + 1);
    }

    static constexpr int kMaxDepth = 200;
    static constexpr size_t kViewBoxes = 4096;

    const Problem& problem_;
    const EstimatorSpec& spec_;
    bool float32_;
    int dim_ = 1;
    uint64_t min_calls_ = 16, min_bisect_ = 512, total_ = 0;
    bool done_ = false;
    Pcg32 points_;
    Workspace* ws_ = nullptr;
    std::vector<MiserBox>* recorded_ = nullptr;
    AdaptiveView view_; // the leaves, when observed
    size_t record_limit_ = 0;
    StratifiedSum strata_;
    uint64_t accumulated_ = 0, probed_n_ = 0;
    double probe_seconds_ = 0.0;
    SamplerPlan plan_; // the run's points
    WeightAccumulator accumulator_;
    RunResult result_;
};

} // namespace

std::vector<MiserBox> miser_leaves(const Problem& problem, const EstimatorSpec& spec, uint64_t n,
                                   Pcg32& rng, size_t limit) {
    std::vector<MiserBox> leaves;
    MiserEstimator miser(problem, spec, Accumulator::Compensated);
    miser.record_leaves(&leaves, limit);
    Workspace ws;
    miser.begin(n, rng);
    while (miser.run_block(rng, ws)) {
    }
    return leaves;
}

const EstimatorKind& miser_estimator_kind() {
    static const EstimatorKind kind{
        "miser",
        "MISER: recursive bisection of the unit cube, calls to the halves by their spread",
        [](const EstimatorSpec&) { return "miser"; },
        // the sum of independent parts: the leaves
        [](const EstimatorSpec&) { return ErrorMethod::PartsSum; },
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<MiserEstimator>(problem, spec, accumulator);
        },
        [](const EstimatorSpec&) { return false; }, // points in regions cut by the run itself
        true,
    };
    return kind;
}

} // namespace mcp
