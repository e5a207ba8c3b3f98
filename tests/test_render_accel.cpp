// Ray-scene intersection: the watertight triangle test [Woop13] (no ray slips through shared
// edges and vertices of closed meshes), BVH [Wald07] against brute force (same triangle, same
// bits of t), occluded against intersect, t_max, self-intersection of offset ray origins on
// large-coordinate geometry, degenerate input, and the BVH's shape.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "core/warps.h"
#include "render/accel.h"
#include "render/geometry.h"

using namespace mcp;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Vec2 next_u(Pcg32& rng) {
    double u1 = rng.next_double();
    double u2 = rng.next_double();
    return {u1, u2};
}

Vec3 random_direction(Pcg32& rng) {
    return sample_uniform_sphere(next_u(rng));
}

Vec3 random_in_box(Pcg32& rng, const Vec3& lo, const Vec3& hi) {
    double x = rng.next_double(), y = rng.next_double(), z = rng.next_double();
    return lo + (hi - lo) * Vec3(x, y, z);
}

uint32_t add_vertex(Mesh* mesh, const Vec3& p) {
    mesh->position.push_back(p);
    return static_cast<uint32_t>(mesh->position.size() - 1);
}

void add_triangle(Mesh* mesh, const Vec3& a, const Vec3& b, const Vec3& c) {
    uint32_t i = add_vertex(mesh, a), j = add_vertex(mesh, b), k = add_vertex(mesh, c);
    mesh->index.push_back({i, j, k});
    mesh->material.push_back(0);
}

/// Icosphere: an icosahedron subdivided `levels` times, vertices shared (closed, watertight).
Mesh make_icosphere(int levels, const Vec3& center, double radius) {
    const double g = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3> dirs = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                              {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                              {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (Vec3& d : dirs) d = glm::normalize(d);
    std::vector<std::array<uint32_t, 3>> faces = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
        auto mid = [&](uint32_t a, uint32_t b) {
            auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto it = midpoint.find(key);
            if (it != midpoint.end()) return it->second;
            dirs.push_back(glm::normalize(dirs[a] + dirs[b]));
            uint32_t id = static_cast<uint32_t>(dirs.size() - 1);
            midpoint[key] = id;
            return id;
        };
        std::vector<std::array<uint32_t, 3>> next;
        for (const auto& f : faces) {
            uint32_t a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
            next.push_back({f[0], a, c});
            next.push_back({f[1], b, a});
            next.push_back({f[2], c, b});
            next.push_back({a, b, c});
        }
        faces = next;
    }
    Mesh mesh;
    for (const Vec3& d : dirs) mesh.position.push_back(center + radius * d);
    mesh.index = faces;
    mesh.material.assign(faces.size(), 0);
    return mesh;
}

/// Closed cube [0, n]^3 * h + offset, each face an n x n grid of quads split into two
/// triangles (alternating diagonals), vertices shared across faces.
Mesh make_cube(int n, double h, const Vec3& offset) {
    Mesh mesh;
    std::map<std::array<int, 3>, uint32_t> ids;
    auto vertex = [&](std::array<int, 3> g) {
        auto it = ids.find(g);
        if (it != ids.end()) return it->second;
        uint32_t id = add_vertex(&mesh, offset + h * Vec3(g[0], g[1], g[2]));
        ids[g] = id;
        return id;
    };
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side <= n; side += n) {
            for (int i = 0; i < n; ++i) {
                for (int j = 0; j < n; ++j) {
                    std::array<uint32_t, 4> q;
                    const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
                    for (int c = 0; c < 4; ++c) {
                        std::array<int, 3> g;
                        g[axis] = side;
                        g[(axis + 1) % 3] = i + di[c];
                        g[(axis + 2) % 3] = j + dj[c];
                        q[c] = vertex(g);
                    }
                    if ((i + j) % 2 == 0) {
                        mesh.index.push_back({q[0], q[1], q[2]});
                        mesh.index.push_back({q[0], q[2], q[3]});
                    } else {
                        mesh.index.push_back({q[0], q[1], q[3]});
                        mesh.index.push_back({q[1], q[2], q[3]});
                    }
                }
            }
        }
    }
    mesh.material.assign(mesh.index.size(), 0);
    return mesh;
}

/// Planar grid of n x n quads (two triangles each) in z = origin.z, spacing h.
Mesh make_grid(int n, double h, const Vec3& origin) {
    Mesh mesh;
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) add_vertex(&mesh, origin + Vec3(i * h, j * h, 0.0));
    }
    auto id = [n](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            mesh.index.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.index.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    mesh.material.assign(mesh.index.size(), 0);
    return mesh;
}

/// Random triangle soup in [-1, 1]^3: triangles of size up to `size` around random centres.
Mesh make_soup(int count, double size, uint64_t seed) {
    Pcg32 rng(seed, 1u);
    Mesh mesh;
    for (int i = 0; i < count; ++i) {
        Vec3 c = random_in_box(rng, Vec3(-1.0), Vec3(1.0));
        Vec3 a = c + size * random_direction(rng) * rng.next_double();
        Vec3 b = c + size * random_direction(rng) * rng.next_double();
        Vec3 d = c + size * random_direction(rng) * rng.next_double();
        add_triangle(&mesh, a, b, d);
    }
    return mesh;
}

Accelerator build(const Mesh& mesh, AccelKind kind) {
    Accelerator accel;
    accel.build(mesh, kind);
    return accel;
}

