// The radiance estimators against closed forms: Lambert's polygon formula under a quad light,
// furnaces (closed emitting enclosures), thread invariance and convergence orders.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/rng.h"
#include "core/special.h"
#include "render/render_study.h"
#include "render_scenes.h"
#include "test_support.h"

namespace mcp {
namespace {

using test::diffuse;

const RadianceStrategy kDirect[] = {
    RadianceStrategy::UniformHemisphere,
    RadianceStrategy::CosineHemisphere,
    RadianceStrategy::Bsdf,
    RadianceStrategy::LightArea,
    RadianceStrategy::LightSolidAngle,
    RadianceStrategy::MisBalance,
    RadianceStrategy::MisPower,
};

RenderEstimator estimator(RadianceStrategy s, PixelSamplerKind px = PixelSamplerKind::Stratified) {
    RenderEstimator e;
    e.strategy = s;
    e.name = strategy_name(s);
    e.pixel_sampler = px;
    return e;
}

RenderSettings settings(int w, int h, uint64_t spp, uint64_t stream) {
    return mcp::test::render_settings(w, h, spp, stream);
}

// A stratum's position (k + u) / n and quotient k / n: a power of two n multiplies by its
// reciprocal and shifts, which must give the division's bits exactly (images do not change
// with the path taken); other counts divide.
TEST(PixelSamplerStratified, StrataScaleGivesTheDivisionsBits) {
    Pcg32 rng(2027u, 3u);
    std::vector<uint64_t> counts = {1, 3, 12, 100, 4101};
    for (int b = 1; b <= 40; ++b) counts.push_back(uint64_t(1) << b);
    for (uint64_t n : counts) {
        SCOPED_TRACE(n);
        const pixel_sampler_detail::StrataScale scale(n);
        for (int i = 0; i < 2000; ++i) {
            const uint64_t k = (uint64_t(rng.next_u32()) << 32 | rng.next_u32()) % n;
            const double u = i == 0 ? 0.0 : (i == 1 ? 1.0 - 0x1p-53 : rng.next_double());
            ASSERT_EQ(scale.position(k, u), (static_cast<double>(k) + u) / static_cast<double>(n));
            const uint64_t cell = uint64_t(rng.next_u32()) << (i % 32) | rng.next_u32();
            ASSERT_EQ(scale.quotient(cell), cell / n);
        }
    }
}

// The stratified pixel sampler: in every dimension a pixel's spp samples take each stratum
// once (1D: [k/spp, (k+1)/spp); 2D: each cell of the grid), and the permutations that pair the
// strata are uniform and independent between dimensions and pixels. Checked on the shuffled
// tables (spp 8 and 12, a non-power of two) and on the hashed bijection beyond kTableMaxSpp.
TEST(PixelSamplerStratified, EveryStratumOnceAndUniformPairing) {
    using test::chi_square;
    for (uint64_t spp :
         {uint64_t(8), uint64_t(12), uint64_t(256), PixelSampler::kTableMaxSpp + 5}) {
        SCOPED_TRACE(spp);
        PixelSampler s;
        s.configure(PixelSamplerKind::Stratified, spp, 64, 64, 12345);
        const auto grid = stratification_grid(spp, 2);
        const int pixels = spp > 64 ? 4 : 4096;
        // Stratum of sample 0 in dimension 0, jointly with its stratum in dimension 3: uniform
        // on spp x spp cells under independent uniform permutations (for the small spp).
        std::vector<double> joint(size_t(spp * spp), 0.0);
        double fixed_points = 0.0; // of dimension 0's permutation, summed over pixels
        for (int px = 0; px < pixels; ++px) {
            s.start_pixel(px % 64, px / 64);
            std::vector<int> seen_1d(spp, 0), seen_2d(spp, 0), seen_late(spp, 0);
            for (uint64_t i = 0; i < spp; ++i) {
                s.start_sample(i);
                const auto k0 = uint64_t(s.get_1d() * double(spp));
                const Vec2 u = s.get_2d(); // dimensions 1 and 2
                const auto k3 = uint64_t(s.get_1d() * double(spp));
                for (int skip = 4; skip < PixelSampler::kStratifiedDimensions - 1; ++skip)
                    s.get_1d();
                const auto k_late = uint64_t(s.get_1d() * double(spp)); // the last stratified
                ASSERT_LT(k0, spp);
                ASSERT_LT(k3, spp);
                ASSERT_LT(k_late, spp);
                ++seen_1d[k0];
                ++seen_late[k_late];
                ++seen_2d[uint64_t(u.y * double(grid[1])) * grid[0] +
                          uint64_t(u.x * double(grid[0]))];
                if (i == 0) joint[k0 * spp + k3] += 1.0;
                if (k0 == i) fixed_points += 1.0;
            }
            for (uint64_t k = 0; k < spp; ++k) {
                ASSERT_EQ(seen_1d[k], 1) << "pixel " << px << " stratum " << k;
                ASSERT_EQ(seen_2d[k], 1) << "pixel " << px << " cell " << k;
                ASSERT_EQ(seen_late[k], 1) << "pixel " << px << " stratum " << k;
            }
        }
        if (spp > 64) continue;
        const std::vector<double> expected(joint.size(), double(pixels) / double(spp * spp));
        const auto chi = chi_square(joint, expected);
        EXPECT_GT(chi.p_value, 1e-4) << "chi^2 " << chi.statistic << " on " << chi.dof << " dof";
        // A uniform permutation has one fixed point on average, with variance 1 (a
        // cyclic-only shuffle, Sattolo's, has none): within 5 standard errors over the pixels.
        EXPECT_NEAR(fixed_points / pixels, 1.0, 5.0 / std::sqrt(double(pixels)));
    }
}

// Floor radiance under the quad light: (albedo / pi) E with E = pi Le F from Lambert's
// polygon formula at the point each pixel's centre ray hits. Every estimator, every pixel,
// within its own error bar (z-threshold for a family-wise level of 1e-3 over all pixels).
TEST(RenderAnalytic, QuadLightFloorMatchesLambertsFormula) {
    const double Le = 5.0, albedo = 0.5;
    Scene scene = test::quad_light_scene(Le);
    RenderScene rs;
    rs.build(scene);
    const Vec3 light[4] = {{-0.5, 1, -0.5}, {0.5, 1, -0.5}, {0.5, 1, 0.5}, {-0.5, 1, 0.5}};
    const int W = 8, H = 8;
    const int tests = W * H * int(std::size(kDirect));
    const double z_max = -normal_quantile(0.5 * test::sidak_level(1e-3, tests));
    for (RadianceStrategy s : kDirect) {
        RenderSettings st = settings(W, H, 512, 77);
        st.jitter_pixels = false;
        RenderImage im = render_image(rs, estimator(s), st);
        EXPECT_EQ(im.diagnostics.discarded_nonfinite, 0u);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                Ray r = camera_ray(scene.camera, W, H, x + 0.5, y + 0.5);
                ASSERT_LT(r.direction.y, 0.0);
                Vec3 p = r.origin + r.direction * (-r.origin.y / r.direction.y);
                double F = lambert_polygon_form_factor(p, Vec3(0, 1, 0), light, 4);
                double expected = albedo * Le * F; // (albedo / pi) * pi Le F
                size_t k = (size_t(y) * W + size_t(x)) * 3;
                double se = std::sqrt(im.variance[k]);
                EXPECT_LE(std::fabs(im.rgb[k] - expected), z_max * se + 1e-12 * expected)
                    << strategy_name(s) << " pixel " << x << "," << y << " expected " << expected
                    << " got " << im.rgb[k] << " +/- " << se;
            }
    }
}

// The same floor radiance in scaled copies of the scene, seen as scenes/quad_light_floor.gltf
// sees it (from z = 1.6, 34 degrees down: the far rows send shadow rays at grazing angles):
// everything (camera too) times 1e3 and 1e4, and the floor alone times 1e5 (its hit points
// near the origin are interpolated from vertices at 2e5, and re-testing the floor from an
// offset origin carries their rounding error; fixed-size ray offsets once left shadow rays
// inside the floor: the far rows self-shadowed, 10-60% darker). Each pixel within its error
// bar, as above.
TEST(RenderAnalytic, ScaledQuadLightScenesMatchLambertsFormula) {
    const double Le = 5.0, albedo = 0.5;
    struct Scaling {
        const char* name;
        double all, floor;
    };
    const Scaling scalings[] = {
        {"all x1e3", 1e3, 1.0}, {"all x1e4", 1e4, 1.0}, {"floor x1e5", 1.0, 1e5}};
    const int W = 8, H = 8;
    const int tests = W * H * int(std::size(kDirect)) * int(std::size(scalings));
    const double z_max = -normal_quantile(0.5 * test::sidak_level(1e-3, tests));
    for (const Scaling& scaling : scalings) {
        Scene scene = test::quad_light_scene(Le);
        for (Vec3& v : scene.mesh.position) {
            if (v.y == 0.0) v = Vec3(v.x * scaling.floor, 0.0, v.z * scaling.floor);
            v *= scaling.all;
        }
        const double tilt = 34.0 * kPi / 180.0;
        const Vec3 eye(0.0, 0.95, 1.6);
        scene.camera = test::look_at(
            eye * scaling.all, (eye + Vec3(0.0, -std::sin(tilt), -std::cos(tilt))) * scaling.all,
            {0, 1, 0}, 0.6);
        RenderScene rs;
        rs.build(scene);
        Vec3 light[4] = {{-0.5, 1, -0.5}, {0.5, 1, -0.5}, {0.5, 1, 0.5}, {-0.5, 1, 0.5}};
        for (Vec3& v : light) v *= scaling.all;
        for (RadianceStrategy s : kDirect) {
            RenderSettings st = settings(W, H, 1024, 91);
            st.jitter_pixels = false;
            RenderImage im = render_image(rs, estimator(s), st);
            EXPECT_EQ(im.diagnostics.discarded_nonfinite, 0u);
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    Ray r = camera_ray(scene.camera, W, H, x + 0.5, y + 0.5);
                    ASSERT_LT(r.direction.y, 0.0);
                    Vec3 p = r.origin + r.direction * (-r.origin.y / r.direction.y);
                    double F = lambert_polygon_form_factor(p, Vec3(0, 1, 0), light, 4);
                    double expected = albedo * Le * F;
                    size_t k = (size_t(y) * W + size_t(x)) * 3;
                    double se = std::sqrt(im.variance[k]);
                    EXPECT_LE(std::fabs(im.rgb[k] - expected), z_max * se + 1e-9 * expected)
                        << scaling.name << " " << strategy_name(s) << " pixel " << x << "," << y
                        << " expected " << expected << " got " << im.rgb[k] << " +/- " << se;
                }
        }
    }
}

