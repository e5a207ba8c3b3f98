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

/// Moves a surface point off its surface, to the side `direction` points to, by a distance
/// that scales with the point's magnitude: a few thousand ulps of the largest coordinate,
/// which exceeds the rounding error of a double-precision hit point and its watertight
/// triangle test (the float-ulp version is [WaechterBinder19], Ray Tracing Gems ch. 6).
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& geometric_normal, const Vec3& direction) {
    double scale = fmax_inline(fmax_inline(std::fabs(p.x), std::fabs(p.y)), std::fabs(p.z));
    double eps = 0x1p-40 * (scale + 1.0); // ~1e-12 near the origin, relative beyond
    Vec3 offset = geometric_normal * eps;
    return glm::dot(direction, geometric_normal) < 0.0 ? p - offset : p + offset;
}

/// Luminance of linear Rec. 709 / sRGB primaries (ITU-R BT.709).
inline double luminance(const Vec3& rgb) {
    return 0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z;
}

} // namespace mcp
