// Adaptive allocation of an image's samples over its pixels (adaptive.h): a pixel's count never
// depends on its own samples, the counts are nets within the budget, the images stay unbiased,
// the error falls where it is uneven over the image, and the render API's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "core/rng.h"
#include "core/special.h"
#include "render/adaptive.h"
#include "render/lights.h"
#include "render_api/mcplay_render.h"
#include "render_scenes.h"
#include "scene_files.h"
#include "test_support.h"

namespace mcp {
namespace {

using nlohmann::json;

/// A first pass of `spp` samples over a w x h image whose pixel p has mean 1 in every channel
/// and sample variance variance[p].
ImageBand first_pass(int w, int h, uint64_t spp, const std::vector<double>& variance) {
    ImageBand b = make_band(w, h, 0, h, PixelSamplerKind::PaddedSobol);
    b.spp = spp;
    for (size_t p = 0; p < b.pixel_count(); ++p) {
        b.kept[p] = spp;
        for (size_t c = 0; c < 3; ++c) {
            b.mean[3 * p + c] = 1.0;
            b.m2[3 * p + c] = variance[p] * double(spp - 1);
        }
    }
    return b;
}

std::vector<double> lognormal_variances(size_t n, uint64_t seed) {
    Pcg32 rng(seed, 1);
    std::vector<double> v(n);
    for (double& x : v) x = std::exp(2.0 * normal_quantile(0.001 + 0.998 * rng.next_double()));
    return v;
}

// A pixel's count comes from the other colour of the checkerboard alone: making one pixel's
// own first pass far noisier (and brighter) changes no count of its colour, its own included,
// and raises counts of its neighbours (the check can see a change).
TEST(RenderAdaptive, CountsLeaveOutThePixelsOwnSamples) {
    const int W = 12, H = 10;
    const uint64_t spp = 16;
    std::vector<double> variance = lognormal_variances(size_t(W * H), 7);
    ImageBand band = first_pass(W, H, spp / 2, variance);
    double gain = 0.0;
    const std::vector<uint32_t> before =
        allocate_pixel_samples(band, spp, PixelSamplerKind::PaddedSobol, &gain);
    EXPECT_GT(gain, kAdaptiveMinGain); // the counts do differ
    const int x0 = 5, y0 = 4;
    const size_t p0 = size_t(y0 * W + x0);
    for (size_t c = 0; c < 3; ++c) {
        band.m2[3 * p0 + c] *= 1e4;
        band.mean[3 * p0 + c] = 3.0;
    }
    const std::vector<uint32_t> after =
        allocate_pixel_samples(band, spp, PixelSamplerKind::PaddedSobol, &gain);
    int changed_other = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const size_t p = size_t(y * W + x);
            if (((x + y) & 1) == ((x0 + y0) & 1))
                EXPECT_EQ(after[p], before[p]) << x << "," << y;
            else if (after[p] != before[p])
                ++changed_other;
        }
    EXPECT_GT(changed_other, 0);
    EXPECT_GT(after[p0 + 1], before[p0 + 1]); // its right neighbour now sees its noise
}

// The counts: the first pass's times a power of two, at most kAdaptiveMaxFactor x spp, each
// colour's sum within its budget and not far below it; under independent samples (the
// steeper Neyman rule) they spread wider than under the padded Sobol' sampler.
TEST(RenderAdaptive, CountsAreNetsWithinTheBudget) {
    const int W = 33, H = 17;
    const uint64_t spp = 32, first = spp / 2;
    const ImageBand band = first_pass(W, H, first, lognormal_variances(size_t(W * H), 11));
    double gain_qmc = 0.0, gain_mc = 0.0;
    const auto qmc = allocate_pixel_samples(band, spp, PixelSamplerKind::PaddedSobol, &gain_qmc);
    const auto mc = allocate_pixel_samples(band, spp, PixelSamplerKind::Independent, &gain_mc);
    for (const auto* counts : {&qmc, &mc}) {
        uint64_t sum[2] = {0, 0}, members[2] = {0, 0};
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const uint32_t n = (*counts)[size_t(y * W + x)];
                ASSERT_GE(n, first);
                ASSERT_LE(n, spp * kAdaptiveMaxFactor);
                ASSERT_EQ(n % first, 0u);
                const uint32_t ratio = n / uint32_t(first);
                EXPECT_EQ(ratio & (ratio - 1), 0u) << n; // a power of two
                sum[(x + y) & 1] += n;
                ++members[(x + y) & 1];
            }
        for (int c = 0; c < 2; ++c) {
            EXPECT_LE(sum[c], spp * members[c]);
            EXPECT_GE(double(sum[c]), 0.9 * double(spp * members[c]));
        }
    }
    auto spread = [](const std::vector<uint32_t>& n) {
        return *std::max_element(n.begin(), n.end()) / *std::min_element(n.begin(), n.end());
    };
    EXPECT_GT(spread(mc), spread(qmc));
    EXPECT_GT(gain_mc, gain_qmc);
}

