// Ray-scene intersection: the watertight ray-triangle test [Woop13], a binned-SAH BVH
// [Wald07] collapsed to eight children per node (four in wasm: kNodeWidth) and flattened depth
// first, and its traversal, which tests a node's boxes four at a time in float SIMD [Wald08]
// with a slab test made conservative as in [Ize13], and a leaf's triangles two at a time in
// double SIMD.
//
// Robustness, in order of where it matters:
// - Triangle test (double precision): every vertex is translated and sheared into the ray's
//   frame by the same arithmetic whichever triangle it belongs to, and the 2D edge function of
//   an edge P->Q is an antisymmetric function of (P, Q) alone (a product difference,
//   recomputed exactly from fma remainders when it rounds to 0), so two triangles sharing an
//   edge see opposite signs and no ray slips between them [Woop13, sec. 3-4].
// - Boxes (float): a box must never cull a hit its triangles would report, whatever the
//   rounding. Boxes and ray origins are taken relative to the centre c of the scene's bounds
//   (in double), so float rounding is relative to the scene's radius R, not to how far it is
//   from the coordinate origin. Each bound is padded by P = 2^-20 R (plus 2^-40 of the largest
//   coordinate, for the double rounding of the triangle test) and then rounded outwards to
//   float. On an axis k where the origin is within 8 R of c, rounding o_k - c_k to float
//   moves the ray by at most 2^-24 |o_k - c_k| <= P/2, so the float ray still passes through
//   the padded box wherever the double ray meets a triangle. On an axis where it is farther,
//   the ray covers at least 7/8 of that distance before it reaches the box, so the rounding
//   moves the plane distances by at most 2^-23 of the hit's t. The distances (b - o) inv
//   carry a relative error of a few 2^-24 besides. The test absorbs both by accepting
//   t_enter <= t_exit (1 + 2^-18) (the 1 + 2 gamma_3 of [Ize13], with room to spare). NaN
//   from 0 * inf (origin on a plane, direction parallel to it) counts as inside.
// - Two triangles at a time: the pair test (watertight2) does the scalar test's operations in
//   the same order in each lane of a double-precision register, so its numbers are the scalar
//   test's bit for bit; it has no branch per triangle (a leaf's hit pattern is hard to
//   predict for rays that scatter, such as shadow rays to light samples).
// - Ties: the closest hit prefers the lower mesh triangle id among hits at exactly the same
//   t, so the answer does not depend on traversal order: BVH and brute force return the same
//   hits, bit for bit.
//
// Timing: `make bench` times rays per second on the render scenes; stats() gives nodes,
// leaves, depth and bytes. Per ray there is no allocation.
#include "render/accel.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/simd2d.h"
#include "render/simd4.h"

namespace mcp {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kMaxDepth = 64;          // build guard; also the traversal stack size
constexpr uint32_t kLeafTriangles = 2;      // nodes this small are always leaves
constexpr uint32_t kMaxLeafTriangles = 16;  // larger nodes split even when SAH says no
constexpr int kBins = 16;                   // [Wald07] uses 8-32
constexpr double kTraversalCost = 1.0;      // SAH cost of one node visit ...
constexpr double kIntersectCost = 1.0;      // ... relative to one triangle test
constexpr double kBoxPad = 0x1p-20;         // of the scene's radius ...
constexpr double kBoxPadAbsolute = 0x1p-40; // ... plus this of its largest coordinate
constexpr float kFarScale = 1.0f + 0x1p-18f;
constexpr int kWidth = Accelerator::kNodeWidth;
// The BVH traversal's leaf test out of line in wasm: inlined, V8's code for the traversal loop
// ran shadow rays at 0.6-0.85 of the speed (Cornell, Veach; `mcplay_bench --only rays`).
#if defined(__EMSCRIPTEN__)
#define MCP_LEAF_TEST_INLINE __attribute__((noinline))
#else
#define MCP_LEAF_TEST_INLINE
#endif
constexpr uint32_t kStackSize = kWidth * kMaxDepth; // pushes at most kWidth, pops 1, depth <= 64

/// Everything about a ray that the triangle and box tests reuse [Woop13, sec. 3; Ize13].
struct RayPrep {
    double o[3];
    int kx, ky, kz;      // axis permutation: kz is the largest |direction| component
    double sx, sy, sz;   // shear that maps the direction to (0, 0, 1)
    double inv[3];       // 1 / direction (+-inf for zero components)
    int near[3], far[3]; // per axis, the row of WideNode::bounds of the entry / exit plane
    double zero;         // 0, from memory: a literal 0 turns the first max into a branch
};

/// False for a ray with an infinite or NaN direction or origin, or t_max <= 0 / NaN.
__attribute__((always_inline)) inline bool ray_finite(const Ray& ray) {
    const double* d = &ray.direction.x;
    const double* o = &ray.origin.x;
    // x - x is NaN exactly when x is infinite or NaN.
    const double finite = (d[0] - d[0]) + (d[1] - d[1]) + (d[2] - d[2]) + (o[0] - o[0]) +
                          (o[1] - o[1]) + (o[2] - o[2]);
    return finite == 0.0 && ray.t_max > 0.0;
}

/// False for rays no triangle can be reported for: zero, infinite or NaN direction or
/// origin, or t_max <= 0 / NaN. The box tests' reciprocals and plane rows (inv, near, far)
/// are filled only when `boxes` is set (brute force needs only the shear). Forced inline into
/// traverse (GCC kept it out of line, its RayPrep in memory): natively 1.2-1.6x the camera
/// rays per second of the direct-lighting scenes, where the per-ray setup is much of the cost
/// (`mcplay_bench scenes 4194304 --only rays`, 2026-12-07); no change in wasm.
__attribute__((always_inline)) inline bool prepare(const Ray& ray, bool boxes, RayPrep* r) {
    const double d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    const double* o = &ray.origin.x;
    if (!ray_finite(ray)) return false;
    const double ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
    const int kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    if (!(std::fabs(d[kz]) > 0.0)) return false;
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0) std::swap(kx, ky); // keeps the winding, hence the sign of the edges
    for (int k = 0; k < 3; ++k) r->o[k] = o[k];
    if (boxes) {
        for (int k = 0; k < 3; ++k) {
            r->inv[k] = 1.0 / d[k]; // -0 gives -inf: the sign still orders the planes
            const int neg = std::signbit(r->inv[k]) ? 1 : 0;
            r->near[k] = k + 3 * neg;
            r->far[k] = k + 3 - 3 * neg;
        }
    }
    r->kx = kx;
    r->ky = ky;
    r->kz = kz;
    r->sz = 1.0 / d[kz]; // the same division as inv[kz]
    r->sx = d[kx] * r->sz;
    r->sy = d[ky] * r->sz;
    r->zero = 0.0;
    return true;
}