/// The two accelerators give bit-identical answers for `ray` (and occluded agrees with
/// intersect for both); returns whether there was a hit.
bool expect_same(const Accelerator& bvh, const Accelerator& brute, const Ray& ray) {
    Hit a, b;
    const bool ha = bvh.intersect(ray, &a);
    const bool hb = brute.intersect(ray, &b);
    EXPECT_EQ(ha, hb);
    EXPECT_EQ(bvh.occluded(ray), ha);
    EXPECT_EQ(brute.occluded(ray), hb);
    if (ha && hb) {
        EXPECT_EQ(a.triangle, b.triangle);
        EXPECT_EQ(a.t, b.t);
        EXPECT_EQ(a.b1, b.b1);
        EXPECT_EQ(a.b2, b.b2);
    }
    return ha;
}

/// Distance from `q` to the plane of triangle `i`.
double plane_distance(const Mesh& mesh, uint32_t i, const Vec3& q) {
    Vec3 n = glm::normalize(mesh.cross_normal(i));
    return std::fabs(glm::dot(q - mesh.vertex(i, 0), n));
}

/// Whether the hit's barycentrics lie in the triangle up to `tol`.
bool barycentrics_inside(const Hit& hit, double tol) {
    return hit.b1 >= -tol && hit.b2 >= -tol && hit.b1 + hit.b2 <= 1.0 + tol;
}

} // namespace

// --- The triangle test alone ------------------------------------------------------------------

TEST(IntersectTriangle, HitDistanceBarycentricsAndBothSides) {
    const Vec3 p0(0.0, 0.0, 1.0), p1(2.0, 0.0, 1.0), p2(0.0, 4.0, 1.0);
    Ray ray;
    ray.origin = Vec3(0.5, 1.0, -1.0);
    ray.direction = Vec3(0.0, 0.0, 2.0); // not unit: t is in its units
    double t, b1, b2;
    ASSERT_TRUE(intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2));
    EXPECT_NEAR(t, 1.0, 1e-15);
    EXPECT_NEAR(b1, 0.25, 1e-15);
    EXPECT_NEAR(b2, 0.25, 1e-15);
    // Reversed winding (back face) is hit too, with the barycentrics following the vertices.
    ASSERT_TRUE(intersect_triangle(ray, p0, p2, p1, &t, &b1, &b2));
    EXPECT_NEAR(b1, 0.25, 1e-15);
    // From the other side, with a negative largest direction component.
    ray.origin = Vec3(0.5, 1.0, 3.0);
    ray.direction = Vec3(0.0, 0.0, -1.0);
    ASSERT_TRUE(intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2));
    EXPECT_NEAR(t, 2.0, 1e-15);
    // Behind the origin, outside, and the open interval (0, t_max).
    ray.direction = Vec3(0.0, 0.0, 1.0);
    EXPECT_FALSE(intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2));
    ray.origin = Vec3(1.5, 1.5, -1.0);
    EXPECT_FALSE(intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2));
    ray.origin = Vec3(0.5, 1.0, -1.0);
    ray.t_max = 2.0; // hit at exactly t = 2
    EXPECT_FALSE(intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2));
    ray.t_max = std::nextafter(2.0, 3.0);
    EXPECT_TRUE(intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2));
    EXPECT_EQ(t, 2.0);
    // A ray starting on the plane (t = 0) does not hit.
    ray.origin = Vec3(0.5, 1.0, 1.0);
    ray.t_max = kInf;
    EXPECT_FALSE(intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2));
}

TEST(IntersectTriangle, BarycentricsReproduceHitPointOnRandomRays) {
    Pcg32 rng(11u, 2u);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        Vec3 p0 = random_in_box(rng, Vec3(-1.0), Vec3(1.0));
        Vec3 p1 = random_in_box(rng, Vec3(-1.0), Vec3(1.0));
        Vec3 p2 = random_in_box(rng, Vec3(-1.0), Vec3(1.0));
        Ray ray;
        ray.origin = random_in_box(rng, Vec3(-2.0), Vec3(2.0));
        Vec3 target = random_in_box(rng, Vec3(-1.0), Vec3(1.0));
        ray.direction = target - ray.origin;
        double t, b1, b2;
        if (!intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2)) continue;
        ++hits;
        Vec3 on_ray = ray.origin + t * ray.direction;
        Vec3 on_tri = (1.0 - b1 - b2) * p0 + b1 * p1 + b2 * p2;
        ASSERT_LT(glm::length(on_ray - on_tri), 1e-9) << i;
        ASSERT_GE(b1, 0.0);
        ASSERT_GE(b2, 0.0);
        ASSERT_LE(b1 + b2, 1.0 + 1e-15);
    }
    EXPECT_GT(hits, 1000);
}

// An edge B->C whose double-precision edge function at the ray rounds to exactly 0 although
// the exact value (4.4e-16) puts the ray outside: the exact recomputation [Woop13, sec. 4.3]
// gives the miss, and the neighbour across the edge gets the hit. Found by an exhaustive
// search over ulp perturbations, checked with rational arithmetic. With the ray along +z
// from the origin the sheared coordinates are the vertices' x, y exactly.
TEST(IntersectTriangle, ZeroEdgeFunctionIsRecomputedExactly) {
    const Vec3 a(5.0, -3.0, 1.0), d(-5.0, 3.0, 1.0);
    const Vec3 b(0x1.8000000000008p+1, 0x1.4000000000003p+2, 1.0);
    const Vec3 c(-0x1.7fffffffffffdp+1, -0x1.3fffffffffffap+2, 1.0);
    ASSERT_EQ(c.x * b.y - c.y * b.x, 0.0); // the rounded edge function vanishes
    Ray ray;
    ray.origin = Vec3(0.0, 0.0, -1.0);
    double t, b1, b2;
    EXPECT_FALSE(intersect_triangle(ray, a, b, c, &t, &b1, &b2));
    EXPECT_TRUE(intersect_triangle(ray, d, c, b, &t, &b1, &b2));
    Mesh pair;
    add_triangle(&pair, a, b, c);
    add_triangle(&pair, d, c, b);
    Hit hit;
    ASSERT_TRUE(build(pair, AccelKind::BruteForce).intersect(ray, &hit));
    EXPECT_EQ(hit.triangle, 1u);
}

