// Randomized quasi-Monte Carlo point sets in [0,1)^d, addressable by (index, dimension):
//
// - Sobol' sequence [Sobol67] with Joe and Kuo's new-joe-kuo-6.21201 direction numbers
//   [JoeKuo08], Gray-code order [AntonovSaleev79], 32-bit digits, up to kSobolMaxDim dimensions.
//   Randomizations: nested uniform (Owen) scrambling by hashing [Owen95, LaineKarras11,
//   Burley20], a random linear matrix scramble plus digital shift [Matousek98], a digital
//   shift alone, or none.
// - Halton sequence [Halton60] in the first kHaltonMaxDim prime bases. Randomizations: nested
//   (Owen) digit scrambling by hashing [Owen95], independent random digit permutations per
//   digit position [BraatenWeller79, Faure09], or none. The random permutations of the digits
//   are affine maps d -> (a d + c) mod b, which for prime b give single digits and pairs of
//   digits the same law as uniform random permutations (all the mean and variance of an
//   estimate depend on [Owen03]).
// - Rank-1 lattice sequence [Hickernell00] with the embedded generating vector
//   lattice-33002-1024-1048576 of [Kuo, CoolsKuoNuyens06] (good for 2^10 .. 2^20 points),
//   taken in radical-inverse order, so every first 2^m points form a lattice. Randomization:
//   a random shift modulo 1 [CranleyPatterson76], or none.
//
// Every randomized coordinate carries 53 random bits: digits past the construction's precision
// are filled uniformly by the randomization, so singular integrands near 0 are sampled as
// finely as plain Monte Carlo samples them. Randomized coordinates lie in (0, 1), the
// deterministic ones in [0, 1) (point 0 is the origin).
//
// Points depend only on (key, kind, randomization, index, dimension): they are the same on
// every platform (integer arithmetic, and IEEE double operations on exact integers), whatever
// the block sizes and their order, and whatever the number of dimensions of the randomizer.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/points.h"

namespace mcp {

constexpr int kSobolMaxDim = 1024;
constexpr int kHaltonMaxDim = 1024;
constexpr int kLatticeMaxDim = 1024;
/// Sobol' digits are 32-bit: indices 0 .. 2^32 - 1.
constexpr uint64_t kSobolMaxPoints = uint64_t(1) << 32;
/// Halton: indices below 2^48 keep every digit exact in double arithmetic.
constexpr uint64_t kHaltonMaxPoints = uint64_t(1) << 48;
/// The generating vector is designed for up to 2^20 points.
constexpr uint64_t kLatticeMaxPoints = uint64_t(1) << 20;

enum class QmcKind { Sobol, Halton, Lattice };

enum class QmcRandomization {
    None,         ///< the deterministic points (no error bar can be estimated)
    Owen,         ///< nested uniform scrambling (Sobol', Halton)
    LmsShift,     ///< random linear matrix scramble + digital shift (Sobol')
    DigitalShift, ///< digital shift, XOR with a random 53-bit vector (Sobol')
    Permutation,  ///< random digit permutations per digit position (Halton)
    RandomShift,  ///< Cranley-Patterson shift modulo 1 (lattice)
};
/// Every randomization, the randomized ones first and the deterministic points last (the order
/// the C API's catalog lists those that apply to a point set).
inline constexpr QmcRandomization kQmcRandomizations[] = {
    QmcRandomization::Owen,        QmcRandomization::LmsShift,    QmcRandomization::DigitalShift,
    QmcRandomization::Permutation, QmcRandomization::RandomShift, QmcRandomization::None};

const char* qmc_kind_name(QmcKind kind);
const char* randomization_name(QmcRandomization r);
/// Parses "none", "owen", "lms_shift", "digital_shift", "permutation", "random_shift".
bool parse_randomization(const std::string& name, QmcRandomization* r);
/// The default randomization of a kind: Owen for Sobol' and Halton, random shift for lattices.
QmcRandomization default_randomization(QmcKind kind);
/// "" when the randomization applies to the kind, else an error naming both and the ones
/// that apply.
std::string check_randomization(QmcKind kind, QmcRandomization r);
/// Largest dimension and number of points per randomization a kind supports.
int qmc_max_dim(QmcKind kind);
uint64_t qmc_max_points(QmcKind kind);

/// Unscrambled Sobol' coordinate `dim` (0-based) of the point with Gray-code index `index`
/// (index < 2^32), as 32 binary digits (the most significant bit is the first digit).
uint32_t sobol_u32(uint64_t index, int dim);

/// Sobol' coordinates 0, 1 and 2 of 32-bit indices by tables instead of a loop over the set
/// bits of the Gray code: since the point is the XOR of the directions of gray(index)'s bits
/// (linear over GF(2)), it is the XOR of four entries, one per byte of gray(index), each the
/// XOR of the directions of that byte's bits. Coordinates 0 and 1 share an entry (low and
/// high halves), so a 2D point takes four lookups. 12 KiB, built once (sobol_byte_tables()).
struct SobolByteTables {
    uint64_t xy[4][256]; ///< coordinate 0 | coordinate 1 << 32
    uint32_t z[4][256];  ///< coordinate 2
    /// sobol_u32(index, 0) | sobol_u32(index, 1) << 32.
    uint64_t point_2d(uint32_t index) const {
        const uint32_t g = index ^ (index >> 1);
        return xy[0][g & 255u] ^ xy[1][(g >> 8) & 255u] ^ xy[2][(g >> 16) & 255u] ^ xy[3][g >> 24];
    }
    /// sobol_u32(index, 2).
    uint32_t coordinate_2(uint32_t index) const {
        const uint32_t g = index ^ (index >> 1);
        return z[0][g & 255u] ^ z[1][(g >> 8) & 255u] ^ z[2][(g >> 16) & 255u] ^ z[3][g >> 24];
    }
};
const SobolByteTables& sobol_byte_tables();

namespace qmc_detail {

inline uint32_t reverse_bits32(uint32_t x) {
    x = (x >> 16) | (x << 16);
    x = ((x & 0xff00ff00u) >> 8) | ((x & 0x00ff00ffu) << 8);
    x = ((x & 0xf0f0f0f0u) >> 4) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x & 0xccccccccu) >> 2) | ((x & 0x33333333u) << 2);
    x = ((x & 0xaaaaaaaau) >> 1) | ((x & 0x55555555u) << 1);
    return x;
}

