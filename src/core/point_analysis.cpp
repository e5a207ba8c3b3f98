// Discrepancies, minimum distances and periodograms of point sets (see point_analysis.h).
//
// The O(N^2 d) double sums run over the pairs i < j (plus the diagonal) in chunks of
// kChunkRows rows. A chunk takes its rows four at a time against four columns at a time, the
// sixteen kernel products kept in vector registers while the coordinates go by (structure of
// arrays: each step loads one coordinate of four columns for four rows), the columns in tiles
// that stay in L1. The products go into a compensated sum per chunk, and the chunks' sums are
// added in chunk order [Neumaier74]: threads take whole chunks, so the numbers do not depend on
// how many there are. The three terms of each closed form are then added in double-double.
#include "core/point_analysis.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/parallel.h"
#include "core/simd.h"
#include "core/stats.h"
#include "core/trig.h"

namespace mcp {

namespace {

constexpr int kTile = 256;          ///< columns per tile (d * 2 KB of coordinates)
constexpr uint64_t kChunkRows = 64; ///< rows per chunk (a multiple of 4)
constexpr double kThreadWork = 3e7; ///< pair-coordinates below which one thread does it all

int hardware_threads() {
#if MCPLAY_HAS_THREADS
    const unsigned hw = std::thread::hardware_concurrency();
    return hw > 0 ? static_cast<int>(std::min(hw, 64u)) : 1;
#else
    return 1;
#endif
}

/// Workers for `tasks` tasks of `work` operations in all: `threads` if given, else the
/// hardware's count for large jobs and one for small ones.
int choose_workers(int threads, double work, uint64_t tasks) {
    // Without threads run_workers runs worker 0 alone, and the power spectrum hands out fixed
    // ranges of rows by worker count: it must be told one worker (hardware_threads() is 1).
    const int asked = threads > 0 && MCPLAY_HAS_THREADS ? threads : hardware_threads();
    const int w = threads <= 0 && work < kThreadWork ? 1 : asked;
    return static_cast<int>(std::max<uint64_t>(1, std::min<uint64_t>(uint64_t(w), tasks)));
}

// ---------------------------------------------------------------------------------------
// Double-double arithmetic for the last steps: the three terms of a closed form are of order 1
// while D^2 may be 1e-3 .. 1e-12 of that, so each term is carried as an unevaluated sum
// hi + lo (about 32 digits) until they are added. Dekker's exact product by Veltkamp
// splitting and Knuth's two-sum [Dekker71]: only +, -, * and / (no fma, no libm pow), so the
// same on every platform.

struct DoubleDouble {
    double hi = 0.0, lo = 0.0;
    double value() const { return hi + lo; }
};

DoubleDouble two_product(double a, double b) {
    constexpr double kSplit = 134217729.0; // 2^27 + 1
    const double p = a * b;
    const double ca = kSplit * a, cb = kSplit * b;
    const double ahi = ca - (ca - a), alo = a - ahi;
    const double bhi = cb - (cb - b), blo = b - bhi;
    return {p, ((ahi * bhi - p) + ahi * blo + alo * bhi) + alo * blo};
}

DoubleDouble two_sum(double a, double b) {
    const double s = a + b, bb = s - a;
    return {s, (a - (s - bb)) + (b - bb)};
}

DoubleDouble quick_two_sum(double a, double b) { // |a| >= |b|
    const double s = a + b;
    return {s, b - (s - a)};
}

DoubleDouble operator+(DoubleDouble a, DoubleDouble b) {
    const DoubleDouble s = two_sum(a.hi, b.hi);
    return quick_two_sum(s.hi, s.lo + (a.lo + b.lo));
}

DoubleDouble operator-(DoubleDouble a) {
    return {-a.hi, -a.lo};
}

DoubleDouble operator*(DoubleDouble a, double b) {
    const DoubleDouble p = two_product(a.hi, b);
    return quick_two_sum(p.hi, p.lo + a.lo * b);
}

DoubleDouble operator/(DoubleDouble a, DoubleDouble b) {
    const double q = a.hi / b.hi;
    const DoubleDouble qb = two_product(q, b.hi);
    // a - q b, to first order in the low parts; then one correction of the quotient.
    const double r = ((a.hi - qb.hi) - qb.lo) + a.lo - q * b.lo;
    return quick_two_sum(q, r / b.hi);
}

/// (p/q)^d for small positive integers p, q (d <= 64): p^d and q^d as double-doubles.
DoubleDouble ratio_power(double p, double q, int d) {
    DoubleDouble a{1.0, 0.0}, b{1.0, 0.0};
    for (int k = 0; k < d; ++k) {
        a = a * p;
        b = b * q;
    }
    return a / b;
}

/// A compensated sum [Neumaier74] (core/stats.h) with its value as a double-double.
DoubleDouble value_of(const NeumaierSum& s) {
    return two_sum(s.running_sum(), s.compensation());
}

// ---------------------------------------------------------------------------------------
// The pair loops, written with the vector extension of GCC and clang: four lanes of doubles,
// which the AVX2 clone keeps in one register, the SSE2 build and wasm SIMD128 in two. Every
// operation is the IEEE operation of the scalar code lane by lane (min and abs as selects), so
// a lane computes what pair_value computes, bit for bit.

// Vec4 values never cross a call that is not inlined: the ABI note is moot.
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#elif defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef double Vec4 __attribute__((vector_size(32)));
// The pair loops must be compiled inside each MCP_VECTOR_CLONES entry (for its instruction set),
// not called as one shared baseline copy.
#define MCP_ANALYSIS_INLINE inline __attribute__((always_inline))

inline Vec4 load4(const double* p) {
    Vec4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
inline Vec4 splat4(double x) {
    return Vec4{x, x, x, x};
}
inline double vmin(double a, double b) {
    return a < b ? a : b;
}
inline Vec4 vmin(Vec4 a, Vec4 b) {
    return a < b ? a : b;
}
typedef int64_t Int4 __attribute__((vector_size(32)));
/// |a| by clearing the sign bit, as fabs does (one AND in each build, v128.and in wasm).
inline double vabs(double a) {
    return std::fabs(a);
}
inline Vec4 vabs(Vec4 a) {
    return reinterpret_cast<Vec4>(reinterpret_cast<Int4>(a) & INT64_MAX);
}

// Kernel factors: K(x_i, x_j) = prod_k f(a_ik, a_jk) over transformed coordinates a.

/// L2-star: 1 - max(x, y) = min(1 - x, 1 - y) (exactly so in floating point: x -> 1 - x
/// rounds monotonically); the arrays hold 1 - x.
struct StarFactor {
    template <class T> static T f(T a, T b) { return vmin(a, b); }
};
/// Centred: 1 + |x-1/2|/2 + |y-1/2|/2 - |x-y|/2; the arrays hold s = x - 1/2.
struct CenteredFactor {
    template <class T> static T f(T a, T b) {
        return 1.0 + 0.5 * ((vabs(a) + vabs(b)) - vabs(a - b));
    }
};
/// Wrap-around: 3/2 - t (1 - t) with t = |x - y|; the arrays hold x.
struct WrapFactor {
    template <class T> static T f(T a, T b) {
        const T t = vabs(a - b);
        return 1.5 - t * (1.0 - t);
    }
};
/// Squared coordinate differences, plain and on the torus.
struct PlainSquare {
    template <class T> static T f(T a, T b) {
        const T t = a - b;
        return t * t;
    }
};
struct TorusSquare {
    template <class T> static T f(T a, T b) {
        const T t0 = vabs(a - b);
        const T t = vmin(t0, 1.0 - t0);
        return t * t;
    }
};

/// The pair term of points i and j: prod_k F (kMin false) or sum_k F (kMin true), k in order.
template <class F, bool kMin>
MCP_ANALYSIS_INLINE double pair_value(const double* t, uint64_t n, int d, uint64_t i, uint64_t j) {
    double p = F::f(t[i], t[j]);
    for (int k = 1; k < d; ++k) {
        const double v = F::f(t[uint64_t(k) * n + i], t[uint64_t(k) * n + j]);
        if constexpr (kMin)
            p += v;
        else
            p *= v;
    }
    return p;
}

/// One chunk of rows [i0, i1) against every column j > i: the sum of the pair terms (returned
/// as hi, the return value, + *lo_part) or, kMin, their minimum. Rows go in blocks of four
/// against four columns at a time, the products of all sixteen pairs kept in registers across
/// the coordinates (a column's coordinates are loaded once for four rows); columns in tiles of
/// kTile, which stay in L1 while the chunk's row blocks pass over them. The pairs inside a row
/// block, a last partial block and the columns past the last multiple of four: scalar.
template <class F, bool kMin>
MCP_ANALYSIS_INLINE double pair_chunk(const double* t, uint64_t n, int d, uint64_t i0, uint64_t i1,
                                      double* lo_part) {
    constexpr int kRows = 4;
    NeumaierSum total;
    double best = std::numeric_limits<double>::infinity();
    auto take = [&](double v) {
        if constexpr (kMin)
            best = vmin(v, best);
        else
            total.add(v);
    };
    const uint64_t blocks_end = i0 + (i1 - i0) / kRows * kRows;
    for (uint64_t i = blocks_end; i < i1; ++i)
        for (uint64_t j = i + 1; j < n; ++j) take(pair_value<F, kMin>(t, n, d, i, j));
    for (uint64_t r0 = i0; r0 < blocks_end; r0 += kRows)
        for (int a = 0; a < kRows; ++a)
            for (int b = a + 1; b < kRows; ++b)
                take(pair_value<F, kMin>(t, n, d, r0 + uint64_t(a), r0 + uint64_t(b)));
    // Tiles start at i0 + 4 and every block's first column r0 + 4 is i0 + 4 modulo 4 too: the
    // vector loop ends short of a multiple of four only at n.
    for (uint64_t j0 = i0 + kRows; j0 < n; j0 += kTile) {
        const uint64_t j1 = std::min<uint64_t>(j0 + kTile, n);
        for (uint64_t r0 = i0; r0 < blocks_end; r0 += kRows) {
            uint64_t j = std::max<uint64_t>(j0, r0 + kRows);
            if (j >= j1) break; // the later blocks start later still
            Vec4 acc = kMin ? splat4(best) : Vec4{};
            for (; j + 4 <= j1; j += 4) {
                Vec4 c = load4(t + j);
                Vec4 p0 = F::f(splat4(t[r0]), c), p1 = F::f(splat4(t[r0 + 1]), c);
                Vec4 p2 = F::f(splat4(t[r0 + 2]), c), p3 = F::f(splat4(t[r0 + 3]), c);
                for (int k = 1; k < d; ++k) {
                    const double* tk = t + uint64_t(k) * n;
                    c = load4(tk + j);
                    if constexpr (kMin) {
                        p0 += F::f(splat4(tk[r0]), c);
                        p1 += F::f(splat4(tk[r0 + 1]), c);
                        p2 += F::f(splat4(tk[r0 + 2]), c);
                        p3 += F::f(splat4(tk[r0 + 3]), c);
                    } else {
                        p0 *= F::f(splat4(tk[r0]), c);
                        p1 *= F::f(splat4(tk[r0 + 1]), c);
                        p2 *= F::f(splat4(tk[r0 + 2]), c);
                        p3 *= F::f(splat4(tk[r0 + 3]), c);
                    }
                }
                if constexpr (kMin)
                    acc = vmin(acc, vmin(vmin(p0, p1), vmin(p2, p3)));
                else
                    acc += (p0 + p1) + (p2 + p3);
            }
            for (int l = 0; l < 4; ++l) take(acc[l]);
            for (; j < j1; ++j)
                for (int a = 0; a < kRows; ++a)
                    take(pair_value<F, kMin>(t, n, d, r0 + uint64_t(a), j));
        }
    }
    if constexpr (kMin) {
        *lo_part = 0.0;
        return best;
    }
    const DoubleDouble v = value_of(total);
    *lo_part = v.lo;
    return v.hi;
}

// One non-template entry per kernel, so that on x86-64 GCC compiles the inlined loops for AVX2
// as well (MCP_VECTOR_CLONES); both versions round every step alike (no reduction reordered,
// no contraction), so they agree bit for bit.
using ChunkFunction = double (*)(const double*, uint64_t, int, uint64_t, uint64_t, double*);
MCP_VECTOR_CLONES double star_chunk(const double* t, uint64_t n, int d, uint64_t i0, uint64_t i1,
                                    double* lo) {
    return pair_chunk<StarFactor, false>(t, n, d, i0, i1, lo);
}
MCP_VECTOR_CLONES double centered_chunk(const double* t, uint64_t n, int d, uint64_t i0,
                                        uint64_t i1, double* lo) {
    return pair_chunk<CenteredFactor, false>(t, n, d, i0, i1, lo);
}
MCP_VECTOR_CLONES double wrap_chunk(const double* t, uint64_t n, int d, uint64_t i0, uint64_t i1,
                                    double* lo) {
    return pair_chunk<WrapFactor, false>(t, n, d, i0, i1, lo);
}
MCP_VECTOR_CLONES double plain_min_chunk(const double* t, uint64_t n, int d, uint64_t i0,
                                         uint64_t i1, double* lo) {
    return pair_chunk<PlainSquare, true>(t, n, d, i0, i1, lo);
}
MCP_VECTOR_CLONES double torus_min_chunk(const double* t, uint64_t n, int d, uint64_t i0,
                                         uint64_t i1, double* lo) {
    return pair_chunk<TorusSquare, true>(t, n, d, i0, i1, lo);
}

/// The chunk function over all chunks of rows, in parallel; the chunks' results in order.
std::vector<DoubleDouble> run_chunks(ChunkFunction fn, const std::vector<double>& t, uint64_t n,
                                     int d, int threads) {
    const uint64_t chunks = (n + kChunkRows - 1) / kChunkRows;
    std::vector<DoubleDouble> out(chunks);
    std::atomic<uint64_t> next{0};
    // The first chunks are the longest (row i has n - 1 - i columns): handed out first.
    run_workers(choose_workers(threads, pair_coordinates(n, d), chunks), [&](int) {
        for (uint64_t c = next.fetch_add(1); c < chunks; c = next.fetch_add(1)) {
            double lo = 0.0;
            const double hi =
                fn(t.data(), n, d, c * kChunkRows, std::min(n, (c + 1) * kChunkRows), &lo);
            out[c] = {hi, lo};
        }
    });
    return out;
}

/// (1/N^2) sum_ij K(x_i, x_j) = (1/N^2) (sum_i K(x_i, x_i) + 2 sum_{i<j} K(x_i, x_j)).
DoubleDouble kernel_mean(ChunkFunction fn, const std::vector<double>& t, uint64_t n, int d,
                         DoubleDouble diagonal, int threads) {
    DoubleDouble off;
    for (const DoubleDouble& c : run_chunks(fn, t, n, d, threads)) off = off + c;
    const double nn = static_cast<double>(n);
    return (diagonal + off * 2.0) / (DoubleDouble{nn, 0.0} * nn); // N^2 exact for N < 2^26
}

/// D from D^2 = c0 + c1 + c2, the three terms of a closed form.
double discrepancy_from_terms(DoubleDouble c0, DoubleDouble c1, DoubleDouble c2) {
    const double d2 = (c0 + c1 + c2).value();
    return d2 > 0.0 ? std::sqrt(d2) : 0.0;
}

} // namespace

double pair_coordinates(uint64_t n, int dim) {
    if (n < 2 || dim < 1) return 0.0;
    return 0.5 * static_cast<double>(n) * static_cast<double>(n - 1) * dim;
}

bool pairwise_affordable(uint64_t n, int dim) {
    return pair_coordinates(n, dim) <= kMaxPairCoordinates;
}

double l2_star_discrepancy(const PointSet& set, int threads) {
    const uint64_t n = set.n;
    const int d = set.dim;
    if (n == 0 || d < 1) return std::numeric_limits<double>::quiet_NaN();
    // y = 1 - x; the diagonal K(x_i, x_i) = prod_k y_ik and the middle term's
    // prod_k (1 - x_ik^2) = prod_k y_ik (1 + x_ik) (no cancellation near x = 1).
    std::vector<double> y(set.coords.size());
    for (size_t m = 0; m < y.size(); ++m) y[m] = 1.0 - set.coords[m];
    NeumaierSum diag, middle;
    for (uint64_t i = 0; i < n; ++i) {
        double k = 1.0, h = 1.0;
        for (int a = 0; a < d; ++a) {
            const double yi = y[uint64_t(a) * n + i];
            k *= yi;
            h *= yi * (1.0 + set.at(i, a));
        }
        diag.add(k);
        middle.add(h);
    }
    const double nn = static_cast<double>(n);
    // [Warnock72]: 3^-d - (2^(1-d) / N) sum_i prod_k (1 - x_ik^2) + (1/N^2) sum_ij K.
    const DoubleDouble m = value_of(middle);
    return discrepancy_from_terms(
        ratio_power(1.0, 3.0, d),
        -(DoubleDouble{std::ldexp(m.hi, 1 - d), std::ldexp(m.lo, 1 - d)} / DoubleDouble{nn, 0.0}),
        kernel_mean(star_chunk, y, n, d, value_of(diag), threads));
}

double centered_l2_discrepancy(const PointSet& set, int threads) {
    const uint64_t n = set.n;
    const int d = set.dim;
    if (n == 0 || d < 1) return std::numeric_limits<double>::quiet_NaN();
    std::vector<double> s(set.coords.size());
    for (size_t m = 0; m < s.size(); ++m) s[m] = set.coords[m] - 0.5;
    NeumaierSum diag, middle;
    for (uint64_t i = 0; i < n; ++i) {
        double k = 1.0, h = 1.0;
        for (int a = 0; a < d; ++a) {
            const double u = std::fabs(s[uint64_t(a) * n + i]);
            k *= 1.0 + u;                     // K(x, x): 1 + u/2 + u/2 - 0
            h *= 1.0 + 0.5 * (u * (1.0 - u)); // 1 + u/2 - u^2/2
        }
        diag.add(k);
        middle.add(h);
    }
    const double nn = static_cast<double>(n);
    // [Hickernell98]: (13/12)^d - (2/N) sum_i prod_k (...) + (1/N^2) sum_ij K.
    return discrepancy_from_terms(ratio_power(13.0, 12.0, d),
                                  -(value_of(middle) * 2.0 / DoubleDouble{nn, 0.0}),
                                  kernel_mean(centered_chunk, s, n, d, value_of(diag), threads));
}

double wraparound_l2_discrepancy(const PointSet& set, int threads) {
    const uint64_t n = set.n;
    const int d = set.dim;
    if (n == 0 || d < 1) return std::numeric_limits<double>::quiet_NaN();
    const double nn = static_cast<double>(n);
    // [Hickernell98]: -(4/3)^d + (1/N^2) sum_ij K (the middle term is -2 (4/3)^d: every
    // int K(x, y) dy = (4/3)^d); K(x, x) = (3/2)^d for every point.
    return discrepancy_from_terms(
        -ratio_power(4.0, 3.0, d), DoubleDouble{},
        kernel_mean(wrap_chunk, set.coords, n, d, ratio_power(3.0, 2.0, d) * nn, threads));
}

// For n independent uniform points and a kernel K, E[D^2] = int int K - 2 E int K(x_1, y) dy
// + (1/n^2)(n E K(x, x) + n (n - 1) E K(x, y)) = (E K(x, x) - int int K) / n, since
// E int K(x_1, y) dy = E K(x, y) = int int K for independent x, y. Per coordinate:
// star: E (1 - x) = 1/2, int int (1 - max) = 1/3; wrap-around: K(x, x) = 3/2, and t = |x - y|
// has density 2 (1 - t), so E t (1 - t) = 1/6 and E K = 4/3; centred: E (1 + |x - 1/2|) = 5/4,
// int int = 1 + 1/8 + 1/8 - (1/2)(1/3) = 13/12.
namespace {
double expected_squared(double p1, double q1, double p2, double q2, uint64_t n, int dim) {
    return ((ratio_power(p1, q1, dim) + -ratio_power(p2, q2, dim)) /
            DoubleDouble{static_cast<double>(n), 0.0})
        .value();
}
} // namespace

double expected_l2_star_squared_iid(uint64_t n, int dim) {
    return expected_squared(1.0, 2.0, 1.0, 3.0, n, dim);
}

double expected_wraparound_squared_iid(uint64_t n, int dim) {
    return expected_squared(3.0, 2.0, 4.0, 3.0, n, dim);
}

double expected_centered_squared_iid(uint64_t n, int dim) {
    return expected_squared(5.0, 4.0, 13.0, 12.0, n, dim);
}

double min_distance(const PointSet& set, bool toroidal, int threads) {
    if (set.n < 2 || set.dim < 1) return std::numeric_limits<double>::infinity();
    double best = std::numeric_limits<double>::infinity();
    for (const DoubleDouble& v : run_chunks(toroidal ? torus_min_chunk : plain_min_chunk,
                                            set.coords, set.n, set.dim, threads))
        best = std::min(best, v.hi);
    return std::sqrt(best);
}

// ---------------------------------------------------------------------------------------
// Periodogram. F(kx, ky) = sum_j A_j(kx) B_j(ky) with A_j(kx) = exp(-2 pi i kx x_j) and
// B_j(ky) = exp(-2 pi i ky y_j): a complex matrix product over the points. Only the rows
// ky = -size/2 .. 0 are computed: the other rows follow from F(-k) = conj F(k) (real points).
// A row is kept as four real sums over kx = 0 .. size/2, which give F at kx and at -kx.

namespace {

constexpr int kPhaseStep = 8;       ///< phases computed directly every kPhaseStep frequencies
constexpr int kSpectrumPoints = 64; ///< points per block of phases (a multiple of 4)

/// exp(-2 pi i k x) for k = k0 .. k0 + count - 1 into re[], im[]. Directly (sincos_turns of
/// the fraction of k x, exact: k x as an exact double-double product) at the multiples of
/// kPhaseStep, and in between as that value times exp(-2 pi i r x), r < kPhaseStep, also
/// direct: two or three rounding errors per phase whatever k, and k = 0 gives exactly 1.
/// sin and cos of 2 pi k x: the fraction of k x taken from its exact product, so the phase of
/// a high frequency is as accurate as that of a low one.
SinCos sincos_turns_of_product(int k, double x) {
    const DoubleDouble kx = two_product(static_cast<double>(k), x);
    double u = (kx.hi - std::floor(kx.hi)) + kx.lo; // in [-eps, 1 + eps]
    u = u < 0.0 ? u + 1.0 : (u > 1.0 ? u - 1.0 : u);
    return sincos_turns(u);
}

void phases(double x, int k0, int count, double* re, double* im) {
    SinCos step[kPhaseStep];
    for (int r = 0; r < kPhaseStep; ++r) step[r] = sincos_turns_of_product(r, x);
    const int k1 = k0 + count;
    const int first = k0 >= 0 ? k0 / kPhaseStep * kPhaseStep
                              : -((-k0 + kPhaseStep - 1) / kPhaseStep) * kPhaseStep;
    for (int base = first; base < k1; base += kPhaseStep) {
        const SinCos b = sincos_turns_of_product(base, x);
        for (int r = 0; r < kPhaseStep; ++r) {
            const int k = base + r;
            if (k < k0 || k >= k1) continue;
            // exp(-i a) exp(-i c) = (cos a - i sin a)(cos c - i sin c)
            re[k - k0] = b.cos * step[r].cos - b.sin * step[r].sin;
            im[k - k0] = -(b.sin * step[r].cos + b.cos * step[r].sin);
        }
    }
}

/// The four real sums of a row of F over the columns kx = 0 .. columns - 1, four points a step
/// (A rows a0..a3, 64-byte aligned stride): P += sum A_re B_re, Q += sum A_im B_im,
/// R += sum A_re B_im, S += sum A_im B_re. Then F(kx) = (P - Q) + i (R + S) and, as
/// A_j(-kx) = conj A_j(kx), F(-kx) = (P + Q) + i (R - S): both halves of the row for half the
/// products of the complex ones.
MCP_VECTOR_CLONES void accumulate_row(double* __restrict sum_p, double* __restrict sum_q,
                                      double* __restrict sum_r, double* __restrict sum_s,
                                      const double* are, const double* aim, size_t stride,
                                      const double* br, const double* bi, int points, int columns) {
    for (int j = 0; j < points; j += 4) {
        const double r0 = br[j], r1 = br[j + 1], r2 = br[j + 2], r3 = br[j + 3];
        const double i0 = bi[j], i1 = bi[j + 1], i2 = bi[j + 2], i3 = bi[j + 3];
        const double *a0r = are + size_t(j) * stride, *a1r = a0r + stride, *a2r = a1r + stride,
                     *a3r = a2r + stride;
        const double *a0i = aim + size_t(j) * stride, *a1i = a0i + stride, *a2i = a1i + stride,
                     *a3i = a2i + stride;
        // Two passes, the real parts of A then the imaginary ones: one pass over all four sums
        // kept eight multipliers and eight columns of A live, more than V8's 15 SIMD registers
        // (it spilled six values an iteration); the sums add the same terms in the same order.
        for (int c = 0; c < columns; ++c) {
            sum_p[c] += (r0 * a0r[c] + r1 * a1r[c]) + (r2 * a2r[c] + r3 * a3r[c]);
            sum_r[c] += (i0 * a0r[c] + i1 * a1r[c]) + (i2 * a2r[c] + i3 * a3r[c]);
        }
        for (int c = 0; c < columns; ++c) {
            sum_q[c] += (i0 * a0i[c] + i1 * a1i[c]) + (i2 * a2i[c] + i3 * a3i[c]);
            sum_s[c] += (r0 * a0i[c] + r1 * a1i[c]) + (r2 * a2i[c] + r3 * a3i[c]);
        }
    }
}

} // namespace

PowerSpectrum power_spectrum(const PointSet& set, int axis_a, int axis_b, int size, int threads) {
    PowerSpectrum out;
    const uint64_t n = set.n;
    const bool one_d = set.dim == 1;
    if (n == 0 || set.dim < 1 || size < 2 || size > 1024 || size % 2 != 0 || axis_a < 0 ||
        axis_a >= set.dim || set.coords.size() != n * uint64_t(set.dim))
        return out;
    if (!one_d && (axis_b < 0 || axis_b >= set.dim || axis_b == axis_a)) return out;
    const int half = size / 2;
    const int columns = half + 1;                        // kx = 0 .. half (and their negatives)
    const size_t stride = size_t((columns + 7) / 8 * 8); // 64-byte rows
    const int rows = one_d ? 1 : half + 1;               // ky = -half .. 0, or 0 alone
    const int ky0 = one_d ? 0 : -half;
    const double* xa = set.coords.data() + uint64_t(axis_a) * n;
    const double* xb = one_d ? nullptr : set.coords.data() + uint64_t(axis_b) * n;

    // The four sums of accumulate_row, row after row.
    std::vector<double> sums(size_t(rows) * 4 * stride, 0.0);
    // Workers own fixed ranges of rows and go through all the points, each computing the
    // column phases itself (N size work against the N size^2 / 2 of the product).
    const double work = double(n) * rows * columns;
    const int workers = choose_workers(threads, work, uint64_t(rows));
    run_workers(workers, [&](int w) {
        const int r0 = int(int64_t(rows) * w / workers),
                  r1 = int(int64_t(rows) * (w + 1) / workers);
        if (r0 >= r1) return;
        const int my_rows = r1 - r0;
        std::vector<double> are(kSpectrumPoints * stride, 0.0), aim(kSpectrumPoints * stride, 0.0);
        // B transposed: row-major over frequencies, so a row's point values are contiguous.
        std::vector<double> bre(size_t(my_rows) * kSpectrumPoints, 0.0),
            bim(size_t(my_rows) * kSpectrumPoints, 0.0);
        std::vector<double> tre(static_cast<size_t>(my_rows)), tim(static_cast<size_t>(my_rows));
        for (uint64_t j0 = 0; j0 < n; j0 += kSpectrumPoints) {
            const int m = static_cast<int>(std::min<uint64_t>(kSpectrumPoints, n - j0));
            const int padded = (m + 3) / 4 * 4; // padding points: B = 0 adds exact zeros
            for (int j = 0; j < padded; ++j) {
                if (j < m) {
                    phases(xa[j0 + j], 0, columns, are.data() + size_t(j) * stride,
                           aim.data() + size_t(j) * stride);
                    phases(one_d ? 0.0 : xb[j0 + j], ky0 + r0, my_rows, tre.data(), tim.data());
                } else {
                    std::fill(tre.begin(), tre.end(), 0.0);
                    std::fill(tim.begin(), tim.end(), 0.0);
                }
                for (int r = 0; r < my_rows; ++r) {
                    bre[size_t(r) * kSpectrumPoints + j] = tre[r];
                    bim[size_t(r) * kSpectrumPoints + j] = tim[r];
                }
            }
            for (int r = 0; r < my_rows; ++r) {
                double* row = sums.data() + size_t(r0 + r) * 4 * stride;
                accumulate_row(row, row + stride, row + 2 * stride, row + 3 * stride, are.data(),
                               aim.data(), stride, bre.data() + size_t(r) * kSpectrumPoints,
                               bim.data() + size_t(r) * kSpectrumPoints, padded, columns);
            }
        }
    });

    out.size = size;
    out.axis_a = axis_a;
    out.axis_b = one_d ? -1 : axis_b;
    out.n = n;
    out.power.assign(size_t(size) * size, 0.0);
    const double nn = static_cast<double>(n);
    auto computed = [&](int r, int c) { // P at row r of F (ky = ky0 + r), column c (kx = c - half)
        const int kx = c - half;
        const double* row = sums.data() + size_t(r) * 4 * stride + size_t(kx < 0 ? -kx : kx);
        const double p = row[0], q = row[stride], rr = row[2 * stride], s = row[3 * stride];
        const double re = kx < 0 ? p + q : p - q, im = kx < 0 ? rr - s : rr + s;
        return (re * re + im * im) / nn; // divided, not times 1/N: P(0) = N^2 / N exactly
    };
    for (int row = 0; row < size; ++row) {
        const int ky = row - half;
        for (int col = 0; col < size; ++col) {
            double p;
            if (one_d)
                p = computed(0, col);
            else if (ky <= 0)
                p = computed(row, col);
            else
                p = computed(half - ky, size - col); // P(kx, ky) = P(-kx, -ky)
            out.power[size_t(row) * size + col] = p;
        }
    }
    return out;
}

double spectrum_operations(uint64_t n, int size) {
    return static_cast<double>(n) * (size / 2 + 1) * (size + 1);
}

RadialSpectrum radial_average(const PowerSpectrum& spectrum) {
    RadialSpectrum out;
    const int size = spectrum.size, half = size / 2;
    const int rings = half - 1;
    if (rings < 1 || spectrum.power.size() != size_t(size) * size) return out;
    std::vector<NeumaierSum> sum(static_cast<size_t>(rings));
    out.count.assign(size_t(rings), 0);
    const bool one_d = spectrum.axis_b < 0;
    for (int row = one_d ? half : 0; row < (one_d ? half + 1 : size); ++row) {
        const int64_t ky = row - half;
        for (int col = 0; col < size; ++col) {
            const int64_t kx = col - half, k2 = kx * kx + ky * ky;
            if (k2 == 0) continue;
            // Ring m: (2m - 1)^2 <= 4 |k|^2 < (2m + 1)^2 (never equal: odd squares vs 4 k2).
            int64_t m = static_cast<int64_t>(std::sqrt(static_cast<double>(k2)) + 0.5);
            while ((2 * m + 1) * (2 * m + 1) <= 4 * k2) ++m;
            while (m > 0 && (2 * m - 1) * (2 * m - 1) > 4 * k2) --m;
            if (m < 1 || m > rings) continue;
            sum[size_t(m - 1)].add(spectrum.power[size_t(row) * size + col]);
            ++out.count[size_t(m - 1)];
        }
    }
    for (int m = 1; m <= rings; ++m) {
        out.frequency.push_back(m);
        const uint64_t c = out.count[size_t(m - 1)];
        out.power.push_back(c > 0 ? sum[size_t(m - 1)].value() / static_cast<double>(c) : 0.0);
    }
    return out;
}

} // namespace mcp
