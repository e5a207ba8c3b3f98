// Ray-scene intersection: a bounding volume hierarchy built with binned SAH [Wald07] and
// collapsed to eight children per node (four in wasm: kNodeWidth), whose boxes are tested in
// float SIMD [Wald08], or a brute-force loop when the surface area heuristic [MacDonaldBooth90]
// expects the BVH not to pay, both on the watertight ray-triangle test of [Woop13], two
// triangles at a time.
#pragma once

#include <cstdint>
#include <vector>

#include "render/scene.h"

namespace mcp {

/// Watertight ray-triangle intersection [Woop13, "Watertight Ray/Triangle Intersection",
/// JCGT 2(1)]: no ray passes between two triangles that share an edge. Returns true and
/// fills t, b1, b2 (barycentrics of p1 and p2) for a hit with 0 < t < t_max. Double-sided.
bool intersect_triangle(const Ray& ray, const Vec3& p0, const Vec3& p1, const Vec3& p2, double* t,
                        double* b1, double* b2);

enum class AccelKind { Auto, BruteForce, Bvh };

struct AccelStats {
    AccelKind kind = AccelKind::BruteForce; ///< what was built (never Auto)
    uint32_t nodes = 0;                     ///< wide nodes (kNodeWidth children)
    uint32_t leaves = 0;                    ///< leaves (runs of triangles)
    uint32_t max_depth = 0;                 ///< of the wide tree (root at 0)
    uint32_t build_depth = 0; ///< of the binary SAH tree it was collapsed from (<= 64)
    uint64_t bytes = 0;       ///< memory of the structure
    /// Per ray, by the surface area heuristic [MacDonaldBooth90]: the wide nodes a ray
    /// visits and the triangles it tests, each weighted by the chance that a ray meeting the
    /// scene's box meets its box (area ratio). For brute force, 0 and the triangle count.
    double expected_node_visits = 0.0;
    double expected_triangle_tests = 0.0;
    /// The same for the pair tests the triangles are tested in: ceil(k / 2) for a leaf of k
    /// triangles. For brute force, 0 visits and ceil(n / 2). Auto compares these.
    double expected_pair_tests = 0.0;
};

class Accelerator {
  public:
    /// Under Auto, scenes of up to this many triangles get the structure of lower expected
    /// cost per ray: brute force's ceil(n / 2) pair tests against the BVH's expected pair
    /// tests plus kNodeCost per expected node visit. Larger scenes always get the BVH.
    static constexpr size_t kAutoMaxTriangles = 64;
    /// Children per BVH node, tested four at a time. Natively, eight visit fewer nodes than
    /// four for about the same latency per node; in wasm, where V8's SIMD code is slower, the
    /// second group of four costs what the saved visits do
    /// (docs/performance-notes.md#traversal-and-the-bvh).
#if defined(__EMSCRIPTEN__)
    static constexpr int kNodeWidth = 4;
#else
    static constexpr int kNodeWidth = 8;
#endif
    /// A node visit's cost in pair tests (both structures test triangles two at a time),
    /// fitted to `make bench`'s rays/closed_N rows (both structures on closed meshes of 4 to 80
    /// triangles; docs/performance-notes.md#traversal-and-the-bvh): 2.7-3.6 natively, 1.9-2.6
    /// in wasm, where V8 runs the float SIMD box test at about native speed and the
    /// double-precision pair test slower.
#if defined(__EMSCRIPTEN__)
    static constexpr double kNodeCost = 2.0;
#else
    static constexpr double kNodeCost = 3.0;
#endif

    /// Builds over the mesh's triangles (which must outlive nothing: the accelerator keeps
    /// its own copy of the vertices it needs). Triangles with a non-finite vertex coordinate
    /// or an exactly zero cross_normal are left out: they are never hit.
    void build(const Mesh& mesh, AccelKind kind = AccelKind::Auto);

    /// Closest hit with 0 < t < ray.t_max; false when there is none. Among hits at exactly
    /// the same t the lowest triangle id wins, so BVH and brute force give the same answer.
    bool intersect(const Ray& ray, Hit* hit) const;
    /// Any hit with 0 < t < ray.t_max (shadow rays).
    bool occluded(const Ray& ray) const;

    const AccelStats& stats() const {
        return stats_;
    }

  private:
    /// A BVH node (32 bytes per child: 256 natively, 128 in wasm): its children's boxes as
    /// lanes of each bound, in float, rounded and padded outwards (see accel.cpp). Unused
    /// lanes hold empty boxes (lo = +inf, hi = -inf), which no ray meets.
    struct alignas(16) WideNode {
        float bounds[6][kNodeWidth]; ///< lo.x, lo.y, lo.z, hi.x, hi.y, hi.z of each child
        uint32_t child[kNodeWidth];  ///< interior child: node index; leaf: first slot (even)
        uint32_t count[kNodeWidth];  ///< triangles of a leaf child; 0 for an interior child
    };
    /// Two triangles' vertices, one per lane (rows p0.x, p0.y, p0.z, p1.x, ..., p2.z), for the
    /// two-at-a-time watertight test of accel.cpp.
    struct alignas(16) TrianglePair {
        double v[9][2];
    };
    template <bool kAnyHit> bool traverse(const Ray& ray, Hit* hit) const; // nodes_ not empty
    bool brute_force(const Ray& ray, Hit* hit) const; // nodes_ empty; hit null: any hit

    AccelStats stats_;
    double center_[3] = {0.0, 0.0, 0.0}; // boxes and ray origins are relative to it
    std::vector<WideNode> nodes_;        // empty for brute force
    // Leaf order: each leaf's triangles start at an even slot; a slot that pads a leaf to whole
    // pairs holds NaN vertices and id UINT32_MAX and is never reported.
    std::vector<TrianglePair> pairs_;   // slots 2k and 2k + 1
    std::vector<uint32_t> triangle_id_; // slot -> mesh triangle id
    uint32_t triangles_ = 0;            // usable triangles (brute force: slots 0 .. n - 1)
};

} // namespace mcp
