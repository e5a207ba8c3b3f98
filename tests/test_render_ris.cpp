// Resampled importance sampling for direct lighting (the render strategy `ris` [Talbot05]):
// unbiased against closed forms with several lights, one candidate is light sampling, fewer
// errors than light sampling where many lights of different power and distance light a floor,
// bounded where light sampling is, and bad candidate counts refused with one-line errors. RIS as
// the light sample of mis_* and path (next-event estimation, MIS against BSDF sampling): unbiased
// against the closed form and the furnace, M = 1 their plain light sample bit for bit, and M
// chosen by a timed pilot ("auto").
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/special.h"
#include "render/contribution_bound.h"
#include "render/renderer.h"
#include "render/splitting.h"
#include "render_api/render_request.h"
#include "render_scenes.h"
#include "scene_files.h"
#include "test_support.h"

namespace mcp {
namespace {

using nlohmann::json;

RenderEstimator ris(int m, LightSampling sampling = LightSampling::SolidAngle) {
    RenderEstimator e;
    e.strategy = RadianceStrategy::Ris;
    e.name = "ris_" + std::to_string(m);
    e.candidates = m;
    e.light_sampling = sampling;
    return e;
}

RenderEstimator light(LightSampling sampling) {
    RenderEstimator e;
    e.strategy = sampling == LightSampling::Area ? RadianceStrategy::LightArea
                                                 : RadianceStrategy::LightSolidAngle;
    e.name = strategy_name(e.strategy);
    e.light_sampling = sampling;
    return e;
}

RenderSettings settings(int w, int h, uint64_t spp, uint64_t stream) {
    return mcp::test::render_settings(w, h, spp, stream);
}

/// A light quad facing down at height h (corners counter-clockwise seen from below).
struct QuadLight {
    double x, z, side, Le;
};
constexpr double kLightHeight = 1.0;

std::vector<Vec3> corners(const QuadLight& q) {
    const double a = 0.5 * q.side, h = kLightHeight;
    return {
        {q.x - a, h, q.z - a}, {q.x + a, h, q.z - a}, {q.x + a, h, q.z + a}, {q.x - a, h, q.z + a}};
}

/// A diffuse floor (albedo 0.5) under lights of different size and radiance, all in the plane
/// y = 1 facing down: no light shadows another, so every floor point has the closed form
/// sum_i (albedo / pi) pi Le_i F_i (Lambert's polygon formula).
const QuadLight kLights[] = {{1.2, -0.8, 1.0, 20.0},
                             {-1.0, 0.3, 0.1, 60.0},
                             {-0.4, 1.0, 0.15, 30.0},
                             {0.3, 0.2, 0.05, 300.0}};
constexpr double kAlbedo = 0.5;

Scene several_lights_scene() {
    Scene s;
    s.materials.push_back(test::diffuse(kAlbedo));
    test::add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0); // faces +y
    for (const QuadLight& q : kLights) {
        Material m = test::diffuse(0.0);
        m.emission = Vec3(q.Le);
        s.materials.push_back(m);
        const std::vector<Vec3> c = corners(q);
        test::add_quad(s, c[0], c[1], c[2], c[3], uint32_t(s.materials.size() - 1));
    }
    s.camera = test::look_at({0, 0.6, 0.01}, {0, 0, 0}, {0, 0, -1}, 1.6);
    return s;
}

/// The closed form at the floor point each pixel's centre ray hits.
std::vector<double> several_lights_exact(const Scene& scene, int w, int h) {
    std::vector<double> out;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Ray r = camera_ray(scene.camera, w, h, x + 0.5, y + 0.5);
            Vec3 p = r.origin + r.direction * (-r.origin.y / r.direction.y);
            double value = 0.0;
            for (const QuadLight& q : kLights) {
                const std::vector<Vec3> c = corners(q);
                const double F = lambert_polygon_form_factor(p, Vec3(0, 1, 0), c.data(), 4);
                value += kAlbedo * q.Le * F; // (albedo / pi) pi Le F
            }
            out.push_back(value);
        }
    return out;
}

/// The image's mean over the pixels against the closed form's, in standard errors of that mean
/// (the pixels are independent): far more power against a bias than any pixel alone.
double pooled_z(const RenderImage& im, const std::vector<double>& exact) {
    double gap = 0.0, var = 0.0;
    for (size_t i = 0; i < exact.size(); ++i) {
        gap += im.rgb[3 * i] - exact[i];
        var += im.variance[3 * i];
    }
    return gap / std::sqrt(var);
}