// A closed box every face of which emits Le and reflects with albedo rho: with direct light
// only each point returns Le (1 + rho); with every bounce Le / (1 - rho). Cosine sampling of
// the diffuse BRDF has weight rho Le for every direction, so it is exact when no ray escapes
// (which also tests watertight intersection).
TEST(RenderAnalytic, FurnaceBox) {
    const double rho = 0.5, Le = 1.0;
    Scene scene = test::furnace_box(rho, Le, 4);
    RenderScene rs;
    rs.build(scene);
    {
        RenderImage im = render_image(rs, estimator(RadianceStrategy::CosineHemisphere),
                                      settings(16, 16, 16, 3));
        for (size_t k = 0; k < im.rgb.size(); ++k) ASSERT_NEAR(im.rgb[k], Le * (1 + rho), 1e-12);
    }
    for (RadianceStrategy s : kDirect) {
        RenderImage im = render_image(rs, estimator(s), settings(16, 16, 64, 5));
        ImageError e;
        RenderImage exact = im;
        for (double& v : exact.rgb) v = Le * (1 + rho);
        for (double& v : exact.variance) v = 0.0;
        e = image_error(im, exact);
        EXPECT_NEAR(e.mean_luminance, Le * (1 + rho), 5.0 * e.mean_luminance_se + 1e-12)
            << strategy_name(s);
        EXPECT_EQ(im.diagnostics.discarded_nonfinite, 0u) << strategy_name(s);
    }
    RenderEstimator path = estimator(RadianceStrategy::Path);
    path.max_depth = 1000;
    RenderImage im = render_image(rs, path, settings(16, 16, 64, 9));
    RenderImage exact = im;
    for (double& v : exact.rgb) v = Le / (1 - rho);
    ImageError e = image_error(im, exact);
    EXPECT_NEAR(e.mean_luminance, Le / (1 - rho), 5.0 * e.mean_luminance_se);
    // Depth 1 is direct lighting: Le (1 + rho) again.
    path.max_depth = 1;
    im = render_image(rs, path, settings(16, 16, 64, 11));
    e = image_error(im, exact);
    EXPECT_NEAR(e.mean_luminance, Le * (1 + rho), 5.0 * e.mean_luminance_se);
}

