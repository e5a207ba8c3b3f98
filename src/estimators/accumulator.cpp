#include "estimators/accumulator.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "core/special.h"
#include "core/walsh_bound.h"

namespace mcp {

namespace {
// Degrees of freedom of an error bar, capped where Student's t is the normal to 1e-6.
int interval_dof(uint64_t dof) {
    return static_cast<int>(std::min<uint64_t>(dof, 1000000));
}
} // namespace

void WeightAccumulator::reset(ErrorMethod method, uint64_t total, size_t batches,
                              bool float32_sum) {
    method_ = method;
    total_ = total;
    float32_ = float32_sum;
    moments_ = RunningMoments();
    abs_sum_ = diff_sq_sum_ = NeumaierSum();
    float_sum_ = 0.0f;
    max_abs_ = 0.0;
    diffs_ = nonzero_ = 0;
    first_w_ = last_w_ = 0.0;
    diagnostics_ = RunDiagnostics();
    top_.clear();
    top_.reserve(kTopCandidates + kBlockSize);
    top_threshold_ = -1.0;
    batch_sums_.assign(batches, NeumaierSum());
    walsh_values_.clear();
    if (method == ErrorMethod::WalshBound) walsh_values_.reserve(total);
}

void WeightAccumulator::keep_top() {
    // Keep the kTailWeights largest: an O(n) selection per block instead of a heap update per
    // sample (an increasing integrand would otherwise replace a heap's root every time).
    if (top_.size() <= kTailWeights) return;
    std::nth_element(top_.begin(), top_.begin() + static_cast<long>(kTailWeights) - 1, top_.end(),
                     std::greater<double>());
    top_.resize(kTailWeights);
    top_threshold_ = top_[kTailWeights - 1];
}

void WeightAccumulator::add_block(uint64_t first, const double* f, const double* p, double* w,
                                  size_t count) {
    if (count == 0) return;
    // One branch-free pass: the weights, sum |w|, max |w|, the non-zero count, and whether any
    // weight needs the slow path (not finite, or p not > 0). Where w aliases p (the fixed and
    // MIS estimators) the pass writes no weight, and a second one does when no sample is bad:
    // the slow path classifies a bad sample by its p (an overwritten p once made every f = inf
    // a "zero pdf" sample, and a run of them all an estimate of 0).
    const bool aliased = w == p;
    double block_abs = 0.0, block_max = 0.0;
    uint64_t block_nonzero = 0, suspicious = 0;
    if (aliased) {
        for (size_t i = 0; i < count; ++i) {
            const double a = std::fabs(f[i] / p[i]);
            suspicious += !(a <= std::numeric_limits<double>::max()) | !(p[i] > 0.0);
            block_abs += a;
            block_max = a > block_max ? a : block_max;
            block_nonzero += a != 0.0;
        }
        if (!suspicious)
            for (size_t i = 0; i < count; ++i) w[i] = f[i] / p[i];
    } else {
        for (size_t i = 0; i < count; ++i) {
            const double wi = f[i] / p[i];
            const double a = std::fabs(wi);
            suspicious += !(a <= std::numeric_limits<double>::max()) | !(p[i] > 0.0);
            w[i] = wi;
            block_abs += a;
            block_max = a > block_max ? a : block_max;
            block_nonzero += a != 0.0;
        }
    }
    if (suspicious) {
        // Rare path: classify, count and drop (contribute 0) the bad samples, then redo the sums.
        block_abs = block_max = 0.0;
        block_nonzero = 0;
        for (size_t i = 0; i < count; ++i) {
            const double fi = f[i], pi = p[i];
            double wi = fi / pi;
            if (!std::isfinite(wi) || !(pi > 0.0)) {
                if (pi > 0.0 && std::isfinite(pi))
                    ++diagnostics_.nonfinite; // f/p overflow, f NaN/Inf
                else if (fi == 0.0) {
                } // 0/0: no mass either side
                else if (!std::isfinite(fi) || std::isnan(pi))
                    ++diagnostics_.nonfinite; // f itself NaN/Inf, whatever p
                else
                    ++diagnostics_.zero_pdf; // f != 0 where p = 0
                wi = 0.0;
            }
            w[i] = wi;
            const double a = std::fabs(wi);
            block_abs += a;
            block_max = std::fmax(block_max, a);
            block_nonzero += a != 0.0;
        }
    }
    if (moments_.count() == 0) first_w_ = w[0];
    moments_.add_block(w, count);
    if (float32_)
        for (size_t i = 0; i < count; ++i) float_sum_ += static_cast<float>(w[i]);
    max_abs_ = std::fmax(max_abs_, block_max);
    nonzero_ += block_nonzero;
    abs_sum_.add(block_abs);
    // Candidates for the top weights: only values above the current threshold (rare once the
    // run is under way), found in a separate pass the compiler can keep branch-light.
    // The selection waits until kTopCandidates have gathered: the threshold only rises, so
    // the kTailWeights largest are among the candidates kept (finish sorts and cuts them).
    // Selecting at every block that beat the threshold cost VEGAS+ 6% of its run on power
    // singularities, whose large weights keep coming.
    if (block_max > top_threshold_) {
        for (size_t i = 0; i < count; ++i)
            if (std::fabs(w[i]) > top_threshold_) top_.push_back(std::fabs(w[i]));
        if (top_.size() >= kTopCandidates) keep_top();
    }

    switch (method_) {
    case ErrorMethod::Randomizations: {
        // Sum each randomization's weights apart (a block may span several batches).
        const size_t batches = batch_sums_.size();
        size_t batch = static_cast<size_t>(first * batches / total_);
        size_t i = 0;
        while (i < count) {
            while (batch_begin(batch + 1) <= first + i) ++batch;
            const size_t end =
                static_cast<size_t>(std::min<uint64_t>(count, batch_begin(batch + 1) - first));
            double part = 0.0;
            for (; i < end; ++i) part += w[i];
            batch_sums_[batch].add(part);
        }
        break;
    }
    case ErrorMethod::PairedStrata: {
        // Two points per cell: pairs (2m, 2m+1) share a cell; blocks start at even indices,
        // so a pair never straddles two blocks.
        double pairs = 0.0;
        for (size_t i = 0; i + 1 < count; i += 2) pairs += (w[i] - w[i + 1]) * (w[i] - w[i + 1]);
        diff_sq_sum_.add(pairs);
        diffs_ += count / 2;
        break;
    }
    case ErrorMethod::CollapsedStrata: {
        // Successive differences of neighbouring cells, across block boundaries too.
        double d2 = 0.0;
        if (first > 0) d2 = (w[0] - last_w_) * (w[0] - last_w_);
        for (size_t i = 1; i < count; ++i) d2 += (w[i] - w[i - 1]) * (w[i] - w[i - 1]);
        diff_sq_sum_.add(d2);
        diffs_ += first == 0 ? count - 1 : count;
        break;
    }
    case ErrorMethod::WalshBound: walsh_values_.insert(walsh_values_.end(), w, w + count); break;
    case ErrorMethod::Iid:
    case ErrorMethod::IidConservative:
    case ErrorMethod::PartsSum:
    case ErrorMethod::Regression:
    case ErrorMethod::None: break;
    }
    last_w_ = w[count - 1];
}

void WeightAccumulator::merge(const WeightAccumulator& later) {
    if (later.moments_.count() == 0) return;
    if (moments_.count() == 0) {
        *this = later;
        return;
    }
    if (method_ == ErrorMethod::CollapsedStrata) {
        // The one difference that straddles the two parts.
        diff_sq_sum_.add((later.first_w_ - last_w_) * (later.first_w_ - last_w_));
        ++diffs_;
    }
    moments_.merge(later.moments_);
    abs_sum_.add(later.abs_sum_.value());
    diff_sq_sum_.add(later.diff_sq_sum_.value());
    float_sum_ += later.float_sum_;
    max_abs_ = std::fmax(max_abs_, later.max_abs_);
    diffs_ += later.diffs_;
    nonzero_ += later.nonzero_;
    last_w_ = later.last_w_;
    diagnostics_.nonfinite += later.diagnostics_.nonfinite;
    diagnostics_.zero_pdf += later.diagnostics_.zero_pdf;
    top_.insert(top_.end(), later.top_.begin(), later.top_.end());
    keep_top();
    for (size_t k = 0; k < batch_sums_.size() && k < later.batch_sums_.size(); ++k)
        batch_sums_[k].add(later.batch_sums_[k].value());
    walsh_values_.insert(walsh_values_.end(), later.walsh_values_.begin(),
                         later.walsh_values_.end());
}

RunResult WeightAccumulator::finish(double scale) const {
    RunResult result;
    const uint64_t n = moments_.count();
    result.n = n;
    const double nd = static_cast<double>(n);
    double mean = float32_ ? static_cast<double>(float_sum_) / nd : moments_.mean();
    double variance_of_mean = std::numeric_limits<double>::quiet_NaN();
    RunningMoments units = moments_; // what the error bar is the spread of
    switch (method_) {
    case ErrorMethod::CollapsedStrata:
    case ErrorMethod::PairedStrata:
        // E[(w_a - w_b)^2] = s_a^2 + s_b^2 + (m_a - m_b)^2: exactly s_a^2 + s_b^2 when a and b
        // share a cell (paired strata, unbiased), an upper bound for neighbouring cells
        // (collapsed strata, conservative; all N-1 successive differences are used, so one
        // unlucky pair cannot make the error bar 0 [Cochran77, 5A.12; vonNeumann41]).
        // Either way Var[I_N] ~ sum d^2 / (2 count N).
        if (diffs_ > 0) {
            variance_of_mean = diff_sq_sum_.value() / (2.0 * static_cast<double>(diffs_)) / nd;
            result.dof = interval_dof(diffs_);
        }
        break;
    case ErrorMethod::Iid:
    case ErrorMethod::IidConservative:
    case ErrorMethod::PartsSum:   // the estimator replaces this by its parts' sum
    case ErrorMethod::Regression: // and this by its residuals'
        if (n > 1) {
            variance_of_mean = moments_.variance() / nd;
            result.dof = interval_dof(n - 1);
        }
        break;
    case ErrorMethod::Randomizations: {
        // K independent randomizations give K independent, unbiased batch means b_k: the run's
        // estimate is their mean and its variance s_b^2 / K, with K - 1 degrees of freedom
        // [LEcuyerLemieux02]. (Equal batches when K divides N: then this is the overall mean.)
        RunningMoments batch_means;
        const size_t batches = batch_sums_.size();
        for (size_t k = 0; k < batches; ++k) {
            const double size = static_cast<double>(batch_begin(k + 1) - batch_begin(k));
            batch_means.add(batch_sums_[k].value() / size);
        }
        if (!float32_) mean = batch_means.mean();
        units = batch_means;
        if (batches > 1) {
            variance_of_mean = batch_means.variance() / static_cast<double>(batches);
            result.dof = interval_dof(batches - 1);
        }
        break;
    }
    case ErrorMethod::WalshBound: {
        // The run's N = 2^m weights are one Sobol' sequence in Gray-code order; the transform
        // wants the net's natural order.
        const uint64_t size = walsh_values_.size();
        if (size == n && (size & (size - 1)) == 0 && size >= (uint64_t(1) << kWalshMinLog2) &&
            size <= (uint64_t(1) << kWalshMaxLog2)) {
            std::vector<double> natural(size);
            for (uint64_t i = 0; i < size; ++i) natural[gray_natural_index(i)] = walsh_values_[i];
            const double half_width = walsh_bound_of(natural).bound();
            variance_of_mean = std::pow(half_width / kNormal975, 2);
            result.dof = interval_dof(uint64_t(1) << 40); // the normal quantile: t = 1.96
        }
        break;
    }
    case ErrorMethod::None: break; // one deterministic point set: no error bar
    }
    result.estimate = mean * scale;
    result.std_error = std::sqrt(variance_of_mean) * scale;
    result.diagnostics = diagnostics_;
    if (n > 0 && diagnostics_.nonfinite == n) {
        // Every sample was NaN or infinite: the sum of the (all dropped) weights is not an
        // estimate of anything, so there is none (not 0 +/- 0).
        result.estimate = result.std_error = std::numeric_limits<double>::quiet_NaN();
    }
    const double total_abs = abs_sum_.value();
    result.diagnostics.max_weight_share = total_abs > 0.0 ? max_abs_ / total_abs : 0.0;
    result.diagnostics.nonzero = nonzero_;
    result.diagnostics.weights = moments_;
    result.diagnostics.error_units = units;
    result.diagnostics.batch_units = method_ == ErrorMethod::Randomizations;
    // Effective sample size [Kish65]: how many equal weights would carry the same information.
    const double sum_sq =
        moments_.sum_squared_deviations() + nd * moments_.mean() * moments_.mean();
    result.diagnostics.ess = sum_sq > 0.0 ? total_abs * total_abs / sum_sq : 0.0;
    result.top = top_;
    std::sort(result.top.begin(), result.top.end(), std::greater<double>());
    if (result.top.size() > kTailWeights) result.top.resize(kTailWeights);
    return result;
}

} // namespace mcp
