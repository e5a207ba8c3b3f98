// Numerically stable running statistics: compensated sums, Welford moments and a
// least-squares line fit with its uncertainty.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace mcp {

/// Neumaier's improved Kahan summation [Neumaier74]: the running compensation also
/// catches the case where the new term is larger than the running sum.
class NeumaierSum {
  public:
    void add(double x) {
        // Branch-free: the larger-magnitude term loses the low bits [Neumaier74].
        const double t = sum_ + x;
        const bool sum_larger = std::fabs(sum_) >= std::fabs(x);
        const double big = sum_larger ? sum_ : x, small = sum_larger ? x : sum_;
        comp_ += (big - t) + small;
        sum_ = t;
    }
    double value() const { return sum_ + comp_; }
    /// The running sum and its compensation, unrounded: value() is their rounded sum.
    double running_sum() const { return sum_; }
    double compensation() const { return comp_; }
    /// A sum carried between processes (study parts): the running sum and its compensation.
    static NeumaierSum from_parts(double running_sum, double compensation) {
        NeumaierSum s;
        s.sum_ = running_sum;
        s.comp_ = compensation;
        return s;
    }

  private:
    double sum_ = 0.0;
    double comp_ = 0.0;
};

/// One value's step of Welford's update [Welford62]: with `count` values counted (the new one
/// included) and the old mean, delta = x - mean, the mean's increment delta / n and the sum of
/// squared deviations' increment delta^2 (n - 1) / n.
struct WelfordStep {
    double delta_n, m2_increment;
    WelfordStep(double x, double mean, uint64_t count) {
        const double n = static_cast<double>(count), delta = x - mean;
        delta_n = delta / n;
        m2_increment = delta * delta_n * (n - 1.0);
    }
};

/// Running mean, variance and third central moment by Welford's update [Welford62] and its
/// extension to higher moments [Pebay08]; the mean is also kept as a compensated sum so that 1e9
/// and more terms lose no digits. Never E[x^2] - E[x]^2.
class RunningMoments {
  public:
    void add(double x) {
        ++n_;
        sum_.add(x);
        const WelfordStep s(x, mean_, n_);
        // Third moment first: it uses the old m2 [Pebay08, eq. 2.1 with one value].
        m3_ += s.m2_increment * s.delta_n * (static_cast<double>(n_) - 2.0) - 3.0 * s.delta_n * m2_;
        mean_ += s.delta_n;
        m2_ += s.m2_increment;
    }
    /// Adds a block of values: a compensated sum for the mean, a two-pass sum of squared
    /// deviations about the block mean, merged by Chan's formula (one division per block
    /// instead of one per value, and loops the compiler can vectorise).
    void add_block(const double* x, size_t n);
    /// Parallel combination of two sets of moments [Chan79, Pebay08].
    void merge(const RunningMoments& o);

    uint64_t count() const { return n_; }
    /// Compensated-sum mean (more accurate than the Welford running mean).
    double mean() const { return n_ ? sum_.value() / static_cast<double>(n_) : 0.0; }
    double sum() const { return sum_.value(); }
    /// Unbiased sample variance, 1/(n-1) sum (x - mean)^2.
    double variance() const { return n_ > 1 ? m2_ / static_cast<double>(n_ - 1) : 0.0; }
    double sum_squared_deviations() const { return m2_; }
    double sum_cubed_deviations() const { return m3_; }
    /// Sample skewness g1 = sqrt(n) m3 / m2^(3/2) (0 without spread beyond round-off).
    double skewness() const;

    /// The exact state, for carrying moments between processes (study parts) bit for bit.
    struct State {
        uint64_t n = 0;
        double sum = 0.0, compensation = 0.0, mean = 0.0, m2 = 0.0, m3 = 0.0;
    };
    State state() const { return {n_, sum_.running_sum(), sum_.compensation(), mean_, m2_, m3_}; }
    static RunningMoments from_state(const State& s) {
        RunningMoments m;
        m.n_ = s.n;
        m.sum_ = NeumaierSum::from_parts(s.sum, s.compensation);
        m.mean_ = s.mean;
        m.m2_ = s.m2;
        m.m3_ = s.m3;
        return m;
    }

