// Float-to-index conversion by integer arithmetic, for hot loops that run in wasm too.
#pragma once

#include <cstdint>
#include <cstring>

namespace mcp {

/// floor(x) for 0 <= x < 2^31, from the bits of x + 2^52 (whose low mantissa bits hold x
/// rounded to the nearest integer), stepped down by one where that rounding went up. Outside
/// that range (negative, NaN, infinite, too large) the result is some value in [0, 2^32):
/// callers clamp or select before using it.
///
/// Why not static_cast: V8 compiles wasm's float-to-int truncation to roundsd + cvttsd2si, and
/// roundsd writes only the low lane of a register it also reads. That false dependency can chain
/// the iterations of a loop: a tabulated-density loop ran 2.5x slower under V8 with the cast than
/// with this form (docs/performance-notes.md#the-estimator-loop-in-wasm); natively the two cost
/// the same.
inline uint32_t floor_to_index(double x) {
    const double shifted = x + 0x1p52;
    uint64_t bits;
    std::memcpy(&bits, &shifted, sizeof bits);
    const double nearest = shifted - 0x1p52;
    return static_cast<uint32_t>(bits) - static_cast<uint32_t>(nearest > x);
}

/// double(i) for any i < 2^32, from the bits of 2^52 + i. V8 compiles wasm's int-to-float
/// conversion to cvtsi2sd, which merges into a scratch register that other code in a loop also
/// writes; this form is integer and floating-point arithmetic only (1.15 against 1.68 ns per
/// element in a V8 loop that converts and scales indices; natively the same).
inline double index_to_double(uint32_t i) {
    const uint64_t bits = 0x4330000000000000ull | i; // 2^52 + i: exact, i < 2^52
    double shifted;
    std::memcpy(&shifted, &bits, sizeof shifted);
    return shifted - 0x1p52;
}

} // namespace mcp
