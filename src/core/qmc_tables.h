// Data tables of the quasi-Monte Carlo point sets (src/core/qmc.cpp): Sobol' direction numbers
// and the generating vector of a rank-1 lattice sequence.
#pragma once

#include <cstdint>

#include "core/qmc.h"

namespace mcp {

/// One row of Joe and Kuo's direction-number file [JoeKuo08]: the primitive polynomial
/// x^s + a_1 x^(s-1) + ... + a_(s-1) x + 1 over GF(2) of degree s (a holds the bits a_1 .. a_(s-1),
/// a_1 the most significant) and the initial odd integers m_1 .. m_s (m_k < 2^k).
struct SobolRow {
    uint8_t degree; ///< s
    uint16_t poly;  ///< a
    uint16_t m[13]; ///< m_1 .. m_s; the degree is at most 13 for the first 1024 dimensions
};

/// Rows for the sequence's dimensions 2 .. kSobolMaxDim (row i is dimension i + 2, 1-based);
/// dimension 1, the van der Corput sequence, has no row.
extern const SobolRow kSobolRows[kSobolMaxDim - 1];

/// Generating vector z_1 .. z_1024 of the embedded rank-1 lattice sequence for 2^10 .. 2^20
/// points [CoolsKuoNuyens06, Kuo]; every z_j is odd and below 2^20.
extern const uint32_t kLatticeGenerator[kLatticeMaxDim];

} // namespace mcp
