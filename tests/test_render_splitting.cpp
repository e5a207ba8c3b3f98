// Splitting (integrator.h: light_samples, bsdf_samples, emission_samples; splitting.h: the count
// chosen by a timed pilot): unbiased against closed forms, lower variance per camera sample, counts
// of 1 the estimators without splitting, and the options' errors.
#include <gtest/gtest.h>

#include <cmath>

#include "core/special.h"
#include "render/render_study.h"
#include "render/splitting.h"
#include "render_api/render_request.h"
#include "render_scenes.h"
#include "test_support.h"

namespace mcp {
namespace {

RenderEstimator split(RadianceStrategy s, int light_samples, int bsdf_samples) {
    RenderEstimator e;
    e.strategy = s;
    e.name = strategy_name(s);
    e.light_samples = light_samples;
    e.bsdf_samples = bsdf_samples;
    return e;
}

RenderSettings settings(int w, int h, uint64_t spp, uint64_t stream) {
    RenderSettings s = mcp::test::render_settings(w, h, spp, stream);
    s.jitter_pixels = false; // each pixel's expectation is the closed form at its centre
    return s;
}

/// Pixels of `im` (quad light floor, pixel-centre rays) farther than z_max of their own
/// standard errors from Lambert's formula, times `scale` (1: the true value).
int pixels_off(const Scene& scene, const RenderImage& im, double z_max, double scale) {
    const double Le = 5.0, albedo = 0.5;
    const Vec3 light[4] = {{-0.5, 1, -0.5}, {0.5, 1, -0.5}, {0.5, 1, 0.5}, {-0.5, 1, 0.5}};
    int off = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            Ray r = camera_ray(scene.camera, im.width, im.height, x + 0.5, y + 0.5);
            Vec3 p = r.origin + r.direction * (-r.origin.y / r.direction.y);
            double expected =
                scale * albedo * Le * lambert_polygon_form_factor(p, Vec3(0, 1, 0), light, 4);
            size_t k = (size_t(y) * size_t(im.width) + size_t(x)) * 3;
            if (std::fabs(im.rgb[k] - expected) > z_max * std::sqrt(im.variance[k]) + 1e-12) ++off;
        }
    return off;
}

struct Case {
    RadianceStrategy strategy;
    int light_samples, bsdf_samples;
};
const Case kSplitCases[] = {
    {RadianceStrategy::LightArea, 3, 1}, {RadianceStrategy::LightSolidAngle, 4, 1},
    {RadianceStrategy::Bsdf, 1, 3},      {RadianceStrategy::MisBalance, 3, 2},
    {RadianceStrategy::MisPower, 2, 5},  {RadianceStrategy::MisPower, 7, 1},
    {RadianceStrategy::Path, 3, 2},
};

// Every split estimator, every pixel, within its error bar of Lambert's formula (Sidak
// level 1e-3 over all pixels); the same images against the formula 20% too bright fail in
// many pixels (the check can see a bias of that size).
TEST(RenderSplitting, UnbiasedUnderTheQuadLight) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    const int W = 8, H = 8;
    const int tests = W * H * int(std::size(kSplitCases));
    const double z_max = -normal_quantile(0.5 * test::sidak_level(1e-3, tests));
    for (const Case& c : kSplitCases) {
        RenderEstimator e = split(c.strategy, c.light_samples, c.bsdf_samples);
        e.max_depth = 1; // path: direct light only, the closed form's quantity
        RenderImage im = render_image(rs, e, settings(W, H, 1024, 31));
        EXPECT_EQ(pixels_off(scene, im, z_max, 1.0), 0)
            << strategy_name(c.strategy) << " " << c.light_samples << "/" << c.bsdf_samples;
        EXPECT_GT(pixels_off(scene, im, z_max, 1.2), W * H / 4)
            << strategy_name(c.strategy) << " " << c.light_samples << "/" << c.bsdf_samples;
    }
}

