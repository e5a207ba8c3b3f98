// The weight accumulator: everything a run learns from its weights w = f/p, gathered block by
// block in one pass and merged exactly across threads: Welford/Chan moments with a compensated
// sum [Welford62, Chan79, Neumaier74], the sum of |w|, the largest |w| (tail index), counts of
// non-finite and zero-pdf samples, the squared differences of neighbouring or paired strata
// [Cochran77], the sums of each quasi-Monte Carlo randomization, and for the Walsh bound every
// weight (its transform needs all of them).
#pragma once

#include <cstdint>
#include <vector>

#include "core/samplers.h"
#include "core/stats.h"
#include "estimators/estimator.h"

namespace mcp {

class WeightAccumulator {
  public:
    /// Starts a run of `total` samples whose error bar is computed by `method`. For
    /// ErrorMethod::Randomizations they are `batches` independent randomizations, batch k the
    /// samples [total k / batches, total (k + 1) / batches): a sampler plan's batches
    /// (SamplerPlan::batch_begin), or an estimator's that draws its own points.
    void reset(ErrorMethod method, uint64_t total, size_t batches, bool float32_sum);
    /// reset for a run of a sampler plan's points and batches (its randomizers).
    void reset(ErrorMethod method, const SamplerPlan& plan, bool float32_sum) {
        reset(method, plan.total, plan.batches(), float32_sum);
    }

    /// Turns the values f and densities p of samples first .. first + count - 1 into weights
    /// w = f/p (w may alias p), drops (as 0) and counts the non-finite and zero-pdf ones, and
    /// accumulates the block. Blocks must come in order, starting at an even index.
    void add_block(uint64_t first, const double* f, const double* p, double* w, size_t count);

    /// Appends the accumulator of the samples that follow this one's (threads that split one
    /// run). Counts, sums and the top weights merge exactly; moments by Chan's formula.
    void merge(const WeightAccumulator& later);

    /// The run's estimate (times `scale`), its standard error and degrees of freedom, and the
    /// sample diagnostics. `top` receives the largest |w|, decreasing.
    RunResult finish(double scale) const;

    uint64_t count() const { return moments_.count(); }

  private:
    /// Candidates top_ gathers before keep_top selects the kTailWeights largest.
    static constexpr size_t kTopCandidates = 4 * kTailWeights;
    void keep_top();
    uint64_t batch_begin(size_t k) const { return total_ * k / batch_sums_.size(); }

    ErrorMethod method_ = ErrorMethod::Iid;
    uint64_t total_ = 0;
    bool float32_ = false;
    RunningMoments moments_;
    NeumaierSum abs_sum_, diff_sq_sum_;
    float float_sum_ = 0.0f; ///< float32 teaching mode only
    double max_abs_ = 0.0;
    uint64_t diffs_ = 0, nonzero_ = 0;
    double first_w_ = 0.0, last_w_ = 0.0; ///< for the difference across a merge
    RunDiagnostics diagnostics_;
    std::vector<double> top_; ///< candidates for the kTailWeights largest |w|
    double top_threshold_ = -1.0;
    std::vector<NeumaierSum> batch_sums_; ///< quasi-Monte Carlo: sum of w per randomization
    std::vector<double> walsh_values_;    ///< WalshBound: every weight, in the run's order
};

} // namespace mcp
