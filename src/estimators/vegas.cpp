#include "estimators/vegas.h"

#include <algorithm>
#include <cmath>

#include "core/float_index.h"

namespace mcp {

VegasOptions vegas_resolved(const VegasOptions& options, SamplerKind sampler, bool plus, int dim) {
    VegasOptions o = options;
    // The trained map on its own (independent points, frozen): damping 1 and up to 20
    // iterations until settled, which a sharp peak needs. Where the frozen map's points are
    // stratified (a QMC or stratified sampler, VEGAS+'s hypercubes) or the map keeps adapting
    // (the iteration average), vegas's 0.5 and 10 whole iterations: with the other settings
    // vegas_sobol's RMSE^2 grew 5-15x on smooth integrands in d = 2 and vegas_plus's up to 35x
    // (docs/benchmarks.md).
    const bool map_alone = sampler == SamplerKind::Independent && !plus && !o.stratify &&
                           o.report == VegasReport::Frozen;
    if (o.alpha < 0.0) o.alpha = map_alone ? 1.0 : 0.5;
    if (o.train_iterations <= 0) o.train_iterations = map_alone ? 20 : 10;
    if (o.train_stop == VegasTrainStop::Default)
        o.train_stop = map_alone ? VegasTrainStop::Settled : VegasTrainStop::Budget;
    // The even share: for the map alone 5% of the whole map, 1 - 0.95^(1/d) on each axis, so
    // that a point is in the learnt part of every axis with probability 0.95. With 0.05 on
    // each axis, 1 - 0.95^d of the points (26% in d = 6) fell in some axis's even part, far
    // from a sharp product peak, with near-zero weights: that alone held the relative variance
    // of the weights near 0.35-0.5 on Genz's product peaks whatever the map learnt. The others
    // keep 0.05 per axis (their strata and nets spread over the even part; smaller shares cost
    // vegas_sobol and vegas_plus 4-5x on discontinuous and corner-peak cases).
    if (o.uniform_share < 0.0)
        o.uniform_share = map_alone ? 1.0 - std::pow(1.0 - kVegasEvenShare, 1.0 / std::max(dim, 1))
                                    : kVegasEvenShare;
    return o;
}

uint64_t vegas_plus_per_axis(int dim, uint64_t points) {
    auto fits = [&](uint64_t m) {
        uint64_t cubes = 1;
        for (int j = 0; j < dim; ++j) {
            cubes *= m;
            if (cubes * 4 > points || cubes > kVegasMaxHypercubes) return false;
        }
        return true;
    };
    uint64_t m = 1;
    while (fits(m + 1)) ++m;
    return m;
}

MedianWithoutOne median_without_one(double* first, double* last) {
    // Without v, the others' median is the sorted value (n - 1) / 2 of the group when v lies
    // above it (v's rank is larger), else the next one: values n/2 - 1 and n/2 for even n,
    // (n-1)/2 and (n+1)/2 for odd n. Ties give equal values either way.
    const std::ptrdiff_t n = last - first;
    double* middle = first + n / 2;
    std::nth_element(first, middle, last);
    MedianWithoutOne m;
    if (n % 2 == 0) {
        m.below = *std::max_element(first, middle);
        m.above = *middle;
    } else {
        m.below = *middle;
        m.above = *std::min_element(middle + 1, last);
    }
    return m;
}

int vegas_increments(int dim, uint64_t points_per_iteration) {
    const uint64_t most = dim <= 4 ? 1000 : (dim <= 8 ? 500 : 200);
    return static_cast<int>(std::max<uint64_t>(2, std::min(most, points_per_iteration / 100)));
}

int vegas_trainable_increments(const VegasOptions& options, int dim, uint64_t points_per_iteration,
                               uint64_t training_calls) {
    const uint64_t most = std::max<uint64_t>(2, points_per_iteration / kVegasPointsPerIncrement);
    if (options.increments <= 0) {
        const uint64_t sizing = std::max<uint64_t>(
            points_per_iteration, training_calls / static_cast<uint64_t>(kVegasSizingIterations));
        const int k = vegas_increments(dim, sizing);
        if (points_per_iteration == 0) return k;
        return static_cast<int>(std::min<uint64_t>(static_cast<uint64_t>(k), most));
    }
    if (points_per_iteration == 0) return options.increments; // no training: the identity
    return static_cast<int>(std::min<uint64_t>(static_cast<uint64_t>(options.increments), most));
}

std::string vegas_untrainable(const VegasOptions& options, uint64_t n_max) {
    if (options.increments <= 0) return {};
    const uint64_t train =
        static_cast<uint64_t>(options.train_fraction * static_cast<double>(n_max));
    uint64_t per_iteration = 0;
    std::string what;
    if (train >= 2) {
        per_iteration = train / static_cast<uint64_t>(vegas_training_iterations(options, train));
        what = "train_fraction x n_max / training iterations";
    } else if (options.report == VegasReport::Iterations) {
        per_iteration = n_max / static_cast<uint64_t>(std::max(options.iterations, 1));
        what = "n_max / iterations";
    } else {
        return {}; // no training: the map stays the identity
    }
    const uint64_t increments = static_cast<uint64_t>(options.increments);
    if (per_iteration >= kVegasPointsPerIncrement * increments) return {};
    return "vegas.increments = " + std::to_string(increments) + " needs " +
           std::to_string(kVegasPointsPerIncrement * increments) +
           " points per training iteration (" + std::to_string(kVegasPointsPerIncrement) +
           " per increment), but n_max = " + std::to_string(n_max) + " gives " +
           std::to_string(per_iteration) + " (" + what + "): lower increments to at most " +
           std::to_string(per_iteration / kVegasPointsPerIncrement) +
           " or raise n_max; fewer points leave the map learning noise";
}

int vegas_training_iterations(const VegasOptions& options, uint64_t calls) {
    return static_cast<int>(
        std::min<uint64_t>(static_cast<uint64_t>(std::max(options.train_iterations, 1)),
                           std::max<uint64_t>(1, calls / kVegasIterationPoints)));
}

VegasMap::VegasMap(int dim, int increments)
    : dim_(dim), k_(increments), edges_(static_cast<size_t>(dim) * (increments + 1)),
      sum_w2_(static_cast<size_t>(dim) * increments, 0.0),
      counts_(static_cast<size_t>(dim) * increments, 0.0) {
    for (int j = 0; j < dim; ++j) {
        double* e = edges_.data() + static_cast<size_t>(j) * (k_ + 1);
        for (int i = 0; i <= k_; ++i) e[i] = static_cast<double>(i) / k_;
        e[k_] = 1.0;
    }
}

void VegasMap::apply_block(PointBlock& points, double* jacobian, uint32_t* bins) const {
    const size_t n = points.n;
    const double k = static_cast<double>(k_);
    for (size_t i = 0; i < n; ++i) jacobian[i] = 1.0;
    for (int j = 0; j < dim_; ++j) {
        double* y = points.coord(j);
        const double* e = edges(j);
        uint32_t* bin = bins ? bins + static_cast<size_t>(j) * kBlockSize : nullptr;
        for (size_t i = 0; i < n; ++i) {
            const double t = y[i] * k; // y < 1, so t < K up to rounding
            const int b = std::min(static_cast<int>(floor_to_index(t)), k_ - 1);
            const double width = e[b + 1] - e[b];
            y[i] = below_one(e[b] + (t - b) * width);
            jacobian[i] *= k * width;
            if (bin) bin[i] = static_cast<uint32_t>(b);
        }
    }
}

void VegasMap::add_training(const uint32_t* bins, const double* weights, size_t count) {
    add_training(bins, weights, nullptr, count);
}

void VegasMap::add_training(const uint32_t* bins, const double* weights, const double* importance,
                            size_t count) {
    for (int j = 0; j < dim_; ++j) {
        const uint32_t* bin = bins + static_cast<size_t>(j) * kBlockSize;
        double* sums = sum_w2_.data() + static_cast<size_t>(j) * k_;
        double* counts = counts_.data() + static_cast<size_t>(j) * k_;
        for (size_t i = 0; i < count; ++i) {
            const double w = weights[i], c = importance ? importance[i] : 1.0;
            if (!std::isfinite(w)) continue;
            sums[bin[i]] += c * w * w;
            counts[bin[i]] += c;
        }
    }
}

void VegasMap::add_square(const uint32_t* bins, size_t stride, double square, double importance) {
    if (!std::isfinite(square)) return;
    for (int j = 0; j < dim_; ++j) {
        const size_t at = static_cast<size_t>(j) * k_ + bins[static_cast<size_t>(j) * stride];
        sum_w2_[at] += importance * square;
        counts_[at] += importance;
    }
}

void VegasMap::adapt(double alpha, double uniform_share) {
    std::vector<double> d(static_cast<size_t>(k_)), smooth(static_cast<size_t>(k_));
    std::vector<double> fresh(static_cast<size_t>(k_) + 1);
    for (int j = 0; j < dim_; ++j) {
        double* sums = sum_w2_.data() + static_cast<size_t>(j) * k_;
        double* counts = counts_.data() + static_cast<size_t>(j) * k_;
        for (int i = 0; i < k_; ++i) d[i] = counts[i] > 0.0 ? sums[i] / counts[i] : 0.0;
        std::fill(sums, sums + k_, 0.0);
        std::fill(counts, counts + k_, 0.0);
        if (k_ == 1) continue;
        // Smoothing with the neighbours [Lepage21]: 1, 6, 1 over 8 inside, 7, 1 at the ends.
        smooth[0] = (7.0 * d[0] + d[1]) / 8.0;
        smooth[k_ - 1] = (7.0 * d[k_ - 1] + d[k_ - 2]) / 8.0;
        for (int i = 1; i + 1 < k_; ++i) smooth[i] = (d[i - 1] + 6.0 * d[i] + d[i + 1]) / 8.0;
        double total = 0.0;
        for (int i = 0; i < k_; ++i) total += smooth[i];
        if (!(total > 0.0) || !std::isfinite(total)) continue; // nothing learnt on this axis
        // Damping: ((1 - d) / ln(1 / d))^alpha of the normalised d keeps the map from jumping
        // to a noisy optimum; alpha = 0 leaves it uniform in d (every increment kept).
        double damped_total = 0.0;
        for (int i = 0; i < k_; ++i) {
            const double r = smooth[i] / total;
            double v = 0.0;
            if (r >= 1.0)
                v = 1.0;
            else if (r > 0.0)
                v = std::pow((1.0 - r) / std::log(1.0 / r), alpha);
            smooth[i] = v;
            damped_total += v;
        }
        if (!(damped_total > 0.0)) continue;
        // A share of the increments spread evenly over the axis, whatever the training saw:
        // no increment is wider than 1 / (share K), so the axis's Jacobian stays below
        // 1 / share. Without it a region where f was seen as 0 collapses into one increment
        // that also reaches into a region where f is large (a discontinuity), and the rare
        // points there carry huge weights (heavy tails, error bars that miss).
        const double* edge = edges(j);
        for (int i = 0; i < k_; ++i)
            smooth[i] = (1.0 - uniform_share) * smooth[i] / damped_total +
                        uniform_share * (edge[i + 1] - edge[i]);
        damped_total = 1.0;
        // New edges: increment i of the old map holds a share smooth[i] of the total, spread
        // evenly over it; the new edges cut the total into K equal shares.
        const double* e = edges(j);
        const double share = damped_total / k_;
        fresh[0] = 0.0;
        double below = 0.0; // the total of the old increments before `old`
        int old = 0;
        for (int i = 1; i < k_; ++i) {
            const double target = share * i;
            while (old + 1 < k_ && below + smooth[old] < target) below += smooth[old++];
            const double within =
                smooth[old] > 0.0 ? std::min(1.0, (target - below) / smooth[old]) : 1.0;
            fresh[i] = std::max(fresh[i - 1], e[old] + within * (e[old + 1] - e[old]));
        }
        fresh[k_] = 1.0;
        std::copy(fresh.begin(), fresh.end(), edges_.begin() + static_cast<long>(j) * (k_ + 1));
    }
}

} // namespace mcp
