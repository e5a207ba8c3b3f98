// GGX pieces and visible-normal sampling: see microfacet.h. Moved from render/bsdf.cpp, which
// keeps calling them (same code, same results).
#include "core/microfacet.h"

#include <limits>

#include <glm/geometric.hpp>

namespace mcp {
namespace {

// A comparison rather than std::fmax (a library call without -ffast-math); maps NaN to 0.
double max0(double x) {
    return x > 0.0 ? x : 0.0;
}

double max_abs(const Vec3& v) {
    double ax = std::fabs(v.x), ay = std::fabs(v.y), az = std::fabs(v.z);
    double m = ax > ay ? ax : ay;
    return m > az ? m : az;
}

} // namespace

bool safe_normalize(const Vec3& v, Vec3* out) {
    double m = max_abs(v);
    if (!(m > 0.0) || !(m <= std::numeric_limits<double>::max())) return false;
    Vec3 s = v * (1.0 / m);
    *out = s * (1.0 / std::sqrt(s.x * s.x + s.y * s.y + s.z * s.z));
    return true;
}

double ggx_d(double alpha, const Vec3& h) {
    double a = (alpha > kMinGgxAlpha ? alpha : kMinGgxAlpha);
    return ggx_d_a2(a * a, h);
}

double ggx_g1(double alpha, const Vec3& w) {
    if (!(w.z > 0.0)) return 0.0;
    double a = (alpha > kMinGgxAlpha ? alpha : kMinGgxAlpha);
    return 2.0 * w.z / (w.z + ggx_smith_root(a * a, w.z));
}

// D_v(h) = G1(wo) max(0, wo.h) D(h) / wo.z [Heitz18, eq. 1], with G1(wo) / wo.z in the
// form 2 / (wo.z + root) that stays finite at grazing wo.
double ggx_visible_normal_pdf(double alpha, const Vec3& wo, const Vec3& h) {
    if (!(wo.z > 0.0)) return 0.0;
    double a = (alpha > kMinGgxAlpha ? alpha : kMinGgxAlpha);
    double a2 = a * a;
    double woh = glm::dot(wo, h);
    if (!(woh > 0.0)) return 0.0;
    return 2.0 * woh * ggx_d_a2(a2, h) / (wo.z + ggx_smith_root(a2, wo.z));
}

// [Heitz18, listing 1]: stretch wo to the configuration where alpha = 1 (sec. 3.2), sample
// the projected area of the hemisphere seen from there as a disk whose half facing away from
// wo is compressed by (1 + Vh.z) / 2 (sec. 4.2), lift the disk point to the hemisphere
// (sec. 4.3) and unstretch the normal (sec. 3.4).
Vec3 ggx_sample_visible_normal(double alpha, const Vec3& wo, const Vec2& u) {
    double a = (alpha > kMinGgxAlpha ? alpha : kMinGgxAlpha);
    Vec3 vh;
    if (!(wo.z > 0.0) || !safe_normalize(Vec3(a * wo.x, a * wo.y, wo.z), &vh))
        return Vec3(0.0, 0.0, 1.0);
    double len2 = vh.x * vh.x + vh.y * vh.y;
    Vec3 t1 = len2 > 0.0 ? Vec3(-vh.y, vh.x, 0.0) / std::sqrt(len2) : Vec3(1.0, 0.0, 0.0);
    Vec3 t2 = glm::cross(vh, t1);
    double r = std::sqrt(u.x);
    double phi = 2.0 * kPi * u.y;
    double p1 = r * std::cos(phi);
    double p2 = r * std::sin(phi);
    double s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * std::sqrt(max0(1.0 - p1 * p1)) + s * p2;
    double p3 = std::sqrt(max0(1.0 - p1 * p1 - p2 * p2));
    Vec3 nh = t1 * p1 + t2 * p2 + vh * p3;
    Vec3 h;
    if (!safe_normalize(Vec3(a * nh.x, a * nh.y, max0(nh.z)), &h)) return Vec3(0.0, 0.0, 1.0);
    return h;
}

} // namespace mcp