/// Pixels whose value lies more than z_max standard errors from the closed form.
int pixels_off(const RenderImage& im, const std::vector<double>& exact, double z_max) {
    int off = 0;
    for (size_t i = 0; i < exact.size(); ++i) {
        const double se = std::sqrt(im.variance[3 * i]);
        off += std::fabs(im.rgb[3 * i] - exact[i]) > z_max * se + 1e-12 * exact[i];
    }
    return off;
}

// Every pixel within its error bar of Lambert's closed form, and the image's mean within its
// own (Sidak's z for a family-wise level of 1e-3 over the pixels or the estimators), for M = 1,
// 4 and 16 candidates drawn by solid angle and by area. Judged both ways: the images scaled by
// 1.02 (a 2% bias) fail the pooled check.
TEST(RenderRis, UnbiasedAgainstTheClosedFormWithSeveralLights) {
    const Scene scene = several_lights_scene();
    RenderScene rs;
    rs.build(scene);
    const int W = 8, H = 8;
    const std::vector<double> exact = several_lights_exact(scene, W, H);
    const std::vector<RenderEstimator> ests = {ris(1), ris(4), ris(16), ris(1, LightSampling::Area),
                                               ris(16, LightSampling::Area)};
    const double z_max = -normal_quantile(0.5 * test::sidak_level(1e-3, W * H * int(ests.size())));
    const double z_pooled = -normal_quantile(0.5 * test::sidak_level(1e-3, int(ests.size())));
    uint64_t stream = 301;
    for (const RenderEstimator& e : ests) {
        RenderSettings st = settings(W, H, 1024, stream++);
        st.jitter_pixels = false;
        RenderImage im = render_image(rs, e, st);
        EXPECT_EQ(im.diagnostics.discarded_nonfinite, 0u) << e.name;
        EXPECT_EQ(pixels_off(im, exact, z_max), 0) << e.name;
        EXPECT_LT(std::fabs(pooled_z(im, exact)), z_pooled) << e.name;
        for (double& v : im.rgb) v *= 1.02;
        EXPECT_GT(pooled_z(im, exact), z_pooled) << e.name << " scaled by 1.02";
    }
}

// One candidate is light sampling: with the same random numbers the same pixels (to rounding:
// ris divides by the target and multiplies by the weight) and the same rays and light misses;
// two candidates are not.
TEST(RenderRis, OneCandidateIsLightSampling) {
    const Scene scene = several_lights_scene();
    RenderScene rs;
    rs.build(scene);
    for (LightSampling sampling : {LightSampling::SolidAngle, LightSampling::Area}) {
        const RenderSettings st = settings(12, 10, 16, 77);
        const RenderImage a = render_image(rs, light(sampling), st);
        const RenderImage b = render_image(rs, ris(1, sampling), st);
        const RenderImage c = render_image(rs, ris(2, sampling), st);
        ASSERT_EQ(a.rgb.size(), b.rgb.size());
        double largest_gap = 0.0, gap_two = 0.0;
        for (size_t k = 0; k < a.rgb.size(); ++k) {
            const double scale = std::max(1e-300, std::fabs(a.rgb[k]));
            largest_gap = std::max(largest_gap, std::fabs(a.rgb[k] - b.rgb[k]) / scale);
            gap_two = std::max(gap_two, std::fabs(a.rgb[k] - c.rgb[k]) / scale);
        }
        EXPECT_LE(largest_gap, 1e-12);
        EXPECT_EQ(a.diagnostics.rays, b.diagnostics.rays);
        EXPECT_EQ(a.diagnostics.light_misses, b.diagnostics.light_misses);
        EXPECT_GT(gap_two, 1e-3); // two candidates resample: other numbers
    }
}

/// A sign test on the pixels: how many have a larger variance in `a` than in `b`, against half
/// the pixels that differ, in standard deviations of that count under equal variances (the
/// pixels are independent; per-pixel variances from rare light choices are heavy-tailed, so
/// their signs, not their sizes, are counted).
double pixels_noisier_z(const RenderImage& a, const RenderImage& b) {
    double larger = 0.0, differ = 0.0;
    for (size_t i = 0; i < a.pixel_count(); ++i) {
        const double va =
            luminance(Vec3(a.variance[3 * i], a.variance[3 * i + 1], a.variance[3 * i + 2]));
        const double vb =
            luminance(Vec3(b.variance[3 * i], b.variance[3 * i + 1], b.variance[3 * i + 2]));
        if (va == vb) continue;
        differ += 1.0;
        larger += va > vb;
    }
    return differ > 0.0 ? (larger - 0.5 * differ) / std::sqrt(0.25 * differ) : 0.0;
}

