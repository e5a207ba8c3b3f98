// The glTF 2.0 metallic-roughness BRDF [glTF2, Appendix B] and its sampling: see bsdf.h.
//
// Numerics. Every density and value is written in a form without a small divisor:
// - D(h) = alpha^2 / (pi (alpha^2 h.z^2 + h.x^2 + h.y^2)^2) [Walter07, eq. 33] uses
//   sin^2 = h.x^2 + h.y^2 instead of 1 - cos^2, which cancels catastrophically at h = n;
// - G1(w) / w.z = 2 / (w.z + r(w)), r(w) = sqrt(w.z^2 + alpha^2 (1 - w.z^2)) [Walter07,
//   eq. 34; Heitz14], so the specular term F D G / (4 wo.z wi.z) = F D / ((wo.z + r(wo))
//   (wi.z + r(wi))), and the density of the reflected visible normal, D_v(h) times the
//   reflection Jacobian 1 / (4 wo.h) [Walter07], = D(h) G1(wo) / (4 wo.z) = D(h) / (2 (wo.z +
//   r(wo))), stay finite at grazing wo;
// - half vectors and sampled directions are normalised after scaling by the largest
//   component, so sums of tiny vectors do not underflow.
//
// Reflected visible normals that leave the hemisphere (wi.z <= 0) are returned as invalid
// samples: the specular density integrates to less than 1 over the hemisphere (by alpha^2 /
// (1 + alpha^2) at normal incidence), and those samples contribute 0, which keeps the
// estimator unbiased.
#include "render/bsdf.h"

#include <cmath>

#include "core/special.h"