TEST(Render, ImagesDoNotDependOnThreads) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    RenderSettings one = settings(12, 10, 8, 42);
    RenderSettings two = one;
    two.threads = 2;
    for (RadianceStrategy s : {RadianceStrategy::MisPower, RadianceStrategy::Bsdf}) {
        RenderImage a = render_image(rs, estimator(s), one);
        RenderImage b = render_image(rs, estimator(s), two);
        EXPECT_EQ(a.rgb, b.rgb);
        EXPECT_EQ(a.diagnostics.rays, b.diagnostics.rays);
    }
}

// Directions sampled at shading points meet the lights first when the lights are at most half
// the scene (RenderScene::emitters_first), then ask the scene whether anything lies in front:
// the images are those of tracing every direction to its closest hit, bit for bit, with a
// blocker half shadowing the floor, a second light above the first (hidden behind it) and a
// light seen from its back. A closed box of emitters keeps the closest-hit path.
TEST(Render, LightsFirstGivesTheClosestHitImages) {
    Scene scene = test::quad_light_scene(5.0);
    Material light = diffuse(0.0);
    light.emission = Vec3(2.0);
    scene.materials.push_back(light);
    test::add_quad(scene, {-0.3, 1.5, -0.3}, {0.3, 1.5, -0.3}, {0.3, 1.5, 0.3}, {-0.3, 1.5, 0.3},
                   2); // faces -y
    test::add_quad(scene, {1.2, 0.8, -1}, {1.2, 0.8, 1}, {1.6, 0.8, 1}, {1.6, 0.8, -1},
                   2);                                                              // faces +y
    test::add_quad(scene, {-1, 0.4, 0}, {-1, 0.4, 1}, {0, 0.4, 1}, {0, 0.4, 0}, 0); // blocker
    test::add_quad(scene, {-1, 0.4, 0}, {0, 0.4, 0}, {0, 0.4, 1}, {-1, 0.4, 1}, 0);
    test::add_quad(scene, {-2, 0, 2}, {-2, 2, 2}, {2, 2, 2}, {2, 0, 2}, 0); // a wall
    test::add_quad(scene, {-2, 0, -2}, {2, 0, -2}, {2, 2, -2}, {-2, 2, -2}, 0);
    scene.camera = test::look_at({0, 1.2, 1.9}, {0, 0, 0}, {0, 1, 0}, 1.3);
    RenderScene lights_first;
    lights_first.build(scene);
    ASSERT_TRUE(lights_first.emitters_first);
    RenderScene closest_hit = lights_first;
    closest_hit.emitters_first = false;
    for (RadianceStrategy s : {RadianceStrategy::UniformHemisphere, RadianceStrategy::Bsdf,
                               RadianceStrategy::MisPower}) {
        for (PixelSamplerKind px : {PixelSamplerKind::Stratified, PixelSamplerKind::PaddedSobol}) {
            RenderImage a = render_image(lights_first, estimator(s, px), settings(16, 12, 16, 9));
            RenderImage b = render_image(closest_hit, estimator(s, px), settings(16, 12, 16, 9));
            EXPECT_EQ(a.rgb, b.rgb) << strategy_name(s);
            EXPECT_EQ(a.diagnostics.rays, b.diagnostics.rays);
            double sum = 0.0;
            for (double v : a.rgb) sum += v;
            EXPECT_GT(sum, 0.0);
        }
    }
    Scene box = test::furnace_box(0.5, 1.0, 2);
    RenderScene all_lights;
    all_lights.build(box);
    EXPECT_FALSE(all_lights.emitters_first);
}