// Pixels whose first passes look alike keep the image's spp (the predicted gain is 1).
TEST(RenderAdaptive, AlikePixelsKeepTheImagesSpp) {
    const int W = 9, H = 7;
    const ImageBand band = first_pass(W, H, 8, std::vector<double>(size_t(W * H), 0.3));
    double gain = 0.0;
    for (uint32_t n : allocate_pixel_samples(band, 16, PixelSamplerKind::Independent, &gain))
        EXPECT_EQ(n, 16u);
    EXPECT_NEAR(gain, 1.0, 1e-12);
}

RenderSettings centre_rays(int w, int h, uint64_t spp, uint64_t stream) {
    RenderSettings s = test::render_settings(w, h, spp, stream, 2);
    s.jitter_pixels = false; // each pixel's expectation is the closed form at its centre
    return s;
}

/// The quad light scene (a 4 x 4 m floor of albedo 0.5, a 1 x 1 m light of radiance 5 at
/// height 1 facing down) seen at a slant from below the light: floor near the light and far
/// from it, the light itself, and sky.
Scene slanted_quad_light() {
    Scene scene = test::quad_light_scene(5.0);
    scene.camera = test::look_at({0, 0.6, 3}, {0, 0.2, 0}, {0, 1, 0}, 1.0);
    return scene;
}

/// What pixel (x, y)'s centre ray sees: the light's radiance, Lambert's closed form on the
/// floor [lambert_polygon_form_factor], or nothing.
double centre_radiance(const Scene& scene, int w, int h, int x, int y) {
    const Vec3 light[4] = {{-0.5, 1, -0.5}, {0.5, 1, -0.5}, {0.5, 1, 0.5}, {-0.5, 1, 0.5}};
    const Ray r = camera_ray(scene.camera, w, h, x + 0.5, y + 0.5);
    if (r.direction.y > 0.0) {
        const Vec3 p = r.origin + r.direction * ((1.0 - r.origin.y) / r.direction.y);
        return std::fabs(p.x) <= 0.5 && std::fabs(p.z) <= 0.5 ? 5.0 : 0.0;
    }
    const Vec3 p = r.origin + r.direction * (-r.origin.y / r.direction.y);
    if (std::fabs(p.x) > 2.0 || std::fabs(p.z) > 2.0) return 0.0;
    return 0.5 * 5.0 * lambert_polygon_form_factor(p, Vec3(0, 1, 0), light, 4);
}

RenderEstimator adaptive(RadianceStrategy s, PixelSamplerKind sampler) {
    RenderEstimator e;
    e.strategy = s;
    e.name = strategy_name(s);
    e.pixel_sampler = sampler;
    e.pixel_allocation = PixelAllocation::Adaptive;
    return e;
}

// Every pixel of adaptive images within its error bar of the closed form (Sidak level 1e-3
// over all pixels and estimators), with counts that differ; against the floor 20% too bright
// many pixels fail.
TEST(RenderAdaptive, UnbiasedUnderTheQuadLight) {
    const Scene scene = slanted_quad_light();
    RenderScene rs;
    rs.build(scene);
    const int W = 16, H = 12;
    const std::pair<RadianceStrategy, PixelSamplerKind> cases[] = {
        {RadianceStrategy::LightSolidAngle, PixelSamplerKind::Independent},
        {RadianceStrategy::LightArea, PixelSamplerKind::PaddedSobol},
        {RadianceStrategy::MisPower, PixelSamplerKind::PaddedSobol}};
    const double z_max =
        -normal_quantile(0.5 * test::sidak_level(1e-3, W * H * int(std::size(cases))));
    for (const auto& [strategy, sampler] : cases) {
        RenderImage im = render_image(rs, adaptive(strategy, sampler), centre_rays(W, H, 256, 5));
        ASSERT_TRUE(im.allocation.adaptive);
        EXPECT_GT(im.allocation.max_spp, im.allocation.min_spp) << strategy_name(strategy);
        int off = 0, off_bright = 0, floor = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const double expected = centre_radiance(scene, W, H, x, y);
                const size_t k = size_t(y * W + x) * 3;
                const double bar = z_max * std::sqrt(im.variance[k]) + 1e-12;
                off += std::fabs(im.rgb[k] - expected) > bar;
                if (expected > 0.0 && expected < 5.0) {
                    ++floor;
                    off_bright += std::fabs(im.rgb[k] - 1.2 * expected) > bar;
                }
            }
        EXPECT_EQ(off, 0) << strategy_name(strategy);
        EXPECT_GT(off_bright, floor / 2) << strategy_name(strategy);
    }
}

