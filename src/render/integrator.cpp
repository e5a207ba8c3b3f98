// The radiance estimators of integrator.h: direct lighting by sampling directions or lights
// (and both, weighted by MIS), and path tracing with next-event estimation, each compiled for
// the four SurfaceKernels.
#include "render/integrator.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/common.hpp>

#include "core/mis.h"

namespace mcp {

namespace {

struct StrategyName {
    RadianceStrategy strategy;
    const char* name;
};
constexpr StrategyName kStrategyNames[] = {
    {RadianceStrategy::UniformHemisphere, "uniform_hemisphere"},
    {RadianceStrategy::CosineHemisphere, "cosine_hemisphere"},
    {RadianceStrategy::Bsdf, "bsdf"},
    {RadianceStrategy::LightArea, "light_area"},
    {RadianceStrategy::LightSolidAngle, "light_solid_angle"},
    {RadianceStrategy::MisBalance, "mis_balance"},
    {RadianceStrategy::MisPower, "mis_power"},
    {RadianceStrategy::Path, "path"},
    {RadianceStrategy::Ris, "ris"},
};

bool is_black(const Vec3& c) {
    return c.x == 0.0 && c.y == 0.0 && c.z == 0.0;
}

/// The multiple importance sampling weight of a sample drawn with density p_this when the
/// other strategy would have drawn it with density p_other, one sample each: the balance or
/// the power (beta = 2) heuristic [Veach97, 9.2.2, 9.2.4] of the shared weight module.
double mis_weight(double p_this, double p_other, bool power) {
    static constexpr MisWeighting kBalance{MisHeuristic::Balance};
    static constexpr MisWeighting kPower{MisHeuristic::Power};
    return mcp::mis_weight(power ? kPower : kBalance, p_this, p_other);
}

/// material_at, with the texture lookup compiled in or left out (a scene without textures).
template <bool kTextured> BsdfParams material_at_impl(const Scene& scene, const Hit& hit) {
    const Mesh& mesh = scene.mesh;
    BsdfParams b;
    uint32_t mi = hit.triangle < mesh.material.size() ? mesh.material[hit.triangle] : 0;
    if (mi >= scene.materials.size()) return b;
    const Material& m = scene.materials[mi];
    b.base_color = m.base_color;
    b.metallic = m.metallic;
    b.roughness = m.roughness;
    b.specular = m.specular;
    if (kTextured && m.base_color_texture >= 0 &&
        size_t(m.base_color_texture) < scene.textures.size() && !mesh.uv.empty()) {
        const Texture& t = scene.textures[size_t(m.base_color_texture)];
        const auto& idx = mesh.index[hit.triangle];
        double b0 = 1.0 - hit.b1 - hit.b2;
        Vec2 uv = b0 * mesh.uv[idx[0]] + hit.b1 * mesh.uv[idx[1]] + hit.b2 * mesh.uv[idx[2]];
        if (t.width > 0 && t.height > 0 && std::isfinite(uv.x) && std::isfinite(uv.y)) {
            // Nearest texel, repeat wrapping (the glTF sampler default).
            double fx = uv.x - std::floor(uv.x), fy = uv.y - std::floor(uv.y);
            int x = std::min(t.width - 1, int(fx * t.width));
            int y = std::min(t.height - 1, int(fy * t.height));
            size_t k = (size_t(y) * size_t(t.width) + size_t(x)) * 3;
            b.base_color *= Vec3(t.rgb[k], t.rgb[k + 1], t.rgb[k + 2]);
        }
    }
    return b;
}

/// The surfaces of a scene as the integrator sees them, compiled for what the scene uses
/// (SurfaceKernel, chosen once per render): every material Lambertian or not (no Fresnel or
/// GGX arithmetic), textured or not (no texture lookup). Each gives the general code's
/// numbers on the scenes it is chosen for, drawing the same random numbers.
template <bool kLambertian, bool kTextured> struct Surfaces {
    static BsdfParams at(const Scene& scene, const Hit& hit) {
        return material_at_impl<kTextured>(scene, hit);
    }
    static Vec3 eval_pdf(const BsdfParams& m, const Vec3& wo, const Vec3& wi, double* pdf) {
        return kLambertian ? lambert_eval_pdf(m, wo, wi, pdf) : bsdf_eval_pdf(m, wo, wi, pdf);
    }
    static BsdfSample sample(const BsdfParams& m, const Vec3& wo, double u_lobe, const Vec2& u) {
        return kLambertian ? lambert_sample(m, wo, u) : bsdf_sample(m, wo, u_lobe, u);
    }
};

/// A shading point: position, geometric normal turned towards the arriving ray, shading
/// frame (interpolated normal on the same side), BRDF parameters and the outgoing direction
/// in the shading frame.
struct ShadingPoint {
    Vec3 p, ng;
    Vec3 p_error; ///< bound on the rounding error of each coordinate of p
    Frame frame;
    BsdfParams bsdf;
    Vec3 wo_local;
    uint32_t triangle = 0;
};

template <class S> ShadingPoint shade(const Scene& scene, const Ray& ray, const Hit& hit) {
    const Mesh& mesh = scene.mesh;
    ShadingPoint sp;
    sp.triangle = hit.triangle;
    const auto& idx = mesh.index[hit.triangle];
    double b0 = 1.0 - hit.b1 - hit.b2;
    const Vec3 &p0 = mesh.position[idx[0]], &p1 = mesh.position[idx[1]],
               &p2 = mesh.position[idx[2]];
    sp.p = b0 * p0 + hit.b1 * p1 + hit.b2 * p2;
    // The barycentrics come from edge functions of the vertices translated by the ray origin,
    // and b0 = 1 - b1 - b2: their absolute errors are a few ulps relative to |p_i| and |o|, so
    // p's error is bounded by gamma_16 (|p0| + |p1| + |p2| + |o|) per coordinate (gamma_7 of
    // sum |b_i p_i| in [PBR4, 6.8.5], widened for this test's barycentrics).
    sp.p_error =
        rounding_gamma(16) * (glm::abs(p0) + glm::abs(p1) + glm::abs(p2) + glm::abs(ray.origin));
    Vec3 wo = -glm::normalize(ray.direction);
    sp.ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    if (glm::dot(sp.ng, wo) < 0.0) sp.ng = -sp.ng;
    Vec3 ns = sp.ng;
    if (!mesh.normal.empty()) {
        Vec3 n =
            b0 * mesh.normal[idx[0]] + hit.b1 * mesh.normal[idx[1]] + hit.b2 * mesh.normal[idx[2]];
        double len = glm::length(n);
        if (len > 0.0 && std::isfinite(len)) {
            n /= len;
            ns = glm::dot(n, sp.ng) < 0.0 ? -n : n;
        }
    }
    sp.frame = Frame::from_normal(ns);
    sp.wo_local = sp.frame.to_local(wo);
    sp.bsdf = S::at(scene, hit);
    return sp;
}

/// Is the segment from the shading point to a light point free? Both ends are moved off
/// their surfaces, and the ray stops just short of the light point.
bool visible(const RenderScene& rs, const ShadingPoint& sp, const Vec3& light_point,
             const Vec3& light_normal, SampleCounters& c) {
    Vec3 to_light = light_point - sp.p;
    Ray shadow;
    shadow.origin = offset_ray_origin(sp.p, sp.p_error, sp.ng, to_light);
    Vec3 target = offset_ray_origin(light_point, light_normal, -to_light);
    shadow.direction = target - shadow.origin;
    shadow.t_max = 1.0;
    ++c.rays;
    return !rs.accel.occluded(shadow);
}

Ray spawn_ray(const ShadingPoint& sp, const Vec3& direction) {
    Ray r;
    r.origin = offset_ray_origin(sp.p, sp.p_error, sp.ng, direction);
    r.direction = direction;
    return r;
}

/// One light sample's contribution f Le cos / p, times its MIS weight against BSDF sampling
/// when `mis` is set (n_light light and n_bsdf BSDF samples per point: q_k = n_k p_k).
template <class S>
Vec3 light_sample_term(const RenderScene& rs, const LightSet& lights, LightSampling mode,
                       const ShadingPoint& sp, PixelSampler& sampler, SampleCounters& c, bool mis,
                       bool power, double n_light = 1.0, double n_bsdf = 1.0) {
    ChoiceSample cs = sampler.get_choice_2d();
    LightSample ls = lights.sample(sp.p, cs.choice, cs.u, mode);
    if (!ls.valid || !(ls.pdf > 0.0)) {
        ++c.light_misses;
        return Vec3(0.0);
    }
    if (is_black(ls.radiance)) return Vec3(0.0);
    Vec3 to_light = ls.point - sp.p;
    double dist = glm::length(to_light);
    if (!(dist > 0.0)) return Vec3(0.0);
    Vec3 wi = to_light / dist;
    if (glm::dot(wi, sp.ng) <= 0.0) return Vec3(0.0); // below the surface: no light leaks
    Vec3 wi_local = sp.frame.to_local(wi);
    if (wi_local.z <= 0.0) return Vec3(0.0);
    double bsdf_density = 0.0;
    Vec3 f = S::eval_pdf(sp.bsdf, sp.wo_local, wi_local, &bsdf_density);
    if (is_black(f)) return Vec3(0.0);
    if (!visible(rs, sp, ls.point, ls.normal, c)) return Vec3(0.0);
    double w = mis ? mis_weight(n_light * ls.pdf, n_bsdf * bsdf_density, power) : 1.0;
    return f * ls.radiance * (wi_local.z * w / ls.pdf);
}

/// What a direction sampled at a shading point reaches: whether the ray hits, the hit, and the
/// radiance emitted there towards the point (0 when the hit does not emit).
struct DirectionResult {
    bool hit = false;
    Hit h;
    Vec3 emitted{0.0};
};
/// Traces the ray from the shading point along the world-space direction wi. With
/// rs.emitters_first the closest light hit comes from the lights' own accelerator and the
/// scene's only says whether anything is hit before it (0 < t < the light's t): the same
/// answer wherever the emission is nonzero (the triangle tests give the same t bit for bit in
/// both structures), r.hit false where the closest hit is not a light. The ray counts once.
DirectionResult trace_direction(const RenderScene& rs, const ShadingPoint& sp, const Vec3& wi,
                                SampleCounters& c) {
    DirectionResult r;
    Ray ray = spawn_ray(sp, wi);
    ++c.rays;
    if (rs.emitters_first) {
        if (!rs.emitters.intersect(ray, &r.h)) return r;
        r.h.triangle = rs.emitter_triangle[r.h.triangle];
        ray.t_max = r.h.t;
        if (rs.accel.occluded(ray)) return r;
        r.hit = true;
    } else {
        r.hit = rs.accel.intersect(ray, &r.h);
    }
    if (r.hit) r.emitted = rs.lights_uniform.emitted(r.h.triangle, -wi);
    return r;
}

/// Direct lighting by sampling directions: wi from the uniform hemisphere, the cosine
/// hemisphere or the BRDF, weighted f Le cos / p (times the MIS weight against light
/// sampling when `mis` is set, with the counts as in light_sample_term).
template <class S>
Vec3 direction_sample_term(const RenderScene& rs, const RenderEstimator& est,
                           const LightSet& lights, const ShadingPoint& sp, PixelSampler& sampler,
                           SampleCounters& c, bool mis, bool power, double n_light = 1.0,
                           double n_bsdf = 1.0) {
    Vec3 wi_local(0.0), f(0.0); // f stays black for a strategy out of range: no term
    double pdf = 0.0;
    bool delta = false;
    switch (est.strategy) {
    case RadianceStrategy::UniformHemisphere:
    case RadianceStrategy::CosineHemisphere: {
        Vec2 u = sampler.get_2d();
        if (est.strategy == RadianceStrategy::UniformHemisphere) {
            wi_local = sample_uniform_hemisphere(u);
            pdf = uniform_hemisphere_pdf();
        } else {
            wi_local = sample_cosine_hemisphere(u);
            pdf = cosine_hemisphere_pdf(wi_local.z);
        }
        if (!(pdf > 0.0) || wi_local.z <= 0.0) return Vec3(0.0);
        double unused_pdf;
        f = S::eval_pdf(sp.bsdf, sp.wo_local, wi_local, &unused_pdf);
        break;
    }
    case RadianceStrategy::Bsdf:
    case RadianceStrategy::MisBalance:
    case RadianceStrategy::MisPower: {
        ChoiceSample cs = sampler.get_choice_2d();
        BsdfSample bs = S::sample(sp.bsdf, sp.wo_local, cs.choice, cs.u);
        if (!bs.valid || !(bs.pdf > 0.0)) return Vec3(0.0);
        wi_local = bs.wi;
        f = bs.f;
        pdf = bs.pdf;
        delta = bs.delta;
        break;
    }
    case RadianceStrategy::LightArea:
    case RadianceStrategy::LightSolidAngle:
    case RadianceStrategy::Path:
    case RadianceStrategy::Ris:
        return Vec3(0.0); // never called with these (direct_radiance, path_radiance)
    }
    if (is_black(f)) return Vec3(0.0);
    Vec3 wi = sp.frame.to_world(wi_local);
    if (glm::dot(wi, sp.ng) <= 0.0) return Vec3(0.0);
    DirectionResult d = trace_direction(rs, sp, wi, c);
    if (!d.hit || is_black(d.emitted)) return Vec3(0.0);
    double w = 1.0;
    if (mis && !delta) {
        Vec3 p_light = sp.p + wi * d.h.t;
        double light_pdf = lights.pdf(sp.p, d.h.triangle, p_light, est.light_sampling);
        w = mis_weight(n_bsdf * pdf, n_light * light_pdf, power);
    }
    return f * d.emitted * (wi_local.z * w / pdf);
}

/// A light sample's unshadowed contribution f Le cos at a shading point (its RIS target is the
/// luminance of `value`), and where it lies, for the shadow ray if it is kept. No member
/// initializers: ris_light_term's array of kMaxRisCandidates is not cleared per sample.
struct RisCandidate {
    Vec3 point, normal, value;
    double target;
    double bsdf_pdf; ///< the BSDF's sampling density towards the candidate (for MIS)
};

/// The unshadowed contribution of one light sample (target 0 where it contributes nothing);
/// its solid-angle density in *pdf (0 for an invalid sample, counted as a light miss).
template <class S>
RisCandidate ris_candidate(const LightSet& lights, LightSampling mode, const ShadingPoint& sp,
                           const ChoiceSample& cs, SampleCounters& c, double* pdf) {
    RisCandidate x{Vec3(0.0), Vec3(0.0), Vec3(0.0), 0.0, 0.0};
    *pdf = 0.0;
    LightSample ls = lights.sample(sp.p, cs.choice, cs.u, mode);
    if (!ls.valid || !(ls.pdf > 0.0)) {
        ++c.light_misses;
        return x;
    }
    *pdf = ls.pdf;
    Vec3 to_light = ls.point - sp.p;
    double dist = glm::length(to_light);
    if (is_black(ls.radiance) || !(dist > 0.0)) return x;
    Vec3 wi = to_light / dist;
    if (glm::dot(wi, sp.ng) <= 0.0) return x; // below the surface: no light leaks
    Vec3 wi_local = sp.frame.to_local(wi);
    if (wi_local.z <= 0.0) return x;
    Vec3 f = S::eval_pdf(sp.bsdf, sp.wo_local, wi_local, &x.bsdf_pdf);
    x.point = ls.point;
    x.normal = ls.normal;
    x.value = f * ls.radiance * wi_local.z;
    x.target = luminance(x.value);
    if (!(x.target > 0.0) || !std::isfinite(x.target)) x.target = 0.0;
    return x;
}

/// Candidate j of M drawn from the first one's numbers x_0 = (choice, u): x_j = frac(x_0 + j g),
/// g = (1/M, a_1, a_2) with a_1, a_2 the fractions of Roberts' R_3 sequence [Roberts18]. Each
/// x_j is uniform because x_0 is (a shift modulo 1 keeps the uniform measure), which is all
/// RIS's unbiasedness asks of its candidates (by linearity: E[w_j f/target ...] needs only each
/// x_j's own density p [Talbot05, 4]); the choices are stratified by j/M, the points a shifted
/// Kronecker set, and one sampler request serves all M (the Sobol' sampler's dimensions cost).
ChoiceSample shifted_candidate(const ChoiceSample& first, int j, int m) {
    constexpr double kA1 = 0.7548776662466927, kA2 = 0.5698402909980532;
    const auto frac = [](double v) { return v - std::floor(v); };
    ChoiceSample cs;
    cs.choice = frac(first.choice + double(j) / double(m));
    cs.u = Vec2(frac(first.u.x + double(j) * kA1), frac(first.u.y + double(j) * kA2));
    return cs;
}

/// Direct lighting by resampled importance sampling [Talbot05, 4]: est.candidates light samples
/// x_j of density p, weights w_j = target(x_j) / p(x_j) with the unshadowed lum(f Le cos) as the
/// target, one y kept with probability w_j / sum_k w_k, and the one shadow ray towards y:
/// f Le cos V(y) / target(y) * (1/M) sum_j w_j [BitterliEtAl20, eq. 6]. Unbiased because the
/// target is positive wherever f Le cos V is (luminance weights every channel positively);
/// visibility is left out of the target, so occluded candidates still draw weight. M = 1 is
/// light sampling. The M candidates share one sampler request (shifted_candidate), and the kept
/// candidate's number is drawn after it (not for M = 1, whose numbers are light sampling's).
/// With `mis` (next-event estimation beside BSDF sampling: mis_* and path with candidates) the
/// integrand is w_L f Le cos V, w_L the heuristic of the counts times the source density p(y)
/// against the BSDF's density: RIS estimates any integrand the target covers without bias
/// [Talbot05, 4], and the BSDF sample's weight 1 - w_L (the same p) completes the partition of
/// unity [Veach97, 9.2], so the pair stays unbiased without RIS's own (intractable) density.
template <class S>
Vec3 ris_light_term(const RenderScene& rs, const RenderEstimator& est, const LightSet& lights,
                    const ShadingPoint& sp, PixelSampler& sampler, SampleCounters& c,
                    bool mis = false, bool power = false, double n_light = 1.0,
                    double n_bsdf = 1.0) {
    const int m = std::clamp(est.candidates, kMinRisCandidates, kMaxRisCandidates);
    RisCandidate candidates[kMaxRisCandidates];
    double weights[kMaxRisCandidates], pdfs[kMaxRisCandidates];
    double weight_sum = 0.0;
    const ChoiceSample first = sampler.get_choice_2d();
    for (int j = 0; j < m; ++j) {
        const ChoiceSample cs = j == 0 ? first : shifted_candidate(first, j, m);
        candidates[j] = ris_candidate<S>(lights, est.light_sampling, sp, cs, c, &pdfs[j]);
        weights[j] = candidates[j].target > 0.0 ? candidates[j].target / pdfs[j] : 0.0;
        weight_sum += weights[j];
    }
    double u = m > 1 ? sampler.get_1d() : 0.0;
    if (!(weight_sum > 0.0)) return Vec3(0.0);
    // An overflowing sum gives a non-finite sample, which the renderer drops and counts.
    if (!std::isfinite(weight_sum)) return Vec3(weight_sum);
    int kept = -1;
    double below = 0.0, threshold = u * weight_sum;
    for (int j = 0; j < m; ++j) {
        if (!(weights[j] > 0.0)) continue;
        kept = j; // the last positive weight takes what rounding leaves past the sum
        below += weights[j];
        if (threshold < below) break;
    }
    const RisCandidate& y = candidates[kept];
    if (!visible(rs, sp, y.point, y.normal, c)) return Vec3(0.0);
    const double w = mis ? mis_weight(n_light * pdfs[kept], n_bsdf * y.bsdf_pdf, power) : 1.0;
    return y.value * (w * weight_sum / (double(m) * y.target));
}

/// Next-event estimation at a shading point beside BSDF sampling (MIS with the counts): one
/// light sample, or RIS over est.candidates light samples (ris_light_term) when there are more.
template <class S>
Vec3 nee_term(const RenderScene& rs, const RenderEstimator& est, const LightSet& lights,
              const ShadingPoint& sp, PixelSampler& sampler, SampleCounters& c, bool power,
              double n_light = 1.0, double n_bsdf = 1.0) {
    if (est.candidates > 1)
        return ris_light_term<S>(rs, est, lights, sp, sampler, c, true, power, n_light, n_bsdf);
    return light_sample_term<S>(rs, lights, est.light_sampling, sp, sampler, c, true, power,
                                n_light, n_bsdf);
}

/// Does the estimator take more than one light or BSDF sample per shading point?
bool is_split(const RenderEstimator& est) {
    return est.light_samples > 1 || est.bsdf_samples > 1;
}

/// The mean of each strategy's samples at a shading point: light_samples light samples for the
/// strategies that sample lights, bsdf_samples direction samples for those that sample
/// directions, weighted by MIS with the counts for mis_* [Veach97, 9.2.1].
template <class S>
Vec3 split_direct_term(const RenderScene& rs, const RenderEstimator& est, const LightSet& lights,
                       const ShadingPoint& sp, PixelSampler& sampler, SampleCounters& c) {
    const bool mis =
        est.strategy == RadianceStrategy::MisBalance || est.strategy == RadianceStrategy::MisPower;
    const bool power = est.strategy == RadianceStrategy::MisPower;
    const bool ris = est.strategy == RadianceStrategy::Ris;
    const bool lights_sampled = mis || ris || est.strategy == RadianceStrategy::LightArea ||
                                est.strategy == RadianceStrategy::LightSolidAngle;
    const int n_light = lights_sampled ? std::max(1, est.light_samples) : 0;
    const int n_bsdf = lights_sampled && !mis ? 0 : std::max(1, est.bsdf_samples);
    LightSampling mode = est.strategy == RadianceStrategy::LightArea ? LightSampling::Area
                         : est.strategy == RadianceStrategy::LightSolidAngle
                             ? LightSampling::SolidAngle
                             : est.light_sampling;
    Vec3 from_light(0.0), from_bsdf(0.0);
    for (int i = 0; i < n_light; ++i)
        from_light += ris   ? ris_light_term<S>(rs, est, lights, sp, sampler, c)
                      : mis ? nee_term<S>(rs, est, lights, sp, sampler, c, power, n_light, n_bsdf)
                            : light_sample_term<S>(rs, lights, mode, sp, sampler, c, false, false);
    for (int i = 0; i < n_bsdf; ++i)
        from_bsdf +=
            direction_sample_term<S>(rs, est, lights, sp, sampler, c, mis, power, n_light, n_bsdf);
    Vec3 sum(0.0);
    if (n_light > 0) sum += from_light / double(n_light);
    if (n_bsdf > 0) sum += from_bsdf / double(n_bsdf);
    return sum;
}

/// The direct-lighting estimators: emission seen by the camera plus one estimate of the
/// reflected direct light at the first hit.
template <class S>
RadianceSample direct_radiance(const RenderScene& rs, const RenderEstimator& est,
                               const Ray& camera_ray, PixelSampler& sampler, SampleCounters& c) {
    RadianceSample out;
    Hit hit;
    ++c.rays;
    if (!rs.accel.intersect(camera_ray, &hit)) return out;
    const Scene& scene = *rs.scene;
    Vec3 wo = -glm::normalize(camera_ray.direction);
    out.emitted = rs.lights_uniform.emitted(hit.triangle, wo);
    ShadingPoint sp = shade<S>(scene, camera_ray, hit);
    if (sp.wo_local.z <= 0.0) return out;
    const LightSet& lights = rs.lights(est.light_selection);
    if (lights.empty()) return out;
    if (is_split(est)) {
        out.reflected = split_direct_term<S>(rs, est, lights, sp, sampler, c);
        return out;
    }
    switch (est.strategy) {
    case RadianceStrategy::UniformHemisphere:
    case RadianceStrategy::CosineHemisphere:
    case RadianceStrategy::Bsdf:
        out.reflected = direction_sample_term<S>(rs, est, lights, sp, sampler, c, false, false);
        break;
    case RadianceStrategy::LightArea:
        out.reflected =
            light_sample_term<S>(rs, lights, LightSampling::Area, sp, sampler, c, false, false);
        break;
    case RadianceStrategy::LightSolidAngle:
        out.reflected = light_sample_term<S>(rs, lights, LightSampling::SolidAngle, sp, sampler, c,
                                             false, false);
        break;
    case RadianceStrategy::MisBalance:
    case RadianceStrategy::MisPower: {
        bool power = est.strategy == RadianceStrategy::MisPower;
        // Two statements: both terms draw from the sampler, and the order in which the
        // operands of + are evaluated is unspecified (g++ and clang differ).
        Vec3 from_light = nee_term<S>(rs, est, lights, sp, sampler, c, power);
        Vec3 from_bsdf = direction_sample_term<S>(rs, est, lights, sp, sampler, c, true, power);
        out.reflected = from_light + from_bsdf;
        break;
    }
    case RadianceStrategy::Ris:
        out.reflected = ris_light_term<S>(rs, est, lights, sp, sampler, c);
        break;
    case RadianceStrategy::Path: break; // path_radiance's (sample_radiance_with)
    }
    return out;
}

/// Path tracing with next-event estimation: at every vertex one light sample and one BSDF
/// sample, weighted by the power heuristic, the BSDF sample continuing the path [Veach97, 9.2;
/// PBR4, 13.4]. Russian roulette from rr_depth on survives with probability
/// min(0.95, max throughput component), dividing the throughput by it (unbiased).
template <class S>
RadianceSample path_radiance(const RenderScene& rs, const RenderEstimator& est,
                             const Ray& camera_ray, PixelSampler& sampler, SampleCounters& c) {
    const Scene& scene = *rs.scene;
    const LightSet& lights = rs.lights(est.light_selection);
    Vec3 L(0.0), beta(1.0), emitted(0.0);
    Ray ray = camera_ray;
    bool previous_delta = true; // the camera "samples" its ray: count emission in full
    double previous_pdf = 0.0;
    Vec3 previous_point(0.0);
    for (int depth = 0;; ++depth) {
        Hit hit;
        ++c.rays;
        if (!rs.accel.intersect(ray, &hit)) break;
        Vec3 wo = -glm::normalize(ray.direction);
        Vec3 Le = lights.emitted(hit.triangle, wo);
        if (!is_black(Le)) {
            double w = 1.0;
            if (!previous_delta) {
                Vec3 p = ray.origin + ray.direction * hit.t;
                w = mis_weight(previous_pdf,
                               lights.pdf(previous_point, hit.triangle, p, est.light_sampling),
                               true);
            }
            if (depth == 0)
                emitted = Le;
            else
                L += beta * Le * w;
        }
        if (depth >= est.max_depth) break;
        ShadingPoint sp = shade<S>(scene, ray, hit);
        if (sp.wo_local.z <= 0.0) break;
        if (!lights.empty()) L += beta * nee_term<S>(rs, est, lights, sp, sampler, c, true);
        ChoiceSample cs = sampler.get_choice_2d();
        BsdfSample bs = S::sample(sp.bsdf, sp.wo_local, cs.choice, cs.u);
        if (!bs.valid || !(bs.pdf > 0.0) || is_black(bs.f)) break;
        Vec3 wi = sp.frame.to_world(bs.wi);
        if (glm::dot(wi, sp.ng) <= 0.0) break;
        beta *= bs.f * (bs.wi.z / bs.pdf);
        previous_delta = bs.delta;
        previous_pdf = bs.pdf;
        previous_point = sp.p;
        ray = spawn_ray(sp, wi);
        if (depth + 1 >= est.rr_depth) {
            double q = std::min(0.95, std::max(beta.x, std::max(beta.y, beta.z)));
            // The roulette's number is a sample dimension like any other.
            if (!(q > 0.0) || sampler.get_1d() >= q) break;
            beta /= q;
        }
    }
    return RadianceSample{emitted, L};
}

/// path_radiance with splitting: at every vertex light_samples light samples and bsdf_samples
/// BSDF samples, each weighted by the power heuristic with the counts and divided by its count
/// [Veach97, 9.2.1]. The BSDF samples count the emission they reach (the next vertex's
/// emission is theirs, not the path's), and the first of them continues the path.
template <class S>
RadianceSample split_path_radiance(const RenderScene& rs, const RenderEstimator& est,
                                   const Ray& camera_ray, PixelSampler& sampler,
                                   SampleCounters& c) {
    const Scene& scene = *rs.scene;
    const LightSet& lights = rs.lights(est.light_selection);
    const int n_light = std::max(1, est.light_samples), n_bsdf = std::max(1, est.bsdf_samples);
    Vec3 L(0.0), beta(1.0), emitted(0.0);
    Ray ray = camera_ray;
    Hit hit;
    ++c.rays;
    if (!rs.accel.intersect(ray, &hit)) return RadianceSample{};
    emitted = lights.emitted(hit.triangle, -glm::normalize(ray.direction));
    for (int depth = 0; depth < est.max_depth; ++depth) {
        ShadingPoint sp = shade<S>(scene, ray, hit);
        if (sp.wo_local.z <= 0.0) break;
        Vec3 direct(0.0), from_bsdf(0.0);
        if (!lights.empty())
            for (int i = 0; i < n_light; ++i)
                direct += nee_term<S>(rs, est, lights, sp, sampler, c, true, n_light, n_bsdf);
        bool next = false;
        Vec3 next_beta(0.0);
        Ray next_ray;
        Hit next_hit;
        for (int j = 0; j < n_bsdf; ++j) {
            ChoiceSample cs = sampler.get_choice_2d();
            BsdfSample bs = S::sample(sp.bsdf, sp.wo_local, cs.choice, cs.u);
            if (!bs.valid || !(bs.pdf > 0.0) || is_black(bs.f)) continue;
            Vec3 wi = sp.frame.to_world(bs.wi);
            if (glm::dot(wi, sp.ng) <= 0.0) continue;
            Ray r = spawn_ray(sp, wi);
            Hit h;
            ++c.rays;
            if (!rs.accel.intersect(r, &h)) continue;
            Vec3 Le = lights.emitted(h.triangle, -wi);
            if (!is_black(Le)) {
                double w = 1.0;
                if (!bs.delta) {
                    Vec3 p = r.origin + r.direction * h.t;
                    w = mis_weight(n_bsdf * bs.pdf,
                                   n_light * lights.pdf(sp.p, h.triangle, p, est.light_sampling),
                                   true);
                }
                from_bsdf += bs.f * Le * (bs.wi.z * w / bs.pdf);
            }
            if (j == 0) {
                next = true;
                next_beta = beta * bs.f * (bs.wi.z / bs.pdf);
                next_ray = r;
                next_hit = h;
            }
        }
        L += beta * (direct / double(n_light) + from_bsdf / double(n_bsdf));
        if (!next || depth + 1 >= est.max_depth) break;
        beta = next_beta;
        ray = next_ray;
        hit = next_hit;
        if (depth + 1 >= est.rr_depth) {
            double q = std::min(0.95, std::max(beta.x, std::max(beta.y, beta.z)));
            if (!(q > 0.0) || sampler.get_1d() >= q) break;
            beta /= q;
        }
    }
    return RadianceSample{emitted, L};
}

} // namespace

Vec3 emitted_along(const RenderScene& rs, const Ray& camera_ray, SampleCounters& c) {
    Ray ray = camera_ray;
    Hit h;
    ++c.rays;
    if (rs.emitters_first) {
        if (!rs.emitters.intersect(ray, &h)) return Vec3(0.0);
        h.triangle = rs.emitter_triangle[h.triangle];
        ray.t_max = h.t;
        if (rs.accel.occluded(ray)) return Vec3(0.0);
    } else if (!rs.accel.intersect(ray, &h)) {
        return Vec3(0.0);
    }
    return rs.lights_uniform.emitted(h.triangle, -ray.direction);
}

Vec2 shifted_jitter(const Vec2& jitter, int j, int n) {
    constexpr double kGolden = 0.6180339887498949;
    const auto frac = [](double v) { return v - std::floor(v); };
    return Vec2(frac(jitter.x + double(j) / double(n)), frac(jitter.y + double(j) * kGolden));
}

const char* strategy_name(RadianceStrategy s) {
    for (const auto& n : kStrategyNames)
        if (n.strategy == s) return n.name;
    return "?";
}

bool parse_strategy(const std::string& name, RadianceStrategy* s) {
    for (const auto& n : kStrategyNames)
        if (name == n.name) {
            *s = n.strategy;
            return true;
        }
    return false;
}

void RenderScene::build(const Scene& s, AccelKind accel_kind) {
    scene = &s;
    accel.build(s.mesh, accel_kind);
    lights_uniform.build(s, LightSelection::Uniform);
    lights_area.build(s, LightSelection::Area);
    lights_power.build(s, LightSelection::Power);
    emitter_triangle.clear();
    for (uint32_t t = 0; t < uint32_t(s.mesh.triangle_count()); ++t)
        if (lights_uniform.light_index(t) >= 0) emitter_triangle.push_back(t);
    emitters_first =
        !emitter_triangle.empty() && 2 * emitter_triangle.size() <= s.mesh.triangle_count();
    emitters = Accelerator();
    if (!emitters_first) return;
    // The lights as a mesh of their own, triangles in the scene's order (so ties between
    // lights at the same t go to the lower mesh id in both structures).
    Mesh lights;
    lights.position = s.mesh.position;
    lights.index.reserve(emitter_triangle.size());
    for (uint32_t t : emitter_triangle) lights.index.push_back(s.mesh.index[t]);
    emitters.build(lights, accel_kind);
}

const LightSet& RenderScene::lights(LightSelection selection) const {
    switch (selection) {
    case LightSelection::Uniform: return lights_uniform;
    case LightSelection::Area: return lights_area;
    case LightSelection::Power: return lights_power;
    }
    return lights_uniform; // not reached: every selection is a case
}

BsdfParams material_at(const Scene& scene, const Hit& hit) {
    return material_at_impl<true>(scene, hit);
}

template <SurfaceKernel K>
RadianceSample sample_radiance_with(const RenderScene& rs, const RenderEstimator& est,
                                    const Ray& camera_ray, PixelSampler& sampler,
                                    SampleCounters& counters) {
    using S =
        Surfaces<K == SurfaceKernel::Lambertian || K == SurfaceKernel::LambertianTextured,
                 K == SurfaceKernel::GeneralTextured || K == SurfaceKernel::LambertianTextured>;
    if (est.strategy == RadianceStrategy::Path)
        return is_split(est) ? split_path_radiance<S>(rs, est, camera_ray, sampler, counters)
                             : path_radiance<S>(rs, est, camera_ray, sampler, counters);
    return direct_radiance<S>(rs, est, camera_ray, sampler, counters);
}

// The four versions, compiled here (the renderer picks one per image).
#define MCP_SAMPLE_RADIANCE_WITH(K)                                                                \
    template RadianceSample sample_radiance_with<SurfaceKernel::K>(                                \
        const RenderScene&, const RenderEstimator&, const Ray&, PixelSampler&, SampleCounters&);
MCP_SAMPLE_RADIANCE_WITH(GeneralTextured)
MCP_SAMPLE_RADIANCE_WITH(General)
MCP_SAMPLE_RADIANCE_WITH(LambertianTextured)
MCP_SAMPLE_RADIANCE_WITH(Lambertian)
#undef MCP_SAMPLE_RADIANCE_WITH

RadianceSample sample_radiance(const RenderScene& rs, const RenderEstimator& est,
                               const Ray& camera_ray, PixelSampler& sampler,
                               SampleCounters& counters) {
    return sample_radiance_with<SurfaceKernel::GeneralTextured>(rs, est, camera_ray, sampler,
                                                                counters);
}

SurfaceKernel surface_kernel(const Scene& scene) {
    const Mesh& mesh = scene.mesh;
    bool lambertian = true, textured = false;
    for (const Material& m : scene.materials) {
        BsdfParams p;
        p.metallic = m.metallic;
        p.specular = m.specular;
        lambertian = lambertian && bsdf_is_lambertian(p);
        textured = textured || m.base_color_texture >= 0;
    }
    textured = textured && !scene.textures.empty() && !mesh.uv.empty();
    // A triangle without a valid material is shaded with the default (glTF) parameters.
    for (uint32_t mi : mesh.material) lambertian = lambertian && mi < scene.materials.size();
    if (mesh.material.size() < mesh.triangle_count()) lambertian = false;
    if (lambertian) return textured ? SurfaceKernel::LambertianTextured : SurfaceKernel::Lambertian;
    return textured ? SurfaceKernel::GeneralTextured : SurfaceKernel::General;
}

const char* surface_kernel_name(SurfaceKernel k) {
    switch (k) {
    case SurfaceKernel::GeneralTextured: return "gltf_textured";
    case SurfaceKernel::General: return "gltf";
    case SurfaceKernel::LambertianTextured: return "lambertian_textured";
    case SurfaceKernel::Lambertian: return "lambertian";
    }
    return "?"; // not reached: every kernel is a case
}

} // namespace mcp