// Relative MSE against a reference falls as 1/spp for every unbiased estimator with
// independent pixel samples (fitted order within 4 standard errors of -1, plus 0.1 for the
// reference's own noise at the largest spp); stratified samples do at least as well.
TEST(RenderConvergence, RelativeMseFallsAsOneOverSpp) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    RenderSettings ref_settings = settings(12, 12, 8192, 1234);
    RenderImage reference = render_image(rs, estimator(RadianceStrategy::MisPower), ref_settings);
    RenderStudySettings st;
    st.width = 12;
    st.height = 12;
    st.spp_min = 1;
    st.spp_max = 32;
    st.reps = 6;
    st.threads = 1;
    std::vector<RenderEstimator> ests;
    for (RadianceStrategy s : kDirect) ests.push_back(estimator(s, PixelSamplerKind::Independent));
    RenderStudyResult r = run_render_study(rs, ests, st, reference);
    for (const RenderEstimatorStudy& e : r.estimators) {
        ASSERT_TRUE(e.fit.valid) << e.estimator.name << ": " << e.fit.note;
        EXPECT_NEAR(e.fit.order, -1.0, 4.0 * e.fit.order_se + 0.1) << e.estimator.name;
    }
    for (RenderEstimator& e : ests) e.pixel_sampler = PixelSamplerKind::Stratified;
    r = run_render_study(rs, ests, st, reference);
    for (const RenderEstimatorStudy& e : r.estimators) {
        ASSERT_TRUE(e.fit.valid) << e.estimator.name;
        EXPECT_LT(e.fit.order, -1.0 + 4.0 * e.fit.order_se + 0.1) << e.estimator.name;
    }
}