/// a b - c d exactly rounded in sign: the rounded products plus their exact fma remainders.
/// Called only when the plain difference rounded to 0, i.e. the rounded products are equal,
/// where the sign of the remainders' difference is the exact sign [Woop13, sec. 4.3 uses
/// a wider type for the same purpose].
double exact_difference(double a, double b, double c, double d) {
    const double p = a * b, q = c * d;
    return (p - q) + (std::fma(a, b, -p) - std::fma(c, d, -q));
}

/// Edge functions and scaled distance of a hit: t = T / det, b1 = v / det, b2 = w / det.
struct TriHit {
    double t, v, w, det;
};

/// [Woop13, fig. 2] in double precision, double-sided. Fills *h on a hit with t > 0; the
/// caller compares t with its t_max.
inline bool watertight(const RayPrep& r, const Vec3* p, TriHit* h) {
    const double* p0 = &p[0].x;
    const double* p1 = &p[1].x;
    const double* p2 = &p[2].x;
    // Translate to the ray origin and shear: the ray becomes the +z axis.
    const double a_z = p0[r.kz] - r.o[r.kz];
    const double b_z = p1[r.kz] - r.o[r.kz];
    const double c_z = p2[r.kz] - r.o[r.kz];
    const double a_x = (p0[r.kx] - r.o[r.kx]) - r.sx * a_z;
    const double a_y = (p0[r.ky] - r.o[r.ky]) - r.sy * a_z;
    const double b_x = (p1[r.kx] - r.o[r.kx]) - r.sx * b_z;
    const double b_y = (p1[r.ky] - r.o[r.ky]) - r.sy * b_z;
    const double c_x = (p2[r.kx] - r.o[r.kx]) - r.sx * c_z;
    const double c_y = (p2[r.ky] - r.o[r.ky]) - r.sy * c_z;
    // 2D edge functions; the edge P->Q is always Q.x P.y - Q.y P.x.
    double u = c_x * b_y - c_y * b_x;
    double v = a_x * c_y - a_y * c_x;
    double w = b_x * a_y - b_y * a_x;
    if ((u == 0.0) | (v == 0.0) | (w == 0.0)) {
        if (u == 0.0) u = exact_difference(c_x, b_y, c_y, b_x);
        if (v == 0.0) v = exact_difference(a_x, c_y, a_y, c_x);
        if (w == 0.0) w = exact_difference(b_x, a_y, b_y, a_x);
    }
    if (((u < 0.0) | (v < 0.0) | (w < 0.0)) & ((u > 0.0) | (v > 0.0) | (w > 0.0))) return false;
    const double det = u + v + w;
    if (det == 0.0) return false;
    const double tt = (u * (r.sz * a_z) + v * (r.sz * b_z) + w * (r.sz * c_z)) / det;
    if (!(tt > 0.0)) return false; // also rejects NaN
    h->t = tt;
    h->v = v;
    h->w = w;
    h->det = det;
    return true;
}

/// One of the six axis permutations prepare() picks, known at compile time: kz, and kx, ky the
/// next two axes in cyclic order, exchanged when the direction's kz component is negative. The
/// brute-force loops are instantiated for each, so that the pair test reads a triangle's rows
/// at fixed offsets. A RayPrep is the same permutation known at run time (its kx, ky, kz), as
/// the BVH traversal uses it. In wasm the fixed offsets took quad_light_floor's shadow rays
/// from 43 to 33 ns (native 27 to 26.6 ns; docs/performance-notes.md#the-estimator-loop-in-wasm).
template <int kZ, bool kSwap> struct FixedAxes {
    static constexpr int kz = kZ;
    static constexpr int kx = kSwap ? (kZ + 2) % 3 : (kZ + 1) % 3;
    static constexpr int ky = kSwap ? (kZ + 1) % 3 : (kZ + 2) % 3;
};

