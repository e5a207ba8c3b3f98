// The GGX microfacet distribution [Walter07] and the sampling of its visible normals
// [Heitz18, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)]: the pure math,
// shared by the renderer's BRDF (render/bsdf.cpp) and the warp tests (estimators/named_warps).
//
// Directions are unit vectors in a local frame whose z axis is the macrosurface normal. wo
// must lie above the surface (wo.z > 0; otherwise the density is 0 and the sampler returns
// n); alpha below kMinGgxAlpha is raised to it.
#pragma once

#include <cmath>

#include "core/special.h" // kPi
#include "core/warps.h"   // Vec2, Vec3

namespace mcp {

/// Lower bound on alpha in the GGX functions below: alpha^4 must not underflow.
constexpr double kMinGgxAlpha = 1e-12;

/// GGX normal distribution D(h) [Walter07, eq. 33] (local h).
double ggx_d(double alpha, const Vec3& h);
/// Smith's masking G1(w) [Walter07, eq. 34].
double ggx_g1(double alpha, const Vec3& w);
/// Density of ggx_sample_visible_normal per unit solid angle of h: the visible-normal
/// distribution D_v(h) = G1(wo) max(0, wo.h) D(h) / wo.z [Heitz18, eq. 1].
double ggx_visible_normal_pdf(double alpha, const Vec3& wo, const Vec3& h);
/// A normal h of the visible-normal distribution seen from wo, from u in [0, 1)^2
/// [Heitz18, listing 1].
Vec3 ggx_sample_visible_normal(double alpha, const Vec3& wo, const Vec2& u);

/// v / |v| computed without overflow or underflow (scaled by its largest component first);
/// false for the zero (or non-finite) vector.
bool safe_normalize(const Vec3& v, Vec3* out);

// --- Inline: the BRDF's evaluation loop calls these per shading point ---------------------

/// sqrt(w.z^2 + alpha^2 (1 - w.z^2)) for a unit w with w.z = c: the Smith term's root, with
/// G1(w) / w.z = 2 / (w.z + root) [Walter07, eq. 34; Heitz14].
inline double ggx_smith_root(double a2, double c) {
    double c2 = c * c;
    double rest = 1.0 - c2; // max(0, rest) by a comparison (NaN to 0)
    return std::sqrt(c2 + a2 * (rest > 0.0 ? rest : 0.0));
}

/// D(h) for a unit h with alpha^2 = a2 > 0: alpha^2 / (pi (alpha^2 h.z^2 + h.x^2 + h.y^2)^2),
/// with sin^2 = h.x^2 + h.y^2 rather than 1 - cos^2 (which cancels at h = n).
inline double ggx_d_a2(double a2, const Vec3& h) {
    if (!(h.z > 0.0)) return 0.0;
    double s2 = h.x * h.x + h.y * h.y;
    double denom = a2 * h.z * h.z + s2;
    return a2 / (kPi * denom * denom);
}

} // namespace mcp
