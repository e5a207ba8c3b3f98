// Images rendered in passes (render/progressive.h) and the pixel sampler that lets a pass add
// samples to an image (padded_sobol, pixel_sampler.h): every power-of-two prefix of a pixel's
// samples is a net, a pixel's samples do not depend on its spp, values are uniform under the
// randomization; passes (1, 2, 4, ... spp) give the one-shot image bit for bit, bands rendered
// apart and merged give the whole image, and what cannot extend is refused.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/progressive.h"
#include "render/render_study.h"
#include "render_api/render_request.h"
#include "render_scenes.h"
#include "scene_files.h"
#include "test_support.h"

namespace mcp {
namespace {

using nlohmann::json;

/// How many elementary intervals of area 2^-m hold other than one point.
int net_defects(const std::vector<Vec2>& pts, int m) {
    int bad = 0;
    for (int j = 0; j <= m; ++j) {
        const uint64_t nx = uint64_t(1) << j, ny = uint64_t(1) << (m - j);
        std::vector<int> count(size_t(nx * ny), 0);
        for (const Vec2& p : pts) ++count[size_t(uint64_t(p.y * ny) * nx + uint64_t(p.x * nx))];
        for (int c : count) bad += c != 1;
    }
    return bad;
}

/// Request `request` (after that many 2D requests) of pixel (x, y)'s first n samples.
std::vector<Vec2> padded_points(PixelSampler& s, int x, int y, uint64_t n, int request,
                                bool choice = false) {
    std::vector<Vec2> pts;
    s.start_pixel(x, y);
    for (uint64_t i = 0; i < n; ++i) {
        s.start_sample(i);
        for (int k = 0; k < request; ++k) s.get_2d();
        pts.push_back(choice ? s.get_choice_2d().u : s.get_2d());
    }
    return pts;
}

// Every power-of-two prefix of a pixel's samples is a (0, m, 2)-net in each 2D request and in
// the point of a choice, for requests kept per pixel and beyond, several pixels and keys.
TEST(PaddedSobolSampler, EveryPowerOfTwoPrefixIsANet) {
    const uint64_t n = 256;
    for (uint64_t key : {1u, 4242u}) {
        PixelSampler s;
        s.configure(PixelSamplerKind::PaddedSobol, n, 13, 7, key);
        for (auto [x, y] : {std::pair{0, 0}, {12, 6}, {5, 3}})
            for (int request : {0, 1, 5, PixelSampler::kSobolPreparedRequests / 2 + 3})
                for (bool choice : {false, true}) {
                    const std::vector<Vec2> pts = padded_points(s, x, y, n, request, choice);
                    for (int m = 0; (uint64_t(1) << m) <= n; ++m) {
                        std::vector<Vec2> prefix(pts.begin(), pts.begin() + (1 << m));
                        EXPECT_EQ(net_defects(prefix, m), 0)
                            << "prefix 2^" << m << " pixel " << x << "," << y << " request "
                            << request << (choice ? " (choice)" : "") << " key " << key;
                    }
                }
    }
}

// A pixel's first samples are the same whatever the spp the sampler was planned for, in every
// kind of request; the sobol and stratified samplers' are not (why they cannot extend).
TEST(PaddedSobolSampler, SamplesDoNotDependOnSpp) {
    auto draws = [](PixelSamplerKind kind, uint64_t spp) {
        PixelSampler s;
        s.configure(kind, spp, 9, 9, 77);
        std::vector<double> v;
        s.start_pixel(4, 7);
        for (uint64_t i = 0; i < 4; ++i) {
            s.start_sample(i);
            v.push_back(s.get_1d());
            Vec2 u = s.get_2d();
            ChoiceSample c = s.get_choice_2d();
            v.insert(v.end(), {u.x, u.y, c.choice, c.u.x, c.u.y});
        }
        return v;
    };
    for (PixelSamplerKind kind : {PixelSamplerKind::PaddedSobol, PixelSamplerKind::Independent}) {
        EXPECT_TRUE(sampler_extends(kind));
        EXPECT_EQ(draws(kind, 4), draws(kind, 64)) << pixel_sampler_name(kind);
        EXPECT_EQ(draws(kind, 4), draws(kind, 1u << 20)) << pixel_sampler_name(kind);
    }
    for (PixelSamplerKind kind : {PixelSamplerKind::Sobol, PixelSamplerKind::Stratified}) {
        EXPECT_FALSE(sampler_extends(kind));
        EXPECT_NE(draws(kind, 4), draws(kind, 64)) << pixel_sampler_name(kind);
    }
}

// Under the randomization (over pixels), each request's value is uniform on (0, 1) and two
// requests of a sample are independent: chi-square of 64 bins and of an 8 x 8 grid of the
// pairs, each at p > 1e-4 (a correct sampler fails one with probability 1e-4), 65536 pixels.
TEST(PaddedSobolSampler, UniformAndPairedAtRandomOverPixels) {
    const int side = 256;
    PixelSampler s;
    s.configure(PixelSamplerKind::PaddedSobol, 16, side, side, 31337);
    std::vector<double> first(64, 0.0), pairs(64, 0.0);
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            s.start_pixel(x, y);
            s.start_sample(3);
            const double a = s.get_1d();
            const double b = s.get_2d().y;
            ASSERT_TRUE(a > 0.0 && a < 1.0 && b > 0.0 && b < 1.0);
            first[size_t(a * 64)] += 1.0;
            pairs[size_t(a * 8) * 8 + size_t(b * 8)] += 1.0;
        }
    const std::vector<double> expected(64, double(side * side) / 64.0);
    EXPECT_GT(test::chi_square(first, expected).p_value, 1e-4);
    EXPECT_GT(test::chi_square(pairs, expected).p_value, 1e-4);
}

// ---------------------------------------------------------------------------------------------
// Passes and bands.

std::shared_ptr<RenderRequest> request(const std::string& name) {
    json options{{"base_dir", test::kScenes}};
    Made<std::shared_ptr<RenderRequest>> r = build_render_request(test::scene_json(name), options);
    EXPECT_TRUE(r.ok()) << name << ": " << r.error;
    return r.value;
}

RenderSettings settings(int w, int h, uint64_t spp, int threads) {
    return mcp::test::render_settings(w, h, spp, 20261204, threads);
}

RenderEstimator estimator(RadianceStrategy strategy, PixelSamplerKind kind) {
    RenderEstimator e;
    e.name = strategy_name(strategy);
    e.strategy = strategy;
    e.pixel_sampler = kind;
    return e;
}

void expect_same_image(const RenderImage& a, const RenderImage& b, const std::string& what) {
    ASSERT_EQ(a.width, b.width) << what;
    ASSERT_EQ(a.height, b.height) << what;
    EXPECT_EQ(a.spp, b.spp) << what;
    // Bit for bit: compare the bytes (NaN == NaN where a pixel kept no sample).
    ASSERT_EQ(a.rgb.size(), b.rgb.size()) << what;
    EXPECT_EQ(0, std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(double))) << what;
    EXPECT_EQ(0,
              std::memcmp(a.variance.data(), b.variance.data(), a.variance.size() * sizeof(double)))
        << what;
    const RenderDiagnostics &da = a.diagnostics, &db = b.diagnostics;
    EXPECT_EQ(da.samples, db.samples) << what;
    EXPECT_EQ(da.rays, db.rays) << what;
    EXPECT_EQ(da.light_misses, db.light_misses) << what;
    EXPECT_EQ(da.discarded_nonfinite, db.discarded_nonfinite) << what;
    EXPECT_EQ(da.dominated_pixels, db.dominated_pixels) << what;
    EXPECT_EQ(da.max_sample_share, db.max_sample_share) << what;
    EXPECT_EQ(da.top, db.top) << what;
}