/// The ray of a RayPrep in both lanes, for watertight2, on the axes `a` (a RayPrep or a
/// FixedAxes of the same permutation).
struct RayLanes {
    D2 ox, oy, oz; // origin on axes kx, ky, kz
    D2 sx, sy, sz;
};
template <class Axes>
__attribute__((always_inline)) inline RayLanes ray_lanes(const RayPrep& r, const Axes& a) {
    return {d2_set1(r.o[a.kx]), d2_set1(r.o[a.ky]), d2_set1(r.o[a.kz]),
            d2_set1(r.sx),      d2_set1(r.sy),      d2_set1(r.sz)};
}

/// watertight2 for a pair with an edge function exactly 0 (rare): watertight() on each
/// triangle, for its exact sign.
template <bool kInclusive>
inline int watertight2_scalar(const RayPrep& r, const double (*rows)[2], double t_limit,
                              TriHit* h) {
    int hits = 0;
    for (int l = 0; l < 2; ++l) {
        const Vec3 p[3] = {Vec3(rows[0][l], rows[1][l], rows[2][l]),
                           Vec3(rows[3][l], rows[4][l], rows[5][l]),
                           Vec3(rows[6][l], rows[7][l], rows[8][l])};
        TriHit th;
        if (watertight(r, p, &th) && (kInclusive ? th.t <= t_limit : th.t < t_limit)) {
            hits |= 1 << l;
            if (h != nullptr) h[l] = th;
        }
    }
    return hits;
}

/// The same with the RayPrep made again from the ray, out of line: the brute-force loops then
/// keep none in memory (in wasm they then have no stack frame and keep the ray in registers).
template <bool kInclusive>
__attribute__((noinline)) int watertight2_scalar(const Ray& ray, const double (*rows)[2],
                                                 double t_limit, TriHit* h) {
    RayPrep r;
    if (!prepare(ray, false, &r)) return 0; // never: the caller's prepare() was true
    return watertight2_scalar<kInclusive>(r, rows, t_limit, h);
}

/// watertight() on the two triangles of a pair at once, one per lane, with the same operations
/// in the same order (so each lane's numbers are the scalar test's, bit for bit) but no branch
/// per triangle: all of a triangle's arithmetic is done and the outcomes are masks. A lane with
/// an edge function exactly 0 (rare) goes through the scalar test for its exact sign. Returns
/// bit l set where triangle l is hit with 0 < t < t_limit (kInclusive: t <= t_limit), with its
/// edge functions and distance in h[l] unless h is null. `q` and `a` are the lanes and axes of
/// prepare(ray); `r` is its RayPrep, or null to make it again in the rare case. (The BVH
/// traversal keeps its RayPrep in memory anyway, and in wasm its shadow rays ran at 0.8 of
/// the speed with the RayPrep made again.)
template <bool kInclusive, class Axes>
__attribute__((always_inline)) inline int
watertight2(const Ray& ray, const RayPrep* r, const RayLanes& q, const Axes& a,
            const double (*rows)[2], double t_limit, TriHit* h) {
    const D2 zero = d2_set1(0.0);
    const D2 a_z = d2_load(rows[a.kz]) - q.oz;
    const D2 b_z = d2_load(rows[3 + a.kz]) - q.oz;
    const D2 c_z = d2_load(rows[6 + a.kz]) - q.oz;
    const D2 a_x = (d2_load(rows[a.kx]) - q.ox) - q.sx * a_z;
    const D2 a_y = (d2_load(rows[a.ky]) - q.oy) - q.sy * a_z;
    const D2 b_x = (d2_load(rows[3 + a.kx]) - q.ox) - q.sx * b_z;
    const D2 b_y = (d2_load(rows[3 + a.ky]) - q.oy) - q.sy * b_z;
    const D2 c_x = (d2_load(rows[6 + a.kx]) - q.ox) - q.sx * c_z;
    const D2 c_y = (d2_load(rows[6 + a.ky]) - q.oy) - q.sy * c_z;
    const D2 u = c_x * b_y - c_y * b_x;
    const D2 v = a_x * c_y - a_y * c_x;
    const D2 w = b_x * a_y - b_y * a_x;
    if (d2_mask_bits(d2_eq(u, zero) | d2_eq(v, zero) | d2_eq(w, zero)) != 0) {
        return r != nullptr ? watertight2_scalar<kInclusive>(*r, rows, t_limit, h)
                            : watertight2_scalar<kInclusive>(ray, rows, t_limit, h);
    }
    const D2 mixed = (d2_lt(u, zero) | d2_lt(v, zero) | d2_lt(w, zero)) &
                     (d2_gt(u, zero) | d2_gt(v, zero) | d2_gt(w, zero));
    const D2 det = u + v + w;
    const D2 tt = (u * (q.sz * a_z) + v * (q.sz * b_z) + w * (q.sz * c_z)) / det;
    const D2 limit = d2_set1(t_limit);
    const D2 in_range = d2_gt(tt, zero) & (kInclusive ? d2_le(tt, limit) : d2_lt(tt, limit));
    const int hits = d2_mask_bits(d2_andnot(mixed | d2_eq(det, zero), in_range));
    if (hits != 0 && h != nullptr) {
        alignas(16) double t2[2], v2[2], w2[2], det2[2];
        d2_store(t2, tt);
        d2_store(v2, v);
        d2_store(w2, w);
        d2_store(det2, det);
        for (int l = 0; l < 2; ++l) h[l] = TriHit{t2[l], v2[l], w2[l], det2[l]};
    }
    return hits;
}

