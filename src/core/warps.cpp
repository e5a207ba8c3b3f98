// Warps from the unit square: the inverses declared in warps.h (the forward maps are inline).
//
// Every inverse returns u in [0, 1)^2: azimuths come from atan2 (range (-pi, pi]) shifted to
// [0, 2 pi), and an angle that rounds up to 2 pi is the direction of angle 0, so it maps to
// u = 0 rather than to u = 1. Radial coordinates are clamped into [0, 1) against rounding.
#include "core/warps.h"

#include <algorithm>
#include <cmath>

#include "core/points.h"
#include "core/special.h"

namespace mcp {
namespace {

constexpr double kTwoPi = 2.0 * kPi;
constexpr double kFourOverPi = 4.0 / kPi;

double clamp_unit(double v) {
    return v > 0.0 ? std::min(v, kOneMinusEpsilon) : 0.0;
}

/// The azimuth of (x, y) as a fraction of a full turn, in [0, 1).
double azimuth_unit(double y, double x) {
    double phi = std::atan2(y, x);
    if (phi < 0.0) phi += kTwoPi;
    double u = phi / kTwoPi;
    return u > 0.0 && u < 1.0 ? u : 0.0; // -0, and 2 pi after rounding, are angle 0
}

} // namespace

// --- Unit disk -------------------------------------------------------------------------

Vec2 invert_disk_polar(Vec2 p) {
    return {clamp_unit(p.x * p.x + p.y * p.y), azimuth_unit(p.y, p.x)};
}

// Inverse of the concentric map. Reflecting the point through the centre when the signed
// radius is negative (s = -1) brings every wedge back to its positive form: on |x| >= |y|,
// atan2(s y, s x) is (pi/4) b/a in [-pi/4, pi/4]; on |y| > |x|, atan2(s x, s y) is
// pi/2 - phi = (pi/4) a/b. Both forms agree on the diagonals, where the map is continuous.
Vec2 invert_disk_concentric(Vec2 p) {
    double r = std::sqrt(p.x * p.x + p.y * p.y);
    if (r == 0.0) return {0.5, 0.5};
    double a, b;
    if (std::fabs(p.x) >= std::fabs(p.y)) {
        double s = p.x >= 0.0 ? 1.0 : -1.0;
        a = s * r;
        b = a * (std::atan2(s * p.y, s * p.x) * kFourOverPi);
    } else {
        double s = p.y >= 0.0 ? 1.0 : -1.0;
        b = s * r;
        a = b * (std::atan2(s * p.x, s * p.y) * kFourOverPi);
    }
    return {clamp_unit(0.5 * (a + 1.0)), clamp_unit(0.5 * (b + 1.0))};
}

// --- Triangle --------------------------------------------------------------------------

// sqrt(u1) = 1 - b0 and u2 = b1 / (1 - b0).
Vec2 invert_triangle_barycentric(Vec2 b) {
    double s = 1.0 - b.x;
    if (!(s > 0.0)) return {0.0, 0.0}; // the vertex b0 = 1, where u2 is arbitrary
    return {clamp_unit(s * s), clamp_unit(b.y / s)};
}

// --- Sphere and hemisphere ------------------------------------------------------------

Vec2 invert_uniform_sphere(Vec3 w) {
    return {clamp_unit(0.5 * (1.0 - w.z)), azimuth_unit(w.y, w.x)};
}

Vec2 invert_uniform_hemisphere(Vec3 w) {
    return {clamp_unit(w.z), azimuth_unit(w.y, w.x)};
}

Vec2 invert_cosine_hemisphere(Vec3 w) {
    return invert_disk_concentric({w.x, w.y});
}

} // namespace mcp
