// Area lights: the scene's emissive triangles, chosen by uniform choice, by area or by power,
// then sampled by area (the course notes' area form of the transport equation) or by solid
// angle (spherical triangles [Arvo95, "Stratified Sampling of Spherical Triangles"]).
#pragma once

#include <cstdint>
#include <vector>

#include "core/spherical_triangle.h"
#include "render/scene.h"

namespace mcp {

enum class LightSelection { Uniform, Area, Power };
enum class LightSampling { Area, SolidAngle };

struct LightSample {
    Vec3 point{0.0};    ///< on the light
    Vec3 normal{0.0};   ///< unit geometric normal of the light triangle (front side)
    Vec3 radiance{0.0}; ///< emitted radiance towards the reference point (0 from the back)
    double pdf = 0.0;   ///< solid-angle density at the reference point, selection included
    uint32_t triangle = 0;
    bool valid = false; ///< false: nothing sampled (no lights, degenerate triangle, pdf 0)
};

class LightSet {
  public:
    /// Collects the emissive triangles of the scene (materials with emission > 0) and builds
    /// the selection distribution (none for a single light). Emissive triangles of zero area
    /// (never hit, never sampled) are left out and counted in degenerate(); triangles whose
    /// emission or area is not finite cannot be lights and are counted in nonfinite() (the
    /// render API refuses such scenes). Selection weights are normalised by the largest
    /// radiance and area before they are multiplied, so lights as bright as 1e308 keep a
    /// valid distribution even when their power overflows (total_power() is then inf).
    void build(const Scene& scene, LightSelection selection);

    bool empty() const { return lights_.empty(); }
    size_t size() const { return lights_.size(); }
    /// Emissive triangles left out because their area is zero.
    size_t degenerate() const { return degenerate_; }
    /// Emissive triangles left out because their emission or area is NaN or infinite.
    size_t nonfinite() const { return nonfinite_; }
    /// Light number of a mesh triangle, or -1 when it does not emit.
    int light_index(uint32_t triangle) const;
    /// Total emitted power (flux) of all lights, luminance.
    double total_power() const;

    /// Chooses a light with u_select, then a point on it with u, as seen from `ref`.
    LightSample sample(const Vec3& ref, double u_select, const Vec2& u, LightSampling mode) const;
    /// Solid-angle density with which sample(ref, ..., mode) returns `point` on mesh triangle
    /// `triangle` (0 when it does not emit), for multiple importance sampling.
    double pdf(const Vec3& ref, uint32_t triangle, const Vec3& point, LightSampling mode) const;

    /// Radiance emitted by mesh triangle `triangle` towards direction `w` (pointing away from
    /// the light; its length does not matter): its emission on the front side (both sides when
    /// double-sided), else 0. 0 for a triangle that is not a light, which includes emissive
    /// triangles of zero area (never hit).
    Vec3 emitted(uint32_t triangle, const Vec3& w) const;

    /// Probability of choosing light number `light` (0 outside [0, size())).
    double selection_pmf(int light) const;

  private:
    /// What sampling, pdf and emission need of one light, gathered once in build() so that a
    /// sample reads one record instead of the mesh's index, position and material arrays.
    struct Light {
        Vec3 p0{0.0}, p1{0.0}, p2{0.0};
        Vec3 e1{0.0}, e2{0.0};  ///< p1 - p0, p2 - p0
        Vec3 cross_normal{0.0}; ///< e1 x e2: front side, length twice the area
        Vec3 unit_normal{0.0};  ///< cross_normal normalised
        Vec3 emission{0.0};     ///< radiance, linear RGB
        Vec3 centroid{0.0};     ///< for light_is_small_from
        double radius2 = 0.0;   ///< largest squared distance from the centroid to a vertex
        bool double_sided = false;
        uint32_t triangle = 0; ///< mesh triangle
    };
    int select(double u_select, double* pmf) const;
    /// The light's emission towards w (any length), or 0 from its back.
    static Vec3 emitted_by(const Light& light, const Vec3& w) {
        return light.double_sided || glm::dot(w, light.cross_normal) > 0.0 ? light.emission
                                                                           : Vec3(0.0);
    }