// Path tracing with splitting in a furnace (every face emits Le, albedo rho): every bounce
// gives Le / (1 - rho), direct light only Le (1 + rho), each within 5 standard errors; the
// other answer is far outside.
TEST(RenderSplitting, PathSplitInTheFurnace) {
    const double rho = 0.5, Le = 1.0;
    Scene scene = test::furnace_box(rho, Le, 4);
    RenderScene rs;
    rs.build(scene);
    for (int depth : {1, 1000}) {
        RenderEstimator e = split(RadianceStrategy::Path, 3, 2);
        e.max_depth = depth;
        RenderImage im = render_image(rs, e, settings(16, 16, 32, 9));
        RenderImage exact = im;
        const double right = depth == 1 ? Le * (1 + rho) : Le / (1 - rho);
        const double wrong = depth == 1 ? Le / (1 - rho) : Le * (1 + rho);
        ImageError err = image_error(im, exact);
        EXPECT_NEAR(err.mean_luminance, right, 5.0 * err.mean_luminance_se) << depth;
        EXPECT_GT(std::fabs(err.mean_luminance - wrong), 5.0 * err.mean_luminance_se) << depth;
    }
}

/// Mean over pixels of the variance of one camera sample (variance of the mean times spp).
double sample_variance(const RenderImage& im) {
    double sum = 0.0;
    for (double v : im.variance) sum += v * double(im.spp);
    return sum / double(im.variance.size());
}

// n light samples per camera sample leave the camera sample's own variance: the variance per
// camera sample falls, by at most 1 / n (V_rest + V_light / n >= V(1) / n). With independent
// pixel samples and jittered pixels, so that V_rest is not 0.
TEST(RenderSplitting, LowerVariancePerCameraSample) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    for (RadianceStrategy s :
         {RadianceStrategy::LightSolidAngle, RadianceStrategy::MisPower, RadianceStrategy::Path}) {
        RenderSettings st = settings(12, 12, 64, 5);
        st.jitter_pixels = true;
        RenderEstimator one = split(s, 1, 1), four = split(s, 4, 1);
        one.pixel_sampler = four.pixel_sampler = PixelSamplerKind::Independent;
        const double v1 = sample_variance(render_image(rs, one, st));
        const double v4 = sample_variance(render_image(rs, four, st));
        EXPECT_LT(v4, 0.7 * v1) << strategy_name(s);
        EXPECT_GT(v4, 0.8 * v1 / 4.0) << strategy_name(s);
    }
}

// Counts of 1, given in the JSON, are the estimator without splitting: the same image, bit for
// bit; a count of 2 is not.
TEST(RenderSplitting, CountsOfOneAreTheEstimatorsWithoutSplitting) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    for (const char* strategy : {"light_solid_angle", "bsdf", "mis_balance", "mis_power", "path"}) {
        const bool lights = std::string(strategy) != "bsdf";
        const bool bsdf = std::string(strategy) != "light_solid_angle";
        Json j{{"strategy", strategy}};
        if (lights) j["light_samples"] = 1;
        if (bsdf) j["bsdf_samples"] = 1;
        Made<RenderEstimator> given = parse_render_estimator(j, "e");
        Made<RenderEstimator> plain = parse_render_estimator(Json(strategy), "e");
        ASSERT_TRUE(given.ok() && plain.ok()) << given.error << plain.error;
        RenderSettings st = settings(10, 8, 16, 3);
        RenderImage a = render_image(rs, given.value, st);
        RenderImage b = render_image(rs, plain.value, st);
        EXPECT_EQ(a.rgb, b.rgb) << strategy;
        EXPECT_EQ(a.diagnostics.rays, b.diagnostics.rays) << strategy;
        j[lights ? "light_samples" : "bsdf_samples"] = 2;
        Made<RenderEstimator> two = parse_render_estimator(j, "e");
        ASSERT_TRUE(two.ok()) << two.error;
        EXPECT_NE(render_image(rs, two.value, st).rgb, b.rgb) << strategy;
    }
}

