// The live view's C API (mcp_render_live_*): sessions over bands of rows merge into the whole
// image's pixels and relative MSE, the image size follows the camera's aspect, references are
// taken when given, and every bad request gets one line naming what is wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render_api/image_io.h" // base64_decode, base64_encode
#include "render_api/mcplay_render.h"
#include "scene_files.h"

namespace mcp {
namespace {

using nlohmann::json;

struct Call {
    int status = MCP_OK;
    std::string error;
    json result;
};

Call finish(int status, char* out) {
    Call c;
    c.status = status;
    c.error = status == MCP_OK ? "" : mcp_last_error();
    if (out) c.result = json::parse(out);
    mcp_free(out);
    return c;
}

Call open_live(const json& scene, json options) {
    options["base_dir"] = test::kScenes;
    char* out = nullptr;
    const int st =
        mcp_render_live_open(scene.dump().c_str(), options.dump().c_str(), nullptr, nullptr, &out);
    return finish(st, out);
}

Call pass(int session, const json& request) {
    char* out = nullptr;
    const int st = mcp_render_live_pass(session, request.dump().c_str(), nullptr, nullptr, &out);
    return finish(st, out);
}

std::vector<float> floats(const json& base64) {
    std::string bytes;
    EXPECT_TRUE(base64_decode(base64.get<std::string>(), &bytes));
    std::vector<float> v(bytes.size() / sizeof(float));
    std::memcpy(v.data(), bytes.data(), v.size() * sizeof(float));
    return v;
}

/// The live reference of a scene at a size, as the page renders one for a size no site ships.
std::string live_reference(const json& scene, int width, int height) {
    json options{{"base_dir", test::kScenes}, {"live", true}, {"width", width}, {"height", height}};
    char* out = nullptr;
    const int st =
        mcp_render_reference(scene.dump().c_str(), options.dump().c_str(), nullptr, nullptr, &out);
    Call c = finish(st, out);
    EXPECT_EQ(c.error, "");
    return c.result.value("reference_data", "");
}

// Two sessions over two bands of rows, and one over every row: after each pass the bands'
// pixels side by side are the whole image's, bit for bit, and their error sums add up to the
// whole image's relative MSE; the relative MSE falls as passes add samples.
// The base64 codec the live view's pixels and references travel in: RFC 4648's test vectors
// (section 10), every byte value at every length modulo 3, and what is not padded base64 refused.
TEST(LiveApi, Base64RoundTripsAndRefusesWhatIsNotBase64) {
    const char* vectors[][2] = {{"", ""},
                                {"f", "Zg=="},
                                {"fo", "Zm8="},
                                {"foo", "Zm9v"},
                                {"foob", "Zm9vYg=="},
                                {"fooba", "Zm9vYmE="},
                                {"foobar", "Zm9vYmFy"}};
    for (const auto& v : vectors) {
        EXPECT_EQ(base64_encode(v[0]), v[1]);
        std::string back = "untouched";
        EXPECT_TRUE(base64_decode(v[1], &back)) << v[1];
        EXPECT_EQ(back, v[0]);
    }
    std::string all;
    for (int c = 0; c < 256; ++c) all += char(c);
    for (size_t n = 250; n <= 256; ++n) {
        const std::string bytes = all.substr(256 - n) + all.substr(0, n / 2);
        std::string back;
        ASSERT_TRUE(base64_decode(base64_encode(bytes), &back)) << n;
        EXPECT_EQ(back, bytes) << n;
    }
    for (const char* bad : {"Zg=", "Zg", "Z===", "====", "Zm9v=Zg=", "Zm9vYg=a", "Zm 9", "Zm9\x80",
                            "Zm-v", "Zm_v", "=Zm9"}) {
        std::string out = "untouched";
        EXPECT_FALSE(base64_decode(bad, &out)) << bad;
        EXPECT_EQ(out, "untouched") << bad;
    }
}

TEST(LiveApi, BandsMergeIntoTheWholeImage) {
    const json scene = test::scene_json("quad_light_floor");
    const json base{{"estimators", {"light_area", "bsdf"}},
                    {"long_side", 24},
                    {"pixels", true},
                    {"live_reference", "available"}};
    Call whole = open_live(scene, base);
    ASSERT_EQ(whole.error, "");
    const int width = whole.result["width"], height = whole.result["height"];
    EXPECT_EQ(width, 24); // quad_light_floor is 48 x 48: square
    EXPECT_EQ(height, 24);
    EXPECT_TRUE(whole.result["reference"].is_null()); // none rendered: "available" only
    EXPECT_EQ(whole.result["pixel_sampler"], "padded_sobol");
    const std::string ref = live_reference(scene, width, height);
    ASSERT_FALSE(ref.empty());
    json options = base;
    options["reference_data"] = ref;
    whole = open_live(scene, options);
    ASSERT_EQ(whole.error, "");
    EXPECT_EQ(whole.result["reference"]["source"], "supplied");
    options["rows"] = {0, 7};
    Call top = open_live(scene, options);
    options["rows"] = {7, height};
    Call bottom = open_live(scene, options);
    ASSERT_EQ(top.error, "");
    ASSERT_EQ(bottom.error, "");
    // The bands' reference pixels are the whole reference's rows.
    std::vector<float> ref_rows = floats(top.result["reference"]["rgb_f32"]);
    const std::vector<float> ref_bottom = floats(bottom.result["reference"]["rgb_f32"]);
    ref_rows.insert(ref_rows.end(), ref_bottom.begin(), ref_bottom.end());
    EXPECT_EQ(ref_rows, floats(whole.result["reference"]["rgb_f32"]));

    const int ids[3] = {whole.result["session"], top.result["session"], bottom.result["session"]};
    for (int estimator = 0; estimator < 2; ++estimator) {
        double first_rel_mse = NAN, last_rel_mse = NAN;
        for (int spp : {1, 2, 4, 8, 16, 64}) {
            const json request{{"estimator", estimator}, {"spp", spp}};
            Call w = pass(ids[0], request), a = pass(ids[1], request), b = pass(ids[2], request);
            ASSERT_EQ(w.error + a.error + b.error, "");
            EXPECT_EQ(w.result["spp"], spp);
            std::vector<float> merged = floats(a.result["rgb_f32"]);
            const std::vector<float> rest = floats(b.result["rgb_f32"]);
            merged.insert(merged.end(), rest.begin(), rest.end());
            EXPECT_EQ(merged, floats(w.result["rgb_f32"]))
                << "estimator " << estimator << ", spp " << spp;
            const json &ew = w.result["error"], &ea = a.result["error"], &eb = b.result["error"];
            EXPECT_EQ(ea["terms"].get<uint64_t>() + eb["terms"].get<uint64_t>(),
                      ew["terms"].get<uint64_t>());
            const double whole_rel = ew["sum"].get<double>() / ew["terms"].get<double>();
            const double bands_rel =
                (ea["sum"].get<double>() + eb["sum"].get<double>()) / ew["terms"].get<double>();
            EXPECT_NEAR(bands_rel, whole_rel, 1e-12 * std::fabs(whole_rel));
            if (spp == 1) first_rel_mse = whole_rel;
            last_rel_mse = whole_rel;
        }
        // 64 times the samples: an unbiased estimator's relative MSE falls about 64-fold (more
        // with the Sobol' points); a fall of 8 leaves room for the 1-spp image's own noise.
        EXPECT_LT(last_rel_mse, first_rel_mse / 8) << "estimator " << estimator;
    }
    for (int id : ids) EXPECT_EQ(mcp_render_live_close(id), MCP_OK);
    EXPECT_NE(mcp_render_live_close(ids[0]), MCP_OK); // closed already
    EXPECT_NE(std::string(mcp_last_error()).find("no open session"), std::string::npos);
}

// A reference given after the session opened (the page renders one in the background) is
// taken when it was made for the session's size, and refused when not.
TEST(LiveApi, TakesAReferenceGivenLater) {
    const json scene = test::scene_json("quad_light_floor");
    Call c = open_live(scene, {{"long_side", 16}, {"live_reference", "available"}});
    ASSERT_EQ(c.error, "");
    const int id = c.result["session"];
    Call p = pass(id, {{"estimator", 0}, {"spp", 2}});
    ASSERT_EQ(p.error, "");
    EXPECT_TRUE(p.result["error"].is_null());
    char* out = nullptr;
    const std::string wrong = live_reference(scene, 16, 8);
    int st = mcp_render_live_reference(id, json{{"reference_data", wrong}}.dump().c_str(), &out);
    Call r = finish(st, out);
    EXPECT_NE(r.status, MCP_OK);
    EXPECT_NE(r.error.find("another scene, image size"), std::string::npos) << r.error;
    const std::string right = live_reference(scene, 16, 16);
    st = mcp_render_live_reference(id, json{{"reference_data", right}}.dump().c_str(), &out);
    r = finish(st, out);
    ASSERT_EQ(r.error, "");
    EXPECT_EQ(r.result["source"], "supplied");
    EXPECT_GT(r.result["mean_luminance"].get<double>(), 0.0);
    p = pass(id, {{"estimator", 0}, {"spp", 4}});
    ASSERT_EQ(p.error, "");
    EXPECT_EQ(p.result["error"]["terms"], 16 * 16 * 3);
    EXPECT_TRUE(std::isfinite(p.result["error"]["sum"].get<double>()));
    EXPECT_EQ(mcp_render_live_close(id), MCP_OK);
}

// The image's shape: the glTF camera's aspectRatio when it has one, else the scene's width /
// height; beyond 8:1 either way, refused with the reason. The scene info reports the default.
TEST(LiveApi, SizeFollowsTheCameraAspect) {
    json scene = test::scene_json("veach_mis");
    Call c = open_live(scene, {{"live_reference", "available"}});
    ASSERT_EQ(c.error, "");
    EXPECT_EQ(c.result["width"], 256); // the scene's 64 x 48
    EXPECT_EQ(c.result["height"], 192);
    mcp_render_live_close(c.result["session"]);
    json gltf = json::parse(test::read(test::kScenes + "/veach_mis.gltf"));
    ASSERT_TRUE(gltf.contains("cameras"));
    gltf["cameras"][0]["perspective"]["aspectRatio"] = 16.0 / 9.0;
    scene["render"]["gltf"] = gltf;
    c = open_live(scene, {{"live_reference", "available"}, {"long_side", 320}});
    ASSERT_EQ(c.error, "");
    EXPECT_EQ(c.result["width"], 320);
    EXPECT_EQ(c.result["height"], 180);
    mcp_render_live_close(c.result["session"]);
    char* out = nullptr;
    json options{{"base_dir", test::kScenes}};
    int st = mcp_render_scene_info(scene.dump().c_str(), options.dump().c_str(), &out);
    Call info = finish(st, out);
    ASSERT_EQ(info.error, "");
    EXPECT_EQ(info.result["live_size"], json({{"width", 256}, {"height", 144}}));
    EXPECT_NEAR(info.result["camera"]["aspect_ratio"].get<double>(), 16.0 / 9.0, 1e-12);

    gltf["cameras"][0]["perspective"]["aspectRatio"] = 20.0;
    scene["render"]["gltf"] = gltf;
    c = open_live(scene, {{"live_reference", "available"}});
    EXPECT_NE(c.status, MCP_OK);
    EXPECT_NE(c.error.find("beyond the live view's 8:1"), std::string::npos) << c.error;
    st = mcp_render_scene_info(scene.dump().c_str(), options.dump().c_str(), &out);
    info = finish(st, out);
    EXPECT_NE(info.result["live_size"]["error"].get<std::string>().find("8:1"), std::string::npos);
}

// Bad requests: one line each, naming what is wrong; the session stays usable after a refused
// pass.
TEST(LiveApi, RefusesBadRequestsWithAReason) {
    const json scene = test::scene_json("quad_light_floor");
    const json base{{"long_side", 16}, {"live_reference", "available"}};
    auto open_error = [&](json extra) {
        json o = base;
        for (auto it = extra.begin(); it != extra.end(); ++it) o[it.key()] = it.value();
        Call c = open_live(scene, o);
        EXPECT_NE(c.status, MCP_OK) << extra.dump();
        return c.error;
    };
    EXPECT_NE(open_error({{"pixel_sampler", "stratified"}}).find("cannot"), std::string::npos);
    EXPECT_NE(open_error({{"pixel_sampler", "sobol"}}).find("padded_sobol"), std::string::npos);
    EXPECT_NE(open_error({{"long_side", 5000}}).find("options.long_side"), std::string::npos);
    EXPECT_NE(open_error({{"long_side", 8}}).find("16..4096"), std::string::npos);
    EXPECT_NE(open_error({{"width", 20}}).find("options.long_side"), std::string::npos);
    EXPECT_NE(open_error({{"rows", {5, 3}}}).find("options.rows"), std::string::npos);
    EXPECT_NE(open_error({{"rows", {0, 17}}}).find("options.rows"), std::string::npos);
    EXPECT_NE(open_error({{"live_reference", "maybe"}}).find("live_reference"), std::string::npos);
    EXPECT_NE(open_error({{"live", false}}).find("options.live"), std::string::npos);
    const json resampled{{"strategy", "path"}, {"candidates", "auto"}};
    EXPECT_NE(open_error({{"estimators", {resampled}}}).find("candidates \"auto\""),
              std::string::npos);
    json fixed = resampled;
    fixed["candidates"] = 4;
    json with_fixed = base;
    with_fixed["estimators"] = json::array({fixed});
    EXPECT_EQ(open_live(scene, with_fixed).error, ""); // a fixed count: no pilot per band
    EXPECT_NE(
        open_error({{"estimators", {"bsdf", "bsdf", "bsdf", "bsdf", "bsdf"}}}).find("at most 4"),
        std::string::npos);
    EXPECT_NE(open_error({{"long_side", 4096},
                          {"estimators", {"bsdf", "light_area", "mis_power", "mis_balance"}}})
                  .find("MiB"),
              std::string::npos);

    Call c = open_live(scene, base);
    ASSERT_EQ(c.error, "");
    const int id = c.result["session"];
    ASSERT_EQ(pass(id, {{"estimator", 0}, {"spp", 4}}).error, "");
    EXPECT_NE(pass(id, {{"estimator", 0}, {"spp", 2}}).error.find("already has 4 spp"),
              std::string::npos);
    EXPECT_NE(pass(id, {{"estimator", 9}, {"spp", 8}}).error.find("pass.estimator"),
              std::string::npos);
    EXPECT_NE(pass(id, {{"estimator", 0}, {"spp", 0}}).error.find("pass.spp"), std::string::npos);
    EXPECT_NE(pass(id, {{"estimator", 0}, {"spp", 1 << 21}}).error.find("pass.spp"),
              std::string::npos);
    EXPECT_NE(pass(id, {{"estimator", 0}}).error.find("pass.spp"), std::string::npos);
    EXPECT_NE(pass(id, {{"estimator", 0}, {"spp", 8}, {"outputs", {"exr"}}}).error.find("exr"),
              std::string::npos);
    EXPECT_NE(pass(id, {{"estimator", 0}, {"spp", 8}, {"colour", 1}}).error.find("pass"),
              std::string::npos);
    EXPECT_NE(pass(id + 1000, {{"estimator", 0}, {"spp", 8}}).error.find("no open session"),
              std::string::npos);
    char* out = nullptr;
    EXPECT_NE(mcp_render_live_pass(id, "{not json", nullptr, nullptr, &out), MCP_OK);
    EXPECT_EQ(out, nullptr);
    // Still usable: the refused passes changed nothing.
    Call p = pass(id, {{"estimator", 0}, {"spp", 8}, {"outputs", {"png", "hdr"}}});
    ASSERT_EQ(p.error, "");
    EXPECT_EQ(p.result["spp"], 8);
    EXPECT_TRUE(p.result["images"].contains("png"));
    EXPECT_TRUE(p.result["images"].contains("hdr"));
    EXPECT_EQ(mcp_render_live_close(id), MCP_OK);
}

// Issue 48: the live view validates its estimators as a study does (the CLI's --estimators
// refuses a name given twice, and so does the API under the page): each name once is taken.
TEST(LiveApi, AnEstimatorNamedTwiceIsRefused) {
    const json scene = test::scene_json("quad_light_floor");
    const json base{{"long_side", 16}, {"live_reference", "available"}};
    json twice = base;
    twice["estimators"] = {"bsdf", "light_area", "bsdf"};
    Call c = open_live(scene, twice);
    EXPECT_EQ(c.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(c.error.find("options.estimators[2]: 'bsdf' is named twice"), std::string::npos)
        << c.error;
    json once = base;
    once["estimators"] = {"bsdf", "light_area"};
    c = open_live(scene, once);
    ASSERT_EQ(c.error, "");
    EXPECT_EQ(c.result["estimators"].size(), 2u);
    mcp_render_live_close(c.result["session"]);
    // A study's options likewise.
    char* out = nullptr;
    json study{{"base_dir", test::kScenes}, {"estimators", {"mis_power", "mis_power"}}};
    EXPECT_EQ(mcp_render_study_plan(scene.dump().c_str(), study.dump().c_str(), &out),
              MCP_ERROR_ARGUMENT);
    EXPECT_NE(std::string(mcp_last_error()).find("'mis_power' is named twice"), std::string::npos)
        << mcp_last_error();
    mcp_free(out);
}

// Issue 48: the memory a session needs counts its rows. The whole 4096 x 4096 image with one
// estimator is beyond the limit (its message names the rows); 64 of its rows are not (the
// estimate counted every row of the pass image and refused them too).
TEST(LiveApi, MemoryEstimateCountsTheRows) {
    const json scene = test::scene_json("quad_light_floor");
    json options{{"long_side", 4096}, {"estimators", {"bsdf"}}, {"live_reference", "available"}};
    Call whole = open_live(scene, options);
    EXPECT_EQ(whole.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(whole.error.find("rows [0, 4096) of a 4096x4096 image"), std::string::npos)
        << whole.error;
    options["rows"] = {0, 64};
    Call band = open_live(scene, options);
    ASSERT_EQ(band.error, "");
    EXPECT_EQ(band.result["width"], 4096);
    mcp_render_live_close(band.result["session"]);
}

} // namespace
} // namespace mcp