// --- Watertightness -----------------------------------------------------------------------

// Rays aimed exactly at interior vertices and at points on interior edges of a planar grid
// (non-dyadic spacing, so the shared edges are not axis-exact after the shear), from above and
// below, including axis-parallel and grazing directions: none passes through.
TEST(Watertight, RaysAtSharedEdgesAndVerticesOfAGridAlwaysHit) {
    const int n = 12;
    const double h = 0.1;
    for (Vec3 origin : {Vec3(-0.6, -0.6, 0.3), Vec3(1e4 + 0.3, -2e4, 3e4)}) {
        Mesh grid = make_grid(n, h, origin);
        Accelerator bvh = build(grid, AccelKind::Bvh), brute = build(grid, AccelKind::BruteForce);
        Pcg32 rng(5u, 7u);
        int misses = 0, rays = 0;
        for (int iter = 0; iter < 4000; ++iter) {
            // Interior vertex and a point on one of its edges (right, up or diagonal).
            int i = 1 + static_cast<int>(rng.next_below(n - 1));
            int j = 1 + static_cast<int>(rng.next_below(n - 1));
            const Vec3& a = grid.position[j * (n + 1) + i];
            const Vec3 ends[3] = {grid.position[j * (n + 1) + i + 1],
                                  grid.position[(j + 1) * (n + 1) + i],
                                  grid.position[(j + 1) * (n + 1) + i + 1]};
            const Vec3& b = ends[rng.next_below(3)];
            double s = rng.next_double();
            const Vec3 targets[2] = {a, a + s * (b - a)};
            for (const Vec3& target : targets) {
                Vec3 dirs[3];
                dirs[0] = random_direction(rng);                   // any direction
                dirs[1] = Vec3(0.0, 0.0, rng.next_double() - 0.5); // axis parallel
                double phi = 6.283185307179586 * rng.next_double(), z = 1e-3 * rng.next_double();
                dirs[2] = Vec3(std::cos(phi), std::sin(phi), z); // grazing
                for (Vec3 d : dirs) {
                    if (d.z == 0.0) continue;
                    Ray ray;
                    ray.origin = target - d * (0.05 + rng.next_double());
                    ray.direction = target - ray.origin;
                    Hit hit;
                    ++rays;
                    bool hb = bvh.intersect(ray, &hit);
                    misses += !hb;
                    misses += !brute.occluded(ray);
                    if (hb) {
                        ASSERT_LT(glm::length(ray.origin + hit.t * ray.direction - target),
                                  1e-9 * (1.0 + std::fabs(origin.z)));
                    }
                }
            }
        }
        EXPECT_EQ(misses, 0) << "of " << rays << " rays at grid offset " << origin.x;
    }
}

// Random rays from random interior points of closed meshes (an icosphere and a tessellated
// cube) all hit, on the surface; so do rays aimed exactly at every vertex and at random points
// of every edge.
TEST(Watertight, EveryRayFromInsideAClosedMeshHits) {
    const Vec3 center(0.3, -0.2, 0.1);
    const double radius = 1.7;
    const Mesh meshes[2] = {make_icosphere(3, center, radius),
                            make_cube(6, 0.3, center - Vec3(0.9))};
    for (int m = 0; m < 2; ++m) {
        const Mesh& mesh = meshes[m];
        Accelerator accel = build(mesh, AccelKind::Auto);
        ASSERT_EQ(accel.stats().kind, AccelKind::Bvh);
        Pcg32 rng(17u, 3u + m);
        int misses = 0, off_surface = 0, outside = 0;
        const int kRays = m == 0 ? 100000 : 30000;
        for (int i = 0; i < kRays; ++i) {
            Ray ray;
            // Interior point: inside the inscribed ball of the icosphere / within the cube.
            if (m == 0) {
                Vec3 d = random_direction(rng);
                ray.origin = center + d * (0.9 * radius * std::cbrt(rng.next_double()));
            } else {
                ray.origin = random_in_box(rng, center - Vec3(0.9), center + Vec3(0.9));
            }
            ray.direction = random_direction(rng);
            Hit hit;
            if (!accel.intersect(ray, &hit)) {
                ++misses;
                continue;
            }
            Vec3 q = ray.origin + hit.t * ray.direction;
            off_surface += plane_distance(mesh, hit.triangle, q) > 1e-12;
            outside += !barycentrics_inside(hit, 1e-12);
        }
        EXPECT_EQ(misses, 0) << "mesh " << m;
        EXPECT_EQ(off_surface, 0) << "mesh " << m;
        EXPECT_EQ(outside, 0) << "mesh " << m;

        // Vertices and edges, from a few interior points including the (symmetric) centre.
        const Vec3 origins[3] = {center, center + Vec3(0.1, 0.2, -0.3),
                                 center + Vec3(0.0, 0.0, 0.5)};
        int targeted = 0;
        for (const Vec3& o : origins) {
            for (const Vec3& p : mesh.position) {
                Ray ray;
                ray.origin = o;
                ray.direction = p - o;
                misses += !accel.occluded(ray);
                ++targeted;
            }
            for (const auto& tri : mesh.index) {
                for (int k = 0; k < 3; ++k) {
                    const Vec3& a = mesh.position[tri[k]];
                    const Vec3& b = mesh.position[tri[(k + 1) % 3]];
                    Ray ray;
                    ray.origin = o;
                    ray.direction = (a + rng.next_double() * (b - a)) - o;
                    misses += !accel.occluded(ray);
                    ++targeted;
                }
            }
        }
        EXPECT_EQ(misses, 0) << "mesh " << m << ", " << targeted << " targeted rays";
    }
}