TEST(RenderSplitting, CountErrorsNameTheField) {
    struct Bad {
        Json j;
        const char* says;
    };
    const Bad bad[] = {
        {{{"strategy", "bsdf"}, {"light_samples", 2}}, "e.light_samples: only the strategies"},
        {{{"strategy", "light_area"}, {"bsdf_samples", 2}}, "e.bsdf_samples: only the strategies"},
        {{{"strategy", "mis_power"}, {"light_samples", 0}}, "e.light_samples: must be a whole"},
        {{{"strategy", "mis_power"}, {"light_samples", 65}}, "got 65"},
        {{{"strategy", "mis_power"}, {"light_samples", 2.5}}, "got 2.5"},
        {{{"strategy", "mis_power"}, {"light_samples", "many"}}, "or \"auto\", got \"many\""},
        {{{"strategy", "path"}, {"bsdf_samples", "auto"}}, "e.bsdf_samples: must be a whole"},
        {{{"strategy", "bsdf"}, {"emission_samples", 0}}, "e.emission_samples: must be a whole"},
        {{{"strategy", "ris"}, {"emission_samples", 65}}, "or \"auto\", got 65"},
    };
    for (const Bad& b : bad) {
        Made<RenderEstimator> m = parse_render_estimator(b.j, "e");
        EXPECT_FALSE(m.ok()) << b.j.dump();
        EXPECT_NE(m.error.find(b.says), std::string::npos) << m.error;
        EXPECT_EQ(m.error.find('\n'), std::string::npos) << m.error;
    }
    Made<RenderEstimator> automatic =
        parse_render_estimator(Json{{"strategy", "mis_power"}, {"light_samples", "auto"}}, "e");
    ASSERT_TRUE(automatic.ok()) << automatic.error;
    EXPECT_EQ(automatic.value.light_samples, 0);
    Made<RenderEstimator> emission =
        parse_render_estimator(Json{{"strategy", "bsdf"}, {"emission_samples", "auto"}}, "e");
    ASSERT_TRUE(emission.ok()) << emission.error;
    EXPECT_EQ(emission.value.emission_samples, 0);
}

// n* = sqrt((V_light / V_rest) (c_rest / c_light)), the better integer neighbour, in
// 1..kMaxSplitSamples.
TEST(RenderSplitting, OptimalSplitCount) {
    EXPECT_EQ(optimal_split(1.0, 16.0, 4.0, 1.0), 8);
    EXPECT_EQ(optimal_split(1.0, 1.0, 1.0, 1.0), 1);
    EXPECT_EQ(optimal_split(1.0, 0.0, 4.0, 1.0), 1);                // nothing to split
    EXPECT_EQ(optimal_split(0.0, 1.0, 4.0, 1.0), kMaxSplitSamples); // all variance split off
    EXPECT_EQ(optimal_split(1e-6, 1.0, 1.0, 1.0), kMaxSplitSamples);
    // n* = sqrt(10) = 3.16: 3 and 4 compared by (V_rest + V_light / n) (c_rest + n c_light).
    EXPECT_EQ(optimal_split(1.0, 10.0, 1.0, 1.0), 3);
}

// "auto": the pilot renders counts 1, 2, ... on its pixels, measures each one's variance and
// cost as positive, and chooses the count of its own figures (pilot_choice); a fixed count runs
// no pilot.
TEST(RenderSplitting, AutoCountComesFromThePilot) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    RenderSettings image = settings(64, 48, 16, 7);
    image.jitter_pixels = true;
    RenderEstimator e = split(RadianceStrategy::MisPower, 0, 1);
    RenderEstimator chosen = resolve_split(rs, e, image);
    ASSERT_TRUE(chosen.split_pilot.ran);
    const SplitPilot& p = chosen.split_pilot;
    ASSERT_GE(p.tried, 2);
    for (int i = 0; i < p.tried; ++i) {
        EXPECT_EQ(p.counts[i], 1 << i);
        EXPECT_GT(p.relative_variance[i], 0.0);
        EXPECT_GT(p.sample_seconds[i], 0.0);
    }
    EXPECT_EQ(chosen.light_samples, pilot_choice(p));
    EXPECT_GE(chosen.light_samples, 1);
    e.light_samples = 3;
    RenderEstimator fixed = resolve_split(rs, e, image);
    EXPECT_FALSE(fixed.split_pilot.ran);
    EXPECT_EQ(fixed.light_samples, 3);
}

