// Spherical triangles: the solid angle of a triangle seen from the origin
// [VanOosteromStrackee83] and Arvo's area-preserving map from the unit square onto it [Arvo95,
// "Stratified Sampling of Spherical Triangles"]; the pure math, shared by the renderer's light
// sampler (render/lights.cpp, which adds its regimes: small and grazing triangles by area) and
// the warp tests (estimators/named_warps).
#pragma once

#include <cmath>

#include <glm/geometric.hpp>

#include "core/special.h" // kPi
#include "core/trig.h"    // sincos_turns
#include "core/warps.h"   // Vec2, Vec3

namespace mcp {

/// Solid angle of the triangle (a, b, c) seen from the origin (its vertices are the vectors
/// from the origin, of any length; either winding).
double spherical_triangle_area(const Vec3& a, const Vec3& b, const Vec3& c);
/// Arvo's map of u in [0, 1)^2 onto the spherical triangle of (a, b, c) (vectors from the
/// origin, any length): a unit direction, with the density 1 / Omega in *pdf (may be null).
/// A triangle of zero solid angle, or one whose plane contains the origin, gives the zero
/// vector and density 0.
Vec3 sample_spherical_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec2& u,
                               double* pdf);

// --- Inline: the light sampler's hot path sets up and samples a triangle per sample ----------

/// The spherical triangle of a mesh triangle seen from a reference point, set up for Arvo's
/// map. Everything is derived from the vectors a, b, c from the reference point to the
/// vertices and the edges e1 = p1 - p0, e2 = p2 - p0 taken from the world-space vertices, so
/// that small or distant triangles keep their relative accuracy: the plane normals of the
/// arcs are a x e1 (= a x b) and a x e2 (= a x c), the triple product is a . (e1 x e2), and
/// angles come from atan2 of such products rather than from differences of unit vectors.
/// Filled by fill_spherical_triangle and read only after it: no default values, whose zeroing (a
/// memset call in wasm) cost 2% of a light-sampling render there.
struct SphericalTriangle {
    Vec3 A, B;       ///< unit directions to vertices 0 and 1
    Vec3 tangent_ac; ///< unit tangent at A of the arc towards C
    /// Sine and cosine of the interior angle alpha at A, or of pi minus it when obtuse (kept
    /// accurate near pi).
    double sin_alpha, cos_alpha;
    bool obtuse;
    double sin_half_c, cos_half_c; ///< of half the arc length AB
    double sin_half_b, cos_half_b; ///< of half the arc length AC
    double sin_b, cos_b;           ///< of the arc length AC
    double omega;                  ///< solid angle
};

/// The vertex vectors' lengths |a|, |b|, |c|.
struct TriangleVertexLengths {
    double a, b, c;
};
inline TriangleVertexLengths triangle_vertex_lengths(const Vec3& a, const Vec3& b, const Vec3& c) {
    return {glm::length(a), glm::length(b), glm::length(c)};
}

/// Solid angle of the triangle (a, b, c) seen from the origin, with det = a . (b x c) and
/// the lengths computed by the caller: tan(Omega / 2) = |det| / (|a||b||c| + (a.b)|c| + (a.c)|b| +
/// (b.c)|a|) [VanOosteromStrackee83]. atan2 keeps the branch right past Omega = pi, where the
/// denominator turns negative.
inline double spherical_triangle_solid_angle(const Vec3& a, const Vec3& b, const Vec3& c,
                                             double det, const TriangleVertexLengths& len) {
    const double la = len.a, lb = len.b, lc = len.c;
    double denom = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
    return 2.0 * std::atan2(std::fabs(det), denom);
}

namespace spherical_detail {

/// std::fmax without the library call it compiles to (without -ffast-math): the larger of a
/// and b, or the other one when one is NaN (render/geometry.h's fmax_inline).
inline double larger_or_other(double a, double b) {
    return (a > b || b != b) ? a : b;
}

/// (s, c) / |(s, c)| for s, c >= 0: the sine and cosine of the angle atan2(s, c), (0, 1) when
/// both are 0. Scaled by the larger first, so that the squares neither overflow nor underflow
/// (hypot's guarantee without its cost: one division, one square root and one more division).
inline void unit_pair(double s, double c, double* sin_out, double* cos_out) {
    const double m = larger_or_other(s, c);
    if (!(m > 0.0)) {
        *sin_out = 0.0;
        *cos_out = 1.0;
        return;
    }
    const double inv_m = 1.0 / m;
    const double a = s * inv_m, b = c * inv_m; // the larger is 1 to an ulp
    const double inv_r = 1.0 / std::sqrt(a * a + b * b);
    *sin_out = a * inv_r;
    *cos_out = b * inv_r;
}

/// Sin and cos of half the angle between a and b, from |a x b| (computed accurately by the
/// caller) and a . b, without the cancellation of |a||b| + a.b near antipodal directions:
/// tan(c/2) = |a x b| / (|a||b| + a.b) = (|a||b| - a.b) / |a x b|.
inline void half_angle(double cross_len, double dot_ab, double len_ab, double* sin_half,
                       double* cos_half) {
    double s = dot_ab >= 0.0 ? cross_len : len_ab - dot_ab;
    double c = dot_ab >= 0.0 ? len_ab + dot_ab : cross_len;
    unit_pair(s, c, sin_half, cos_half);
}

} // namespace spherical_detail

