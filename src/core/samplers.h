// Point sets in the unit cube [0,1)^d, generated block by block (structure of arrays) so
// that a run of N samples needs O(1) memory whatever N is.
//
// - Independent: every coordinate an independent uniform.
// - Stratified (jittered): the cube is cut into N cells, one jittered sample per cell.
//   The grid rule for any N (not only perfect powers k^d) is stratification_grid().
// - Latin hypercube (N-rooks) [McKay79]: each axis cut into N slabs, each slab of each axis
//   holds exactly one sample; the slab orders are independent random permutations,
//   evaluated by a keyed bijection instead of stored arrays [Kensler13].
// - Randomized quasi-Monte Carlo (Sobol', Halton, rank-1 lattice; core/qmc.h): a run of N
//   points is K independent randomizations of N/K points each, so that the run's error bar
//   comes from the spread of its K batch means [Owen95, LEcuyerLemieux02].
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/made.h"
#include "core/points.h"
#include "core/qmc.h"
#include "core/rng.h"

namespace mcp {

enum class SamplerKind { Independent, Stratified, LatinHypercube, Sobol, Halton, Lattice };
/// Every sampler, in the order messages and the C API's catalog list them.
inline constexpr SamplerKind kSamplerKinds[] = {
    SamplerKind::Independent, SamplerKind::Stratified, SamplerKind::LatinHypercube,
    SamplerKind::Sobol,       SamplerKind::Halton,     SamplerKind::Lattice};

const char* sampler_name(SamplerKind kind);
/// Parses "independent", "stratified", "latin_hypercube", "sobol", "halton", "lattice".
bool parse_sampler(const std::string& name, SamplerKind* kind);
/// The names parse_sampler knows, comma separated (for messages).
const char* sampler_names();
/// Is the sampler a randomized quasi-Monte Carlo point set (Sobol', Halton, lattice)?
bool is_qmc(SamplerKind kind);
/// The point set behind a quasi-Monte Carlo sampler (is_qmc(kind) must hold).
QmcKind qmc_kind_of(SamplerKind kind);

/// Default number of independent randomizations per run of a quasi-Monte Carlo sampler.
constexpr int kDefaultRandomizations = 16;
/// Randomizations per run: a power of two in [2, kMaxRandomizations] (1 without randomization).
constexpr int kMaxRandomizations = 1024;

/// How a sampler places its points, beyond its kind.
struct SamplerOptions {
    uint64_t per_stratum = 1; ///< stratified: points per cell (1 or 2)
    QmcRandomization randomization = QmcRandomization::Owen; ///< quasi-Monte Carlo samplers
    int randomizations = kDefaultRandomizations;             ///< K; 1 when randomization is None
};

/// "" when the options suit the sampler kind and a sample dimension, else an error naming the
/// field: the randomization must apply to the point set, K must be a power of two in
/// [2, kMaxRandomizations] (exactly 1 for "none"), the dimension within the point set's table.
std::string check_sampler_options(SamplerKind kind, const SamplerOptions& options, int dim);

/// Strata counts k_0..k_{d-1} with k_0 k_1 ... k_{d-1} = n exactly, as even as the
/// factors of n allow: k_j is the largest divisor of the remaining count not above its
/// (d-j)-th root, so the counts never decrease with j. For n = 2^m the counts are powers
/// of two within a factor 2 of each other (n = 8, d = 2: 2 x 4); for prime n the grid
/// degenerates to n slabs along the last axis, which is still a valid stratification.
std::vector<uint64_t> stratification_grid(uint64_t n, int dim);

/// A keyed pseudo-random permutation of [0, n): cycle-walking over a bijection of the
/// enclosing power-of-two range [Kensler13, Black02]; O(1) memory, any n >= 1.
uint64_t permute_index(uint64_t index, uint64_t n, uint64_t key);

/// permute_index's permutation of [0, n) for one key, prepared once (its round keys and the
/// enclosing power of two) for many indices: a pixel's samples share one per dimension.
struct IndexPermutation {
    uint64_t n = 1, mask = 0, round_key[4] = {0, 0, 0, 0};
    int bits = 0;
};
IndexPermutation index_permutation(uint64_t n, uint64_t key);
/// The same value as permute_index(index, p.n, key) for the key `p` was prepared with.
uint64_t permute_index(uint64_t index, const IndexPermutation& p);

/// Everything a run needs to generate its points; built once per run.
struct SamplerPlan {
    SamplerKind kind = SamplerKind::Independent;
    int dim = 1;
    uint64_t total = 0;           ///< N, the number of points of the whole run
    std::vector<uint64_t> strata; ///< stratified: counts per axis (product = total / per_stratum)
    uint64_t per_stratum = 1;     ///< stratified: points per cell (1 or 2)
    std::vector<uint64_t> perm_keys; ///< Latin hypercube: one permutation key per axis
    /// Quasi-Monte Carlo: one randomization per batch; batch k holds points
    /// [batch_begin(k), batch_begin(k + 1)) of the run.
    std::vector<QmcRandomizer> randomizers;
    /// Independent, stratified and Latin hypercube runs: the generator of the jitter at the
    /// run's first draw. Coordinate j of point i is the double drawn at steps 2 (i dim + j) and
    /// 2 (i dim + j) + 1 of its sequence, so every coordinate of every point is addressable
    /// (jitter_at jumps there in O(log N)): blocks may be generated in any order, by any thread.
    Pcg32 jitter;
    size_t batches() const { return randomizers.size(); }
    /// The jitter generator positioned at the first draw of point `index`.
    Pcg32 jitter_at(uint64_t index) const {
        Pcg32 g = jitter;
        g.advance(static_cast<int64_t>(2 * index * static_cast<uint64_t>(dim)));
        return g;
    }
    // total x k stays far below 2^64: runs are at most 2^36 points and k <= 1024.
    uint64_t batch_begin(size_t k) const { return total * k / randomizers.size(); }
};

/// Plans a run of n points in dim dimensions. Latin hypercube keys, the keys of the
/// quasi-Monte Carlo randomizations and the seed and stream of the jitter are drawn from rng.
/// Stratified runs put per_stratum points in each of n / per_stratum cells (n must be a
/// multiple of per_stratum; points 2c and 2c+1 share cell c when per_stratum = 2).
/// Quasi-Monte Carlo runs are min(K, n) batches of (nearly) equal size, each the first points
/// of its own randomization (equal sizes n / K when K divides n, as on the study's ladder).
SamplerPlan make_sampler_plan(SamplerKind kind, int dim, uint64_t n, Pcg32& rng,
                              const SamplerOptions& options = {});

/// Writes points first .. first + count - 1 of the run into u (count <= u.capacity). Blocks
/// may come in any order: a point depends on the plan and its index alone.
void generate_block(const SamplerPlan& plan, uint64_t first, size_t count, PointBlock& u);

/// Coordinate `dim` of point `index` of the run, equal bit for bit to what generate_block
/// writes (random access; the slow path for tests and single points).
double sample_coordinate(const SamplerPlan& plan, uint64_t index, int dim);

} // namespace mcp