namespace mcp {
namespace {

constexpr double kMinLobeProbability = 0.05;

// Comparisons rather than std::fmin / std::fmax (library calls without -ffast-math); maps NaN
// to 0.
double clamp01(double x) {
    return x > 0.0 ? (x < 1.0 ? x : 1.0) : 0.0;
}

/// Schlick's Fresnel f0 + (f90 - f0) (1 - c)^5 [Schlick94] for c in [0, 1] (f90 = 1 but for
/// a dielectric whose KHR_materials_specular factor scales its layer).
Vec3 schlick(const Vec3& f0, const Vec3& f90, double c) {
    double t = 1.0 - clamp01(c);
    double t2 = t * t;
    return f0 + (f90 - f0) * (t2 * t2 * t);
}

/// The material reduced to what the lobes need, for one wo.
struct Lobes {
    Vec3 c_diff{0.0};     ///< diffuse colour (1 - metallic) base
    Vec3 f0{0.04};        ///< Fresnel at normal incidence
    Vec3 f90{1.0};        ///< Fresnel at grazing incidence
    bool specular = true; ///< the specular layer exists (f90 != 0)
    double alpha = 1.0;   ///< roughness^2
    double a2 = 1.0;      ///< alpha^2
    bool mirror = false;  ///< alpha < kMirrorAlpha: the specular lobe is a delta
    bool diffuse = false; ///< c_diff != 0
    double p_spec = 1.0;  ///< probability of picking the specular lobe
};

Lobes make_lobes(const BsdfParams& m, double cos_o) {
    Lobes l;
    Vec3 base(clamp01(m.base_color.x), clamp01(m.base_color.y), clamp01(m.base_color.z));
    double metallic = clamp01(m.metallic);
    double roughness = clamp01(m.roughness);
    // KHR_materials_specular: the dielectric's layer F = s (f0 + (1 - f0)(1 - V.H)^5).
    double spec = clamp01(m.specular);
    l.c_diff = base * (1.0 - metallic);
    l.f0 = Vec3(0.04 * spec) * (1.0 - metallic) + base * metallic;
    l.f90 = Vec3(spec * (1.0 - metallic) + metallic);
    l.specular = l.f90.x > 0.0;
    l.alpha = roughness * roughness;
    l.a2 = l.alpha * l.alpha;
    l.mirror = l.alpha < kMirrorAlpha;
    l.diffuse = l.c_diff.x > 0.0 || l.c_diff.y > 0.0 || l.c_diff.z > 0.0;
    if (!l.diffuse) {
        l.p_spec = 1.0;
        return l;
    }
    if (!l.specular) {
        l.p_spec = 0.0; // a pure Lambertian
        return l;
    }
    // Lobe selection: the luminance of each lobe's weight at the mirror configuration
    // (V.H = wo.z): Schlick's F for the specular lobe, (1 - F) c_diff for the diffuse one;
    // clamped so that neither lobe is ever starved.
    Vec3 F = schlick(l.f0, l.f90, cos_o);
    double w_spec = luminance(F);
    double w_diff = luminance((Vec3(1.0) - F) * l.c_diff);
    double p = w_spec + w_diff > 0.0 ? w_spec / (w_spec + w_diff) : 0.5;
    l.p_spec = p > kMinLobeProbability
                   ? (p < 1.0 - kMinLobeProbability ? p : 1.0 - kMinLobeProbability)
                   : kMinLobeProbability;
    return l;
}

/// f (non-delta lobes) and the mixture density of sampling wi; both 0 below the surface.
void eval_and_pdf(const Lobes& l, const Vec3& wo, const Vec3& wi, Vec3* f, double* pdf) {
    *f = Vec3(0.0);
    *pdf = 0.0;
    if (!(wo.z > 0.0) || !(wi.z > 0.0)) return;
    Vec3 h;
    if (!safe_normalize(wo + wi, &h)) return;
    double voh = clamp01(glm::dot(wo, h));
    Vec3 F = schlick(l.f0, l.f90, voh);
    if (l.diffuse) {
        *f += (Vec3(1.0) - F) * l.c_diff * kInvPi;
        *pdf += (1.0 - l.p_spec) * cosine_hemisphere_pdf(wi.z);
    }
    if (!l.mirror && l.specular) {
        double d = ggx_d_a2(l.a2, h);
        double root_o = wo.z + ggx_smith_root(l.a2, wo.z);
        double root_i = wi.z + ggx_smith_root(l.a2, wi.z);
        *f += F * (d / (root_o * root_i));
        *pdf += l.p_spec * d / (2.0 * root_o);
    }
    if (!std::isfinite(*pdf) || !std::isfinite(f->x) || !std::isfinite(f->y) ||
        !std::isfinite(f->z)) {
        *f = Vec3(0.0);
        *pdf = 0.0;
    }
}

} // namespace

Vec3 bsdf_eval(const BsdfParams& m, const Vec3& wo, const Vec3& wi) {
    Vec3 f;
    double pdf;
    eval_and_pdf(make_lobes(m, wo.z), wo, wi, &f, &pdf);
    return f;
}

double bsdf_pdf(const BsdfParams& m, const Vec3& wo, const Vec3& wi) {
    Vec3 f;
    double pdf;
    eval_and_pdf(make_lobes(m, wo.z), wo, wi, &f, &pdf);
    return pdf;
}

Vec3 bsdf_eval_pdf(const BsdfParams& m, const Vec3& wo, const Vec3& wi, double* pdf) {
    Vec3 f;
    eval_and_pdf(make_lobes(m, wo.z), wo, wi, &f, pdf);
    return f;
}

double bsdf_specular_probability(const BsdfParams& m, const Vec3& wo) {
    return make_lobes(m, wo.z).p_spec;
}

bool bsdf_has_delta(const BsdfParams& m) {
    double roughness = clamp01(m.roughness);
    bool layer = clamp01(m.specular) > 0.0 || clamp01(m.metallic) > 0.0;
    return layer && roughness * roughness < kMirrorAlpha;
}

bool bsdf_is_lambertian(const BsdfParams& m) {
    return clamp01(m.metallic) == 0.0 && clamp01(m.specular) == 0.0;
}

Vec3 lambert_eval_pdf(const BsdfParams& m, const Vec3& wo, const Vec3& wi, double* pdf) {
    *pdf = 0.0;
    if (!(wo.z > 0.0) || !(wi.z > 0.0)) return Vec3(0.0);
    const Vec3 c(clamp01(m.base_color.x), clamp01(m.base_color.y), clamp01(m.base_color.z));
    if (!(c.x > 0.0 || c.y > 0.0 || c.z > 0.0)) return Vec3(0.0); // no lobe: no density
    *pdf = cosine_hemisphere_pdf(wi.z);
    return c * kInvPi;
}

BsdfSample lambert_sample(const BsdfParams& m, const Vec3& wo, const Vec2& u) {
    BsdfSample s;
    if (!(wo.z > 0.0)) return s;
    const Vec3 c(clamp01(m.base_color.x), clamp01(m.base_color.y), clamp01(m.base_color.z));
    if (!(c.x > 0.0 || c.y > 0.0 || c.z > 0.0)) return s; // black: no direction carries light
    const Vec3 wi = sample_cosine_hemisphere(u);
    if (!(wi.z > 0.0)) return s;
    s.wi = wi;
    s.f = c * kInvPi;
    s.pdf = cosine_hemisphere_pdf(wi.z);
    s.valid = s.pdf > 0.0;
    return s;
}

BsdfSample bsdf_sample(const BsdfParams& m, const Vec3& wo, double u_lobe, const Vec2& u) {
    BsdfSample s;
    if (!(wo.z > 0.0)) return s;
    Lobes l = make_lobes(m, wo.z);
    bool specular = u_lobe < l.p_spec;
    if (specular && l.mirror) {
        // The delta lobe: weight f cos / pdf = F(wo.z) / p_spec.
        s.wi = Vec3(-wo.x, -wo.y, wo.z);
        s.pdf = l.p_spec;
        s.f = schlick(l.f0, l.f90, wo.z) / wo.z;
        s.delta = true;
        s.valid = std::isfinite(s.f.x) && std::isfinite(s.f.y) && std::isfinite(s.f.z);
        if (!s.valid) s.f = Vec3(0.0);
        return s;
    }
    Vec3 wi;
    if (specular) {
        Vec3 h = ggx_sample_visible_normal(l.alpha, wo, u);
        if (!safe_normalize(h * (2.0 * glm::dot(wo, h)) - wo, &wi)) return s;
    } else {
        wi = sample_cosine_hemisphere(u);
    }
    if (!(wi.z > 0.0)) return s;
    s.wi = wi;
    eval_and_pdf(l, wo, wi, &s.f, &s.pdf);
    s.valid = s.pdf > 0.0;
    return s;
}

} // namespace mcp
