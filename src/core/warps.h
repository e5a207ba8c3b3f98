// Warps from the unit square to sampling domains. Every warp is a triad: sample_x maps
// u in [0,1)^2 to the domain, x_pdf is its density with respect to the domain's measure
// (area, or solid angle on the sphere), invert_x maps a domain point back to u.
//
// The sample_x maps are inline and branch-free (selects, no data-dependent jumps): they run
// in the block loops, where a branch on a random point is mispredicted half the time, and
// V8 compiles such branches in wasm to slow code (the concentric map took 37 ns per point
// with its wedge test as a branch, 8 ns with it as selects).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/trig.h"

namespace mcp {

using Vec2 = glm::dvec2;
using Vec3 = glm::dvec3;

// --- Unit disk -------------------------------------------------------------------------

/// Polar map of the course notes: r = sqrt(u1), phi = 2 pi u2. Uniform on the unit disk,
/// but it squeezes the strata of u near the centre.
inline Vec2 sample_disk_polar(Vec2 u) {
    const double r = std::sqrt(u.x);
    const SinCos phi = sincos_turns(u.y);
    return {r * phi.cos, r * phi.sin};
}
Vec2 invert_disk_polar(Vec2 p);

/// Shirley and Chiu's concentric map [ShirleyChiu97]: squares to rings, low distortion,
/// so stratification of u survives the warp. With (a, b) = 2u - 1, the square ring
/// max(|a|, |b|) = r goes to the circle of radius r; on the wedge |a| > |b| the angle is
/// t = (pi/4) b/a, on |b| >= |a| it is pi/2 - t with t = (pi/4) a/b, whose cosine and sine
/// are sin t and cos t. A negative r puts the point on the opposite side of the centre;
/// r = 0 (the centre) gives t = 0 and the point 0. |t| <= pi/4: no range reduction.
inline Vec2 sample_disk_concentric(Vec2 u) {
    const double a = 2.0 * u.x - 1.0, b = 2.0 * u.y - 1.0;
    const bool wide = std::fabs(a) > std::fabs(b);
    const double r = wide ? a : b, other = wide ? b : a;
    const SinCos t = sincos_quarter((0.25 * kPi) * (other / (r == 0.0 ? 1.0 : r)));
    const double along = r * t.cos, across = r * t.sin;
    return {wide ? along : across, wide ? across : along};
}
Vec2 invert_disk_concentric(Vec2 p);

/// Density of both disk warps per unit area of the unit disk.
inline double disk_pdf() {
    return 0.31830988618379067154;
}

// --- Triangle --------------------------------------------------------------------------

/// Uniform barycentric coordinates (b0, b1) on the triangle, b2 = 1 - b0 - b1:
/// b0 = 1 - sqrt(u1), b1 = u2 sqrt(u1) [Turk90]. The point is b0 a + b1 b + b2 c; the
/// density is 1/area (2 on the barycentric simplex).
inline Vec2 sample_triangle_barycentric(Vec2 u) {
    const double su = std::sqrt(u.x);
    return {1.0 - su, u.y * su};
}
Vec2 invert_triangle_barycentric(Vec2 b);

// --- Sphere and hemisphere (z up) ------------------------------------------------------

/// Uniform direction: z = 1 - 2 u1, phi = 2 pi u2 (Archimedes' hat-box theorem).
/// The radius of the circle of latitude sqrt(1 - z^2) = 2 sqrt(u1 (1 - u1)) keeps its
/// relative precision near the poles.
inline Vec3 sample_uniform_sphere(Vec2 u) {
    const double z = 1.0 - 2.0 * u.x;
    const double r = 2.0 * std::sqrt(u.x * (1.0 - u.x));
    const SinCos phi = sincos_turns(u.y);
    return {r * phi.cos, r * phi.sin, z};
}
Vec2 invert_uniform_sphere(Vec3 w);
inline double uniform_sphere_pdf() {
    return 0.25 * 0.31830988618379067154;
}

/// Uniform direction on the hemisphere z >= 0: z = u1, phi = 2 pi u2.
inline Vec3 sample_uniform_hemisphere(Vec2 u) {
    const double z = u.x;
    const double r = std::sqrt(std::max(0.0, (1.0 - z) * (1.0 + z)));
    const SinCos phi = sincos_turns(u.y);
    return {r * phi.cos, r * phi.sin, z};
}
Vec2 invert_uniform_hemisphere(Vec3 w);
inline double uniform_hemisphere_pdf() {
    return 0.5 * 0.31830988618379067154;
}

/// Cosine-weighted hemisphere by Malley's method: a concentric disk sample lifted to the
/// hemisphere [PBR4, A.5]: the projection of a cosine-weighted direction onto the disk is
/// uniform. Density cos(theta)/pi per unit solid angle.
inline Vec3 sample_cosine_hemisphere(Vec2 u) {
    const Vec2 d = sample_disk_concentric(u);
    const double z = std::sqrt(std::max(0.0, 1.0 - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}
Vec2 invert_cosine_hemisphere(Vec3 w);
inline double cosine_hemisphere_pdf(double cos_theta) {
    return cos_theta > 0.0 ? cos_theta * 0.31830988618379067154 : 0.0;
}

} // namespace mcp