// Passes to 1, 2, 4, ... 32 spp (and an uneven step) leave the image the one-shot render of
// 32 spp gives, bit for bit, diagnostics included, for direct-lighting estimators and path
// tracing on Veach's scene (glossy plates, four lights) with both samplers that extend.
TEST(ProgressiveRender, PassesEqualOneShotBitForBit) {
    auto r = request("veach_mis");
    ASSERT_TRUE(r);
    RenderScene rs;
    rs.build(*r->scene, r->accel);
    const int W = 23, H = 17;
    for (PixelSamplerKind kind : {PixelSamplerKind::PaddedSobol, PixelSamplerKind::Independent})
        for (RadianceStrategy strategy :
             {RadianceStrategy::MisPower, RadianceStrategy::Bsdf, RadianceStrategy::Path}) {
            const RenderEstimator est = estimator(strategy, kind);
            const std::string what =
                std::string(strategy_name(strategy)) + " with " + pixel_sampler_name(kind);
            const RenderImage one_shot = render_image(rs, est, settings(W, H, 32, 2));
            ImageBand band = make_band(W, H, 0, H, kind);
            for (uint64_t spp : {1u, 2u, 3u, 4u, 8u, 16u, 32u}) {
                ASSERT_EQ(check_pass(band, est, spp), "") << what;
                ASSERT_TRUE(render_pass(rs, est, settings(W, H, spp, 1), band)) << what;
            }
            expect_same_image(band_image(band), one_shot, what);
        }
}