// Area sampling of the light: a floor pixel's relative variance depends on where it lies (the
// 1 / r^2 and the cosines vary most close under the light), and the sky's and the light's own
// pixels have none. Spreading the samples by
// it lowers the relative MSE against the closed form (eps = 1e-2 mean^2, summed over 4 images
// of each, independent samples) below 3/4 of the same spp everywhere, with as many samples
// (within the rounding to nets).
TEST(RenderAdaptive, LowersTheErrorWhereItIsUneven) {
    const Scene scene = slanted_quad_light();
    RenderScene rs;
    rs.build(scene);
    const int W = 32, H = 24;
    std::vector<double> expected;
    double mean = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            expected.push_back(centre_radiance(scene, W, H, x, y));
            mean += expected.back() / (W * H);
        }
    RenderEstimator uniform = adaptive(RadianceStrategy::LightArea, PixelSamplerKind::Independent);
    uniform.pixel_allocation = PixelAllocation::Uniform;
    RenderEstimator spread = adaptive(RadianceStrategy::LightArea, PixelSamplerKind::Independent);
    double error[2] = {0.0, 0.0};
    uint64_t samples[2] = {0, 0};
    for (uint64_t stream = 1; stream <= 4; ++stream) {
        int e = 0;
        for (const RenderEstimator* est : {&uniform, &spread}) {
            RenderImage im = render_image(rs, *est, centre_rays(W, H, 32, stream));
            samples[e] += im.diagnostics.samples;
            for (size_t p = 0; p < expected.size(); ++p) {
                const double d = im.rgb[3 * p] - expected[p];
                error[e] += d * d / (expected[p] * expected[p] + 1e-2 * mean * mean);
            }
            ++e;
        }
    }
    EXPECT_LT(error[1], 0.75 * error[0]) << error[0] << " " << error[1];
    EXPECT_LE(samples[1], samples[0]);
    EXPECT_GE(double(samples[1]), 0.9 * double(samples[0]));
}

// The progress an adaptive image reports runs once over the rows (two passes inside), never
// back; returning false from it cancels the image.
TEST(RenderAdaptive, ProgressRunsOnceOverTheRows) {
    const Scene scene = slanted_quad_light();
    RenderScene rs;
    rs.build(scene);
    RenderSettings st = centre_rays(16, 12, 16, 3);
    std::vector<int> seen;
    st.progress = [&](int done, int rows) {
        EXPECT_EQ(rows, 12);
        seen.push_back(done);
        return true;
    };
    const RenderEstimator e = adaptive(RadianceStrategy::LightArea, PixelSamplerKind::Independent);
    RenderImage im = render_image(rs, e, st);
    EXPECT_FALSE(im.cancelled);
    ASSERT_FALSE(seen.empty());
    for (size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
    EXPECT_LE(seen.back(), 12);
    EXPECT_GT(seen.back(), 6); // the second pass reported too
    st.progress = [](int done, int) { return done < 3; };
    EXPECT_TRUE(render_image(rs, e, st).cancelled);
}

// The render API: 'adaptive' with a sampler that cannot add samples to a pixel is an error
// naming the samplers that can, as is 'adaptive' in the live view; an image reports its counts.
TEST(RenderAdaptive, RenderApi) {
    const std::string text = test::read(test::kScenes + "/quad_light_floor.json");
    auto render = [&](const json& estimator, json* result) {
        json options{
            {"base_dir", test::kScenes}, {"width", 16},           {"height", 12}, {"spp", 16},
            {"outputs", json::array()},  {"estimator", estimator}};
        char* out = nullptr;
        const int st = mcp_render_image(text.c_str(), options.dump().c_str(), &out);
        if (out) *result = json::parse(out);
        mcp_free(out);
        return st;
    };
    json result;
    ASSERT_NE(
        render({{"strategy", "bsdf"}, {"pixel_sampler", "sobol"}, {"pixel_allocation", "adaptive"}},
               &result),
        MCP_OK);
    EXPECT_NE(std::string(mcp_last_error()).find("padded_sobol"), std::string::npos)
        << mcp_last_error();
    ASSERT_NE(render({{"strategy", "bsdf"}, {"pixel_allocation", "everywhere"}}, &result), MCP_OK);
    EXPECT_NE(std::string(mcp_last_error()).find("pixel_allocation"), std::string::npos);
    ASSERT_EQ(render({{"strategy", "bsdf"},
                      {"pixel_sampler", "independent"},
                      {"pixel_allocation", "adaptive"}},
                     &result),
              MCP_OK)
        << mcp_last_error();
    EXPECT_EQ(result["estimator"]["pixel_allocation"], "adaptive");
    const json& a = result["pixel_allocation"];
    EXPECT_EQ(a["adaptive"], true);
    EXPECT_EQ(a["first_pass_spp"], 8);
    EXPECT_GE(a["min_spp"].get<int>(), 8);
    EXPECT_GE(a["max_spp"].get<int>(), a["min_spp"].get<int>());
    EXPECT_TRUE(a["predicted_gain"].is_number());
    EXPECT_LE(result["diagnostics"]["samples"].get<int>(), 16 * 12 * 16);

    json scene = json::parse(text);
    json options{{"base_dir", test::kScenes},
                 {"estimators", json::array({json{{"strategy", "bsdf"},
                                                  {"pixel_sampler", "padded_sobol"},
                                                  {"pixel_allocation", "adaptive"}}})}};
    char* out = nullptr;
    EXPECT_NE(
        mcp_render_live_open(scene.dump().c_str(), options.dump().c_str(), nullptr, nullptr, &out),
        MCP_OK);
    mcp_free(out);
    EXPECT_NE(std::string(mcp_last_error()).find("live view"), std::string::npos)
        << mcp_last_error();
}

} // namespace
} // namespace mcp
