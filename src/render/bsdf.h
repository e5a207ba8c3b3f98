// The glTF 2.0 metallic-roughness BRDF (glTF 2.0 specification, Appendix B): a Lambertian
// base under a GGX microfacet layer mixed by Schlick's Fresnel, and a GGX conductor with
// Fresnel f0 = base colour, blended by `metallic`; alpha = roughness^2, Smith's separable
// masking-shadowing. Sampling picks a lobe, then the cosine hemisphere or the GGX
// distribution of visible normals [Heitz18, "Sampling the GGX Distribution of Visible
// Normals", JCGT 7(4)].
//
// All directions are unit vectors in the local shading frame (z = shading normal), both
// pointing away from the surface. f excludes the cosine factor. Parameters are clamped to
// [0, 1]. Only reflection: f = 0 when wo.z <= 0 or wi.z <= 0. Values and densities are finite
// for any unit directions (grazing ones included), never NaN or Inf.
#pragma once

#include "core/microfacet.h" // the GGX pieces: ggx_d, ggx_g1, visible normals [Heitz18]
#include "render/geometry.h"

namespace mcp {

/// Below this alpha = roughness^2 the specular lobe is treated as a perfect mirror (a delta
/// lobe): GGX's peak D(h = n) = 1 / (pi alpha^2) then exceeds 3e5 and both evaluating and
/// light-sampling it are numerically meaningless.
///
/// The mirror lobe: bsdf_sample picks it with probability p = bsdf_specular_probability and
/// returns delta = true, wi = (-wo.x, -wo.y, wo.z), pdf = p and f = F(wo.z) / wi.z, so that
/// the path weight f wi.z / pdf is Schlick's F(wo.z) (f0 as below) divided by p. bsdf_eval and
/// bsdf_pdf then hold only the diffuse lobe (its pdf (1 - p) cos / pi): both are 0 for a metal.
constexpr double kMirrorAlpha = 1e-3;

/// The BRDF's parameters at one shading point (texture lookups already applied).
struct BsdfParams {
    Vec3 base_color{1.0};
    double metallic = 0.0;
    double roughness = 1.0;
    /// KHR_materials_specular specularFactor: scales the dielectric's Fresnel layer (f0 and
    /// f90); 0 with metallic 0 is a pure Lambertian c / pi.
    double specular = 1.0;
};

struct BsdfSample {
    Vec3 wi{0.0, 0.0, 1.0};
    Vec3 f{0.0};      ///< BRDF value (for a delta lobe: its weight times 1 / (pdf cos))
    double pdf = 0.0; ///< solid-angle density of the whole mixture (delta: probability of the lobe)
    bool delta = false; ///< sampled the mirror lobe: light sampling cannot reach this direction
    bool valid = false; ///< false: no direction (below the surface, zero pdf); contributes 0
};

/// f(wo, wi) of the non-delta lobes; 0 when either direction is below the surface.
Vec3 bsdf_eval(const BsdfParams& m, const Vec3& wo, const Vec3& wi);
/// Solid-angle density with which bsdf_sample returns wi (non-delta lobes only).
double bsdf_pdf(const BsdfParams& m, const Vec3& wo, const Vec3& wi);
/// Both at once (one half vector, one D): returns bsdf_eval, stores bsdf_pdf in *pdf.
Vec3 bsdf_eval_pdf(const BsdfParams& m, const Vec3& wo, const Vec3& wi, double* pdf);
/// Samples wi: u_lobe chooses the lobe (specular when u_lobe < bsdf_specular_probability), u
/// the direction within it. pdf is the mixture density bsdf_pdf(wo, wi) and f is
/// bsdf_eval(wo, wi), whichever lobe produced wi. A specular sample whose reflected direction
/// falls below the surface is invalid (up to half of them for roughness 1 at normal
/// incidence): bsdf_pdf integrates to 1 minus that probability over the hemisphere.
BsdfSample bsdf_sample(const BsdfParams& m, const Vec3& wo, double u_lobe, const Vec2& u);
/// True when the material has a delta (mirror) lobe.
bool bsdf_has_delta(const BsdfParams& m);
/// Probability that bsdf_sample picks the specular lobe at wo: the luminance of Schlick's
/// F(wo.z) against that of the diffuse weight (1 - F(wo.z)) c_diff, clamped to [0.05, 0.95];
/// exactly 1 when c_diff = (1 - metallic) base is black (no diffuse lobe).
double bsdf_specular_probability(const BsdfParams& m, const Vec3& wo);

/// Is the BRDF of these parameters the pure Lambertian c / pi (metallic 0 and specular 0
/// after clamping)? Such a material has no specular layer at all.
bool bsdf_is_lambertian(const BsdfParams& m);
/// The Lambertian BRDF c / pi (c = base colour clamped to [0, 1]) with the cosine density
/// cos / pi, and its sampling: for parameters where bsdf_is_lambertian holds, the same
/// numbers as bsdf_eval_pdf and bsdf_sample, which a scene of such materials uses without
/// their Fresnel and GGX arithmetic (the choice number bsdf_sample would use is not needed).
Vec3 lambert_eval_pdf(const BsdfParams& m, const Vec3& wo, const Vec3& wi, double* pdf);
BsdfSample lambert_sample(const BsdfParams& m, const Vec3& wo, const Vec2& u);

// The GGX pieces the BRDF is built of (ggx_d, ggx_g1, ggx_visible_normal_pdf,
// ggx_sample_visible_normal) are declared in core/microfacet.h.

} // namespace mcp