// The choice: the count of the least variance x seconds, a larger count only where it is at
// least 10 % more efficient than the one kept so far; non-finite figures never chosen.
TEST(RenderSplitting, PilotChoiceTakesTheMeasuredBest) {
    SplitPilot p;
    p.tried = 4;
    const int counts[4] = {1, 2, 4, 8};
    const double v[4] = {1.0, 0.5, 0.2, 0.15}, c[4] = {1.0, 1.5, 2.0, 2.5};
    for (int i = 0; i < 4; ++i) {
        p.counts[i] = counts[i];
        p.relative_variance[i] = v[i];
        p.sample_seconds[i] = c[i];
    }
    EXPECT_EQ(pilot_choice(p), 4); // products 1, 0.75, 0.4, 0.375: 8 is < 10 % better than 4
    p.relative_variance[3] = 0.1;  // 0.25: 8 now is
    EXPECT_EQ(pilot_choice(p), 8);
    p.relative_variance[3] = NAN;
    EXPECT_EQ(pilot_choice(p), 4);
    p.relative_variance[1] = p.relative_variance[2] = 2.0; // 1 is best
    EXPECT_EQ(pilot_choice(p), 1);
    p.tried = 0;
    EXPECT_EQ(pilot_choice(p), 1);
}

/// An estimator with `field` "auto" on the quad light scene (pixel-centre jitter off: the image's
/// camera samples jitter) with the given pixel sampler, resolved for a 192 x 144 image of `spp`.
RenderEstimator resolved_on_the_quad_light(RenderEstimator e, PixelSamplerKind kind, uint64_t spp,
                                           int width = 192, int height = 144) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    RenderSettings image = settings(width, height, spp, 7);
    image.jitter_pixels = true;
    image.threads = 2;
    e.pixel_sampler = kind;
    return resolve_split(rs, e, image);
}

// The pilot measures with the render's own pixel sampler, and the best count depends on it.
// Under one quad light over a diffuse floor with Sobol' pixels, the plain light sample (RIS with
// one candidate) is stratified over each pixel's net and its error falls far faster than with
// independent pixels (the pilot's variance per camera sample at count 1 below a tenth of the
// independent pixels'); RIS's shifted candidates and its pick keep little of that, so 1
// candidate is the most efficient, while with independent pixels the candidates' variance
// reduction pays (the old pilot's model, V_target + V / M, read with independent pixels, chose
// 32 with Sobol' pixels too). Both ways: the same scene and estimator, two answers. The choice
// rests on timed renders (count 1's efficiency about 1.7 times count 4's with Sobol' pixels): at
// 384 x 288 each of the pilot's renders takes tens of milliseconds, long enough that a burst of
// load on the machine during one of them does not turn the answer (at 192 x 144, about 15 ms,
// it once did under Node during `make test`).
TEST(RenderSplitting, PilotMeasuresWithTheRendersPixelSampler) {
    RenderEstimator e = split(RadianceStrategy::Ris, 1, 1);
    e.candidates = 0;
    const RenderEstimator sobol =
        resolved_on_the_quad_light(e, PixelSamplerKind::Sobol, 64, 384, 288);
    const RenderEstimator independent =
        resolved_on_the_quad_light(e, PixelSamplerKind::Independent, 64, 384, 288);
    ASSERT_TRUE(sobol.candidate_pilot.ran && independent.candidate_pilot.ran);
    EXPECT_LT(sobol.candidate_pilot.relative_variance[0],
              0.1 * independent.candidate_pilot.relative_variance[0]);
    EXPECT_EQ(sobol.candidates, 1);
    EXPECT_GT(independent.candidates, 1);
}