// Issue 10: relative MSE does not depend on the radiance scale (1e-200 and 1e300 radiances
// give the numbers of radiance 1, to rounding), is undefined (NaN) against a black
// reference instead of 0, and the reference's noise floor has its closed form.
RenderImage flat_image(int w, int h, double value, double variance) {
    RenderImage im;
    im.width = w;
    im.height = h;
    im.spp = 16;
    im.rgb.assign(im.pixel_count() * 3, value);
    im.variance.assign(im.pixel_count() * 3, variance);
    return im;
}

TEST(RenderError, RelativeMseIsScaleFreeAndUndefinedOnBlack) {
    RenderImage ref = flat_image(4, 3, 1.0, 0.0), im = flat_image(4, 3, 1.0, 0.01);
    im.rgb[0] = 2.0;
    im.rgb[7] = 0.5;
    ImageError unit = image_error(im, ref);
    ASSERT_GT(unit.rel_mse, 0.0);
    for (double scale : {1e-200, 1e300}) {
        RenderImage a = ref, b = im;
        for (double& v : a.rgb) v *= scale;
        for (double& v : b.rgb) v *= scale;
        ImageError e = image_error(b, a);
        EXPECT_NEAR(e.rel_mse, unit.rel_mse, 1e-14 * unit.rel_mse) << scale;
        EXPECT_NEAR(e.rel_mse_raw, unit.rel_mse_raw, 1e-14 * unit.rel_mse) << scale;
    }
    RenderImage black = flat_image(4, 3, 0.0, 0.0);
    ImageError e = image_error(black, black);
    EXPECT_TRUE(std::isnan(e.rel_mse));
    EXPECT_TRUE(std::isnan(e.rel_mse_raw));
    EXPECT_TRUE(std::isnan(relative_mse_floor(black)));
}