// --- Build ------------------------------------------------------------------------------

struct Prim {
    double lo[3], hi[3], c[3]; // bounds and their centre
    uint32_t id;
};

struct Box {
    double lo[3] = {kInf, kInf, kInf};
    double hi[3] = {-kInf, -kInf, -kInf};
    void grow(const double* plo, const double* phi) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], plo[k]);
            hi[k] = std::max(hi[k], phi[k]);
        }
    }
    void grow(const Box& b) { grow(b.lo, b.hi); }
    /// Half the surface area (SAH only uses ratios).
    double half_area() const {
        const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
        return dx * dy + dy * dz + dz * dx;
    }
};

/// Bin of centroid coordinate c on the centroid interval [lo, lo + extent], extent > 0.
inline int bin_of(double c, double lo, double extent) {
    const double f = (c - lo) / extent * kBins; // in [0, kBins] as c - lo <= extent
    const int b = static_cast<int>(f);
    return b < 0 ? 0 : (b >= kBins ? kBins - 1 : b);
}

struct SplitDecision {
    bool leaf;
    uint32_t mid;
};

/// Chooses how to treat prims [begin, end) and partitions them: binned SAH on the longest
/// axis of the centroid bounds [Wald07, sec. 3], cost C_trav + C_isect (A_L N_L + A_R N_R)/A
/// against the leaf cost C_isect N. Equal centroids split by count.
SplitDecision decide(std::vector<Prim>& prims, uint32_t begin, uint32_t end, uint32_t depth,
                     const Box& bounds) {
    const uint32_t n = end - begin;
    if (n <= kLeafTriangles || depth >= kMaxDepth) return {true, 0};
    Box cbox;
    for (uint32_t i = begin; i < end; ++i) cbox.grow(prims[i].c, prims[i].c);
    uint32_t axis = 0;
    double extent = cbox.hi[0] - cbox.lo[0];
    for (uint32_t k = 1; k < 3; ++k) {
        if (cbox.hi[k] - cbox.lo[k] > extent) {
            extent = cbox.hi[k] - cbox.lo[k];
            axis = k;
        }
    }
    if (!(extent > 0.0) || !std::isfinite(extent)) {
        if (n <= kMaxLeafTriangles) return {true, 0};
        // All centroids equal (or overflowing): halve by count, ordered where it means anything.
        const uint32_t mid = begin + n / 2;
        std::nth_element(prims.begin() + begin, prims.begin() + mid, prims.begin() + end,
                         [axis](const Prim& a, const Prim& b) { return a.c[axis] < b.c[axis]; });
        return {false, mid};
    }
    const double clo = cbox.lo[axis];
    Box bins[kBins];
    uint32_t counts[kBins] = {};
    for (uint32_t i = begin; i < end; ++i) {
        const int b = bin_of(prims[i].c[axis], clo, extent);
        bins[b].grow(prims[i].lo, prims[i].hi);
        ++counts[b];
    }
    // Sweep from the right: area and count of bins [s, kBins) for the split before bin s.
    double right_area[kBins];
    uint32_t right_count[kBins];
    Box acc;
    uint32_t cnt = 0;
    for (int s = kBins - 1; s > 0; --s) {
        acc.grow(bins[s]);
        cnt += counts[s];
        right_area[s] = acc.half_area();
        right_count[s] = cnt;
    }
    acc = Box();
    cnt = 0;
    double best_cost = kInf;
    int best_split = -1;
    for (int s = 1; s < kBins; ++s) {
        acc.grow(bins[s - 1]);
        cnt += counts[s - 1];
        if (cnt == 0 || right_count[s] == 0) continue;
        const double cost = acc.half_area() * cnt + right_area[s] * right_count[s];
        if (cost < best_cost) {
            best_cost = cost;
            best_split = s;
        }
    }
    const double area = bounds.half_area();
    const double split_cost = kTraversalCost * area + kIntersectCost * best_cost;
    const double leaf_cost = kIntersectCost * n * area;
    if (best_split < 0) return {n <= kMaxLeafTriangles, begin + n / 2}; // cannot happen
    if (!(split_cost < leaf_cost) && n <= kMaxLeafTriangles) return {true, 0};
    const auto it = std::partition(prims.begin() + begin, prims.begin() + end, [&](const Prim& p) {
        return bin_of(p.c[axis], clo, extent) < best_split;
    });
    uint32_t mid = static_cast<uint32_t>(it - prims.begin());
    if (mid == begin || mid == end) mid = begin + n / 2; // unreachable: both sides counted
    return {false, mid};
}

/// A node of the binary SAH tree, before it is collapsed to wide nodes.
struct BuildNode {
    Box bounds;
    uint32_t left = 0, right = 0;  // interior: children (build indices)
    uint32_t first = 0, count = 0; // leaf: triangles [first, first + count) in leaf order
};