std::shared_ptr<RenderRequest> bundled(const std::string& name) {
    json options{{"base_dir", test::kScenes}};
    Made<std::shared_ptr<RenderRequest>> r = build_render_request(test::scene_json(name), options);
    EXPECT_TRUE(r.ok()) << name << ": " << r.error;
    return r.value;
}

// scenes/many_lights: at equal samples resampling 8 candidates (drawn as light sampling draws
// them: by power, by solid angle) leaves more pixels with a smaller variance than light
// sampling, by more than 5 standard deviations of a sign test; light sampling against itself
// on another stream stays within 5 (the rule judged the other way: no gap where there is none).
TEST(RenderRis, FewerErrorsThanLightSamplingAmongManyLights) {
    std::shared_ptr<RenderRequest> r = bundled("many_lights");
    ASSERT_TRUE(r);
    RenderScene rs;
    rs.build(*r->scene, r->accel);
    const RenderImage by_light =
        render_image(rs, light(LightSampling::SolidAngle), settings(48, 36, 64, 5));
    const RenderImage by_ris = render_image(rs, ris(8), settings(48, 36, 64, 6));
    const RenderImage again =
        render_image(rs, light(LightSampling::SolidAngle), settings(48, 36, 64, 7));
    EXPECT_GT(pixels_noisier_z(by_light, by_ris), 5.0);
    EXPECT_LT(std::fabs(pixels_noisier_z(by_light, again)), 5.0);
}

// Bounded by construction exactly where light sampling of the same kind is: f Le cos / target
// <= 1 / 0.0722 and the mean of the weights is at most light sampling's largest weight.
TEST(RenderRis, BoundedWhereLightSamplingIs) {
    for (const char* name : {"quad_light_floor", "perpendicular_plates", "many_lights"}) {
        std::shared_ptr<RenderRequest> r = bundled(name);
        ASSERT_TRUE(r);
        RenderScene rs;
        rs.build(*r->scene, r->accel);
        const LightContacts contacts = light_contacts(rs, 1.0);
        for (LightSampling sampling : {LightSampling::SolidAngle, LightSampling::Area}) {
            const ContributionBound l = contribution_bound(light(sampling), contacts);
            const ContributionBound b = contribution_bound(ris(8, sampling), contacts);
            EXPECT_EQ(b.bounded, l.bounded) << name;
            EXPECT_EQ(b.infinite_variance, l.infinite_variance) << name;
            EXPECT_NE(b.reason.find("resampled"), std::string::npos) << b.reason;
        }
    }
    // Both ways: area sampling of the plates that share an edge is unbounded (infinite
    // variance), solid-angle sampling of the floor's light bounded.
    std::shared_ptr<RenderRequest> plates = bundled("perpendicular_plates");
    RenderScene rs;
    rs.build(*plates->scene, plates->accel);
    EXPECT_FALSE(contribution_bound(ris(8, LightSampling::Area), light_contacts(rs)).bounded);
    std::shared_ptr<RenderRequest> floor = bundled("quad_light_floor");
    rs.build(*floor->scene, floor->accel);
    EXPECT_TRUE(contribution_bound(ris(8), light_contacts(rs)).bounded);
}

std::string request_error(const json& estimator) {
    json scene = test::scene_json("quad_light_floor");
    json options{{"base_dir", test::kScenes}, {"estimators", json::array({estimator})}};
    return build_render_request(scene, options).error;
}

// The candidate count: ris's option, in 1..64, refused elsewhere and outside the bounds with
// an error naming the field and the value; the bounds and a string name are accepted.
TEST(RenderRis, BadCandidateCountsAreRefused) {
    const json base{{"name", "r"}, {"strategy", "ris"}};
    for (int m : {1, 8, 64}) {
        json e = base;
        e["candidates"] = m;
        EXPECT_EQ(request_error(e), "") << m;
    }
    EXPECT_EQ(request_error("ris"), "");
    struct Bad {
        json value;
        std::string message;
    };
    const Bad bad[] = {{0, "must be a whole number in 1..64 or \"auto\", got 0"},
                       {65, "got 65"},
                       {"many", "got \"many\""},
                       {-3, "candidates"},
                       {2.5, "candidates"},
                       {"8", "candidates"}};
    for (const Bad& b : bad) {
        json e = base;
        e["candidates"] = b.value;
        const std::string error = request_error(e);
        EXPECT_NE(error.find("options.estimators[0].candidates"), std::string::npos) << error;
        EXPECT_NE(error.find(b.message), std::string::npos) << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
    }
    const std::string other = request_error(json{{"strategy", "light_area"}, {"candidates", 4}});
    EXPECT_NE(other.find("only ris, mis_balance, mis_power and path resample candidates, not "
                         "'light_area'"),
              std::string::npos)
        << other;
    const std::string unknown = request_error("riss");
    EXPECT_NE(unknown.find("ris"), std::string::npos) << unknown;
}