TEST(RenderError, ReferenceFloorHasItsClosedForm) {
    // A flat reference of value 2 with variance 0.04 per channel: floor = v / (R^2 + eps),
    // eps = 1e-2 R^2 (the mean luminance of a grey image is its value).
    RenderImage ref = flat_image(5, 4, 2.0, 0.04);
    EXPECT_NEAR(relative_mse_floor(ref), 0.04 / (4.0 * 1.01), 1e-15);
    EXPECT_EQ(relative_mse_floor(flat_image(5, 4, 2.0, 0.0)), 0.0); // an HDR file
    // An image identical to the reference has corrected relative MSE -floor: below the
    // reference's noise, flagged, without efficiency, and left out of the fit.
    RenderImage im = ref;
    im.seconds = 0.1;
    std::vector<ImageSummary> images{summarise_image(im, ref), summarise_image(im, ref)};
    LevelStats l = render_level_stats(images, ref);
    EXPECT_EQ(l.measure, LevelMeasure::RelativeMse);
    EXPECT_NEAR(l.variance, -relative_mse_floor(ref), 1e-15);
    EXPECT_TRUE(below_reference_noise(l, relative_mse_floor(ref)));
    EXPECT_TRUE(std::isnan(l.efficiency));
    LevelStats above = l;
    above.variance = 2.0 * relative_mse_floor(ref);
    EXPECT_FALSE(below_reference_noise(above, relative_mse_floor(ref)));
    // Three levels falling as 1/spp above the floor, the fourth below it: the fit uses three.
    std::vector<LevelStats> levels;
    for (uint64_t n : {1, 2, 4, 8}) {
        LevelStats x;
        x.n = n;
        x.reps = 4;
        x.variance = 1.0 / double(n);
        x.variance_lo = 0.9 * x.variance;
        x.variance_hi = 1.1 * x.variance;
        levels.push_back(x);
    }
    ConvergenceFit all = fit_render_convergence(levels, 0.0);
    EXPECT_EQ(all.levels_used, 4);
    ConvergenceFit fit = fit_render_convergence(levels, 0.15);
    EXPECT_EQ(fit.measure, LevelMeasure::RelativeMse);
    EXPECT_EQ(fit.levels_used, 3);
    EXPECT_NEAR(fit.order, -1.0, 1e-12);
}

// Issue 15: a level's relative MSE resting on a few (pixel, image) errors is flagged, with
// Kish's effective number of terms (sum t)^2 / sum t^2 [Kish65]; error spread over the image
// gives hundreds, one rare large pixel error about one.
RenderImage noisy_image(const RenderImage& ref, double sigma, uint64_t seed) {
    RenderImage im = ref;
    Pcg32 rng(seed, 7);
    for (double& v : im.rgb) {
        // Box-Muller: independent normal errors of standard deviation sigma on every channel.
        const double u1 = rng.next_double(), u2 = rng.next_double();
        v += sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }
    std::fill(im.variance.begin(), im.variance.end(), sigma * sigma);
    return im;
}

