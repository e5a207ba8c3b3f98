// Measures of how evenly a point set fills the unit cube, for the sampler lab:
//
// - L2 discrepancies, exact, by their closed forms: the star (anchored-box) discrepancy by
//   Warnock's formula [Warnock72], the centred and the wrap-around discrepancies
//   [Hickernell98]. Each is D^2 = int int K - (2/N) sum_i int K(x_i, .) + (1/N^2) sum_ij
//   K(x_i, x_j) for a product kernel K; the three terms nearly cancel for a good set, so the
//   O(N^2 d) double sum is taken with per-chunk accumulators combined by a compensated sum
//   [Neumaier74], in fixed chunks of rows (the same result for any number of threads).
// - Their expectations for N independent uniform points, (E K(x, x) - int int K) / N.
// - The minimum Euclidean distance between two points, in the cube and on the unit torus.
// - The periodogram of two coordinates on a grid of integer frequencies, and its average over
//   rings of |k| (the usual picture of a blue-noise or low-discrepancy spectrum).
//
// Coordinates are taken in [0, 1]; nothing here validates them (the API layer does).
#pragma once

#include <cstdint>
#include <vector>

namespace mcp {

/// n points in dim dimensions, axis-major: coordinate k of point i is coords[k * n + i].
struct PointSet {
    int dim = 0;
    uint64_t n = 0;
    std::vector<double> coords;

    double at(uint64_t i, int k) const { return coords[static_cast<uint64_t>(k) * n + i]; }
};

/// Limits of the analysis (the API rejects larger sets).
constexpr uint64_t kMaxAnalysisPoints = uint64_t(1) << 20;
constexpr int kMaxAnalysisDim = 64;
/// The O(N^2 d) measures (discrepancies, min_distance) run only when pair_coordinates(n, dim)
/// is at most this: 2^33, about 8.6e9 (a few seconds natively, tens in wasm).
constexpr double kMaxPairCoordinates = 8589934592.0;

/// n (n - 1) / 2 * dim: the pair-coordinate operations of an O(N^2 d) measure (0 for n < 2).
double pair_coordinates(uint64_t n, int dim);
/// pair_coordinates(n, dim) <= kMaxPairCoordinates.
bool pairwise_affordable(uint64_t n, int dim);

/// The discrepancies below take n >= 1, 1 <= dim <= kMaxAnalysisDim and return D, the square
/// root of max(0, D^2) (rounding can leave a tiny negative D^2 for a near-perfect set). They
/// do not check pairwise_affordable: callers do. threads: worker threads for the double sum
/// (0 = the hardware's count; large sets only); the result does not depend on it.
///
/// L2-star discrepancy by Warnock's formula [Warnock72]: D^2 = 3^-d - (2^(1-d)/N) sum_i prod_k
/// (1 - x_ik^2) + (1/N^2) sum_ij prod_k (1 - max(x_ik, x_jk)).
double l2_star_discrepancy(const PointSet& set, int threads = 0);
/// Centred L2 discrepancy [Hickernell98]: with a_ik = |x_ik - 1/2|, D^2 = (13/12)^d - (2/N)
/// sum_i prod_k (1 + a_ik/2 - a_ik^2/2) + (1/N^2) sum_ij prod_k (1 + a_ik/2 + a_jk/2 -
/// |x_ik - x_jk|/2).
double centered_l2_discrepancy(const PointSet& set, int threads = 0);
/// Wrap-around L2 discrepancy [Hickernell98]: with t = |x_ik - x_jk|, D^2 = -(4/3)^d + (1/N^2)
/// sum_ij prod_k (3/2 - t (1 - t)). Invariant under shifts modulo 1.
double wraparound_l2_discrepancy(const PointSet& set, int threads = 0);

/// E[D^2] for n independent uniform points: (E K(x, x) - int int K) / n for the discrepancy's
/// kernel K (derivation in point_analysis.cpp).
double expected_l2_star_squared_iid(uint64_t n, int dim);    ///< (2^-d - 3^-d) / n
double expected_wraparound_squared_iid(uint64_t n, int dim); ///< ((3/2)^d - (4/3)^d) / n
double expected_centered_squared_iid(uint64_t n, int dim);   ///< ((5/4)^d - (13/12)^d) / n

/// The smallest Euclidean distance between two points of different indices (0 when a point is
/// repeated; +infinity for n < 2). toroidal: on the unit torus, each coordinate difference t
/// taken as min(t, 1 - t). O(N^2 d), as the discrepancies (check pairwise_affordable).
double min_distance(const PointSet& set, bool toroidal, int threads = 0);

/// A periodogram on a size x size grid of integer frequencies k = (kx, ky), each from -size/2 to
/// size/2 - 1: power[row * size + column] with row = ky + size/2, column = kx + size/2.
struct PowerSpectrum {
    int size = 0;
    int axis_a = 0, axis_b = 1; ///< the coordinates of kx and ky; axis_b = -1 for a 1-D set
    uint64_t n = 0;
    std::vector<double> power;
};

/// P(k) = (1/N) |sum_j exp(-2 pi i (kx x_j,a + ky x_j,b))|^2: P(0) = N, P(-k) = P(k), and
/// E P(k) = 1 at k != 0 for independent uniform points. size even, 2 .. 1024; axes distinct and
/// in [0, dim). A 1-D set (dim 1) is read as points on the line y = 0: axis_b is ignored and
/// returned as -1, and every row equals the ky = 0 row. Returns an empty spectrum (size 0) for
/// invalid arguments. O(N size^2 / 2) by a blocked complex matrix product.
PowerSpectrum power_spectrum(const PointSet& set, int axis_a, int axis_b, int size,
                             int threads = 0);
/// The complex multiply-adds power_spectrum does: n (size/2 + 1) (size + 1) (4096 points on
/// 256 x 256: 1.35e8, a tenth of a second natively on one core).
double spectrum_operations(uint64_t n, int size);

/// Ring averages of a spectrum: ring m = 1, 2, .. holds the k != 0 with m - 1/2 <= |k| < m + 1/2;
/// only rings wholly inside the grid (m <= size/2 - 1) are kept. frequency[m-1] = m, power the
/// mean P over the ring, count its number of frequencies. For a 1-D spectrum (axis_b = -1) the
/// rings are taken on the ky = 0 row (|k| = |kx|, two frequencies per ring).
struct RadialSpectrum {
    std::vector<double> frequency, power;
    std::vector<uint64_t> count;
};
RadialSpectrum radial_average(const PowerSpectrum& spectrum);

} // namespace mcp
