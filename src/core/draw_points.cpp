#include "core/draw_points.h"

#include <algorithm>

namespace mcp {

std::string check_point_set_request(const PointSetRequest& request) {
    if (request.n < 1 || request.n > kMaxAnalysisPoints)
        return "n: expected 1 to " + std::to_string(kMaxAnalysisPoints) + " points, got " +
               std::to_string(request.n);
    if (request.dim < 1 || request.dim > kMaxAnalysisDim)
        return "dim: expected 1 to " + std::to_string(kMaxAnalysisDim) + ", got " +
               std::to_string(request.dim);
    if (!is_qmc(request.kind)) return "";
    const QmcKind qmc = qmc_kind_of(request.kind);
    if (request.dim > qmc_max_dim(qmc))
        return "dim: the " + std::string(sampler_name(request.kind)) + " points have at most " +
               std::to_string(qmc_max_dim(qmc)) + " dimensions, got " + std::to_string(request.dim);
    if (request.n > qmc_max_points(qmc))
        return "n: the " + std::string(sampler_name(request.kind)) + " points number at most " +
               std::to_string(qmc_max_points(qmc)) + ", got " + std::to_string(request.n);
    const std::string why = check_randomization(qmc, request.randomization);
    return why.empty() ? "" : "randomization: " + why;
}

PointSet draw_point_set(const PointSetRequest& request) {
    // Set k of a seed has its own stream: sets never share draws, and set 0 does not depend on
    // how many sets are drawn.
    Pcg32 rng(request.seed, 2 * request.set_index + 1);
    SamplerOptions options;
    options.randomization = request.randomization;
    options.randomizations = 1; // one point set: one randomization
    const SamplerPlan plan = make_sampler_plan(request.kind, request.dim, request.n, rng, options);
    PointSet set;
    set.dim = request.dim;
    set.n = request.n;
    set.coords.assign(static_cast<size_t>(request.n) * static_cast<size_t>(request.dim), 0.0);
    PointBlock block;
    block.reset(request.dim, kBlockSize);
    for (uint64_t first = 0; first < request.n; first += kBlockSize) {
        const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, request.n - first));
        generate_block(plan, first, count, block);
        for (int k = 0; k < request.dim; ++k)
            std::copy(block.coord(k), block.coord(k) + count,
                      set.coords.begin() +
                          static_cast<ptrdiff_t>(static_cast<uint64_t>(k) * request.n + first));
    }
    return set;
}

} // namespace mcp
