#include "core/stats.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

namespace mcp {

namespace {
// Moments (n, mean, m2, m3) of b merged into a: the pairwise update of Chan, Golub and LeVeque
// for m2 and Pebay's for m3 (the third moment first: it uses a's old m2) [Chan79, Pebay08].
void merge_moments(double& mean_a, double& m2_a, double& m3_a, double na, double mean_b,
                   double m2_b, double m3_b, double nb) {
    const double n = na + nb, delta = mean_b - mean_a;
    m3_a += m3_b + delta * delta * delta * na * nb * (na - nb) / (n * n) +
            3.0 * delta * (na * m2_b - nb * m2_a) / n;
    m2_a += m2_b + delta * delta * na * nb / n;
    mean_a += delta * nb / n;
}
} // namespace

void RunningMoments::add_block(const double* x, size_t n) {
    if (n == 0) return;
    double block_sum = 0.0;
    for (size_t i = 0; i < n; ++i) block_sum += x[i];
    const double block_mean = block_sum / static_cast<double>(n);
    double m2 = 0.0, m3 = 0.0, correction = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double d = x[i] - block_mean;
        const double d2 = d * d;
        m2 += d2;
        m3 += d2 * d;
        correction += d;
    }
    const double nb = static_cast<double>(n);
    // Corrected two-pass formulas: about the block's mean block_mean + c/n rather than the
    // rounded block_mean [Chan79, eq. 1.7]; for the cubes sum (d - c/n)^3 expanded.
    const double c_n = correction / nb;
    m3 += -3.0 * c_n * m2 + 2.0 * c_n * c_n * correction;
    m2 -= correction * c_n;
    for (size_t i = 0; i < n; ++i) sum_.add(x[i]);
    merge_moments(mean_, m2_, m3_, static_cast<double>(n_), block_mean + c_n, m2, m3, nb);
    n_ += n;
}

void RunningMoments::merge(const RunningMoments& o) {
    if (o.n_ == 0) return;
    if (n_ == 0) {
        *this = o;
        return;
    }
    merge_moments(mean_, m2_, m3_, static_cast<double>(n_), o.mean_, o.m2_, o.m3_,
                  static_cast<double>(o.n_));
    n_ += o.n_;
    sum_.add(o.sum_.value());
}

double RunningMoments::skewness() const {
    // Values that agree to round-off (their spread within 64 eps of the mean, as an exact
    // estimator's weights): the skewness of the rounding, which differs between platforms'
    // libm, means nothing.
    const double n = static_cast<double>(n_);
    const double roundoff = 64.0 * 2.220446049250313e-16 * std::fabs(mean_);
    if (n_ < 2 || !(m2_ > n * roundoff * roundoff)) return 0.0;
    return std::sqrt(n) * m3_ / (m2_ * std::sqrt(m2_));
}

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
    LineFit fit;
    size_t n = x.size();
    fit.points = static_cast<int>(n);
    if (n < 2 || y.size() != n) return fit;
    double mx = 0.0, my = 0.0;
    for (size_t i = 0; i < n; ++i) {
        mx += x[i];
        my += y[i];
    }
    mx /= static_cast<double>(n);
    my /= static_cast<double>(n);
    double sxx = 0.0, sxy = 0.0;
    for (size_t i = 0; i < n; ++i) {
        sxx += (x[i] - mx) * (x[i] - mx);
        sxy += (x[i] - mx) * (y[i] - my);
    }
    if (!(sxx > 0.0)) return fit;
    fit.sxx = sxx;
    fit.slope = sxy / sxx;
    fit.intercept = my - fit.slope * mx;
    if (n > 2) {
        double ss = 0.0;
        for (size_t i = 0; i < n; ++i) {
            double r = y[i] - (fit.intercept + fit.slope * x[i]);
            ss += r * r;
        }
        fit.residual_variance = ss / static_cast<double>(n - 2);
        fit.slope_se = std::sqrt(fit.residual_variance / sxx);
    }
    return fit;
}

LineFit fit_weighted_line(const std::vector<double>& x, const std::vector<double>& y,
                          const std::vector<double>& sd) {
    const size_t n = x.size();
    bool weighted = sd.size() == n && n > 0;
    for (size_t i = 0; weighted && i < n; ++i) weighted = sd[i] > 0.0 && std::isfinite(sd[i]);
    if (!weighted) return fit_line(x, y);
    LineFit fit;
    fit.points = static_cast<int>(n);
    if (n < 2 || y.size() != n) return fit;
    double sw = 0.0, mx = 0.0, my = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double w = 1.0 / (sd[i] * sd[i]);
        sw += w;
        mx += w * x[i];
        my += w * y[i];
    }
    mx /= sw;
    my /= sw;
    double sxx = 0.0, sxy = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double w = 1.0 / (sd[i] * sd[i]);
        sxx += w * (x[i] - mx) * (x[i] - mx);
        sxy += w * (x[i] - mx) * (y[i] - my);
    }
    if (!(sxx > 0.0)) return fit;
    fit.sxx = sxx;
    fit.slope = sxy / sxx;
    fit.intercept = my - fit.slope * mx;
    double chi2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double r = (y[i] - (fit.intercept + fit.slope * x[i])) / sd[i];
        chi2 += r * r;
    }
    fit.chi2 = chi2;
    fit.residual_variance = n > 2 ? chi2 / static_cast<double>(n - 2) : 0.0;
    fit.slope_se = std::sqrt(std::max(1.0, fit.residual_variance) / sxx);
    return fit;
}