// --- BVH against brute force --------------------------------------------------------------

TEST(Bvh, MatchesBruteForceOnARandomSoup) {
    Mesh soup = make_soup(2000, 0.15, 23u);
    Accelerator bvh = build(soup, AccelKind::Bvh), brute = build(soup, AccelKind::BruteForce);
    ASSERT_EQ(bvh.stats().kind, AccelKind::Bvh);
    ASSERT_EQ(brute.stats().kind, AccelKind::BruteForce);
    Pcg32 rng(29u, 4u);
    int hits = 0, limited = 0;
    for (int i = 0; i < 4000; ++i) {
        Ray ray;
        ray.origin = random_in_box(rng, Vec3(-1.5), Vec3(1.5));
        ray.direction = random_direction(rng) * (0.5 + rng.next_double());
        if (i % 3 == 1) ray.t_max = 2.0 * rng.next_double(); // occluded vs intersect on t_max
        if (i % 3 == 2) {
            // Through a random vertex: ties between triangles sharing it resolve the same way.
            const Vec3& v = soup.position[rng.next_below(uint32_t(soup.position.size()))];
            ray.direction = v - ray.origin;
        }
        limited += ray.t_max < kInf;
        hits += expect_same(bvh, brute, ray);
        if (::testing::Test::HasFailure()) return;
    }
    EXPECT_GT(hits, 1000);
    EXPECT_GT(limited, 1000); // a third of the rays
}

// Both structures test a leaf's triangles two at a time (one per SIMD lane); their answers
// must be the scalar test's, bit for bit: the closest of intersect_triangle over every triangle
// (lowest id on ties). An odd triangle count leaves a padding lane; rays through vertices and
// along shared edges of a grid make edge functions exactly 0 (the lanes' scalar fallback), and
// rays with t_max at the hit distance probe the limit.
TEST(Accel, PairTestGivesTheScalarTestsAnswers) {
    Mesh mesh = make_soup(301, 0.3, 37u);
    const Mesh grid = make_grid(6, 0.25, Vec3(-0.75, -0.75, 0.1));
    for (size_t t = 0; t < grid.triangle_count(); ++t) {
        add_triangle(&mesh, grid.vertex(t, 0), grid.vertex(t, 1), grid.vertex(t, 2));
    }
    ASSERT_EQ(mesh.triangle_count() % 2, 1u);
    const Accelerator bvh = build(mesh, AccelKind::Bvh);
    const Accelerator brute = build(mesh, AccelKind::BruteForce);
    Pcg32 rng(41u, 6u);
    int hits = 0, zero_edges = 0;
    for (int i = 0; i < 3000; ++i) {
        Ray ray;
        ray.origin = random_in_box(rng, Vec3(-1.5), Vec3(1.5));
        ray.direction = random_direction(rng);
        const uint32_t target = rng.next_below(uint32_t(mesh.triangle_count()));
        if (i % 3 == 1) ray.direction = mesh.vertex(target, int(rng.next_below(3))) - ray.origin;
        if (i % 3 == 2) {
            // Down onto a grid line x = const (an edge shared by two triangles).
            const double x = -0.75 + 0.25 * double(rng.next_below(7));
            ray.origin = Vec3(x, -0.6 + 1.2 * rng.next_double(), 1.0);
            ray.direction = Vec3(0.0, 0.2 * rng.next_double() - 0.1, -1.0);
            ++zero_edges;
        }
        // The reference: the scalar test on every triangle.
        bool found = false;
        Hit ref;
        for (size_t t = 0; t < mesh.triangle_count(); ++t) {
            double th, b1, b2;
            if (!intersect_triangle(ray, mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2),
                                    &th, &b1, &b2))
                continue;
            if (!found || th < ref.t) {
                ref.t = th, ref.b1 = b1, ref.b2 = b2, ref.triangle = uint32_t(t);
                found = true;
            }
        }
        if (i % 4 == 3 && found) ray.t_max = ref.t; // t < t_max is strict: no hit at ref.t
        for (const Accelerator* a : {&bvh, &brute}) {
            Hit h;
            bool want = found && ref.t < ray.t_max;
            if (found && !want) {
                // The closest hit below the new t_max, if any, again by the scalar test.
                for (size_t t = 0; t < mesh.triangle_count(); ++t) {
                    double th, b1, b2;
                    if (intersect_triangle(ray, mesh.vertex(t, 0), mesh.vertex(t, 1),
                                           mesh.vertex(t, 2), &th, &b1, &b2) &&
                        (!want || th < ref.t)) {
                        ref.t = th, ref.b1 = b1, ref.b2 = b2, ref.triangle = uint32_t(t);
                        want = true;
                    }
                }
            }
            ASSERT_EQ(a->intersect(ray, &h), want) << "ray " << i;
            ASSERT_EQ(a->occluded(ray), want) << "ray " << i;
            if (!want) continue;
            EXPECT_EQ(h.triangle, ref.triangle) << "ray " << i;
            EXPECT_EQ(h.t, ref.t) << "ray " << i;
            EXPECT_EQ(h.b1, ref.b1) << "ray " << i;
            EXPECT_EQ(h.b2, ref.b2) << "ray " << i;
            hits += a == &bvh;
        }
        if (::testing::Test::HasFailure()) return;
    }
    EXPECT_GT(hits, 1000);
    EXPECT_GT(zero_edges, 900);
}