// And where more light samples clearly pay with Sobol' pixels: MIS (power heuristic with the
// counts) under the same light, where a second light sample per shading point also moves weight
// off the BSDF samples that hit the light by chance (the measured variance per camera sample
// falls about tenfold from 1 to 2 light samples): more than one.
TEST(RenderSplitting, PilotSplitsWhereLightSamplesPay) {
    const RenderEstimator chosen = resolved_on_the_quad_light(
        split(RadianceStrategy::MisPower, 0, 1), PixelSamplerKind::Sobol, 16);
    ASSERT_TRUE(chosen.split_pilot.ran);
    EXPECT_GT(chosen.light_samples, 1);
    // The pilot's pixels: about 1/96 of the image (at least 256), each at the image's spp.
    const double pixels = double(chosen.split_pilot.samples) / 16.0;
    EXPECT_GE(pixels, 256.0);
    EXPECT_LE(pixels, 192.0 * 144.0 / 64.0);
}

/// The quad light scene seen from below: the camera at height 0.2 looks straight up at the
/// 1 x 1 light (albedo 0: it reflects nothing) at height 1, whose edges cross the image; the
/// rest of the view meets nothing.
Scene light_seen_from_below() {
    Scene s = test::quad_light_scene(5.0);
    s.camera = test::look_at({0, 0.2, 0}, {0, 1, 0}, {0, 0, -1}, 1.2);
    return s;
}

/// Pixels of `im` (light_seen_from_below) farther than z_max of their own standard errors from
/// the emission seen through them, Le times the fraction of the pixel the light covers, times
/// `scale` (1: the true value). The light is parallel to the image plane: its image is the
/// rectangle |sx|, |sy| <= 0.5 / 0.8 in the camera's tangent coordinates.
int emission_pixels_off(const Scene& scene, const RenderImage& im, double z_max, double scale) {
    const double Le = 5.0, half = 0.5 / 0.8;
    const double tan_half = std::tan(0.5 * scene.camera.yfov);
    const double aspect = double(im.width) / double(im.height);
    const auto overlap = [&](double a, double b) { // of [a, b] with [-half, half], relative
        return std::max(0.0, std::min(b, half) - std::max(a, -half)) / (b - a);
    };
    int off = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const double sx0 = (2.0 * x / im.width - 1.0) * tan_half * aspect;
            const double sx1 = (2.0 * (x + 1) / im.width - 1.0) * tan_half * aspect;
            const double sy0 = (1.0 - 2.0 * (y + 1) / im.height) * tan_half;
            const double sy1 = (1.0 - 2.0 * y / im.height) * tan_half;
            const double expected = scale * Le * overlap(sx0, sx1) * overlap(sy0, sy1);
            size_t k = (size_t(y) * size_t(im.width) + size_t(x)) * 3;
            if (std::fabs(im.rgb[k] - expected) > z_max * std::sqrt(im.variance[k]) + 1e-12) ++off;
        }
    return off;
}

