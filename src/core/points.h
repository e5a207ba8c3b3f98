// Blocks of sample points stored as structure of arrays, the unit of work of every hot loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mcp {

/// Points per block: large enough to amortise one dispatch per block, small enough that a
/// block of a few dimensions stays in L1/L2 cache.
constexpr size_t kBlockSize = 256;

/// The largest double below 1: coordinates of points in [0, 1)^d never reach 1.
constexpr double kOneMinusEpsilon = 0x1.fffffffffffffp-1;

/// x kept inside [0, 1) for x >= 0 that may round up to 1, e.g. (c + xi) / k with xi close to 1
/// and k large. x must not be NaN.
inline double below_one(double x) {
    return x < kOneMinusEpsilon ? x : kOneMinusEpsilon;
}

/// v (< 2^63) as a double: converted as a signed integer, one instruction natively and in wasm
/// (unsigned 64-bit conversions take a branchy sequence); exact below 2^53.
inline double u63_to_double(uint64_t v) {
    return static_cast<double>(static_cast<int64_t>(v));
}

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
