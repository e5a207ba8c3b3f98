// Warps from the unit square to sampling domains. Every warp is a triad: sample_x maps
// u in [0,1)^2 to the domain, x_pdf is its density with respect to the domain's measure
// (area, or solid angle on the sphere), invert_x maps a domain point back to u.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace mcp {

using Vec2 = glm::dvec2;
using Vec3 = glm::dvec3;

// --- Unit disk -------------------------------------------------------------------------

/// Polar map of the course notes: r = sqrt(u1), phi = 2 pi u2. Uniform on the unit disk,
/// but it squeezes the strata of u near the centre.
Vec2 sample_disk_polar(Vec2 u);
Vec2 invert_disk_polar(Vec2 p);

/// Shirley and Chiu's concentric map [ShirleyChiu97]: squares to rings, low distortion,
/// so stratification of u survives the warp.
Vec2 sample_disk_concentric(Vec2 u);
Vec2 invert_disk_concentric(Vec2 p);

/// Density of both disk warps per unit area of the unit disk.
inline double disk_pdf() {
    return 0.31830988618379067154;
}

// --- Triangle --------------------------------------------------------------------------

/// Uniform barycentric coordinates (b0, b1) on the triangle, b2 = 1 - b0 - b1:
/// b0 = 1 - sqrt(u1), b1 = u2 sqrt(u1) [Turk90]. The point is b0 a + b1 b + b2 c; the
/// density is 1/area (2 on the barycentric simplex).
Vec2 sample_triangle_barycentric(Vec2 u);
Vec2 invert_triangle_barycentric(Vec2 b);

// --- Sphere and hemisphere (z up) ------------------------------------------------------

/// Uniform direction: z = 1 - 2 u1, phi = 2 pi u2 (Archimedes' hat-box theorem).
Vec3 sample_uniform_sphere(Vec2 u);
Vec2 invert_uniform_sphere(Vec3 w);
inline double uniform_sphere_pdf() {
    return 0.25 * 0.31830988618379067154;
}

/// Uniform direction on the hemisphere z >= 0: z = u1, phi = 2 pi u2.
Vec3 sample_uniform_hemisphere(Vec2 u);
Vec2 invert_uniform_hemisphere(Vec3 w);
inline double uniform_hemisphere_pdf() {
    return 0.5 * 0.31830988618379067154;
}

/// Cosine-weighted hemisphere by Malley's method: a concentric disk sample lifted to the
/// hemisphere. Density cos(theta)/pi per unit solid angle.
Vec3 sample_cosine_hemisphere(Vec2 u);
Vec2 invert_cosine_hemisphere(Vec3 w);
inline double cosine_hemisphere_pdf(double cos_theta) {
    return cos_theta > 0.0 ? cos_theta * 0.31830988618379067154 : 0.0;
}

} // namespace mcp
