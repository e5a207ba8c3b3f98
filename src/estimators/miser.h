// MISER recursive stratified sampling [PressFarrar90] (estimators/miser.cpp): the regions a
// run cuts the unit cube into, for the tests and the playground's sample view.
#pragma once

#include <cstdint>
#include <vector>

#include "core/rng.h"
#include "estimators/problem.h"

namespace mcp {

/// A leaf region of a MISER run: the box [lo, hi) of the sampler's unit cube and the calls
/// spent in it as plain Monte Carlo.
struct MiserBox {
    std::vector<double> lo, hi;
    uint64_t calls = 0;
};

/// The leaves of one MISER run of n calls (the first `limit` of them, in the order sampled),
/// drawing from rng as run_estimate would.
std::vector<MiserBox> miser_leaves(const Problem& problem, const EstimatorSpec& spec, uint64_t n,
                                   Pcg32& rng, size_t limit);

} // namespace mcp
