// Blocks of sample points stored as structure of arrays, the unit of work of every hot loop.
#pragma once

#include <cstddef>
#include <vector>

namespace mcp {

/// Points per block: large enough to amortise one dispatch per block, small enough that a
/// block of a few dimensions stays in L1/L2 cache.
constexpr size_t kBlockSize = 256;

/// n points in dim dimensions; coordinate j of point i is at coord(j)[i].
struct PointBlock {
    int dim = 0;
    size_t n = 0;
    size_t capacity = 0;
    std::vector<double> data;

    void reset(int dimension, size_t cap) {
        dim = dimension;
        capacity = cap;
        n = 0;
        data.assign(static_cast<size_t>(dimension) * cap, 0.0);
    }
    double* coord(int j) { return data.data() + static_cast<size_t>(j) * capacity; }
    const double* coord(int j) const { return data.data() + static_cast<size_t>(j) * capacity; }
};

} // namespace mcp
