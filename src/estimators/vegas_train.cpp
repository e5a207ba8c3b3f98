// VEGAS training shared by VEGAS and VEGAS+ (estimators/vegas_train.h): the map as a warp stage
// and the training iterations [Lepage21, sec. 2.2].
#include "estimators/vegas_train.h"

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

void train_map(MapStage& stage, const VegasOptions& options, const Problem& problem,
               const Proposal& proposal, int iterations, uint64_t calls, TrainingPoints& points,
               Pcg32& rng, Workspace& ws, TrainingLog& log) {
    for (int iteration = 0; iteration < iterations; ++iteration) {
        points.start(part_of(calls, iterations, iteration), rng);
        while (const size_t count = points.next(ws.u)) {
            stage.warp(problem, proposal, ws, true);
            evaluate_block(problem.integrand, ws.x, ws.f.data());
            double* weights = stage.scratch(); // the Jacobians are used up
            const double* importance = points.weigh(ws, count, weights);
            stage.map().add_training(stage.bins(), weights, importance, count);
            log.trained(count);
        }
        points.finish();
        stage.map().adapt(options.alpha, options.uniform_share);
        log.adapted(stage.map(), iteration + 1);
    }
}

} // namespace mcp