TEST(Bvh, MatchesBruteForceOnAClosedMeshWithRaysAtVertices) {
    Mesh sphere = make_icosphere(2, Vec3(0.1, 0.2, 0.3), 1.0);
    Accelerator bvh = build(sphere, AccelKind::Bvh), brute = build(sphere, AccelKind::BruteForce);
    Pcg32 rng(31u, 5u);
    for (int i = 0; i < 4000; ++i) {
        Ray ray;
        ray.origin = random_in_box(rng, Vec3(-2.0), Vec3(2.0));
        const Vec3& v = sphere.position[rng.next_below(uint32_t(sphere.position.size()))];
        ray.direction = i % 2 ? v - ray.origin : random_direction(rng);
        if (i % 4 == 3) ray.t_max = 3.0 * rng.next_double();
        expect_same(bvh, brute, ray);
        if (::testing::Test::HasFailure()) return;
    }
}

// The float box test must never cull what the double triangle test reports: scenes far
// from the coordinate origin, origins far from the scene (beyond the limit where the origin's
// float rounding needs a slack), and directions with exactly zero components.
TEST(Bvh, FloatBoxesCullNothingTheTrianglesWouldReport) {
    struct Case {
        Vec3 offset;   // where the scene is
        double scale;  // its size
        double origin; // how far rays start, in scene sizes
    };
    const Case cases[] = {{Vec3(0.0), 1.0, 1.5},   {Vec3(3e7, -2e6, 5e5), 1e-3, 2.0},
                          {Vec3(0.0), 1.0, 40.0},  {Vec3(1e4, 0.0, -1e4), 10.0, 1e6},
                          {Vec3(-0.5), 1e-6, 1e3}, {Vec3(0.0), 1e5, 1e-2}};
    Pcg32 rng(53u, 10u);
    for (const Case& c : cases) {
        Mesh soup = make_soup(600, 0.2, 59u);
        for (Vec3& p : soup.position) p = c.offset + c.scale * p;
        Accelerator bvh = build(soup, AccelKind::Bvh), brute = build(soup, AccelKind::BruteForce);
        int hits = 0;
        for (int i = 0; i < 1500; ++i) {
            const uint32_t target = rng.next_below(uint32_t(soup.triangle_count()));
            const int corner = int(rng.next_below(3));
            Vec3 p = soup.vertex(target, corner); // through a vertex: ties and shared edges
            if (i % 2) {
                const Vec2 b = sample_triangle_barycentric(next_u(rng));
                p = b.x * soup.vertex(target, 0) + b.y * soup.vertex(target, 1) +
                    (1.0 - b.x - b.y) * soup.vertex(target, 2);
            }
            Ray ray;
            ray.origin = p + c.origin * c.scale * random_direction(rng);
            ray.direction = p - ray.origin;
            if (i % 5 == 0) {
                // Exactly zero components: the ray runs parallel to one or two axes.
                const int axis = int(rng.next_below(3));
                ray.origin[axis] = p[axis];
                ray.direction[axis] = 0.0;
                if (i % 10 == 0) {
                    const int other = (axis + 1) % 3;
                    ray.origin[other] = p[other];
                    ray.direction[other] = 0.0;
                }
            }
            if (i % 7 == 3) ray.t_max = 1.0; // the hit at p is at t = 1 or just before
            hits += expect_same(bvh, brute, ray);
            if (::testing::Test::HasFailure()) return;
        }
        EXPECT_GT(hits, 1000) << "offset " << c.offset.x << " scale " << c.scale;
    }
}

// --- t_max and self-intersection ----------------------------------------------------------

TEST(Accel, TMaxIsRespected) {
    Mesh soup = make_soup(500, 0.2, 37u);
    for (AccelKind kind : {AccelKind::Bvh, AccelKind::BruteForce}) {
        Accelerator accel = build(soup, kind);
        Pcg32 rng(41u, 6u);
        for (int i = 0; i < 2000; ++i) {
            // Aimed at a random point of a random triangle: there is a hit.
            uint32_t target = rng.next_below(uint32_t(soup.triangle_count()));
            Vec2 b = sample_triangle_barycentric(next_u(rng));
            Vec3 p = b.x * soup.vertex(target, 0) + b.y * soup.vertex(target, 1) +
                     (1.0 - b.x - b.y) * soup.vertex(target, 2);
            Ray ray;
            ray.origin = random_in_box(rng, Vec3(-1.5), Vec3(1.5));
            ray.direction = p - ray.origin;
            Hit hit;
            ASSERT_TRUE(accel.intersect(ray, &hit));
            EXPECT_LE(hit.t, 1.0 + 1e-12);
            Ray limited = ray;
            limited.t_max = hit.t; // the closest hit is at t_max: nothing in (0, t_max)
            Hit other;
            EXPECT_FALSE(accel.intersect(limited, &other));
            EXPECT_FALSE(accel.occluded(limited));
            limited.t_max = std::nextafter(hit.t, kInf);
            ASSERT_TRUE(accel.intersect(limited, &other));
            EXPECT_EQ(other.triangle, hit.triangle);
            EXPECT_EQ(other.t, hit.t);
            EXPECT_TRUE(accel.occluded(limited));
        }
    }
}