// Laine-Karras hash of bit-reversed digits [LaineKarras11, Burley20] with the constants of
// [Vegdahl21], who searched them for avalanche between the bits it is allowed to mix (the
// original ones leave visible structure). Every step (x ^= x * even, x += seed, x *= odd) is
// a bijection that changes bit i by a function of bits 0 .. i-1 (and the seed) only: products
// and carries move upwards. After reversal bit i is digit i + 1, so each digit is flipped by a
// function of the digits before it, which is a nested (Owen) scramble of the 32 digits.
inline uint32_t owen_hash_reversed(uint32_t x, uint32_t seed) {
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

} // namespace qmc_detail

/// Nested uniform scrambling of 32 binary digits by a keyed hash: every digit is flipped by a
/// hash of the digits before it and the seed [LaineKarras11, Burley20], with the hash
/// constants of [Vegdahl21]. The seed should be random (a full 32-bit draw). Inline: the
/// pixel samplers call it several times per sample.
inline uint32_t owen_scramble_u32(uint32_t v, uint32_t seed) {
    using namespace qmc_detail;
    return reverse_bits32(owen_hash_reversed(reverse_bits32(v), seed));
}

/// 32 digits followed by 21 fill bits as a double in (0, 1): ((v << 21 | fill) + 1/2) 2^-53.
/// Above 1/2 the half step is not representable and k + 1/2 rounds to an even neighbour; the
/// top value 2^53 - 1 would round to 1, so it is kept at the largest double below 1.
inline double bits53_to_unit(uint64_t k53) {
    const double x = (static_cast<double>(static_cast<int64_t>(k53)) + 0.5) * 0x1p-53;
    return below_one(x);
}

/// The random parameters of one randomization of one point set, drawn from a 64-bit key.
/// Built once per randomization; generating points allocates nothing.
struct QmcRandomizer {
    QmcKind kind = QmcKind::Sobol;
    QmcRandomization randomization = QmcRandomization::Owen;
    int dim = 0;
    uint64_t key = 0;
    std::vector<uint32_t> seeds; ///< Owen (both kinds) / Permutation: one hash seed per dimension
    std::vector<uint64_t>
        shifts; ///< digital shift (53 bits) or lattice shift (53 bits) per dimension
    std::vector<uint32_t> matrices; ///< LMS: 32 scrambled direction columns per dimension
    /// Points that will be drawn from this randomization (0: up to qmc_max_points). Halton's
    /// nested scramble then hashes only the digits where these points' prefixes can agree and
    /// draws the rest as one uniform (see halton_owen).
    uint64_t points = 0;
};

/// Draws the parameters of one randomization from `key`: dimension j from its own generator
/// seeded by (key, j), so the first dimensions do not depend on dim. dim is clamped to
/// [0, qmc_max_dim(kind)]; r must apply to kind (check_randomization), a randomization that
/// does not apply gives the deterministic points.
/// `points` (0: no bound) is how many points will be drawn, indices below it (QmcRandomizer).
QmcRandomizer make_qmc_randomizer(QmcKind kind, QmcRandomization r, int dim, uint64_t key,
                                  uint64_t points = 0);

/// Coordinate `dim` of point `index` of the randomized point set (random access; slow path
/// for tests and single points). index < qmc_max_points(r.kind), 0 <= dim < r.dim.
double qmc_coordinate(const QmcRandomizer& r, uint64_t index, int dim);

/// Writes points first .. first + count - 1 of the randomized point set into the columns of u
/// starting at row `offset` (u.coord(j)[offset + i] = coordinate j of point first + i), for
/// j < r.dim. Any first and count (blocks need not come in order); results equal
/// qmc_coordinate bit for bit. Needs u.dim >= r.dim, offset + count <= u.capacity and
/// first + count <= qmc_max_points(r.kind); u.n is left to the caller. Sobol' walks the Gray
/// code (one XOR per point and dimension), Halton counts the digits of the index in an
/// odometer (no division per point), lattices take one product per point and dimension.
void qmc_points(const QmcRandomizer& r, uint64_t first, size_t count, PointBlock& u,
                size_t offset = 0);

} // namespace mcp
