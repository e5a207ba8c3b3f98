// Estimators of the radiance arriving at the camera through one pixel sample.
//
// The direct-lighting estimators estimate L(x -> wo) = Le(x -> wo) + integral of
// f(wo, wi) Li(wi) cos(theta_i) d(wi) at the first visible point x, with Li the emitted
// radiance reached along wi. The same integral in the area form of the transport equation
// (the course notes' formula) is an integral over the light points x':
//   integral f(wo, wi) Le(x' -> x) v(x, x') cos(theta_i) cos(theta') / |x - x'|^2 dA(x'),
// and the strategies differ only in the density they sample:
//   uniform_hemisphere  1 / (2 pi) in solid angle
//   cosine_hemisphere   cos(theta) / pi
//   bsdf                the BRDF's own sampling density (bsdf.h)
//   light_area          a light chosen by uniform, area or power weights, then a point
//                       uniform in its area, the density converted to solid angle by
//                       |x - x'|^2 / cos(theta') [course notes; PBR4, 12.2]
//   light_solid_angle   a light chosen as above, then a direction uniform in its spherical
//                       triangle [Arvo95]
//   mis_balance,        one light sample and one BSDF sample combined by multiple importance
//   mis_power           sampling with the balance or power (beta = 2) heuristic [Veach97, 9.2]
//   path                path tracing with next-event estimation, MIS (power heuristic) of
//                       light and BSDF samples at every vertex, a maximum number of bounces
//                       and Russian roulette [Veach97; PBR4, 13]
//   ris                 resampled importance sampling [Talbot05]: M candidates from light
//                       sampling (light_selection, light_sampling; the render API's default
//                       for ris: uniform choice, by area), one of them chosen in
//                       proportion to w_j = target(x_j) / p(x_j), the target the unshadowed
//                       contribution's luminance lum(f Le cos); the chosen y gets the one
//                       shadow ray, weighted f Le cos V / target(y) * (1/M) sum_j w_j
//                       [Talbot05, 4; BitterliEtAl20, eq. 6]: unbiased, since the target is
//                       positive wherever f Le cos is
// mis_* and path take candidates too: their light sample (next-event estimation at every
// vertex) is then resampled from M light samples the same way, weighted by MIS against the
// BSDF sample with the source density p (integrator.cpp's ris_light_term).
// Splitting (light_samples, bsdf_samples): n_L light samples and n_B BSDF samples per shading
// point, each term divided by its count, combined by multi-sample MIS whose heuristics take
// q_k = n_k p_k [Veach97, 9.2; PBR4, 13.4's several light samples per point]; path tracing
// continues along the first BSDF sample. Counts of 1 are the estimators above.
#pragma once

#include <cstdint>
#include <string>

#include "render/accel.h"
#include "render/bsdf.h"
#include "render/lights.h"
#include "render/pixel_sampler.h"
#include "render/scene.h"

