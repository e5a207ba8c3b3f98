// The block driver's shared pieces (estimators/block_driver.h): the workspace and its blocks,
// generate -> warp -> evaluate for a sampler plan, and what the adaptive estimators record of
// their training (TrainingLog, view_of).
#include "estimators/block_driver.h"

#include <algorithm>
#include <chrono>

namespace mcp {

void prepare_workspace(const Domain& domain, Workspace& ws) {
    const int sdim = domain.sample_dim(), pdim = domain.point_dim();
    if (ws.u.dim != sdim || ws.u.capacity != kBlockSize) ws.u.reset(sdim, kBlockSize);
    if (ws.x.dim != pdim || ws.x.capacity != kBlockSize) ws.x.reset(pdim, kBlockSize);
    ws.pdf.resize(kBlockSize);
    ws.f.resize(kBlockSize);
}

SampleBlock block_of(Workspace& ws, uint64_t first, size_t count) {
    SampleBlock block;
    block.first = first;
    block.count = count;
    block.u = &ws.u;
    block.x = &ws.x;
    block.pdf = ws.pdf.data();
    block.f = ws.f.data();
    return block;
}

SampleBlock sample_block(const Problem& problem, const Proposal& proposal, const SamplerPlan& plan,
                         uint64_t first, size_t count, Workspace& ws) {
    generate_block(plan, first, count, ws.u);
    warp_block(proposal, problem.domain, ws.u, ws.x, ws.pdf.data());
    evaluate_block(problem.integrand, ws.x, ws.f.data());
    return block_of(ws, first, count);
}

void copy_points(const PointBlock& src, size_t from, PointBlock& dst, size_t at, size_t count) {
    for (int j = 0; j < src.dim; ++j)
        std::copy(src.coord(j) + from, src.coord(j) + from + count, dst.coord(j) + at);
}

SampleBlock detail::block_from_batch(uint64_t first, size_t count, Workspace& ws) {
    const FunctionBatch& b = ws.batch;
    const size_t from = static_cast<size_t>(first - b.begin);
    copy_points(b.u, from, ws.u, 0, count);
    copy_points(b.x, from, ws.x, 0, count);
    std::copy(b.pdf.begin() + static_cast<long>(from),
              b.pdf.begin() + static_cast<long>(from + count), ws.pdf.begin());
    std::copy(b.f.begin() + static_cast<long>(from), b.f.begin() + static_cast<long>(from + count),
              ws.f.begin());
    ws.u.n = ws.x.n = count;
    return block_of(ws, first, count);
}

SampleBlock sample_block_batched(const Problem& problem, const Proposal& proposal,
                                 const SamplerPlan& plan, uint64_t first, size_t count,
                                 Workspace& ws) {
    return batched_block(problem, first, count, plan.total, ws, [&](uint64_t at, size_t m) {
        generate_block(plan, at, m, ws.u);
        warp_block(proposal, problem.domain, ws.u, ws.x, ws.pdf.data());
    });
}

double clock_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

AdaptiveView view_of(const VegasMap& map) {
    AdaptiveView v;
    for (int j = 0; j < map.dim(); ++j)
        v.edges.emplace_back(map.edges(j), map.edges(j) + map.increments() + 1);
    return v;
}

void TrainingLog::begin(const VegasMap& map, int iterations, bool record) {
    record_ = record;
    ended_ = false;
    iterations_ = iterations;
    calls_ = 0;
    start_ = clock_seconds();
    seconds_ = 0.0;
    history_.clear();
    this->record(map, 0);
}

void TrainingLog::adapted(const VegasMap& map, int iteration) {
    record(map, iteration);
}

void TrainingLog::end_training() {
    if (ended_) return;
    ended_ = true;
    seconds_ = clock_seconds() - start_;
}

void TrainingLog::report(RunResult* r) const {
    r->training_n = calls_;
    r->training_seconds = calls_ > 0 ? seconds_ : 0.0;
}

void TrainingLog::record(const VegasMap& map, int iteration) {
    if (!record_) return;
    // Snapshots 0 .. iterations; keep about kViewIterations of them, evenly, and the last.
    const int stride = std::max(1, (iterations_ + kViewIterations - 1) / kViewIterations);
    if (iteration % stride != 0 && iteration != iterations_) return;
    const int k = map.increments();
    const int step = std::max(1, (k + kViewEdges - 1) / kViewEdges);
    std::vector<std::vector<double>> axes;
    for (int j = 0; j < std::min(map.dim(), 2); ++j) {
        std::vector<double> e;
        for (int i = 0; i <= k; i += step) e.push_back(map.edges(j)[i]);
        if ((k % step) != 0) e.push_back(map.edges(j)[k]);
        axes.push_back(e);
    }
    history_.push_back(axes);
}
} // namespace mcp
