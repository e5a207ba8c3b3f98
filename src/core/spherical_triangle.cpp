// Spherical triangles: see spherical_triangle.h. Moved from render/lights.cpp, which keeps
// calling them (same code, same results).
#include "core/spherical_triangle.h"

namespace mcp {

double spherical_triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
    return spherical_triangle_solid_angle(a, b, c, glm::dot(a, glm::cross(b - a, c - a)),
                                          triangle_vertex_lengths(a, b, c));
}

Vec3 sample_spherical_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec2& u,
                               double* pdf) {
    // The same map as the light sampler, without its fallback regimes: only a triangle of
    // zero solid angle (or one that contains the origin in its plane) is refused.
    Vec3 e1 = b - a, e2 = c - a;
    double det = glm::dot(a, glm::cross(e1, e2));
    SphericalTriangle st;
    const TriangleVertexLengths len = triangle_vertex_lengths(a, b, c);
    st.omega = spherical_triangle_solid_angle(a, b, c, det, len);
    if (det == 0.0 || !(st.omega > 0.0) || !std::isfinite(st.omega)) {
        if (pdf) *pdf = 0.0;
        return Vec3(0.0);
    }
    fill_spherical_triangle(a, b, c, e1, e2, det, len, &st);
    if (pdf) *pdf = 1.0 / st.omega;
    return sample_spherical_triangle(st, u);
}

} // namespace mcp