/// Binned-SAH binary tree over prims (reordered into leaf order); node 0 is the root.
std::vector<BuildNode> build_binary(std::vector<Prim>& prims, uint32_t* depth_reached) {
    const uint32_t n = static_cast<uint32_t>(prims.size());
    std::vector<BuildNode> nodes;
    nodes.reserve(2 * size_t(n) - 1);
    struct Task {
        uint32_t begin, end, depth, parent;
        bool right;
    };
    std::vector<Task> tasks;
    tasks.push_back({0, n, 0, 0, false});
    while (!tasks.empty()) {
        const Task task = tasks.back();
        tasks.pop_back();
        const uint32_t index = static_cast<uint32_t>(nodes.size());
        nodes.emplace_back();
        if (index > 0) (task.right ? nodes[task.parent].right : nodes[task.parent].left) = index;
        Box bounds;
        for (uint32_t i = task.begin; i < task.end; ++i) bounds.grow(prims[i].lo, prims[i].hi);
        const SplitDecision split = decide(prims, task.begin, task.end, task.depth, bounds);
        nodes[index].bounds = bounds;
        *depth_reached = std::max(*depth_reached, task.depth);
        if (split.leaf) {
            nodes[index].first = task.begin;
            nodes[index].count = task.end - task.begin;
        } else {
            tasks.push_back({split.mid, task.end, task.depth + 1, index, true});
            tasks.push_back({task.begin, split.mid, task.depth + 1, index, false});
        }
    }
    return nodes;
}

/// The largest float <= x and the smallest float >= x.
float float_below(double x) {
    float f = static_cast<float>(x);
    return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity())
                                      : f;
}
float float_above(double x) {
    float f = static_cast<float>(x);
    return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity())
                                      : f;
}

} // namespace

bool intersect_triangle(const Ray& ray, const Vec3& p0, const Vec3& p1, const Vec3& p2, double* t,
                        double* b1, double* b2) {
    RayPrep r;
    if (!prepare(ray, false, &r)) return false;
    const Vec3 p[3] = {p0, p1, p2};
    TriHit h;
    if (!watertight(r, p, &h) || !(h.t < ray.t_max)) return false;
    *t = h.t;
    *b1 = h.v / h.det;
    *b2 = h.w / h.det;
    return true;
}