  private:
    uint64_t n_ = 0;
    NeumaierSum sum_;
    double mean_ = 0.0;
    double m2_ = 0.0;
    double m3_ = 0.0; ///< sum of cubed deviations from the mean
};

/// A sum of independent estimates, as stratified sampling, MISER's leaves and multi-sample MIS
/// make: I = sum_h a_h mean_h with variance sum_h a_h^2 s_h^2 / n_h, and the degrees of freedom
/// of that variance estimate by Satterthwaite's approximation [Satterthwaite46]:
/// (sum_h v_h)^2 / sum_h v_h^2 / (n_h - 1).
class StratifiedSum {
  public:
    /// Adds a_h times the mean of the stratum's values m.
    void add(double a, const RunningMoments& m);
    /// Adds an estimate `value` whose variance estimate `variance` comes from `values` values
    /// (values - 1 degrees of freedom; fewer than 2: no variance estimate).
    void add_part(double value, double variance, uint64_t values);
    double estimate() const { return estimate_.value(); }
    double variance() const { return variance_.value() > 0.0 ? variance_.value() : 0.0; }
    /// Whether every stratum had two values or more (else there is no variance estimate).
    bool has_variance() const { return complete_; }
    /// Satterthwaite's degrees of freedom, capped at 10^6; when every variance is 0, the
    /// values' own count sum_h (n_h - 1).
    int dof() const;

  private:
    NeumaierSum estimate_, variance_;
    double satterthwaite_ = 0.0;
    uint64_t free_ = 0;
    bool complete_ = true;
};

/// Adds `points` to the counts in proportion to share[h] (shares >= 0 summing to 1): the whole
/// parts, then one more to the largest remainders until the total is exact, ties to the lower
/// index (a total order, so every standard library allocates alike).
void allocate_largest_remainders(uint64_t points, const std::vector<double>& share,
                                 std::vector<uint64_t>* counts);

/// Ordinary least squares y = intercept + slope * x.
struct LineFit {
    double slope = 0.0;
    double intercept = 0.0;
    double slope_se = 0.0; ///< from the residuals, s / sqrt(Sxx)
    double residual_variance = 0.0;
    double sxx = 0.0; ///< sum (x - mean x)^2
    int points = 0;
    /// Weighted fits: the sum of the squared residuals over their standard deviations,
    /// chi-square with points - 2 degrees of freedom when the line and the deviations are right;
    /// NaN for unit weights (no deviations to measure the residuals by).
    double chi2 = std::numeric_limits<double>::quiet_NaN();
};

/// Fits a line through (x[i], y[i]); needs at least two distinct x.
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

/// Weighted least squares through (x[i], y[i]) where y[i] has standard deviation sd[i] > 0
/// (weights 1 / sd^2). slope_se is the slope's standard error from those deviations, inflated
/// by sqrt(chi^2 / dof) when the residuals exceed them; residual_variance is chi^2 / dof, chi2
/// the chi^2 itself, and sxx the weighted sum of squares. With sd empty, or any sd not positive and
/// finite, it is fit_line (unit weights, slope_se from the residuals alone).
LineFit fit_weighted_line(const std::vector<double>& x, const std::vector<double>& y,
                          const std::vector<double>& sd);

/// The median of n values and its distribution-free confidence interval from order statistics
/// [DavidNagaraja03, 7.1]: [x_(j), x_(n+1-j)] covers the median with probability
/// 1 - 2 P(B < j), B ~ Binomial(n, 1/2); j is the largest with that at least `level`, or 1 (the
/// whole range, with its own lower level) when n is too small. Sorts `values`.
struct MedianInterval {
    double median = 0.0, lo = 0.0, hi = 0.0;
    double level = 0.0; ///< the interval's exact coverage
};
MedianInterval median_interval(std::vector<double>& values, double level = 0.95);

} // namespace mcp