// Points on triangles with coordinates around 1e4, moved off by offset_ray_origin, with
// directions down to grazing angles of 1e-7 rad on either side: the triangle is not hit again.
TEST(Accel, OffsetOriginsDoNotReHitTheirTriangle) {
    Pcg32 rng(43u, 8u);
    int self_hits = 0;
    for (int i = 0; i < 20000; ++i) {
        Vec3 c = random_in_box(rng, Vec3(-2e4), Vec3(2e4));
        double size = std::pow(10.0, 4.0 * rng.next_double()); // 1 to 1e4
        Vec3 p0 = c + size * random_direction(rng);
        Vec3 p1 = c + size * random_direction(rng);
        Vec3 p2 = c + size * random_direction(rng);
        Vec3 cross = glm::cross(p1 - p0, p2 - p0);
        if (glm::length(cross) < 1e-3 * size * size) continue; // skip slivers
        Vec3 n = glm::normalize(cross);
        Vec2 b = sample_triangle_barycentric(next_u(rng));
        Vec3 p = b.x * p0 + b.y * p1 + (1.0 - b.x - b.y) * p2;
        Vec3 tangent = glm::normalize(glm::cross(n, random_direction(rng)));
        double angle = std::pow(10.0, -7.0 * rng.next_double()); // 1e-7 .. 1 rad
        double side = rng.next_double() < 0.5 ? -1.0 : 1.0;
        Ray ray;
        ray.direction = std::cos(angle) * tangent + side * std::sin(angle) * n;
        ray.origin = offset_ray_origin(p, n, ray.direction);
        double t, b1, b2;
        self_hits += intersect_triangle(ray, p0, p1, p2, &t, &b1, &b2);
    }
    EXPECT_EQ(self_hits, 0);
}

// On a closed convex mesh far from the origin, offset rays leaving a surface point outwards
// never hit anything, and rays leaving inwards always hit another triangle.
TEST(Accel, OffsetRaysOnAFarConvexMesh) {
    const Vec3 center(1e4, -2e4, 1.5e4);
    Mesh sphere = make_icosphere(3, center, 50.0);
    Accelerator accel = build(sphere, AccelKind::Auto);
    Pcg32 rng(47u, 9u);
    int escaped = 0, self = 0, outward_hits = 0;
    for (int i = 0; i < 20000; ++i) {
        uint32_t tri = rng.next_below(uint32_t(sphere.triangle_count()));
        Vec3 n = glm::normalize(sphere.cross_normal(tri));
        if (glm::dot(n, sphere.vertex(tri, 0) - center) < 0.0) n = -n; // outward
        Vec2 b = sample_triangle_barycentric(next_u(rng));
        Vec3 p = b.x * sphere.vertex(tri, 0) + b.y * sphere.vertex(tri, 1) +
                 (1.0 - b.x - b.y) * sphere.vertex(tri, 2);
        Vec3 tangent = glm::normalize(glm::cross(n, random_direction(rng)));
        double angle = std::pow(10.0, -7.0 * rng.next_double());
        Vec3 out = std::cos(angle) * tangent + std::sin(angle) * n;
        Vec3 in = std::cos(angle) * tangent - std::sin(angle) * n;
        Ray ray;
        ray.direction = out;
        ray.origin = offset_ray_origin(p, n, out);
        outward_hits += accel.occluded(ray);
        ray.direction = in;
        ray.origin = offset_ray_origin(p, n, in);
        Hit hit;
        if (!accel.intersect(ray, &hit)) {
            ++escaped;
        } else {
            self += hit.triangle == tri;
        }
    }
    EXPECT_EQ(outward_hits, 0);
    EXPECT_EQ(escaped, 0);
    EXPECT_EQ(self, 0);
}

// --- Degenerate input ---------------------------------------------------------------------

TEST(Accel, EmptyMeshNeverHits) {
    Mesh empty;
    for (AccelKind kind : {AccelKind::Auto, AccelKind::Bvh, AccelKind::BruteForce}) {
        Accelerator accel = build(empty, kind);
        EXPECT_EQ(accel.stats().nodes, 0u);
        Ray ray;
        Hit hit;
        EXPECT_FALSE(accel.intersect(ray, &hit));
        EXPECT_FALSE(accel.occluded(ray));
    }
    Accelerator unbuilt;
    Ray ray;
    Hit hit;
    EXPECT_FALSE(unbuilt.intersect(ray, &hit));
    EXPECT_FALSE(unbuilt.occluded(ray));
}

// Auto keeps the BVH of a small scene only when its expected cost per ray (node visits at
// kNodeCost plus pair tests, by surface area) is below brute force's ceil(n / 2) pair tests.
TEST(Accel, AutoPicksTheStructureOfLowerExpectedCost) {
    // A closed tetrahedron: every box overlaps every other; the BVH saves no test.
    Mesh tetra;
    const Vec3 v[4] = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
    add_triangle(&tetra, v[0], v[1], v[2]);
    add_triangle(&tetra, v[0], v[3], v[1]);
    add_triangle(&tetra, v[0], v[2], v[3]);
    add_triangle(&tetra, v[1], v[3], v[2]);
    const Accelerator t = build(tetra, AccelKind::Auto);
    EXPECT_EQ(t.stats().kind, AccelKind::BruteForce);
    EXPECT_EQ(t.stats().expected_triangle_tests, 4.0);
    EXPECT_EQ(t.stats().expected_pair_tests, 2.0);
    // 16 small triangles in two clusters 100 apart: a ray meets one cluster's box at most,
    // and each box is a small part of the scene's.
    Mesh clusters = make_soup(8, 0.3, 3u);
    const Mesh far = make_soup(8, 0.3, 5u);
    for (size_t i = 0; i < far.triangle_count(); ++i) {
        const Vec3 shift(100.0, 0.0, 0.0);
        add_triangle(&clusters, far.vertex(i, 0) + shift, far.vertex(i, 1) + shift,
                     far.vertex(i, 2) + shift);
    }
    const Accelerator c = build(clusters, AccelKind::Auto);
    EXPECT_EQ(c.stats().kind, AccelKind::Bvh);
    EXPECT_LT(Accelerator::kNodeCost * c.stats().expected_node_visits +
                  c.stats().expected_pair_tests,
              8.0);
    // The BVH built on request reports the tetrahedron's expected costs, above brute force's.
    const Accelerator tb = build(tetra, AccelKind::Bvh);
    EXPECT_EQ(tb.stats().kind, AccelKind::Bvh);
    EXPECT_GE(Accelerator::kNodeCost * tb.stats().expected_node_visits +
                  tb.stats().expected_pair_tests,
              2.0);
    // Above kAutoMaxTriangles the BVH is kept without comparing.
    Mesh large = make_soup(int(Accelerator::kAutoMaxTriangles) + 1, 0.3, 3u);
    EXPECT_EQ(build(large, AccelKind::Auto).stats().kind, AccelKind::Bvh);
}