// emission_samples: the emission seen directly, from n camera rays per sample, is Le times the
// pixel's coverage in every pixel (Sidak level 1e-3 over all pixels), for every strategy and
// with each pixel sampler; 20% too bright fails in many pixels.
TEST(RenderSplitting, EmissionSamplesUnbiased) {
    Scene scene = light_seen_from_below();
    RenderScene rs;
    rs.build(scene);
    const int W = 10, H = 8;
    const RadianceStrategy strategies[] = {RadianceStrategy::LightSolidAngle,
                                           RadianceStrategy::MisPower, RadianceStrategy::Path};
    const PixelSamplerKind samplers[] = {PixelSamplerKind::Independent, PixelSamplerKind::Sobol};
    const int tests = W * H * int(std::size(strategies) * std::size(samplers));
    const double z_max = -normal_quantile(0.5 * test::sidak_level(1e-3, tests));
    for (RadianceStrategy s : strategies)
        for (PixelSamplerKind k : samplers) {
            RenderEstimator e = split(s, 1, 1);
            e.emission_samples = 5;
            e.pixel_sampler = k;
            RenderSettings st = settings(W, H, 64, 13);
            st.jitter_pixels = true;
            RenderImage im = render_image(rs, e, st);
            EXPECT_EQ(emission_pixels_off(scene, im, z_max, 1.0), 0) << strategy_name(s);
            EXPECT_GT(emission_pixels_off(scene, im, z_max, 1.2), W * H / 4) << strategy_name(s);
        }
}

// Both ways: where the camera sees an emitter's edges, n camera rays per sample cut the
// variance per camera sample of the pixels they cross (independent rays: to about 1 / n), and
// only there (pixels inside or outside the light take none); where it sees no emitter (the
// floor under the light) the image is the one without them, bit for bit (the extra rays draw
// no numbers), at the cost of the four corner probes of each pixel.
TEST(RenderSplitting, EmissionSamplesCutEdgeVarianceOnly) {
    for (bool seen : {true, false}) {
        Scene scene = seen ? light_seen_from_below() : test::quad_light_scene(5.0);
        RenderScene rs;
        rs.build(scene);
        RenderSettings st = settings(12, 10, 64, 5);
        st.jitter_pixels = true;
        RenderEstimator one = split(RadianceStrategy::LightSolidAngle, 1, 1), four = one;
        four.emission_samples = 4;
        one.pixel_sampler = four.pixel_sampler = PixelSamplerKind::Independent;
        RenderImage a = render_image(rs, one, st), b = render_image(rs, four, st);
        const uint64_t probes = 4 * 12 * 10, all_split = 3 * 12 * 10 * 64;
        if (seen) {
            EXPECT_GT(b.diagnostics.rays, a.diagnostics.rays + probes);
            EXPECT_LT(b.diagnostics.rays, a.diagnostics.rays + probes + all_split / 2);
            EXPECT_GT(sample_variance(a), 0.0);
            EXPECT_LT(sample_variance(b), 0.5 * sample_variance(a));
        } else {
            EXPECT_EQ(b.diagnostics.rays, a.diagnostics.rays + probes);
            EXPECT_EQ(a.rgb, b.rgb);
        }
    }
}

// emission_samples "auto": the pilot measures the emission's variance where the light is seen
// and chooses the count of its own figures; a count of 1 renders the plain estimator's image.
TEST(RenderSplitting, EmissionSamplesFromThePilot) {
    Scene scene = light_seen_from_below();
    RenderScene rs;
    rs.build(scene);
    RenderSettings image = settings(64, 48, 16, 7);
    image.jitter_pixels = true;
    RenderEstimator e = split(RadianceStrategy::LightSolidAngle, 1, 1);
    e.emission_samples = 0;
    RenderEstimator chosen = resolve_split(rs, e, image);
    ASSERT_TRUE(chosen.emission_pilot.ran);
    const SplitPilot& p = chosen.emission_pilot;
    ASSERT_GE(p.tried, 2);
    EXPECT_GT(p.relative_variance[0], 0.0);
    EXPECT_EQ(chosen.emission_samples, pilot_choice(p));
    EXPECT_FALSE(chosen.split_pilot.ran);
    Made<RenderEstimator> plain = parse_render_estimator(Json("light_solid_angle"), "e");
    Made<RenderEstimator> ones = parse_render_estimator(
        Json{{"strategy", "light_solid_angle"}, {"emission_samples", 1}}, "e");
    ASSERT_TRUE(plain.ok() && ones.ok());
    EXPECT_EQ(render_image(rs, plain.value, image).rgb, render_image(rs, ones.value, image).rgb);
}

} // namespace
} // namespace mcp