/// Fills the map's parameters of the triangle with vertex vectors a, b, c, edges e1 = b - a,
/// e2 = c - a and triple product det = a . (e1 x e2), det != 0.
inline void fill_spherical_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& e1,
                                    const Vec3& e2, double det, const TriangleVertexLengths& len,
                                    SphericalTriangle* st) {
    Vec3 n_ab = glm::cross(a, e1); // normal of the great circle through A and B
    Vec3 n_ac = glm::cross(a, e2); // ... through A and C
    const double la = len.a, lb = len.b;
    // The angle at A is the angle between the two arc planes; |n_ab x n_ac| = |a| |det|
    // since (a x e1) x (a x e2) = (a . (e1 x e2)) a. Near pi its supplement is kept instead.
    double cos_term = glm::dot(n_ab, n_ac);
    st->obtuse = cos_term < 0.0;
    spherical_detail::unit_pair(la * std::fabs(det), std::fabs(cos_term), &st->sin_alpha,
                                &st->cos_alpha);
    spherical_detail::half_angle(glm::length(n_ab), glm::dot(a, b), la * lb, &st->sin_half_c,
                                 &st->cos_half_c);
    spherical_detail::half_angle(glm::length(n_ac), glm::dot(a, c), la * len.c, &st->sin_half_b,
                                 &st->cos_half_b);
    st->sin_b = 2.0 * st->sin_half_b * st->cos_half_b;
    st->cos_b = (st->cos_half_b - st->sin_half_b) * (st->cos_half_b + st->sin_half_b);
    st->A = a / la;
    st->B = b / lb;
    st->tangent_ac = glm::normalize(glm::cross(n_ac, st->A)); // (A x C) x A = C - (A.C) A
}

/// Arvo's area-preserving map from the unit square to the spherical triangle [Arvo95]:
/// u1 picks the sub-triangle A B C' of area u1 Omega (C' on the arc AC), u2 a point on the
/// arc B C' with 1 - cos(theta) uniform. Arvo's closed form for cos |AC'| is rewritten here
/// as
///   tan(|AC'| / 2) = cos(c/2) sin(A'/2) / (sin(c/2) sin(alpha - A'/2)),  A' = u1 Omega,
/// (our derivation: with phi = A' - alpha, Arvo's law-of-cosines step gives the angle beta'
/// of the sub-triangle at B as (sin beta', cos beta') ~ (u, -v), u = cos phi - cos alpha =
/// 2 sin(A'/2) sin(alpha - A'/2), v = sin phi + sin alpha cos c; the four-part formula
/// sin c cot|AC'| = cos c cos alpha + sin alpha cot beta' then simplifies by half-angle
/// identities to tan of a double angle). Its factors are all well conditioned: no
/// cancellation for small sub-triangles and no sqrt(1 - q^2) near q = 1. Likewise the second step,
/// 1 - cos(theta) = u2 (1 - cos |BC'|), is solved as tan(theta/2) = sqrt(u2) s / sqrt((1 - u2) s^2
/// + k^2) with s = |C' - B| / 2 and k = |C' + B| / 2 the sine and cosine of |BC'| / 2.
inline Vec3 sample_spherical_triangle(const SphericalTriangle& st, const Vec2& u) {
    // A'/2 = u1 Omega / 2 in [0, pi], in turns for sincos_turns.
    const SinCos h = sincos_turns(u.x * st.omega * (0.25 / kPi));
    // sin(alpha - A'/2) by the difference formula (for an obtuse angle, stored as pi - alpha,
    // sin(pi - alpha + A'/2) by the sum), clamped at 0 where A'/2 passes alpha: a sub-triangle
    // fits in its lune, and past it the sine turns negative.
    const double sin_rest = spherical_detail::larger_or_other(
        0.0, st.obtuse ? st.sin_alpha * h.cos + st.cos_alpha * h.sin
                       : st.sin_alpha * h.cos - st.cos_alpha * h.sin);
    double num = st.cos_half_c * h.sin;
    double den = st.sin_half_c * sin_rest;
    // |AC'| = 2 atan2(num, den) (num >= 0), clamped to |AC|. Its cosine and sine follow from
    // the half angle's by cos 2x = (d^2 - n^2) / (d^2 + n^2), sin 2x = 2 n d / (d^2 + n^2),
    // and the clamp compares the half angles by a cross product: no trigonometric call.
    double cos_arc = st.cos_b, sin_arc = st.sin_b;
    if (num * st.cos_half_b - den * st.sin_half_b < 0.0) { // |AC'| / 2 < |AC| / 2
        const double m = spherical_detail::larger_or_other(num, std::fabs(den));
        const double n = m > 0.0 ? num / m : 0.0, d = m > 0.0 ? den / m : 1.0;
        const double r2 = n * n + d * d;
        cos_arc = (d - n) * (d + n) / r2;
        sin_arc = 2.0 * n * d / r2;
    }
    Vec3 c_hat = st.A * cos_arc + st.tangent_ac * sin_arc;
    double s = 0.5 * glm::length(c_hat - st.B), k = 0.5 * glm::length(c_hat + st.B);
    // theta = 2 atan2(y, x), y = sqrt(u2) s, x = sqrt((1 - u2) s^2 + k^2): again by the
    // half-angle formulas, with x^2 + y^2 = s^2 + k^2.
    const double x2 = (1.0 - u.y) * s * s + k * k, y2 = u.y * s * s, r2 = x2 + y2;
    if (!(r2 > 0.0)) return st.B;
    const double cos_theta = (x2 - y2) / r2;
    const double sin_theta = 2.0 * std::sqrt(x2 * y2) / r2;
    Vec3 t = c_hat - st.B * glm::dot(c_hat, st.B);
    double lt = glm::length(t);
    if (!(lt > 0.0)) return st.B;
    return st.B * cos_theta + t * (sin_theta / lt);
}

} // namespace mcp
