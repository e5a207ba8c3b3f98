// Geometry shared by the renderer: rays, hits, orthonormal frames and ray origins that do not
// re-hit the surface they leave.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/geometric.hpp>

#include "core/warps.h" // Vec2, Vec3

namespace mcp {

struct Ray {
    Vec3 origin{0.0};
    Vec3 direction{0.0, 0.0, 1.0}; ///< not necessarily unit length; t is in its units
    double t_max = std::numeric_limits<double>::infinity();
};

/// A ray-triangle hit: distance along the ray and the barycentric coordinates (b1, b2) of the
/// hit point p = (1 - b1 - b2) p0 + b1 p1 + b2 p2 of triangle `triangle` of the mesh.
struct Hit {
    double t = std::numeric_limits<double>::infinity();
    uint32_t triangle = 0;
    double b1 = 0.0, b2 = 0.0;
};

/// Orthonormal basis (s, t, n) around a unit vector n, branch-free and continuous except on
/// the n.z = -0 seam [Duff17, "Building an orthonormal basis, revisited"].
struct Frame {
    Vec3 s{1.0, 0.0, 0.0}, t{0.0, 1.0, 0.0}, n{0.0, 0.0, 1.0};

    static Frame from_normal(const Vec3& n) {
        double sign = std::copysign(1.0, n.z);
        double a = -1.0 / (sign + n.z);
        double b = n.x * n.y * a;
        Frame f;
        f.s = Vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        f.t = Vec3(b, sign + n.y * n.y * a, -n.y);
        f.n = n;
        return f;
    }
    Vec3 to_local(const Vec3& v) const {
        return Vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n));
    }
    Vec3 to_world(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

/// std::fmax without the library call it compiles to (without -ffast-math): the larger of a
/// and b, or the other one when one is NaN.
inline double fmax_inline(double a, double b) {
    return (a > b || b != b) ? a : b;
}

/// gamma_n = n u / (1 - n u), u = 2^-53: bounds the relative error of n chained roundings
/// [PBR4, 6.8.1].
constexpr double rounding_gamma(int n) {
    return n * 0x1p-53 / (1.0 - n * 0x1p-53);
}

/// Moves a surface point off its surface, to the side `direction` points to. The distance is
/// the larger of two bounds: a few thousand ulps of the point's largest coordinate (the
/// rounding of a hit point near its triangle's vertices, and of the watertight triangle test;
/// [WaechterBinder19] is the float-ulp version), and the largest of `p_error`, the bound on
/// the rounding error of the point's and its triangle's coordinates. pbrt-v4 offsets ray
/// origins by such bounds [PBR4, 6.8.6]; here the largest coordinate's bound is used, not its
/// projection on the normal, because a ray leaving the surface is tested against the same
/// triangle again, and that test's t carries the error of every coordinate of the vertices
/// translated to the ray origin (a floor in y = 0 whose vertices are at x, z = 2e4 has an
/// exact y but a self-hit t off by 2e4 ulps). It matters when the point is far smaller than
/// its vertices (a hit near the origin on a huge floor). Each coordinate is then rounded away
/// from the surface, so the offset is never lost to rounding.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& p_error, const Vec3& geometric_normal,
                              const Vec3& direction) {
    double scale = fmax_inline(fmax_inline(std::fabs(p.x), std::fabs(p.y)), std::fabs(p.z));
    double relative = 0x1p-40 * (scale + 1.0); // ~1e-12 near the origin, relative beyond
    double bounded = fmax_inline(fmax_inline(p_error.x, p_error.y), p_error.z);
    Vec3 offset = geometric_normal * fmax_inline(relative, bounded);
    if (glm::dot(direction, geometric_normal) < 0.0) offset = -offset;
    Vec3 moved = p + offset;
    for (int k = 0; k < 3; ++k) {
        if (offset[k] > 0.0)
            moved[k] = std::nextafter(moved[k], std::numeric_limits<double>::infinity());
        else if (offset[k] < 0.0)
            moved[k] = std::nextafter(moved[k], -std::numeric_limits<double>::infinity());
    }
    return moved;
}

/// The same for a point whose rounding is relative to its own coordinates (a light sample).
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& geometric_normal, const Vec3& direction) {
    return offset_ray_origin(p, Vec3(0.0), geometric_normal, direction);
}

/// Luminance of linear Rec. 709 / sRGB primaries (ITU-R BT.709).
inline double luminance(const Vec3& rgb) {
    return 0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z;
}

} // namespace mcp