TEST(Accel, OneTriangleWithEitherStructure) {
    Mesh one;
    add_triangle(&one, Vec3(-1.0, -1.0, 2.0), Vec3(1.0, -1.0, 2.0), Vec3(0.0, 1.0, 2.0));
    for (AccelKind kind : {AccelKind::Bvh, AccelKind::BruteForce}) {
        Accelerator accel = build(one, kind);
        EXPECT_EQ(accel.stats().nodes, kind == AccelKind::Bvh ? 1u : 0u);
        Ray ray; // from the origin along +z
        Hit hit;
        ASSERT_TRUE(accel.intersect(ray, &hit));
        EXPECT_EQ(hit.triangle, 0u);
        EXPECT_NEAR(hit.t, 2.0, 1e-15);
        EXPECT_NEAR(hit.b1, 0.25, 1e-15);
        EXPECT_NEAR(hit.b2, 0.5, 1e-15);
        ray.direction = Vec3(0.0, 0.0, -1.0);
        EXPECT_FALSE(accel.intersect(ray, &hit));
        EXPECT_FALSE(accel.occluded(ray));
    }
}

TEST(Accel, IdenticalTrianglesResolveToTheLowestId) {
    Mesh same;
    for (int i = 0; i < 600; ++i) {
        add_triangle(&same, Vec3(-1.0, -1.0, 2.0), Vec3(1.0, -1.0, 2.0), Vec3(0.0, 1.0, 2.0));
    }
    Accelerator bvh = build(same, AccelKind::Bvh), brute = build(same, AccelKind::BruteForce);
    EXPECT_LE(bvh.stats().max_depth, 64u);
    EXPECT_GE(bvh.stats().leaves, 600u / 16u);
    Pcg32 rng(53u, 10u);
    for (int i = 0; i < 200; ++i) {
        Ray ray;
        // Within 0.1 + 0.05 * 2 / 0.95 of the z axis at z = 2: inside the triangle.
        ray.origin = random_in_box(rng, Vec3(-0.1, -0.1, 0.0), Vec3(0.1, 0.1, 1.0));
        ray.direction = Vec3(0.0, 0.0, 1.0) + 0.05 * random_direction(rng);
        Hit hit;
        ASSERT_TRUE(bvh.intersect(ray, &hit));
        EXPECT_EQ(hit.triangle, 0u);
        expect_same(bvh, brute, ray);
    }
}

TEST(Accel, ZeroAreaTrianglesAreNeverHit) {
    Mesh mesh;
    add_triangle(&mesh, Vec3(0.0), Vec3(0.0), Vec3(0.0));                      // a point
    add_triangle(&mesh, Vec3(-1.0, 0.0, 1.0), Vec3(1.0, 0.0, 1.0), Vec3(0.0)); // fine
    add_triangle(&mesh, Vec3(-1.0, 0.0, 0.0), Vec3(0.0), Vec3(1.0, 0.0, 0.0)); // collinear
    add_triangle(&mesh, Vec3(0.0, 0.0, 2.0), Vec3(0.0, 0.0, 2.0), Vec3(1.0, 0.0, 2.0));
    for (int i = 0; i < 40; ++i) mesh.index.push_back(mesh.index[i % 4]); // past brute force
    mesh.material.assign(mesh.index.size(), 0);
    Accelerator bvh = build(mesh, AccelKind::Auto), brute = build(mesh, AccelKind::BruteForce);
    Pcg32 rng(59u, 11u);
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
        Ray ray;
        ray.origin = random_in_box(rng, Vec3(-1.0, -1.0, -1.0), Vec3(1.0, 1.0, 3.0));
        // Aim at points of the degenerate triangles and along their lines, or anywhere.
        Vec3 target = i % 2 ? Vec3(2.0 * rng.next_double() - 1.0, 0.0, 0.0) : Vec3(0.0);
        ray.direction = i % 3 ? target - ray.origin : random_direction(rng);
        Hit hit;
        if (bvh.intersect(ray, &hit)) {
            ++hits;
            EXPECT_EQ(hit.triangle % 4, 1u);
        }
        expect_same(bvh, brute, ray);
    }
    EXPECT_GT(hits, 100);
}