TEST(RenderError, FewPixelErrorsAreFlaggedAndSpreadErrorsAreNot) {
    const RenderImage ref = flat_image(16, 16, 1.0, 0.0);
    const int reps = 4;
    std::vector<ImageSummary> spread, rare;
    for (int r = 0; r < reps; ++r) {
        RenderImage im = noisy_image(ref, 0.01, uint64_t(r + 1));
        spread.push_back(summarise_image(im, ref));
        if (r == 2) im.rgb[3 * (5 * 16 + 9) + 1] += 2.0; // pixel (9, 5), 200 sigma in green
        rare.push_back(summarise_image(im, ref));
    }
    // Independent normal errors on three channels: a pixel's term is sigma^2 chi^2_3, whose
    // Kish ratio E[t]^2 / E[t^2] is 9 / 15, so about 0.6 x 1024 terms; half of that allows a
    // spread of the sample second moment far beyond its standard error (about 4%).
    ErrorConcentration c;
    LevelStats l = render_level_stats(spread, ref, &c);
    EXPECT_GT(c.effective_terms, 0.5 * 0.6 * 16 * 16 * reps);
    EXPECT_LT(c.effective_terms, 1.5 * 0.6 * 16 * 16 * reps);
    EXPECT_TRUE(render_level_flags(l, c, 0.0).empty());
    // One pixel 200 sigma off carries 4e4 sigma^2 of a total of about 3 x 1024 sigma^2: one
    // effective term (1.17 for these totals), flagged, located, and the median image is the
    // noise's, not the event's.
    l = render_level_stats(rare, ref, &c);
    EXPECT_LT(c.effective_terms, 1.3);
    EXPECT_GT(c.effective_terms, 1.0);
    EXPECT_EQ(c.worst_image, 2);
    EXPECT_EQ(c.worst_x, 9);
    EXPECT_EQ(c.worst_y, 5);
    EXPECT_GT(c.worst_share, 0.9);
    EXPECT_LT(c.median_rel_mse, 1.5 * 0.01 * 0.01 / 1.01); // sigma^2 / (R^2 + eps) per channel
    EXPECT_GT(l.variance, 10.0 * c.median_rel_mse);
    std::vector<Flag> flags = render_level_flags(l, c, 0.0);
    ASSERT_EQ(flags.size(), 1u);
    EXPECT_EQ(flags[0].code, FlagCode::FewPixelErrors);
    EXPECT_EQ(flags[0].n, l.n);
    // Exactly two equal pixel errors and nothing else: two effective terms.
    std::vector<ImageSummary> two;
    for (int r = 0; r < reps; ++r) {
        RenderImage im = ref;
        if (r < 2) im.rgb[3 * size_t(r)] += 0.5;
        two.push_back(summarise_image(im, ref));
    }
    render_level_stats(two, ref, &c);
    EXPECT_NEAR(c.effective_terms, 2.0, 1e-12);
    // A pixel error whose square is beyond the doubles (1e200 times the reference's mean):
    // one term rules, and the other images do not hide it.
    std::vector<ImageSummary> huge = spread;
    {
        RenderImage im = noisy_image(ref, 0.01, 9);
        im.rgb[0] = 1e200;
        huge[1] = summarise_image(im, ref);
    }
    ErrorConcentration hc;
    render_level_stats(huge, ref, &hc);
    EXPECT_EQ(hc.effective_terms, 1.0);
    EXPECT_EQ(hc.worst_image, 1);
    EXPECT_EQ(hc.worst_x, 0);
    // The study flag counts such levels and names the most concentrated one.
    RenderEstimatorStudy s;
    s.levels = {l, l};
    s.levels[1].n = 2 * l.n;
    ErrorConcentration spread_c;
    render_level_stats(spread, ref, &spread_c);
    s.concentration = {spread_c, c};
    bool found = false;
    for (const Flag& f : render_flags(s, 0.0))
        if (f.code == FlagCode::RareLargeErrors) {
            found = true;
            EXPECT_EQ(f.count, 1u);
            EXPECT_EQ(f.of, 2u);
            EXPECT_EQ(f.n, 2 * l.n);
            EXPECT_NEAR(f.value, 2.0, 1e-12);
        }
    EXPECT_TRUE(found);
}

} // namespace
} // namespace mcp