// An image cut into bands, each rendered on its own in passes (as the page's workers do) and
// merged, equals one worker's image; so does a stratified image rendered in one pass per band.
TEST(ProgressiveRender, MergedBandsEqualOneWorkersImage) {
    auto r = request("cornell_box");
    ASSERT_TRUE(r);
    RenderScene rs;
    rs.build(*r->scene, r->accel);
    const int W = 19, H = 14;
    for (PixelSamplerKind kind : {PixelSamplerKind::PaddedSobol, PixelSamplerKind::Stratified}) {
        const RenderEstimator est = estimator(RadianceStrategy::Path, kind);
        const uint64_t spp = 16;
        const RenderImage one_worker = render_image(rs, est, settings(W, H, spp, 1));
        std::vector<ImageBand> bands;
        for (auto [a, b] : {std::pair{5, 9}, {0, 5}, {9, 14}})
            bands.push_back(make_band(W, H, a, b, kind));
        for (ImageBand& band : bands) {
            const std::vector<uint64_t> passes =
                sampler_extends(kind) ? std::vector<uint64_t>{4, 16} : std::vector<uint64_t>{16};
            for (uint64_t s : passes) ASSERT_TRUE(render_pass(rs, est, settings(W, H, s, 2), band));
        }
        RenderImage merged;
        std::string error;
        ASSERT_TRUE(merge_bands({&bands[0], &bands[1], &bands[2]}, &merged, &error)) << error;
        expect_same_image(merged, one_worker, pixel_sampler_name(kind));

        // Bands that leave out or repeat rows, or differ in spp, are refused with a reason.
        EXPECT_FALSE(merge_bands({&bands[0], &bands[1]}, &merged, &error));
        EXPECT_NE(error.find("row"), std::string::npos) << error;
        EXPECT_FALSE(merge_bands({&bands[0], &bands[0], &bands[1], &bands[2]}, &merged, &error));
    }
}

// What cannot be extended is refused before any work: a second pass with a sampler whose
// samples depend on the final spp, fewer spp than the image has, a band a cancelled pass tore.
TEST(ProgressiveRender, RefusesWhatCannotExtend) {
    auto r = request("quad_light_floor");
    ASSERT_TRUE(r);
    RenderScene rs;
    rs.build(*r->scene, r->accel);
    for (PixelSamplerKind kind : {PixelSamplerKind::Stratified, PixelSamplerKind::Sobol}) {
        const RenderEstimator est = estimator(RadianceStrategy::MisPower, kind);
        ImageBand band = make_band(8, 6, 0, 6, kind);
        EXPECT_EQ(check_pass(band, est, 4), "");
        ASSERT_TRUE(render_pass(rs, est, settings(8, 6, 4, 1), band));
        EXPECT_NE(check_pass(band, est, 8).find("cannot add samples"), std::string::npos)
            << pixel_sampler_name(kind);
    }
    const RenderEstimator est =
        estimator(RadianceStrategy::MisPower, PixelSamplerKind::PaddedSobol);
    ImageBand band = make_band(8, 6, 0, 6, PixelSamplerKind::PaddedSobol);
    ASSERT_TRUE(render_pass(rs, est, settings(8, 6, 4, 1), band));
    EXPECT_NE(check_pass(band, est, 2).find("already has 4 spp"), std::string::npos);
    std::atomic<bool> cancel{true};
    RenderSettings cancelled = settings(8, 6, 8, 1);
    cancelled.cancel = &cancel;
    EXPECT_FALSE(render_pass(rs, est, cancelled, band));
    EXPECT_TRUE(band.torn);
    EXPECT_NE(check_pass(band, est, 16).find("cancelled"), std::string::npos);
}

// The extending sampler keeps what a Sobol' pixel gives: on the quad light with light
// sampling (a smooth 2D integrand per pixel), its relative MSE at 256 spp, averaged over 4
// image streams, is below half the independent sampler's (stratification's gain; at 256 spp
// of a smooth integrand it is an order of magnitude, so the margin is wide).
TEST(ProgressiveRender, PaddedSobolConvergesFasterThanIndependent) {
    Scene scene = test::quad_light_scene(5.0);
    RenderScene rs;
    rs.build(scene);
    const int W = 12, H = 12;
    RenderSettings ref_settings = settings(W, H, 16384, 1);
    ref_settings.stream = 99;
    const RenderImage reference = render_image(
        rs, estimator(RadianceStrategy::LightArea, PixelSamplerKind::Independent), ref_settings);
    double mse[2] = {0.0, 0.0};
    int k = 0;
    for (PixelSamplerKind kind : {PixelSamplerKind::PaddedSobol, PixelSamplerKind::Independent}) {
        for (uint64_t stream = 1; stream <= 4; ++stream) {
            RenderSettings s = settings(W, H, 256, 2);
            s.stream = stream;
            const RenderImage image =
                render_image(rs, estimator(RadianceStrategy::LightArea, kind), s);
            mse[k] += image_error(image, reference).rel_mse_raw / 4.0;
        }
        ++k;
    }
    EXPECT_LT(mse[0], 0.5 * mse[1]) << "padded_sobol " << mse[0] << ", independent " << mse[1];
}

} // namespace
} // namespace mcp