namespace mcp {

enum class RadianceStrategy {
    UniformHemisphere,
    CosineHemisphere,
    Bsdf,
    LightArea,
    LightSolidAngle,
    MisBalance,
    MisPower,
    Path,
    Ris,
};
const char* strategy_name(RadianceStrategy s);
bool parse_strategy(const std::string& name, RadianceStrategy* s);

/// The most light or BSDF samples one shading point takes (splitting).
constexpr int kMaxSplitSamples = 64;

/// A timed pilot's figures behind an automatic count (splitting.h): the counts it rendered
/// (1, 2, 4, ...) with, for each, the relative variance of one camera sample (the pixel
/// estimate's variance times spp, at the image's spp and pixel sampler) and one camera sample's
/// processor seconds; the count chosen is the one of the least product. variance_rest,
/// variance_light, seconds_rest, seconds_light: the model V(n) = V_rest + V_light / n,
/// C(n) = c_rest + n c_light through count 1 and the largest count tried, for the record.
struct SplitPilot {
    static constexpr int kMaxTried = 7; ///< 1, 2, 4, ..., 64
    bool ran = false;
    double variance_rest = 0.0, variance_light = 0.0; ///< relative (as the images' rel. MSE)
    double seconds_rest = 0.0, seconds_light = 0.0;   ///< per camera sample
    uint64_t samples = 0;                             ///< camera samples of each pilot render
    double seconds = 0.0;                             ///< the pilot's own wall time
    int tried = 0;                                    ///< counts rendered
    int counts[kMaxTried] = {};
    double relative_variance[kMaxTried] = {}; ///< per camera sample, relative
    double sample_seconds[kMaxTried] = {};    ///< processor seconds per camera sample
    /// The heavy tail's share of relative_variance at count 1 (pooled over the counts tried;
    /// count n's share is tail / n).
    double tail = 0.0;
};

/// How an image's samples are spread over its pixels (adaptive.h).
enum class PixelAllocation { Uniform, Adaptive };

struct RenderEstimator {
    std::string name; ///< unique within a study: keys its random streams
    RadianceStrategy strategy = RadianceStrategy::MisPower;
    LightSelection light_selection = LightSelection::Power;
    /// How light samples are drawn in mis_* and path (light_area / light_solid_angle fix it).
    LightSampling light_sampling = LightSampling::SolidAngle;
    /// Where every number of a sample comes from (camera jitter, light selection and
    /// sampling, BSDF sampling, Russian roulette): pixel_sampler.h.
    PixelSamplerKind pixel_sampler = PixelSamplerKind::Stratified;
    int max_depth = 5; ///< path: bounces (1 = direct lighting only)
    int rr_depth = 3;  ///< path: Russian roulette from this bounce on
    /// Light samples resampled per shading point (M): ris (the render API's default 8), and
    /// the light sample of mis_* and path (1: plain light sampling). 0 (JSON "auto") until a
    /// timed pilot chooses it (splitting.h): the integrator takes 0 as 1.
    int candidates = 1;
    /// Light samples per shading point (strategies that sample lights); 0 (JSON "auto") until
    /// a timed pilot chooses it (splitting.h): the integrator takes 0 as 1.
    int light_samples = 1;
    int bsdf_samples = 1; ///< BSDF samples per shading point (strategies that sample the BSDF)
    /// Camera rays per camera sample for the emission seen directly (every strategy), in the
    /// pixels where the emission seen through the four corners differs (an emitter's or an
    /// occluder's edge crosses the pixel; a choice fixed by the geometry, so unbiased): the
    /// sample's own ray and emission_samples - 1 more through the same pixel, whose first hits
    /// count only their emission (emitted_along), the mean of all replacing the sample's
    /// RadianceSample::emitted. Splitting the pixel integral by term: the pixel's coverage by
    /// an emitter is camera-sample noise no light or BSDF sample touches, and a ray that
    /// meets no light costs a test of the lights alone. 0 (JSON "auto") until a timed pilot
    /// chooses it (splitting.h).
    int emission_samples = 1;
    /// How the image's samples are spread over its pixels: the same spp everywhere, or a first
    /// pass and the rest where the neighbours' error shows they pay (adaptive.h).
    PixelAllocation pixel_allocation = PixelAllocation::Uniform;
    SplitPilot split_pilot;     ///< what the pilot measured, when it chose light_samples
    SplitPilot emission_pilot;  ///< the same for emission_samples
    SplitPilot candidate_pilot; ///< the same for candidates (variance_light: the resampled part)
};
/// The bounds of ris's candidate count M, checked where estimators are parsed.
constexpr int kMinRisCandidates = 1, kMaxRisCandidates = 64;

/// Per-sample counters, summed per image.
struct SampleCounters {
    uint64_t rays = 0;         ///< camera, bounce and shadow rays traced
    uint64_t light_misses = 0; ///< light samples that came back invalid (degenerate, pdf 0)
};

/// What the integrator needs of a scene: the scene, its accelerator, and its lights built
/// for each light-selection rule.
struct RenderScene {
    const Scene* scene = nullptr;
    Accelerator accel;
    LightSet lights_uniform, lights_area, lights_power;
    /// The lights' triangles alone (emitter_triangle: its triangle -> the mesh's), built when
    /// they are at most half the scene's: a direction sampled at a shading point contributes
    /// only when its closest hit is a light, so it is tested against the lights first and the
    /// whole scene is asked only whether something lies in front of the light it meets (an
    /// any-hit query) instead of tracing every direction to its closest hit.
    Accelerator emitters;
    std::vector<uint32_t> emitter_triangle;
    bool emitters_first = false;

    /// Builds the accelerator and the light sets (selection tables only where there is more
    /// than one light). The scene must outlive this object.
    void build(const Scene& s, AccelKind accel_kind = AccelKind::Auto);
    const LightSet& lights(LightSelection selection) const;
};

/// One sample of the radiance towards the camera, split into the emission of the first
/// visible surface (not random given the camera ray) and the estimate of the light it
/// reflects (where the estimators differ, and where heavy tails live).
struct RadianceSample {
    Vec3 emitted{0.0};
    Vec3 reflected{0.0};
    Vec3 total() const { return emitted + reflected; }
};

/// Radiance carried towards the camera along `camera_ray` (one sample of the estimator),
/// drawing its random numbers from `sampler`: the general integrator, for any scene.
RadianceSample sample_radiance(const RenderScene& rs, const RenderEstimator& est,
                               const Ray& camera_ray, PixelSampler& sampler,
                               SampleCounters& counters);

/// The emission seen along `ray` at its closest hit (0 when it misses or the hit does not
/// emit): with rs.emitters_first the lights' own accelerator first, then an any-hit query of
/// the scene short of the light (as a sampled direction is traced), so a ray that meets no
/// light costs a test of the lights alone. One ray counted.
Vec3 emitted_along(const RenderScene& rs, const Ray& ray, SampleCounters& counters);

/// Pixel position j of n for the extra camera rays of emission_samples: the sample's own
/// jitter shifted by (j / n, j a) modulo 1, a the golden ratio's fraction (a rank-1 lattice
/// around the sample's point; a = R_1 of [Roberts18]). Each is uniform over the pixel when the
/// sample's jitter is, which is all the mean of the n emissions asks to stay unbiased.
Vec2 shifted_jitter(const Vec2& jitter, int j, int n);

/// The versions of the integrator compiled for what a scene's surfaces use, so that a scene
/// does not pay for what it leaves out: GeneralTextured is sample_radiance itself; General
/// leaves out texture lookups; Lambertian (every material metallic 0, specular 0) leaves out
/// the Fresnel and GGX arithmetic as well. On the scenes surface_kernel picks them for, they
/// give sample_radiance's numbers, drawing the same random numbers.
enum class SurfaceKernel { GeneralTextured, General, LambertianTextured, Lambertian };
/// The narrowest kernel that serves every surface of the scene (chosen once per render).
SurfaceKernel surface_kernel(const Scene& scene);
const char* surface_kernel_name(SurfaceKernel k);
template <SurfaceKernel K>
RadianceSample sample_radiance_with(const RenderScene& rs, const RenderEstimator& est,
                                    const Ray& camera_ray, PixelSampler& sampler,
                                    SampleCounters& counters);

/// The BRDF parameters at a hit: the material's factors times its base colour texture.
BsdfParams material_at(const Scene& scene, const Hit& hit);

} // namespace mcp