void StratifiedSum::add(double a, const RunningMoments& m) {
    const uint64_t n = m.count();
    if (n == 0) return;
    estimate_.add(a * m.mean());
    complete_ = complete_ && n > 1;
    if (n < 2) return;
    const double v = a * a * m.variance() / static_cast<double>(n);
    variance_.add(v);
    satterthwaite_ += v * v / static_cast<double>(n - 1);
    free_ += n - 1;
}

void StratifiedSum::add_part(double value, double variance, uint64_t values) {
    estimate_.add(value);
    complete_ = complete_ && values > 1;
    if (values < 2) return;
    variance_.add(variance);
    satterthwaite_ += variance * variance / static_cast<double>(values - 1);
    free_ += values - 1;
}

int StratifiedSum::dof() const {
    const double v = variance();
    if (satterthwaite_ > 0.0)
        return static_cast<int>(std::min(1e6, std::max(1.0, v * v / satterthwaite_)));
    return static_cast<int>(std::min<uint64_t>(1000000, free_));
}

void allocate_largest_remainders(uint64_t points, const std::vector<double>& share,
                                 std::vector<uint64_t>* counts) {
    const size_t n = share.size();
    uint64_t given = 0;
    std::vector<double> remainders(n);
    for (size_t h = 0; h < n; ++h) {
        const double exact = static_cast<double>(points) * share[h];
        const uint64_t whole = std::min(points - given, static_cast<uint64_t>(exact));
        (*counts)[h] += whole;
        given += whole;
        remainders[h] = exact - static_cast<double>(whole);
    }
    const uint64_t left = points - given;
    if (left == 0) return;
    if (left < n) {
        // The `left` largest remainders get a point, ties to the lower index: v, the left-th
        // largest value, is found by counting the remainders (in [0, 1]; above 1 only where the
        // total capped a whole part) in buckets and selecting within the one bucket v is in;
        // then every remainder above v gets a point, and the first ones equal to it. (VEGAS+'s
        // 10^5 hypercubes per iteration spent 12% of its run in a sort, then 4% in a selection
        // of (remainder, index) pairs.)
        const size_t buckets = std::min<size_t>(n, 4096); // about one remainder each, or more
        const auto bucket = [buckets](double r) {
            return r >= 1.0 ? buckets
                            : (r > 0.0 ? static_cast<size_t>(r * static_cast<double>(buckets))
                                       : size_t(0));
        };
        std::vector<uint64_t> in_bucket(buckets + 1, 0);
        for (size_t h = 0; h < n; ++h) ++in_bucket[bucket(remainders[h])];
        size_t b = buckets;
        uint64_t above_bucket = 0; // remainders in buckets above b
        while (above_bucket + in_bucket[b] < left) above_bucket += in_bucket[b--];
        std::vector<double> candidates;
        candidates.reserve(static_cast<size_t>(in_bucket[b]));
        for (size_t h = 0; h < n; ++h)
            if (bucket(remainders[h]) == b) candidates.push_back(remainders[h]);
        const size_t rank = static_cast<size_t>(left - above_bucket) - 1;
        std::nth_element(candidates.begin(), candidates.begin() + static_cast<long>(rank),
                         candidates.end(), std::greater<double>());
        const double v = candidates[rank];
        uint64_t above = 0;
        for (size_t h = 0; h < n; ++h) above += remainders[h] > v;
        uint64_t at_v = left - above; // of the remainders equal to v, the first ones
        for (size_t h = 0; h < n; ++h) {
            const bool gets = remainders[h] > v || (remainders[h] == v && at_v > 0);
            if (remainders[h] == v && at_v > 0) --at_v;
            (*counts)[h] += gets;
        }
        return;
    }
    // More points left than hypercubes (only by rounding): all of them, largest first, again.
    std::vector<std::pair<double, size_t>> ranked(n);
    for (size_t h = 0; h < n; ++h) ranked[h] = {remainders[h], h};
    std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    for (size_t k = 0; given < points; k = (k + 1) % n, ++given) ++(*counts)[ranked[k].second];
}

MedianInterval median_interval(std::vector<double>& values, double level) {
    MedianInterval m;
    const size_t n = values.size();
    if (n == 0) return m;
    std::sort(values.begin(), values.end());
    m.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
    // P(B <= k) for B ~ Binomial(n, 1/2), term by term in logs (n may be large).
    const double log_half_n = -static_cast<double>(n) * std::log(2.0);
    double log_term = log_half_n; // log P(B = 0)
    double cdf = std::exp(log_term);
    size_t j = 1;
    m.level = 1.0 - 2.0 * cdf;
    for (size_t k = 1; 2 * k < n; ++k) {
        log_term += std::log(static_cast<double>(n - k + 1) / static_cast<double>(k));
        cdf += std::exp(log_term);
        const double cover = 1.0 - 2.0 * cdf;
        if (cover < level) break;
        j = k + 1;
        m.level = cover;
    }
    m.lo = values[j - 1];
    m.hi = values[n - j];
    return m;
}

} // namespace mcp