TEST(Accel, NonFiniteVerticesAreNeverHitAndDoNotDisturbTheRest) {
    Mesh mesh = make_soup(300, 0.3, 61u);
    Pcg32 rng(67u, 12u);
    const size_t good = mesh.triangle_count();
    for (int i = 0; i < 100; ++i) {
        Vec3 a = random_in_box(rng, Vec3(-1.0), Vec3(1.0)), b = a + Vec3(0.2, 0.0, 0.0);
        Vec3 c = a + Vec3(0.0, 0.2, 0.1);
        double bad = i % 3 == 0 ? kNaN : (i % 3 == 1 ? kInf : -kInf);
        (i % 2 ? b : c)[i % 3] = bad;
        add_triangle(&mesh, a, b, c);
    }
    Accelerator bvh = build(mesh, AccelKind::Bvh), brute = build(mesh, AccelKind::BruteForce);
    EXPECT_LE(bvh.stats().max_depth, 64u);
    for (int i = 0; i < 3000; ++i) {
        Ray ray;
        ray.origin = random_in_box(rng, Vec3(-1.5), Vec3(1.5));
        // Half the rays aim at a good triangle's centroid, so they hit.
        const uint32_t target = rng.next_below(uint32_t(good));
        const Vec3 c =
            (mesh.vertex(target, 0) + mesh.vertex(target, 1) + mesh.vertex(target, 2)) / 3.0;
        ray.direction = i % 2 ? c - ray.origin : random_direction(rng);
        Hit hit;
        const bool hb = bvh.intersect(ray, &hit);
        if (i % 2) {
            EXPECT_TRUE(hb);
        }
        if (hb) {
            EXPECT_LT(hit.triangle, good);
        }
        expect_same(bvh, brute, ray);
        if (::testing::Test::HasFailure()) return;
    }
    // Rays that are themselves not finite or have no direction hit nothing.
    Ray ray;
    Hit hit;
    for (Vec3 d : {Vec3(0.0), Vec3(kNaN, 0.0, 1.0), Vec3(kInf, 0.0, 0.0)}) {
        ray.direction = d;
        EXPECT_FALSE(bvh.intersect(ray, &hit));
        EXPECT_FALSE(brute.occluded(ray));
    }
    ray.direction = Vec3(0.0, 0.0, 1.0);
    ray.origin = Vec3(kNaN, 0.0, 0.0);
    EXPECT_FALSE(bvh.occluded(ray));
    ray.origin = Vec3(0.0);
    ray.t_max = kNaN;
    EXPECT_FALSE(bvh.intersect(ray, &hit));
}

// Triangles shrinking geometrically towards a point: SAH peels a few off per level, so only
// the depth guard bounds the tree (and the traversal stack).
TEST(Accel, DeepTreesStopAtTheDepthGuard) {
    Mesh mesh;
    double s = 1.0;
    for (int k = 0; k < 1500; ++k, s *= 0.85) {
        add_triangle(&mesh, Vec3(s, 0.0, 0.0), Vec3(1.1 * s, 0.0, 0.0), Vec3(s, 0.1 * s, 0.05 * s));
    }
    Accelerator bvh = build(mesh, AccelKind::Bvh), brute = build(mesh, AccelKind::BruteForce);
    EXPECT_EQ(bvh.stats().build_depth, 64u);
    EXPECT_LE(bvh.stats().max_depth, 64u); // the wide tree is no deeper than the binary one
    Pcg32 rng(71u, 13u);
    for (int i = 0; i < 500; ++i) {
        uint32_t target = rng.next_below(uint32_t(mesh.triangle_count()));
        Vec2 b = sample_triangle_barycentric(next_u(rng));
        Vec3 p = b.x * mesh.vertex(target, 0) + b.y * mesh.vertex(target, 1) +
                 (1.0 - b.x - b.y) * mesh.vertex(target, 2);
        double size = mesh.vertex(target, 1).x - mesh.vertex(target, 0).x;
        Ray ray; // from a distance comparable to the triangle's size
        ray.origin = p + size * (Vec3(0.0, -2.0, 1.0) + 0.5 * random_direction(rng));
        ray.direction = p - ray.origin;
        EXPECT_TRUE(expect_same(bvh, brute, ray));
        if (::testing::Test::HasFailure()) return;
    }
}

// --- BVH shape ----------------------------------------------------------------------------

TEST(Bvh, GridTreeIsShallowWithSmallLeaves) {
    const int n = 128;
    Mesh grid = make_grid(n, 1.0 / n, Vec3(0.0));
    const uint32_t triangles = 2 * n * n;
    Accelerator accel = build(grid, AccelKind::Auto);
    const AccelStats& s = accel.stats();
    EXPECT_EQ(s.kind, AccelKind::Bvh);
    // Collapsed from a full binary tree: every node has 2 to kNodeWidth children.
    const uint32_t width = Accelerator::kNodeWidth;
    EXPECT_GE((width - 1) * s.nodes + 1, s.leaves);
    EXPECT_LE(s.nodes + 1, s.leaves);
    EXPECT_LE(s.nodes, (s.leaves + 1) / (width == 8 ? 3 : 2)); // most nodes half full or more
    EXPECT_LE(s.build_depth, 2u * 15u);                        // 2 log2(triangles)
    EXPECT_GE(s.build_depth, 11u); // log2(triangles / 16): leaves are not huge
    // log2(width) binary levels per wide level, but for the last
    EXPECT_LE(s.max_depth, s.build_depth / (width == 8 ? 3 : 2) + 1);
    EXPECT_GE(s.max_depth, width == 8 ? 4u : 6u); // log_width(triangles / 16)
    EXPECT_GE(s.leaves, triangles / 8u);          // mean leaf size at most 8
    EXPECT_LE(s.leaves, triangles);
    EXPECT_GE(s.bytes, uint64_t(triangles) * 3 * sizeof(Vec3));
    // A ray straight down onto the centre of each of a few cells finds exactly that cell.
    for (int k = 0; k < 50; ++k) {
        int i = (37 * k) % n, j = (91 * k + 5) % n;
        Ray ray;
        ray.origin = Vec3((i + 0.75) / n, (j + 0.25) / n, 1.0);
        ray.direction = Vec3(0.0, 0.0, -1.0);
        Hit hit;
        ASSERT_TRUE(accel.intersect(ray, &hit));
        EXPECT_EQ(hit.triangle, uint32_t(2 * (j * n + i)));
        EXPECT_NEAR(hit.t, 1.0, 1e-15);
    }
}