void Accelerator::build(const Mesh& mesh, AccelKind kind) {
    stats_ = AccelStats();
    nodes_.clear();
    pairs_.clear();
    triangle_id_.clear();

    // Usable triangles: finite vertices, nonzero cross product.
    std::vector<Prim> prims;
    prims.reserve(mesh.triangle_count());
    double scale = 0.0;
    for (size_t i = 0; i < mesh.triangle_count(); ++i) {
        const Vec3 &p0 = mesh.vertex(i, 0), &p1 = mesh.vertex(i, 1), &p2 = mesh.vertex(i, 2);
        bool finite = true;
        for (int k = 0; k < 3; ++k) {
            finite = finite && std::isfinite(p0[k]) && std::isfinite(p1[k]) && std::isfinite(p2[k]);
        }
        if (!finite) continue;
        const Vec3 n = mesh.cross_normal(i);
        if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) continue;
        Prim prim;
        for (int k = 0; k < 3; ++k) {
            prim.lo[k] = std::min(std::min(p0[k], p1[k]), p2[k]);
            prim.hi[k] = std::max(std::max(p0[k], p1[k]), p2[k]);
            prim.c[k] = 0.5 * prim.lo[k] + 0.5 * prim.hi[k];
            scale = std::max(scale, std::max(std::fabs(prim.lo[k]), std::fabs(prim.hi[k])));
        }
        prim.id = static_cast<uint32_t>(i);
        prims.push_back(prim);
    }
    const uint32_t n = static_cast<uint32_t>(prims.size());
    // Auto on a small scene builds the BVH and keeps it only if it is expected to pay.
    const bool choose = kind == AccelKind::Auto && n <= kAutoMaxTriangles;
    if (kind == AccelKind::Auto) kind = n > 0 ? AccelKind::Bvh : AccelKind::BruteForce;

    // Slot of each prim in leaf order, where every leaf starts a pair (an even slot).
    std::vector<uint32_t> slot(n);
    for (uint32_t i = 0; i < n; ++i) slot[i] = i;

    if (kind == AccelKind::Bvh && n > 0) {
        const std::vector<BuildNode> tree = build_binary(prims, &stats_.build_depth);
        std::vector<std::pair<uint32_t, uint32_t>> leaves; // (first, count) in prims order
        for (const BuildNode& b : tree) {
            if (b.count > 0) leaves.emplace_back(b.first, b.count);
        }
        std::sort(leaves.begin(), leaves.end());
        uint32_t next = 0;
        for (const auto& leaf : leaves) {
            for (uint32_t i = 0; i < leaf.second; ++i) slot[leaf.first + i] = next + i;
            next += (leaf.second + 1) & ~1u;
        }
        double radius = 0.0;
        for (int k = 0; k < 3; ++k) {
            const Box& b = tree[0].bounds;
            center_[k] = 0.5 * b.lo[k] + 0.5 * b.hi[k];
            radius = std::max(radius, std::max(b.hi[k] - center_[k], center_[k] - b.lo[k]));
        }
        const double pad = kBoxPad * radius + kBoxPadAbsolute * scale;
        // Collapse: each wide node takes a binary node's children and keeps opening the
        // interior child of largest surface area until it has kWidth [Wald08, sec. 3].
        nodes_.reserve(tree.size() / 2 + 1);
        struct Task {
            uint32_t build, depth; // a binary interior node (or the root leaf) to emit
            uint32_t parent, lane; // where its index goes (parent == UINT32_MAX: the root)
        };
        std::vector<Task> tasks;
        tasks.push_back({0, 0, UINT32_MAX, 0});
        while (!tasks.empty()) {
            const Task task = tasks.back();
            tasks.pop_back();
            const uint32_t index = static_cast<uint32_t>(nodes_.size());
            nodes_.emplace_back();
            if (task.parent != UINT32_MAX) nodes_[task.parent].child[task.lane] = index;
            stats_.max_depth = std::max(stats_.max_depth, task.depth);
            uint32_t lanes[kWidth] = {task.build};
            int used = 1;
            const BuildNode& top = tree[task.build];
            if (top.count == 0) lanes[0] = top.left, lanes[1] = top.right, used = 2;
            while (used < kWidth) {
                int open = -1;
                double area = -1.0;
                for (int l = 0; l < used; ++l) {
                    const BuildNode& b = tree[lanes[l]];
                    if (b.count == 0 && b.bounds.half_area() > area) {
                        area = b.bounds.half_area();
                        open = l;
                    }
                }
                if (open < 0) break;
                const BuildNode& b = tree[lanes[open]];
                lanes[open] = b.left;
                lanes[used++] = b.right;
            }
            WideNode& node = nodes_[index];
            for (int l = 0; l < kWidth; ++l) {
                for (int k = 0; k < 3; ++k) {
                    node.bounds[k][l] = std::numeric_limits<float>::infinity();
                    node.bounds[k + 3][l] = -std::numeric_limits<float>::infinity();
                }
                node.child[l] = 0;
                node.count[l] = 0;
            }
            for (int l = used - 1; l >= 0; --l) {
                const BuildNode& b = tree[lanes[l]];
                for (int k = 0; k < 3; ++k) {
                    node.bounds[k][l] = float_below(b.bounds.lo[k] - center_[k] - pad);
                    node.bounds[k + 3][l] = float_above(b.bounds.hi[k] - center_[k] + pad);
                }
                if (b.count > 0) {
                    node.child[l] = slot[b.first];
                    node.count[l] = b.count;
                    ++stats_.leaves;
                } else {
                    tasks.push_back({lanes[l], task.depth + 1, index, uint32_t(l)});
                }
            }
        }
        nodes_.shrink_to_fit();
        stats_.nodes = static_cast<uint32_t>(nodes_.size());
        // Surface area heuristic [MacDonaldBooth90]: the root is always visited; a child box
        // is entered with the ratio of its area to the root's.
        const double root_area = tree[0].bounds.half_area();
        stats_.expected_node_visits = 1.0;
        for (const WideNode& node : nodes_) {
            for (int l = 0; l < kWidth; ++l) {
                const double dx = double(node.bounds[3][l]) - double(node.bounds[0][l]);
                const double dy = double(node.bounds[4][l]) - double(node.bounds[1][l]);
                const double dz = double(node.bounds[5][l]) - double(node.bounds[2][l]);
                if (!(dx >= 0.0)) continue; // an unused lane's empty box
                const double p = root_area > 0.0 ? (dx * dy + dy * dz + dz * dx) / root_area : 1.0;
                if (node.count[l] == 0)
                    stats_.expected_node_visits += std::min(1.0, p);
                else {
                    stats_.expected_triangle_tests += std::min(1.0, p) * node.count[l];
                    stats_.expected_pair_tests += std::min(1.0, p) * ((node.count[l] + 1) / 2);
                }
            }
        }
        const double bvh_cost =
            kNodeCost * stats_.expected_node_visits + stats_.expected_pair_tests;
        if (choose && !(bvh_cost < double((n + 1) / 2))) {
            kind = AccelKind::BruteForce;
            nodes_.clear();
            nodes_.shrink_to_fit();
            stats_ = AccelStats();
            for (uint32_t i = 0; i < n; ++i) slot[i] = i;
        }
    }
    stats_.kind = kind;
    if (kind == AccelKind::BruteForce) {
        stats_.expected_node_visits = 0.0;
        stats_.expected_triangle_tests = double(n);
        stats_.expected_pair_tests = double((n + 1) / 2);
    }

    // Triangles in leaf order (build order for brute force), two per pair.
    uint32_t slots = 0;
    for (uint32_t i = 0; i < n; ++i) slots = std::max(slots, slot[i] + 1);
    slots = (slots + 1) & ~1u;
    TrianglePair empty;
    for (auto& row : empty.v) row[0] = row[1] = std::numeric_limits<double>::quiet_NaN();
    pairs_.assign(slots / 2, empty);
    triangle_id_.assign(slots, UINT32_MAX);
    triangles_ = n;
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t id = prims[i].id, at = slot[i];
        triangle_id_[at] = id;
        for (int j = 0; j < 3; ++j) {
            for (int k = 0; k < 3; ++k) pairs_[at / 2].v[3 * j + k][at % 2] = mesh.vertex(id, j)[k];
        }
    }
    stats_.bytes = nodes_.size() * sizeof(WideNode) + pairs_.size() * sizeof(TrianglePair) +
                   triangle_id_.size() * sizeof(uint32_t);
}