/// An estimator parsed from JSON as the render API reads it.
RenderEstimator parsed(const json& j) {
    Made<RenderEstimator> m = parse_render_estimator(j, "e");
    EXPECT_TRUE(m.ok()) << j.dump() << ": " << m.error;
    return m.value;
}

// The light sample of mis_* and path resampled from M candidates, weighted by MIS against the
// BSDF sample with the source density (and with splitting's counts), and ris with several
// resampled light samples per point: every pixel within its error bar of Lambert's closed form
// and the image's mean within its own (Sidak, family-wise 1e-3); scaled by 1.02 the pooled
// check fails (it sees a 2% bias). Path with max_depth 1 is direct light, the closed form's.
TEST(RenderRis, ResampledNextEventUnbiasedWithSeveralLights) {
    const Scene scene = several_lights_scene();
    RenderScene rs;
    rs.build(scene);
    const int W = 8, H = 8;
    const std::vector<double> exact = several_lights_exact(scene, W, H);
    const std::vector<json> ests = {
        {{"strategy", "mis_power"}, {"candidates", 4}},
        {{"strategy", "mis_balance"}, {"candidates", 16}},
        {{"strategy", "mis_power"}, {"candidates", 4}, {"light_samples", 2}, {"bsdf_samples", 3}},
        {{"strategy", "path"}, {"max_depth", 1}, {"candidates", 8}},
        {{"strategy", "path"}, {"max_depth", 1}, {"candidates", 4}, {"light_samples", 3}},
        {{"strategy", "ris"}, {"candidates", 4}, {"light_samples", 3}}};
    const double z_max = -normal_quantile(0.5 * test::sidak_level(1e-3, W * H * int(ests.size())));
    const double z_pooled = -normal_quantile(0.5 * test::sidak_level(1e-3, int(ests.size())));
    uint64_t stream = 901;
    for (const json& j : ests) {
        RenderSettings st = settings(W, H, 1024, stream++);
        st.jitter_pixels = false;
        RenderImage im = render_image(rs, parsed(j), st);
        EXPECT_EQ(im.diagnostics.discarded_nonfinite, 0u) << j.dump();
        EXPECT_EQ(pixels_off(im, exact, z_max), 0) << j.dump();
        EXPECT_LT(std::fabs(pooled_z(im, exact)), z_pooled) << j.dump();
        for (double& v : im.rgb) v *= 1.02;
        EXPECT_GT(pooled_z(im, exact), z_pooled) << j.dump() << " scaled by 1.02";
    }
}

// Path tracing with resampled next-event estimation in a furnace (every face emits Le, albedo
// rho): every bounce gives Le / (1 - rho), direct light only Le (1 + rho), each within 5
// standard errors; the other answer is far outside.
TEST(RenderRis, ResampledPathInTheFurnace) {
    const double rho = 0.5, Le = 1.0;
    const Scene scene = test::furnace_box(rho, Le, 4);
    RenderScene rs;
    rs.build(scene);
    for (int depth : {1, 1000}) {
        RenderImage im = render_image(
            rs, parsed({{"strategy", "path"}, {"max_depth", depth}, {"candidates", 6}}),
            settings(16, 16, 32, 19));
        const double right = depth == 1 ? Le * (1 + rho) : Le / (1 - rho);
        const double wrong = depth == 1 ? Le / (1 - rho) : Le * (1 + rho);
        ImageError err = image_error(im, im);
        EXPECT_NEAR(err.mean_luminance, right, 5.0 * err.mean_luminance_se) << depth;
        EXPECT_GT(std::fabs(err.mean_luminance - wrong), 5.0 * err.mean_luminance_se) << depth;
    }
}

