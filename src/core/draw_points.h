// One point set drawn from one of mcplay's samplers, whole, for looking at it: the sampler lab's
// points, discrepancies and spectra (core/point_analysis.h). A study draws its points block by
// block instead (core/samplers.h); this is the same plan, generated at once.
#pragma once

#include <cstdint>
#include <string>

#include "core/point_analysis.h"
#include "core/samplers.h"

namespace mcp {

/// Which point set: a sampler, its randomization (quasi-Monte Carlo samplers), how many points in
/// how many dimensions, and the seed. Sets 0, 1, 2, ... of one seed are independent draws (for a
/// quasi-Monte Carlo sampler, independent randomizations of the same points).
struct PointSetRequest {
    SamplerKind kind = SamplerKind::Independent;
    QmcRandomization randomization = QmcRandomization::Owen;
    uint64_t n = 256;
    int dim = 2;
    uint64_t seed = 1;
    uint64_t set_index = 0;
};

/// "" when the request can be drawn, else an error naming the field: n in [1, kMaxAnalysisPoints],
/// dim in [1, kMaxAnalysisDim] and within the point set's table, a randomization that applies.
std::string check_point_set_request(const PointSetRequest& request);

/// The request's points (check_point_set_request must hold). Stratified sets have one point per
/// cell of stratification_grid(n, dim); Latin hypercube sets one point per slab of each axis;
/// quasi-Monte Carlo sets are the first n points of one randomization.
PointSet draw_point_set(const PointSetRequest& request);

} // namespace mcp