namespace {

/// Brute force over the n triangles of `pairs` (slots 0 .. n - 1, the last pair padded when n
/// is odd) for a usable ray (prepare() true) whose axis permutation is Axes. hit null: an
/// any-hit query, true at the first hit. Else the closest hit: true when there is one, *hit
/// filled; among hits at the same t the lowest id (ids[slot]) wins, as in
/// Accelerator::traverse. One function per permutation, which makes its own RayPrep (in wasm, a
/// RayPrep handed over in memory cost what the fixed offsets save) and serves both queries:
/// with two callers, and not inlined, it stays out of the function that holds the BVH
/// traversal (Binaryen inlines a function with one caller; the traversal's shadow rays in wasm
/// ran at 0.9 of the speed with the six loops beside it).
template <class Axes, class Pair>
__attribute__((noinline)) bool brute_force_pairs(const Ray& ray, const Pair* pairs,
                                                 const uint32_t* ids, uint32_t n, Hit* hit) {
    const Axes axes;
    const double* d = &ray.direction.x;
    const double* o = &ray.origin.x;
    RayPrep r;
    for (int k = 0; k < 3; ++k) r.o[k] = o[k];
    r.kx = axes.kx;
    r.ky = axes.ky;
    r.kz = axes.kz;
    r.sz = 1.0 / d[axes.kz]; // as in prepare()
    r.sx = d[axes.kx] * r.sz;
    r.sy = d[axes.ky] * r.sz;
    r.zero = 0.0;
    const RayLanes lanes{d2_set1(o[axes.kx]), d2_set1(o[axes.ky]), d2_set1(o[axes.kz]),
                         d2_set1(r.sx),       d2_set1(r.sy),       d2_set1(r.sz)};
    if (hit == nullptr) {
        for (uint32_t at = 0; at < n; at += 2) {
            int hits =
                watertight2<false>(ray, nullptr, lanes, axes, pairs[at / 2].v, ray.t_max, nullptr);
            if (n - at < 2) hits &= 1;
            if (hits != 0) return true;
        }
        return false;
    }
    double best_t = ray.t_max;
    TriHit best_hit{0.0, 0.0, 0.0, 1.0};
    uint32_t best = 0;
    bool found = false;
    for (uint32_t at = 0; at < n; at += 2) {
        TriHit h[2];
        int hits = watertight2<true>(ray, nullptr, lanes, axes, pairs[at / 2].v, best_t, h);
        if (n - at < 2) hits &= 1;
        while (hits != 0) {
            const int l = __builtin_ctz(static_cast<unsigned>(hits));
            hits &= hits - 1;
            const uint32_t i = at + uint32_t(l);
            if (h[l].t < best_t || (found && h[l].t == best_t && ids[i] < ids[best])) {
                best_t = h[l].t;
                best_hit = h[l];
                best = i;
                found = true;
            }
        }
    }
    if (!found) return false;
    hit->t = best_hit.t;
    hit->triangle = ids[best];
    hit->b1 = best_hit.v / best_hit.det;
    hit->b2 = best_hit.w / best_hit.det;
    return true;
}

} // namespace

bool Accelerator::brute_force(const Ray& ray, Hit* hit) const {
    if (triangle_id_.empty() || !ray_finite(ray)) return false;
    const double* d = &ray.direction.x;
    const auto* p = pairs_.data();
    const uint32_t* ids = triangle_id_.data();
    const uint32_t n = triangles_;
    // prepare()'s axes and its test of a zero direction (ax > ay >= 0 and ay > az >= 0 are
    // nonzero), as branches on the comparisons themselves: in wasm, an axis index computed by
    // selects and then branched on cost ~4 ns more a ray.
    const double ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
    if (ax > ay && ax > az) {
        return d[0] < 0.0 ? brute_force_pairs<FixedAxes<0, true>>(ray, p, ids, n, hit)
                          : brute_force_pairs<FixedAxes<0, false>>(ray, p, ids, n, hit);
    }
    if (!(ax > ay) && ay > az) {
        return d[1] < 0.0 ? brute_force_pairs<FixedAxes<1, true>>(ray, p, ids, n, hit)
                          : brute_force_pairs<FixedAxes<1, false>>(ray, p, ids, n, hit);
    }
    if (!(az > 0.0)) return false;
    return d[2] < 0.0 ? brute_force_pairs<FixedAxes<2, true>>(ray, p, ids, n, hit)
                      : brute_force_pairs<FixedAxes<2, false>>(ray, p, ids, n, hit);
}

