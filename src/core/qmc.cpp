#include "core/qmc.h"

#include <cmath>

#include "core/qmc_tables.h"
#include "core/rng.h"
#include "core/simd.h"

namespace mcp {

namespace {

using qmc_detail::owen_hash_reversed;
using qmc_detail::reverse_bits32;

constexpr int kDigitBits = 32;             // Sobol' digits per coordinate
constexpr int kFillBits = 53 - kDigitBits; // random bits below the digits
constexpr uint64_t kMask53 = (uint64_t(1) << 53) - 1;
constexpr int kLatticeBits = 20; // the lattice sequence has 2^20 points
constexpr uint32_t kLatticeMask = (uint32_t(1) << kLatticeBits) - 1;
constexpr int kMaxDigits = 64; // digits of a 64-bit index in base 2
constexpr size_t kChunk = 256; // points per pass of the block loops

inline int trailing_zeros(uint64_t x) {
    return __builtin_ctzll(x);
}

inline uint32_t parity32(uint32_t x) {
    x ^= x >> 16;
    x ^= x >> 8;
    x ^= x >> 4;
    x ^= x >> 2;
    x ^= x >> 1;
    return x & 1u;
}

// n mod b by two multiplications instead of a division [LemireKaserKurz19]: with
// M = floor((2^64 - 1) / b) + 1 the fraction frac(n / b) is (M n mod 2^64) / 2^64 up to an
// excess below n b 2^-64, and n mod b = floor(frac(n / b) b). Rounding the fraction up to 32
// bits adds less than b 2^-32, so for n, b < 2^31 the floor is still exact.
struct FastMod {
    uint32_t b = 1;
    uint64_t m = 0; ///< M; 0 for b = 1, where every remainder is 0
    FastMod() = default;
    explicit FastMod(uint32_t divisor) : b(divisor), m(~uint64_t(0) / divisor + 1) {}
    uint32_t operator()(uint32_t n) const {
        const uint64_t fraction32 = ((m * n) >> 32) + 1;
        return static_cast<uint32_t>((fraction32 * b) >> 32);
    }
};

// ---------------------------------------------------------------------------------------------
// Tables built once: Sobol' direction integers, Halton bases and their digit counts.

struct HaltonBase {
    uint32_t base = 2;
    int digits = 53;          ///< K: base^-K <= 2^-53, the digits a randomized point carries
    int chunk = 53;           ///< g: the largest g with base^g <= 2^53
    double chunk_scale = 0.0; ///< base^g, exact in double
    FastMod mod;              ///< remainders modulo base
};

struct QmcTables {
    uint32_t sobol[kSobolMaxDim][kDigitBits]; ///< v_k = m_k 2^(32-k), k = 1 .. 32
    HaltonBase halton[kHaltonMaxDim];
    QmcTables();
};

// Direction integers v_k = m_k 2^(32-k) from the initial m_1 .. m_s and the primitive
// polynomial by the recurrence v_k = a_1 v_(k-1) ^ ... ^ a_(s-1) v_(k-s+1) ^ v_(k-s) ^
// (v_(k-s) >> s) [BratleyFox88, JoeKuo08].
void sobol_directions(const SobolRow& row, uint32_t* v) {
    const int s = row.degree;
    for (int k = 0; k < s && k < kDigitBits; ++k) v[k] = uint32_t(row.m[k]) << (31 - k);
    for (int k = s; k < kDigitBits; ++k) {
        uint32_t x = v[k - s] ^ (v[k - s] >> s);
        for (int i = 1; i < s; ++i)
            if ((row.poly >> (s - 1 - i)) & 1u) x ^= v[k - i];
        v[k] = x;
    }
}

QmcTables::QmcTables() {
    for (int k = 0; k < kDigitBits; ++k) sobol[0][k] = uint32_t(1) << (31 - k); // m_k = 1
    for (int j = 1; j < kSobolMaxDim; ++j) sobol_directions(kSobolRows[j - 1], sobol[j]);

    constexpr uint64_t k2p53 = uint64_t(1) << 53;
    uint32_t candidate = 2;
    for (int j = 0; j < kHaltonMaxDim; ++j, ++candidate) {
        for (;; ++candidate) { // next prime by trial division (8161 is the 1024th)
            bool prime = true;
            for (uint32_t q = 2; q * q <= candidate && prime; ++q) prime = candidate % q != 0;
            if (prime) break;
        }
        HaltonBase& h = halton[j];
        h.base = candidate;
        h.mod = FastMod(candidate);
        uint64_t power = 1;
        int g = 0;
        while (power <= k2p53 / candidate) { // power * candidate <= 2^53
            power *= candidate;
            ++g;
        }
        h.chunk = g;
        h.chunk_scale = static_cast<double>(power);
        h.digits = power == k2p53 ? g : g + 1; // base^(g+1) > 2^53 unless base^g is 2^53
    }
}

const QmcTables& tables() {
    static const QmcTables t;
    return t;
}

uint32_t sobol_from_directions(const uint32_t* v, uint64_t index) {
    // Gray-code order [AntonovSaleev79]: the point is the XOR of the directions of the bits
    // of gray(index); bits of gray(index) above the 32 digits are ignored.
    uint32_t g = static_cast<uint32_t>(index ^ (index >> 1));
    uint32_t x = 0;
    for (; g != 0; g &= g - 1) x ^= v[trailing_zeros(g)];
    return x;
}

// ---------------------------------------------------------------------------------------------
// Owen scrambling of base-2 digits by hashing.

// A per-dimension key for the fill bits and the Halton digit permutations.
inline uint64_t dimension_key(uint32_t seed, int dim) {
    return hash_combine(seed, static_cast<uint64_t>(dim));
}

// The 21 fill bits below 32 scrambled digits, hashed from them: the digits below a nested
// scramble's precision are uniform and depend on the point's digits (distinct points have
// distinct 32-digit prefixes, so their fills are draws of a keyed bijection). A 32-bit hash
// (Wellons' lowbias32 [Wellons18]) so that the loop over points vectorizes.
inline uint32_t owen_fill(uint32_t scrambled, uint32_t fill_key) {
    uint32_t h = scrambled ^ fill_key;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h >> (32 - kFillBits);
}

inline uint64_t owen_bits53(uint32_t scrambled, uint32_t fill_key) {
    return (uint64_t(scrambled) << kFillBits) | owen_fill(scrambled, fill_key);
}

// (low + 1/2) 2^-53 for the low kFillBits bits of a 53-bit number k.
inline double low_bits_term(uint64_t k53) {
    return (static_cast<double>(k53 & ((uint64_t(1) << kFillBits) - 1)) + 0.5) * 0x1p-53;
}

// bits53_to_unit(k) with k = high 2^21 + low, given high and low_bits_term(k), without 64-bit
// integers so that the loops over points vectorize: high 2^-32 and (low + 1/2) 2^-53 are exact,
// and their sum is the same single rounding of (k + 1/2) 2^-53.
inline double split_bits53_to_unit(uint32_t high, double low_plus_half_scaled) {
    const double h = static_cast<double>(static_cast<int32_t>(high ^ 0x80000000u)) + 0x1p31;
    const double x = h * 0x1p-32 + low_plus_half_scaled;
    return below_one(x);
}

inline uint64_t shifted_bits53(uint32_t digits, uint64_t shift) {
    return (uint64_t(digits) << kFillBits) ^ shift;
}

// ---------------------------------------------------------------------------------------------
// Halton digits.

// Digits of index in base b, least significant first; returns their count (0 for index 0).
int index_digits(uint64_t index, uint32_t b, uint32_t* digits) {
    int n = 0;
    for (; index != 0; ++n) {
        const uint64_t q = index / b;
        digits[n] = static_cast<uint32_t>(index - q * b);
        index = q;
    }
    return n;
}

// A random permutation d -> (a d + c) mod b of the digits (a in 1 .. b-1, c in 0 .. b-1) drawn
// from a 64-bit hash by multiply-shift (relative bias below b 2^-32). For prime b these maps
// are sharply 2-transitive: one digit goes to a uniform digit, two distinct digits to a
// uniformly random pair of distinct digits, exactly as under a uniformly random permutation.
// The mean and variance of an equal-weight rule depend on the randomization only through the
// laws of single points and of pairs [Owen03], so these maps scramble as well as uniform
// permutations do, for a product and a remainder per digit.
struct DigitMap {
    uint32_t a = 1, c = 0;
};

inline DigitMap digit_map(uint64_t h, uint32_t b) {
    DigitMap m;
    m.a = 1 + static_cast<uint32_t>((uint64_t(static_cast<uint32_t>(h >> 32)) * (b - 1)) >> 32);
    m.c = static_cast<uint32_t>((uint64_t(static_cast<uint32_t>(h)) * b) >> 32);
    return m;
}

inline uint32_t map_digit(DigitMap m, uint32_t d, const FastMod& mod) {
    return mod(m.a * d + m.c);
}

// sum_k e_k b^-(k+1) + tail b^-n for digits e_0 .. e_(n-1): Horner over chunks of g digits
// read as exact integers (b^g <= 2^53), from the last chunk, in double. Only IEEE additions and
// divisions of exact integers, so the result is the same on every platform.
double digits_to_unit(const uint32_t* e, int n, const HaltonBase& hb, double tail) {
    const int g = hb.chunk;
    double x = tail;
    for (int lo = (n - 1) / g * g; lo >= 0; lo -= g) {
        const int hi = lo + g < n ? lo + g : n;
        uint64_t chunk = 0;
        for (int k = lo; k < hi; ++k) chunk = chunk * hb.base + e[k];
        double scale = hb.chunk_scale;
        if (hi - lo < g) {
            uint64_t power = 1;
            for (int k = lo; k < hi; ++k) power *= hb.base;
            scale = static_cast<double>(power);
        }
        x = (static_cast<double>(chunk) + x) / scale;
    }
    return x;
}

// Randomized coordinates carry K digits, b^-K <= 2^-53; the digits of the index beyond its
// length are 0 and scrambled like the others. The point is the centre of its finest cell.
inline double halton_randomized_value(const uint32_t* e, int n, const HaltonBase& hb) {
    return below_one(digits_to_unit(e, n, hb, 0.5));
}

// The number of base-b digits M that tell apart the indices below `points`: b^M >= points
// (M = hb.digits when points is 0 or beyond b^digits).
int distinct_digits(const HaltonBase& hb, uint64_t points) {
    if (points == 0) return hb.digits;
    int m = 0;
    for (uint64_t span = 1; span < points && m < hb.digits; ++m) {
        if (span > (uint64_t(1) << 63) / hb.base) return hb.digits;
        span *= hb.base;
    }
    return m;
}

// Nested scramble [Owen95]: digit k goes through a permutation keyed by the seed, k and the
// index's digits 0 .. k-1 (the prefix index mod b^k, which is the index itself once all its
// digits are consumed; below 2^58, so (prefix, k) packs into 64 bits without collisions).
// Past the index's length the digit is 0 and its image the map's c. From digit M on
// (b^M >= the points drawn, distinct_digits) every point's prefix is its own index, distinct
// from all others', so its digits there are independent uniform draws: they are drawn at once,
// as one 53-bit uniform below b^-M keyed by the index, instead of one hash per digit.
double halton_owen(const uint32_t* digits, int len, const HaltonBase& hb, uint64_t key,
                   int free_from) {
    uint32_t e[kMaxDigits];
    const int nested = len > free_from ? len : free_from; // len <= free_from when in range
    uint64_t prefix = 0, weight = 1;
    for (int k = 0; k < len; ++k) {
        const DigitMap map = digit_map(mix64(key ^ ((prefix << 6) | uint64_t(k))), hb.base);
        e[k] = map_digit(map, digits[k], hb.mod);
        prefix += digits[k] * weight;
        weight *= hb.base;
    }
    for (int k = len; k < nested; ++k)
        e[k] = digit_map(mix64(key ^ ((prefix << 6) | uint64_t(k))), hb.base).c;
    if (nested >= hb.digits) return halton_randomized_value(e, nested, hb);
    const uint64_t tail_bits = mix64(key ^ (prefix << 6) ^ 0x3fu) >> 11; // k = 63: never a digit
    const double tail = (u63_to_double(tail_bits) + 0.5) * 0x1p-53;
    return below_one(digits_to_unit(e, nested, hb, tail));
}

// One random permutation per digit position, the same for every prefix [BraatenWeller79].
inline DigitMap position_map(uint64_t key, int k, uint32_t b) {
    return digit_map(hash_combine(key, static_cast<uint64_t>(k)), b);
}

double halton_permuted(const uint32_t* digits, int len, const HaltonBase& hb,
                       const DigitMap* maps) {
    uint32_t e[kMaxDigits];
    const int n = len > hb.digits ? len : hb.digits;
    for (int k = 0; k < n; ++k) e[k] = map_digit(maps[k], k < len ? digits[k] : 0, hb.mod);
    return halton_randomized_value(e, n, hb);
}

// ---------------------------------------------------------------------------------------------
// Lattice.

// Radical-inverse order: point i of the sequence is point reverse_20(i) of the 2^20-point
// rule, so every first 2^m points form the embedded rule of 2^m points [Hickernell00].
inline uint32_t lattice_rank(uint64_t index) {
    return reverse_bits32(static_cast<uint32_t>(index)) >> (32 - kLatticeBits);
}

inline uint32_t lattice_numerator(uint32_t rank, uint32_t z) {
    return (rank * z) & kLatticeMask; // the low 20 bits of the product are those mod 2^32
}

// k 2^-20 + s mod 1 in 53-bit fixed point, exact.
inline double lattice_shifted(uint32_t numerator, uint64_t shift) {
    return bits53_to_unit(((uint64_t(numerator) << (53 - kLatticeBits)) + shift) & kMask53);
}

// ---------------------------------------------------------------------------------------------
// Randomizer parameters.

inline uint64_t draw_bits53(Pcg32& rng) {
    const uint64_t hi = rng.next_u32() >> 5; // 27 bits
    const uint64_t lo = rng.next_u32() >> 6; // 26 bits
    return (hi << 26) | lo;
}

// Random lower-triangular binary matrix with unit diagonal [Matousek98], as 32 rows: row r
// (digit r + 1, bit 31 - r) has its diagonal bit and uniform bits for the earlier digits.
void draw_lower_triangular(Pcg32& rng, uint32_t* rows) {
    for (int r = 0; r < kDigitBits; ++r) {
        const int bit = 31 - r;
        const uint32_t earlier_digits = static_cast<uint32_t>(~uint64_t(0) << (bit + 1));
        rows[r] = (uint32_t(1) << bit) | (rng.next_u32() & earlier_digits);
    }
}

// y = L x over GF(2), x and y as 32 digits (first digit the most significant bit).
uint32_t apply_lower_triangular(const uint32_t* rows, uint32_t x) {
    uint32_t y = 0;
    for (int r = 0; r < kDigitBits; ++r) y |= parity32(rows[r] & x) << (31 - r);
    return y;
}

struct KindInfo {
    QmcKind kind;
    const char* name;
    QmcRandomization applicable[4];
    int count;
};

constexpr KindInfo kKinds[] = {
    {QmcKind::Sobol,
     "sobol",
     {QmcRandomization::Owen, QmcRandomization::LmsShift, QmcRandomization::DigitalShift,
      QmcRandomization::None},
     4},
    {QmcKind::Halton,
     "halton",
     {QmcRandomization::Owen, QmcRandomization::Permutation, QmcRandomization::None},
     3},
    {QmcKind::Lattice, "lattice", {QmcRandomization::RandomShift, QmcRandomization::None}, 2},
};

const KindInfo& kind_info(QmcKind kind) {
    for (const KindInfo& info : kKinds)
        if (info.kind == kind) return info;
    return kKinds[0];
}

constexpr QmcRandomization kAllRandomizations[] = {
    QmcRandomization::None,         QmcRandomization::Owen,        QmcRandomization::LmsShift,
    QmcRandomization::DigitalShift, QmcRandomization::Permutation, QmcRandomization::RandomShift,
};

bool applies(QmcKind kind, QmcRandomization r) {
    const KindInfo& info = kind_info(kind);
    for (int i = 0; i < info.count; ++i)
        if (info.applicable[i] == r) return true;
    return false;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Names and limits.

const char* qmc_kind_name(QmcKind kind) {
    return kind_info(kind).name;
}

const char* randomization_name(QmcRandomization r) {
    switch (r) {
    case QmcRandomization::None: return "none";
    case QmcRandomization::Owen: return "owen";
    case QmcRandomization::LmsShift: return "lms_shift";
    case QmcRandomization::DigitalShift: return "digital_shift";
    case QmcRandomization::Permutation: return "permutation";
    case QmcRandomization::RandomShift: return "random_shift";
    }
    return "?";
}

bool parse_randomization(const std::string& name, QmcRandomization* r) {
    for (QmcRandomization candidate : kAllRandomizations)
        if (name == randomization_name(candidate)) {
            *r = candidate;
            return true;
        }
    return false;
}

QmcRandomization default_randomization(QmcKind kind) {
    return kind == QmcKind::Lattice ? QmcRandomization::RandomShift : QmcRandomization::Owen;
}

std::string check_randomization(QmcKind kind, QmcRandomization r) {
    if (applies(kind, r)) return "";
    const KindInfo& info = kind_info(kind);
    std::string msg = std::string("randomization '") + randomization_name(r) +
                      "' does not apply to " + info.name + " points (" + info.name + ": ";
    for (int i = 0; i < info.count; ++i) {
        if (i > 0) msg += ", ";
        msg += randomization_name(info.applicable[i]);
    }
    return msg + ")";
}

int qmc_max_dim(QmcKind kind) {
    switch (kind) {
    case QmcKind::Sobol: return kSobolMaxDim;
    case QmcKind::Halton: return kHaltonMaxDim;
    case QmcKind::Lattice: return kLatticeMaxDim;
    }
    return 0;
}

uint64_t qmc_max_points(QmcKind kind) {
    switch (kind) {
    case QmcKind::Sobol: return kSobolMaxPoints;
    case QmcKind::Halton: return kHaltonMaxPoints;
    case QmcKind::Lattice: return kLatticeMaxPoints;
    }
    return 0;
}

// ---------------------------------------------------------------------------------------------
// Points.

uint32_t sobol_u32(uint64_t index, int dim) {
    return sobol_from_directions(tables().sobol[dim], index);
}

const SobolByteTables& sobol_byte_tables() {
    static const SobolByteTables t = [] {
        SobolByteTables b{};
        const QmcTables& q = tables();
        for (int byte = 0; byte < 4; ++byte)
            for (uint32_t g = 0; g < 256; ++g) {
                // The XOR of the directions of gray-code bits 8 byte .. 8 byte + 7 set in g.
                uint32_t c[3] = {0, 0, 0};
                for (int bit = 0; bit < 8; ++bit)
                    if ((g >> bit) & 1u)
                        for (int dim = 0; dim < 3; ++dim) c[dim] ^= q.sobol[dim][8 * byte + bit];
                b.xy[byte][g] = uint64_t(c[0]) | (uint64_t(c[1]) << 32);
                b.z[byte][g] = c[2];
            }
        return b;
    }();
    return t;
}

QmcRandomizer make_qmc_randomizer(QmcKind kind, QmcRandomization r, int dim, uint64_t key,
                                  uint64_t points) {
    QmcRandomizer q;
    q.points = points;
    q.kind = kind;
    q.randomization = r;
    q.dim = dim < 0 ? 0 : (dim > qmc_max_dim(kind) ? qmc_max_dim(kind) : dim);
    q.key = key;
    const uint64_t stream = (uint64_t(kind) << 8) | uint64_t(r);
    for (int j = 0; j < q.dim; ++j) {
        // One generator per dimension: the first d dimensions do not depend on q.dim.
        Pcg32 rng(hash_combine(key, static_cast<uint64_t>(j)), stream);
        switch (r) {
        case QmcRandomization::None: break;
        case QmcRandomization::Owen:
        case QmcRandomization::Permutation: q.seeds.push_back(rng.next_u32()); break;
        case QmcRandomization::DigitalShift:
        case QmcRandomization::RandomShift: q.shifts.push_back(draw_bits53(rng)); break;
        case QmcRandomization::LmsShift: {
            uint32_t rows[kDigitBits];
            draw_lower_triangular(rng, rows);
            // L C: the scrambled generator matrix, column by column (direction integers).
            if (kind == QmcKind::Sobol)
                for (int k = 0; k < kDigitBits; ++k)
                    q.matrices.push_back(apply_lower_triangular(rows, tables().sobol[j][k]));
            q.shifts.push_back(draw_bits53(rng));
            break;
        }
        }
    }
    return q;
}

double qmc_coordinate(const QmcRandomizer& r, uint64_t index, int dim) {
    const size_t j = static_cast<size_t>(dim);
    const QmcRandomization rand =
        applies(r.kind, r.randomization) ? r.randomization : QmcRandomization::None;
    switch (r.kind) {
    case QmcKind::Sobol: {
        if (rand == QmcRandomization::LmsShift)
            return bits53_to_unit(shifted_bits53(
                sobol_from_directions(&r.matrices[j * kDigitBits], index), r.shifts[j]));
        const uint32_t v = sobol_u32(index, dim);
        if (rand == QmcRandomization::Owen) {
            const uint32_t y = owen_scramble_u32(v, r.seeds[j]);
            return bits53_to_unit(
                owen_bits53(y, static_cast<uint32_t>(dimension_key(r.seeds[j], dim))));
        }
        if (rand == QmcRandomization::DigitalShift)
            return bits53_to_unit(shifted_bits53(v, r.shifts[j]));
        return static_cast<double>(v) * 0x1p-32;
    }
    case QmcKind::Halton: {
        const HaltonBase& hb = tables().halton[dim];
        uint32_t digits[kMaxDigits];
        const int len = index_digits(index, hb.base, digits);
        if (rand == QmcRandomization::Owen)
            return halton_owen(digits, len, hb, dimension_key(r.seeds[j], dim),
                               distinct_digits(hb, r.points));
        if (rand == QmcRandomization::Permutation) {
            DigitMap maps[kMaxDigits];
            const uint64_t key = dimension_key(r.seeds[j], dim);
            const int n = len > hb.digits ? len : hb.digits;
            for (int k = 0; k < n; ++k) maps[k] = position_map(key, k, hb.base);
            return halton_permuted(digits, len, hb, maps);
        }
        return digits_to_unit(digits, len, hb, 0.0);
    }
    case QmcKind::Lattice: {
        const uint32_t k = lattice_numerator(lattice_rank(index), kLatticeGenerator[j]);
        if (rand == QmcRandomization::RandomShift) return lattice_shifted(k, r.shifts[j]);
        return static_cast<double>(k) * 0x1p-20;
    }
    }
    return 0.0;
}

namespace {

// Walks the Gray code from point `first`: point i + 1 is point i XOR v[ctz(i + 1)]. v has 64
// entries, zero beyond the 32 digits, so the walk agrees with sobol_from_directions for any
// index. The walk is a serial chain of XORs; the randomization then runs over the digits in a
// separate loop, which the compiler vectorizes.
void sobol_walk(const uint32_t* v, uint64_t first, size_t count, uint32_t* digits) {
    uint32_t x = sobol_from_directions(v, first);
    for (size_t i = 0; i < count; ++i) {
        digits[i] = x;
        x ^= v[trailing_zeros((first + i + 1) | (uint64_t(1) << 63))];
    }
}

MCP_VECTOR_CLONES void sobol_block(const QmcRandomizer& r, QmcRandomization rand, int dim,
                                   uint64_t first, size_t count, double* out) {
    const size_t j = static_cast<size_t>(dim);
    const uint32_t* directions =
        rand == QmcRandomization::LmsShift ? &r.matrices[j * kDigitBits] : tables().sobol[dim];
    const bool reversed = rand == QmcRandomization::Owen; // the hash wants reversed digits
    uint32_t v[64] = {};
    for (int k = 0; k < kDigitBits; ++k)
        v[k] = reversed ? reverse_bits32(directions[k]) : directions[k];
    uint32_t digits[kChunk];
    for (size_t done = 0; done < count; done += kChunk) {
        const size_t n = count - done < kChunk ? count - done : kChunk;
        double* o = out + done;
        sobol_walk(v, first + done, n, digits);
        switch (rand) {
        case QmcRandomization::Owen: {
            const uint32_t seed = r.seeds[j];
            const uint32_t fill_key = static_cast<uint32_t>(dimension_key(seed, dim));
            uint32_t fills[kChunk];
            for (size_t i = 0; i < n; ++i) {
                const uint32_t y = reverse_bits32(owen_hash_reversed(digits[i], seed));
                digits[i] = y;
                fills[i] = owen_fill(y, fill_key);
            }
            for (size_t i = 0; i < n; ++i) {
                const double fill = static_cast<double>(static_cast<int32_t>(fills[i]));
                o[i] = split_bits53_to_unit(digits[i], (fill + 0.5) * 0x1p-53);
            }
            break;
        }
        case QmcRandomization::LmsShift:
        case QmcRandomization::DigitalShift: {
            // The shift's top 32 bits flip the digits; its low 21 bits are the same for every
            // point, so (low + 1/2) 2^-53 is a constant.
            const uint64_t shift = r.shifts[j];
            const uint32_t high = static_cast<uint32_t>(shift >> kFillBits);
            const double low = low_bits_term(shift);
            for (size_t i = 0; i < n; ++i) o[i] = split_bits53_to_unit(digits[i] ^ high, low);
            break;
        }
        default:
            for (size_t i = 0; i < n; ++i) o[i] = static_cast<double>(digits[i]) * 0x1p-32;
            break;
        }
    }
}

// Odometer over the digits of the index in base b: one increment per point, no division.
struct DigitCounter {
    uint32_t digits[kMaxDigits] = {};
    int len = 0;

    void increment(uint32_t b) {
        for (int k = 0; k < kMaxDigits; ++k) {
            if (++digits[k] < b) {
                if (k >= len) len = k + 1;
                return;
            }
            digits[k] = 0;
        }
        len = 0; // wrapped around 2^64
    }
};

void halton_block(const QmcRandomizer& r, QmcRandomization rand, int dim, uint64_t first,
                  size_t count, double* out) {
    const size_t j = static_cast<size_t>(dim);
    const HaltonBase& hb = tables().halton[dim];
    DigitCounter counter;
    counter.len = index_digits(first, hb.base, counter.digits);
    switch (rand) {
    case QmcRandomization::Owen: {
        const uint64_t key = dimension_key(r.seeds[j], dim);
        const int free_from = distinct_digits(hb, r.points);
        for (size_t i = 0; i < count; ++i, counter.increment(hb.base))
            out[i] = halton_owen(counter.digits, counter.len, hb, key, free_from);
        break;
    }
    case QmcRandomization::Permutation: {
        DigitMap maps[kMaxDigits];
        const uint64_t key = dimension_key(r.seeds[j], dim);
        for (int k = 0; k < kMaxDigits; ++k) maps[k] = position_map(key, k, hb.base);
        for (size_t i = 0; i < count; ++i, counter.increment(hb.base))
            out[i] = halton_permuted(counter.digits, counter.len, hb, maps);
        break;
    }
    default:
        for (size_t i = 0; i < count; ++i, counter.increment(hb.base))
            out[i] = digits_to_unit(counter.digits, counter.len, hb, 0.0);
        break;
    }
}

MCP_VECTOR_CLONES void lattice_block(const QmcRandomizer& r, QmcRandomization rand, uint64_t first,
                                     size_t count, PointBlock& u, size_t offset) {
    uint32_t ranks[kChunk];
    for (size_t done = 0; done < count; done += kChunk) {
        const size_t n = count - done < kChunk ? count - done : kChunk;
        for (size_t i = 0; i < n; ++i) ranks[i] = lattice_rank(first + done + i);
        for (int dim = 0; dim < r.dim; ++dim) {
            const uint32_t z = kLatticeGenerator[dim];
            double* out = u.coord(dim) + offset + done;
            if (rand == QmcRandomization::RandomShift) {
                // lattice_shifted in 32-bit pieces: k 2^33 + s = (k 2^12 + s_high) 2^21 + s_low,
                // with no carry out of the low 21 bits.
                const uint64_t shift = r.shifts[static_cast<size_t>(dim)];
                const uint32_t high = static_cast<uint32_t>(shift >> kFillBits);
                const double low = low_bits_term(shift);
                for (size_t i = 0; i < n; ++i)
                    out[i] = split_bits53_to_unit(
                        (lattice_numerator(ranks[i], z) << (32 - kLatticeBits)) + high, low);
            } else {
                for (size_t i = 0; i < n; ++i)
                    out[i] = static_cast<double>(lattice_numerator(ranks[i], z)) * 0x1p-20;
            }
        }
    }
}

} // namespace

void qmc_points(const QmcRandomizer& r, uint64_t first, size_t count, PointBlock& u,
                size_t offset) {
    const QmcRandomization rand =
        applies(r.kind, r.randomization) ? r.randomization : QmcRandomization::None;
    if (r.kind == QmcKind::Lattice) {
        lattice_block(r, rand, first, count, u, offset);
        return;
    }
    for (int dim = 0; dim < r.dim; ++dim) {
        double* out = u.coord(dim) + offset;
        if (r.kind == QmcKind::Sobol)
            sobol_block(r, rand, dim, first, count, out);
        else
            halton_block(r, rand, dim, first, count, out);
    }
}

} // namespace mcp