// One candidate, given in the JSON, is the plain light sample of mis_* and path: the same
// image bit for bit and the same rays; two candidates resample (other numbers).
TEST(RenderRis, OneCandidateIsThePlainNextEventEstimate) {
    const Scene scene = several_lights_scene();
    RenderScene rs;
    rs.build(scene);
    const RenderSettings st = settings(10, 8, 16, 3);
    for (const char* strategy : {"mis_balance", "mis_power", "path"}) {
        const RenderImage plain = render_image(rs, parsed(json(strategy)), st);
        const RenderImage one =
            render_image(rs, parsed({{"strategy", strategy}, {"candidates", 1}}), st);
        const RenderImage two =
            render_image(rs, parsed({{"strategy", strategy}, {"candidates", 2}}), st);
        EXPECT_EQ(one.rgb, plain.rgb) << strategy;
        EXPECT_EQ(one.diagnostics.rays, plain.diagnostics.rays) << strategy;
        EXPECT_NE(two.rgb, plain.rgb) << strategy;
    }
}

// "auto": the pilot runs for the candidates (counts 1, 2, ...), measures their variance and
// costs, and chooses the count of its own figures; with light_samples "auto" too, a second
// pilot chooses those for that count. A fixed count runs no pilot.
TEST(RenderRis, AutoCandidatesComeFromThePilot) {
    const Scene scene = several_lights_scene();
    RenderScene rs;
    rs.build(scene);
    RenderSettings image = settings(64, 48, 16, 7);
    for (const char* strategy : {"ris", "mis_power", "path"}) {
        RenderEstimator e = parsed({{"strategy", strategy}, {"candidates", "auto"}});
        ASSERT_EQ(e.candidates, 0);
        const RenderEstimator chosen = resolve_split(rs, e, image);
        ASSERT_TRUE(chosen.candidate_pilot.ran) << strategy;
        EXPECT_FALSE(chosen.split_pilot.ran) << strategy;
        const SplitPilot& p = chosen.candidate_pilot;
        ASSERT_GE(p.tried, 2) << strategy;
        EXPECT_GT(p.relative_variance[0], 0.0) << strategy;
        EXPECT_EQ(chosen.candidates, pilot_choice(p)) << strategy;
        EXPECT_GE(chosen.candidates, kMinRisCandidates);
        EXPECT_LE(chosen.candidates, kMaxRisCandidates);
        e.light_samples = 0;
        const RenderEstimator both = resolve_split(rs, e, image);
        EXPECT_TRUE(both.candidate_pilot.ran && both.split_pilot.ran) << strategy;
        EXPECT_GE(both.light_samples, 1) << strategy;
        EXPECT_GE(both.candidates, 1) << strategy;
        e = parsed({{"strategy", strategy}, {"candidates", 3}});
        const RenderEstimator fixed = resolve_split(rs, e, image);
        EXPECT_FALSE(fixed.candidate_pilot.ran) << strategy;
        EXPECT_EQ(fixed.candidates, 3) << strategy;
    }
}

// "auto" candidates are refused where a pilot cannot choose them once: a reference, a render
// in parts, and the live view's bands (render_live.cpp; tested there).
TEST(RenderRis, AutoCandidatesRefusedInAReference) {
    const json scene = test::scene_json("quad_light_floor");
    json options{{"base_dir", test::kScenes}};
    options["reference"] = json{{"estimator", {{"strategy", "mis_power"}, {"candidates", "auto"}}}};
    const std::string error = build_render_request(scene, options).error;
    EXPECT_NE(error.find("options.reference.estimator.candidates: \"auto\" depends on timing"),
              std::string::npos)
        << error;
    options["reference"] = json{{"estimator", {{"strategy", "mis_power"}, {"candidates", 4}}}};
    EXPECT_EQ(build_render_request(scene, options).error, "");
}

// veach_mis's glossy plates: resampling 8 light samples by a target with the BSDF in it leaves
// more pixels with a smaller variance than light sampling alone (sign test, > 5 standard
// deviations), at equal samples.
TEST(RenderRis, FewerErrorsThanLightSamplingOnGlossyPlates) {
    std::shared_ptr<RenderRequest> r = bundled("veach_mis");
    ASSERT_TRUE(r);
    RenderScene rs;
    rs.build(*r->scene, r->accel);
    RenderEstimator by_power = ris(8);
    by_power.light_selection = LightSelection::Power;
    RenderEstimator plain = light(LightSampling::SolidAngle);
    const RenderImage by_light = render_image(rs, plain, settings(64, 36, 32, 5));
    const RenderImage by_ris = render_image(rs, by_power, settings(64, 36, 32, 6));
    EXPECT_GT(pixels_noisier_z(by_light, by_ris), 5.0);
}

} // namespace
} // namespace mcp
