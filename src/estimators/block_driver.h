// The one loop every path that samples goes through: generate unit-cube points -> warp them by
// the proposal (domain points and densities) -> evaluate the integrand, a block of kBlockSize
// samples at a time (structure of arrays), then hand the block to a consumer (the weight
// accumulator of a run, a probe counter, a recorder of points). Dispatch happens per block.
#pragma once

#include <algorithm>
#include <cstdint>

#include "core/samplers.h"
#include "estimators/accumulator.h"
#include "estimators/estimator.h"
#include "estimators/problem.h"

namespace mcp {

/// Buffers reused across runs so that a run allocates nothing per block.
struct Workspace {
    PointBlock u, x;
    std::vector<double> pdf, f;
    WeightAccumulator accumulator;
};

/// One block of samples: unit-cube points u, domain points x, densities pdf, values f.
struct SampleBlock {
    uint64_t first = 0; ///< index of the block's first sample in the run
    size_t count = 0;
    const PointBlock* u = nullptr;
    const PointBlock* x = nullptr;
    double* pdf = nullptr; ///< writable: a consumer may turn the densities into weights
    const double* f = nullptr;
};

/// Sizes the workspace's buffers for a domain (no allocation when they already fit).
void prepare_workspace(const Domain& domain, Workspace& ws);

/// Samples 0 .. plan.total - 1 of the plan, block by block, calling consume(const SampleBlock&)
/// for each. Randomness (jitter, independent points) is drawn from rng in order.
template <class Consume>
void for_each_block(const Problem& problem, const Proposal& proposal, const SamplerPlan& plan,
                    Pcg32& rng, Workspace& ws, Consume&& consume) {
    prepare_workspace(problem.domain, ws);
    const uint64_t n = plan.total;
    for (uint64_t first = 0; first < n; first += kBlockSize) {
        const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, n - first));
        generate_block(plan, first, count, rng, ws.u);
        warp_block(proposal, problem.domain, ws.u, ws.x, ws.pdf.data());
        evaluate_block(problem.integrand, ws.x, ws.f.data());
        SampleBlock block;
        block.first = first;
        block.count = count;
        block.u = &ws.u;
        block.x = &ws.x;
        block.pdf = ws.pdf.data();
        block.f = ws.f.data();
        consume(static_cast<const SampleBlock&>(block));
    }
}

} // namespace mcp