template <bool kAnyHit> bool Accelerator::traverse(const Ray& ray, Hit* hit) const {
    RayPrep r;
    if (triangle_id_.empty() || !prepare(ray, true, &r)) return false;
    const RayLanes lanes = ray_lanes(r, r);
    double best_t = ray.t_max;
    TriHit best_hit{0.0, 0.0, 0.0, 1.0};
    uint32_t best = 0;
    bool found = false;
    // Tests the `count` triangles of a leaf from slot `first` (even), two at a time; true when
    // an any-hit query can stop. Among a pair's hits the closest-hit rule runs in slot order.
    auto test_leaf = [&](uint32_t first, uint32_t count) MCP_LEAF_TEST_INLINE {
        const uint32_t end = first + count;
        for (uint32_t at = first; at < end; at += 2) {
            TriHit h[2];
            int hits = watertight2<!kAnyHit>(ray, &r, lanes, r, pairs_[at / 2].v,
                                             kAnyHit ? ray.t_max : best_t, h);
            if (end - at < 2) hits &= 1;
            if (kAnyHit) {
                if (hits != 0) return true;
                continue;
            }
            while (hits != 0) {
                const int l = __builtin_ctz(static_cast<unsigned>(hits));
                hits &= hits - 1;
                const uint32_t i = at + uint32_t(l);
                if (h[l].t < best_t ||
                    (found && h[l].t == best_t && triangle_id_[i] < triangle_id_[best])) {
                    best_t = h[l].t;
                    best_hit = h[l];
                    best = i;
                    found = true;
                }
            }
        }
        return false;
    };

    // The ray in float, relative to the scene's centre (see the file comment).
    float o_rel[3];
    for (int k = 0; k < 3; ++k) o_rel[k] = static_cast<float>(r.o[k] - center_[k]);
    const F4 ox = f4_set1(o_rel[0]);
    const F4 oy = f4_set1(o_rel[1]);
    const F4 oz = f4_set1(o_rel[2]);
    const F4 ix = f4_set1(static_cast<float>(r.inv[0]));
    const F4 iy = f4_set1(static_cast<float>(r.inv[1]));
    const F4 iz = f4_set1(static_cast<float>(r.inv[2]));
    const F4 zero = f4_set1(0.0f), far_scale = f4_set1(kFarScale);
    const int nx = r.near[0], ny = r.near[1], nz = r.near[2];
    const int fx = r.far[0], fy = r.far[1], fz = r.far[2];

    // Children met by the ray wait on the stack, nearest on top, with their entry
    // distance; one is skipped when a hit got closer than its box.
    struct Pending {
        uint32_t child, count; // count 0: a node; else a leaf's triangles
        float t_enter;
    };
    Pending stack[kStackSize];
    uint32_t top = 0, current = 0;
    for (;;) {
        const WideNode& node = nodes_[current];
        const float t_max = static_cast<float>(best_t);
        // Slab test of the boxes, four at a time [KayKajiya86]; max_keep / min_keep
        // ignore NaN.
        const F4 t_far = f4_set1(t_max);
        int mask = 0;
        alignas(16) float t_enter[kWidth];
        for (int g = 0; g < kWidth; g += 4) {
            const F4 tx0 = (f4_load(node.bounds[nx] + g) - ox) * ix;
            const F4 tx1 = (f4_load(node.bounds[fx] + g) - ox) * ix;
            const F4 ty0 = (f4_load(node.bounds[ny] + g) - oy) * iy;
            const F4 ty1 = (f4_load(node.bounds[fy] + g) - oy) * iy;
            const F4 tz0 = (f4_load(node.bounds[nz] + g) - oz) * iz;
            const F4 tz1 = (f4_load(node.bounds[fz] + g) - oz) * iz;
            const F4 t0 = f4_max_keep(tz0, f4_max_keep(ty0, f4_max_keep(tx0, zero)));
            const F4 t1 = f4_min_keep(tz1, f4_min_keep(ty1, f4_min_keep(tx1, t_far)));
            mask |= f4_le_mask(t0, t1 * far_scale) << g;
            f4_store(t_enter + g, t0);
        }
        // One interior child met: go straight down.
        if ((mask & (mask - 1)) == 0 && mask != 0) {
            const int l = __builtin_ctz(static_cast<unsigned>(mask));
            if (node.count[l] == 0) {
                current = node.child[l];
                continue;
            }
        }
        // Push the boxes met, farthest first (closest hit); an any-hit query tests the
        // leaves met at once and pushes only the nodes.
        const uint32_t base = top;
        while (mask != 0) {
            const int l = __builtin_ctz(static_cast<unsigned>(mask));
            mask &= mask - 1;
            const Pending p{node.child[l], node.count[l], t_enter[l]};
            uint32_t at = top++;
            if (kAnyHit) {
                if (p.count == 0) {
                    stack[at] = p;
                    continue;
                }
                --top;
                if (test_leaf(p.child, p.count)) return true;
                continue;
            }
            for (; at > base && stack[at - 1].t_enter < p.t_enter; --at) stack[at] = stack[at - 1];
            stack[at] = p;
        }
        bool descend = false;
        while (top > 0) {
            const Pending p = stack[--top];
            if (!kAnyHit && !(p.t_enter <= static_cast<float>(best_t) * kFarScale)) continue;
            if (p.count == 0) {
                current = p.child;
                descend = true;
                break;
            }
            if (test_leaf(p.child, p.count)) return true;
        }
        if (!descend) break;
    }
    if (kAnyHit || !found) return false;
    hit->t = best_hit.t;
    hit->triangle = triangle_id_[best];
    hit->b1 = best_hit.v / best_hit.det;
    hit->b2 = best_hit.w / best_hit.det;
    return true;
}

bool Accelerator::intersect(const Ray& ray, Hit* hit) const {
    return nodes_.empty() ? brute_force(ray, hit) : traverse<false>(ray, hit);
}

bool Accelerator::occluded(const Ray& ray) const {
    return nodes_.empty() ? brute_force(ray, nullptr) : traverse<true>(ray, nullptr);
}

} // namespace mcp
