// VEGAS training shared by VEGAS and VEGAS+ (estimators/vegas_train.h): the map as a warp stage
// and the training iterations [Lepage21, sec. 2.2].
#include "estimators/vegas_train.h"

#include <algorithm>
#include <cmath>

#include "core/stats.h"

namespace mcp {

void MapStage::reset(int dim, int increments) {
    map_ = VegasMap(dim, increments);
    jacobian_.assign(kBlockSize, 1.0);
    bins_.assign(static_cast<size_t>(dim) * kBlockSize, 0);
}

void MapStage::warp(const Problem& problem, const Proposal& proposal, Workspace& ws,
                    bool record_bins) {
    const size_t count = ws.u.n;
    map_.apply_block(ws.u, jacobian_.data(), record_bins ? bins_.data() : nullptr);
    warp_block(proposal, problem.domain, ws.u, ws.x, ws.pdf.data());
    for (size_t i = 0; i < count; ++i) ws.pdf[i] /= jacobian_[i]; // p(x) / J(y)
}

namespace {

/// Lowers `least` to x; true when x is below (1 - kVegasSettleGain) times the old least (or
/// when it is the first value).
bool fell(double x, double* least) {
    const bool first = *least < 0.0;
    const bool lower = first || x < (1.0 - kVegasSettleGain) * *least;
    if (first || x < *least) *least = x;
    return lower;
}

} // namespace

bool TrainingStop::settled(double estimate, double variance, uint64_t points, double movement) {
    const bool finite =
        std::isfinite(estimate) && std::isfinite(variance) && std::isfinite(movement) && points > 0;
    bool improving = !finite;
    if (finite) {
        const bool variance_rose =
            least_variance_ >= 0.0 && variance > kVegasSettleRise * least_variance_;
        const bool variance_fell = fell(variance, &least_variance_);
        const bool movement_fell = fell(movement, &least_movement_);
        improving = variance_fell || movement_fell || variance_rose;
    }
    stalled_ = improving ? 0 : stalled_ + 1;
    const double se2 = finite ? variance / static_cast<double>(points) : 0.0;
    const double gap = estimate - last_estimate_;
    const bool agree = finite && has_last_ && gap * gap <= 9.0 * (se2 + last_se2_);
    last_estimate_ = estimate;
    last_se2_ = se2;
    has_last_ = finite;
    return stalled_ >= 2 && agree;
}

double vegas_movement(const VegasMap& before, const VegasMap& after) {
    const int k = after.increments();
    if (before.dim() != after.dim() || before.increments() != k || k < 1 || after.dim() < 1)
        return 0.0;
    NeumaierSum moved;
    for (int j = 0; j < after.dim(); ++j) {
        const double *a = before.edges(j), *b = after.edges(j);
        double axis = 0.0;
        for (int i = 1; i < k; ++i) axis += std::fabs(b[i] - a[i]);
        moved.add(axis);
    }
    return moved.value() * k / (static_cast<double>(after.dim()) * std::max(1, k - 1));
}

TrainingSpent train_map(MapStage& stage, const VegasOptions& options, const Problem& problem,
                        const Proposal& proposal, int iterations, uint64_t calls,
                        TrainingPoints& points, Pcg32& rng, Workspace& ws, TrainingLog& log) {
    TrainingSpent spent;
    TrainingStop stop;
    VegasMap before; // the map before an iteration's adaptation, for its movement
    for (int iteration = 0; iteration < iterations; ++iteration) {
        const uint64_t size = part_of(calls, iterations, iteration);
        points.start(size, rng);
        NeumaierSum sum_cw, sum_cw2; // the iteration's mean(c w) and mean(c w^2)
        uint64_t seen = 0;
        while (const size_t count = points.next(ws.u)) {
            stage.warp(problem, proposal, ws, true);
            evaluate_block(problem.integrand, ws.x, ws.f.data());
            double* weights = stage.scratch(); // the Jacobians are used up
            const double* importance = points.weigh(ws, count, weights);
            points.train(stage.map(), stage.bins(), weights, importance, count);
            double block_cw = 0.0, block_cw2 = 0.0; // one block: plain sums, then compensated
            for (size_t i = 0; i < count; ++i) {
                const double c = importance ? importance[i] : 1.0, w = weights[i];
                block_cw += c * w;
                block_cw2 += c * w * w;
            }
            sum_cw.add(block_cw);
            sum_cw2.add(block_cw2);
            seen += count;
            log.trained(count);
        }
        points.finish(stage.map());
        const bool judge = options.train_stop == VegasTrainStop::Settled && seen > 0;
        if (judge) before = stage.map(); // edges and (cleared) sums: per iteration, not per point
        stage.map().adapt(options.alpha, options.uniform_share);
        spent.calls += seen;
        spent.iterations = iteration + 1;
        log.adapted(stage.map(), iteration + 1);
        if (!judge) continue;
        const double n = static_cast<double>(seen);
        const double mean = sum_cw.value() / n;
        const double variance = std::max(0.0, sum_cw2.value() / n - mean * mean);
        if (stop.settled(mean, variance, seen, vegas_movement(before, stage.map()))) break;
    }
    return spent;
}

} // namespace mcp