    LightSelection selection_ = LightSelection::Uniform;
    std::vector<Light> lights_;              // light number -> its record
    std::vector<int32_t> light_of_triangle_; // mesh triangle -> light or -1
    std::vector<double> selection_cdf_;      // empty for one light and for uniform choice
    std::vector<double> selection_pmf_;      // likewise
    double total_power_ = 0.0;
    size_t degenerate_ = 0, nonfinite_ = 0;
};

/// Regime of LightSampling::SolidAngle: a triangle whose solid angle Omega at the reference
/// point lies outside [kMinSphericalSolidAngle, kMaxSphericalSolidAngle], or whose plane
/// contains the reference point, is sampled by area instead, and pdf() applies the same rule.
/// The map here (a half-angle form of Arvo's, see lights.cpp) has no 1/Omega cancellation:
/// against a quad-precision reference it kept its sample points to ~1e-15 of their distance
/// for Omega down to 1e-17 sr and within 1e-20 of the plane (2e-9 at worst, 1e-12 from an
/// edge), where Arvo's own formula loses 1e-7 even in quad precision at Omega = 1e-13. So
/// the bounds are margins, not accuracy limits: below 1e-12 sr (a triangle under ~1e-6 rad
/// across) and within 1e-12 of 2 pi (the solid angle is 2 pi to a few thousand ulps) the
/// spherical quantities are at the edge of their floating-point range.
constexpr double kMinSphericalSolidAngle = 1e-12;
constexpr double kMaxSphericalSolidAngle = 6.283185307179586 - 1e-12;

/// The other area regime of LightSampling::SolidAngle, for speed: a triangle that is small
/// from the reference point x, R <= |x - c| / 64 for its centroid c and R the largest distance
/// from c to a vertex, is sampled by area too. Its area density in solid angle, d^2 / (A
/// cos theta_light) = d^3 / (A h) for h the distance from x to its plane, then varies over the
/// triangle by at most ((1 + 1/64) / (1 - 1/64))^3 < 1.1 against the uniform density 1 / Omega,
/// since every distance d lies within |x - c| -+ R: the sample weights spread by at most 5%
/// more than spherical sampling's, at a fraction of its cost (no solid angle, no Arvo map).
/// pdf() applies the same test.
constexpr double kSmallLightInverseRatio = 64.0;
inline bool light_is_small_from(const Vec3& centroid, double radius2, const Vec3& x) {
    const Vec3 d = centroid - x;
    return radius2 * (kSmallLightInverseRatio * kSmallLightInverseRatio) <= glm::dot(d, d);
}

// Spherical triangles (the solid angle of triangle (a, b, c) seen from the origin
// [VanOosteromStrackee83], and Arvo's area-preserving map from the unit square) are declared in
// core/spherical_triangle.h: spherical_triangle_area, sample_spherical_triangle.

/// Most vertices lambert_polygon_form_factor accepts.
constexpr int kMaxFormFactorVertices = 32;

/// Point-to-polygon form factor by Lambert's formula [Lambert1760]: the fraction of a
/// uniform Lambertian polygon's radiance that reaches the surface point x with unit normal
/// n, F = (1 / 2 pi) |sum_i beta_i n . (v_i x v_i+1) / |v_i x v_i+1||, with v_i the unit
/// vectors from x to the vertices and beta_i the angle between v_i and v_i+1; the polygon
/// (planar, simple, either winding) is first clipped to the half-space above x's tangent
/// plane. Irradiance from a fully visible polygon of radiance L: E = pi L F. Occlusion is
/// ignored. NaN when count is outside [3, kMaxFormFactorVertices].
double lambert_polygon_form_factor(const Vec3& x, const Vec3& n, const Vec3* vertices, int count);

} // namespace mcp
