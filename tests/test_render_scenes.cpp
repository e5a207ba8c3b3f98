// The render scenes in scenes/ through the render API: they load, stiff scenes give finite
// pixels, the diagnostics flag infinite variance where theory says it is, MIS is never worse
// than the worse of its parts, and bad render scene files get clear errors.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include "render/render_study.h"
#include "render/renderer.h"
#include "render_api/image_io.h"
#include "render_api/mcplay_render.h"
#include "render_api/render_request.h"
#include "scene_files.h"

namespace mcp {
namespace {

using nlohmann::json;

using test::kScenes;
using test::read;
using test::scene_json;

std::shared_ptr<RenderRequest> request(const std::string& name, json options = json::object()) {
    options["base_dir"] = kScenes;
    Made<std::shared_ptr<RenderRequest>> r = build_render_request(scene_json(name), options);
    EXPECT_TRUE(r.ok()) << name << ": " << r.error;
    return r.value;
}

json study(const std::string& name, json options) {
    options["base_dir"] = kScenes;
    char* out = nullptr;
    std::string scene = read(kScenes + "/" + name + ".json");
    int st = mcp_render_study_run(scene.c_str(), options.dump().c_str(), nullptr, nullptr, &out);
    EXPECT_EQ(st, MCP_OK) << mcp_last_error();
    json j = out ? json::parse(out) : json();
    mcp_free(out);
    return j;
}

bool has_code(const json& warnings, const std::string& code) {
    for (const json& w : warnings)
        if (w["code"] == code) return true;
    return false;
}

bool has_warning(const json& estimator, const std::string& code) {
    return has_code(estimator["warnings"], code);
}

const json& find_estimator(const json& result, const std::string& name) {
    for (const json& e : result["estimators"])
        if (e["name"] == name) return e;
    static const json none;
    ADD_FAILURE() << "no estimator " << name;
    return none;
}

const char* const kRenderScenes[] = {
    "quad_light_floor",     "cornell_box", "cornell_box_path", "veach_mis",
    "tiny_bright_light",    "near_mirror", "grazing_light",    "touching_light",
    "perpendicular_plates", "furnace_box", "sphere_interior",  "many_lights",
    "occluded_light",
};

TEST(RenderScenes, AllLoad) {
    for (const char* name : kRenderScenes) {
        std::string text = read(kScenes + "/" + name + ".json");
        json options{{"base_dir", kScenes}};
        char* info = nullptr;
        ASSERT_EQ(mcp_render_scene_info(text.c_str(), options.dump().c_str(), &info), MCP_OK)
            << name << ": " << mcp_last_error();
        json j = json::parse(info);
        mcp_free(info);
        EXPECT_GT(j["triangles"].get<int>(), 0) << name;
        EXPECT_GT(j["lights"].get<int>(), 0) << name;
        EXPECT_TRUE(j["warnings"].empty()) << name << ": " << j["warnings"].dump();
    }
}

// Stiff scenes: every estimator gives finite pixels, and any sample it had to drop is counted.
// The integrator compiled for a scene's surfaces (Lambertian, untextured) against the general
// one, on every render scene and estimator: with the same random numbers the images are the
// same bit for bit (it leaves out only arithmetic whose result it knows), and with independent
// numbers their means agree within 5 standard errors, per channel.
TEST(RenderScenes, SpecialisedIntegratorsAgreeWithTheGeneralOne) {
    int specialised = 0;
    for (const char* name : kRenderScenes) {
        std::shared_ptr<RenderRequest> r = request(name);
        ASSERT_TRUE(r);
        RenderScene rs;
        rs.build(*r->scene, r->accel);
        const SurfaceKernel kernel = surface_kernel(*r->scene);
        specialised += kernel != SurfaceKernel::GeneralTextured;
        for (const RenderEstimator& e : r->estimators) {
            RenderSettings st;
            st.width = 24;
            st.height = 16;
            st.spp = 16;
            st.stream = 11;
            RenderImage fast = render_image(rs, e, st);
            st.specialize = false;
            RenderImage general = render_image(rs, e, st);
            ASSERT_EQ(fast.rgb, general.rgb) << name << " " << e.name;
            EXPECT_EQ(fast.diagnostics.rays, general.diagnostics.rays) << name << " " << e.name;
            st.stream = 12;
            general = render_image(rs, e, st);
            for (int c = 0; c < 3; ++c) {
                double sum_fast = 0.0, sum_general = 0.0, var_sum = 0.0;
                for (size_t i = size_t(c); i < fast.rgb.size(); i += 3) {
                    sum_fast += fast.rgb[i];
                    sum_general += general.rgb[i];
                    var_sum += fast.variance[i] + general.variance[i];
                }
                EXPECT_LE(std::fabs(sum_fast - sum_general), 5.0 * std::sqrt(var_sum) + 1e-12)
                    << name << " " << e.name << " channel " << c;
            }
        }
    }
    EXPECT_GE(specialised, 8); // most bundled scenes are Lambertian and untextured
    // Which kernel a scene gets is reported, and follows its materials.
    std::string text = read(kScenes + "/veach_mis.json");
    json options{{"base_dir", kScenes}};
    char* info = nullptr;
    ASSERT_EQ(mcp_render_scene_info(text.c_str(), options.dump().c_str(), &info), MCP_OK);
    EXPECT_EQ(json::parse(info)["surface_kernel"], "gltf");
    mcp_free(info);
    text = read(kScenes + "/cornell_box.json");
    ASSERT_EQ(mcp_render_scene_info(text.c_str(), options.dump().c_str(), &info), MCP_OK);
    EXPECT_EQ(json::parse(info)["surface_kernel"], "lambertian");
    mcp_free(info);
}

TEST(RenderScenes, StiffScenesGiveFinitePixels) {
    for (const char* name : {"tiny_bright_light", "near_mirror", "grazing_light", "touching_light",
                             "perpendicular_plates"}) {
        auto r = request(name, json{{"width", 16}, {"height", 16}});
        ASSERT_TRUE(r);
        RenderScene rs;
        rs.build(*r->scene, r->accel);
        for (const RenderEstimator& e : r->estimators) {
            RenderSettings st;
            st.width = st.height = 16;
            st.spp = 16;
            st.stream = 99;
            RenderImage im = render_image(rs, e, st);
            for (double v : im.rgb) ASSERT_TRUE(std::isfinite(v)) << name << " " << e.name;
            EXPECT_EQ(im.diagnostics.samples, 16u * 16u * 16u);
            EXPECT_EQ(im.diagnostics.discarded_nonfinite, 0u) << name << " " << e.name;
        }
    }
}

// Two perpendicular squares sharing an edge: sampling the emitter by area gives weights
// ~ 1/r^2 near the shared edge, a tail index about 1.5 < 2 (infinite variance); solid-angle
// sampling bounds the weights. The study must say so.
TEST(RenderScenes, PerpendicularPlatesFlagInfiniteVarianceOfAreaSampling) {
    json r = study("perpendicular_plates", json{{"width", 24},
                                                {"height", 24},
                                                {"spp_min", 4},
                                                {"spp_max", 64},
                                                {"reps", 4},
                                                {"estimators", {"light_area", "light_solid_angle"}},
                                                {"reference", {{"spp", 1024}}}});
    const json& area = find_estimator(r, "light_area");
    const json& solid = find_estimator(r, "light_solid_angle");
    EXPECT_TRUE(has_warning(area, "heavy_tail")) << area["warnings"].dump();
    EXPECT_FALSE(has_warning(solid, "heavy_tail")) << solid["warnings"].dump();
    EXPECT_LT(area["levels"].back()["tail_index"].get<double>(), 2.0);
}

// Rare large pixel errors (issue 15): a light touching the lit wall makes light sampling's
// pixel errors ~ 1/r^2 near the contact (heavy-tailed), so a few pixels carry each level's
// relative MSE and the study says so; the quad light's error is spread over the image, with
// hundreds of effective (pixel, image) terms at every spp, and no level is flagged.
TEST(RenderScenes, RareLargePixelErrorsAreFlaggedWhereTheyOccurOnly) {
    const json touching = study("touching_light", json{{"spp_min", 1},
                                                       {"spp_max", 16},
                                                       {"reps", 4},
                                                       {"estimators", {"light_solid_angle"}},
                                                       {"reference", {{"spp", 256}}}});
    const json& solid = find_estimator(touching, "light_solid_angle");
    EXPECT_TRUE(has_warning(solid, "rare_large_errors")) << solid["warnings"].dump();
    const json quad =
        study("quad_light_floor",
              json{{"spp_min", 1}, {"spp_max", 16}, {"reps", 4}, {"reference", {{"spp", 256}}}});
    for (const json& e : quad["estimators"]) {
        EXPECT_FALSE(has_warning(e, "rare_large_errors")) << e["name"] << e["warnings"].dump();
        for (const json& l : e["levels"]) {
            EXPECT_GT(l["error_concentration"]["effective_terms"].get<double>(), 100.0)
                << e["name"] << " spp " << l["n"];
            EXPECT_FALSE(has_code(l["warnings"], "few_pixel_errors"));
        }
    }
}

// Veach's scene: multiple importance sampling is never worse than the worse of its two
// strategies (light sampling by solid angle, BSDF sampling) [Veach97, theorem 9.2]. Each
// estimator's error constant relMSE x spp is pooled over the levels (a 1/spp estimator has
// the same constant at every spp), and the comparison allows three standard errors of the
// difference, from the spread of each level's images.
TEST(RenderScenes, MisNeverWorseThanTheWorseOfItsParts) {
    json r = study("veach_mis",
                   json{{"width", 32},
                        {"height", 24},
                        {"spp_min", 16},
                        {"spp_max", 64},
                        {"reps", 4},
                        {"estimators", {"bsdf", "light_solid_angle", "mis_balance", "mis_power"}},
                        {"reference", {{"spp", 1024}}}});
    auto constant = [&](const char* name, double* se) {
        const json& e = find_estimator(r, name);
        double sum = 0.0, var = 0.0;
        size_t levels = e["levels"].size();
        for (const json& l : e["levels"]) {
            double n = l["n"].get<double>();
            double half =
                0.5 * (l["variance_ci95"][1].get<double>() - l["variance_ci95"][0].get<double>());
            double t = 3.182446305284263; // Student t, 97.5%, 3 degrees of freedom (4 images)
            sum += l["variance"].get<double>() * n;
            var += (half / t * n) * (half / t * n);
        }
        *se = std::sqrt(var) / double(levels);
        return sum / double(levels);
    };
    double se_bsdf = 0, se_light = 0;
    double c_bsdf = constant("bsdf", &se_bsdf), c_light = constant("light_solid_angle", &se_light);
    double worse = std::max(c_bsdf, c_light);
    double se_worse = c_bsdf > c_light ? se_bsdf : se_light;
    for (const char* mis : {"mis_balance", "mis_power"}) {
        double se = 0;
        double c = constant(mis, &se);
        EXPECT_LE(c, worse + 3.0 * std::sqrt(se * se + se_worse * se_worse))
            << mis << " " << c << " +/- " << se << " against bsdf " << c_bsdf << " +/- " << se_bsdf
            << ", light " << c_light << " +/- " << se_light;
    }
}

// Furnace and sphere interior through the scene files: cosine sampling of a Lambertian inside
// a closed uniformly emitting enclosure returns Le (1 + rho) (furnace) and rho Le (a dark quad
// inside the sphere) exactly, for every pixel that sees such a surface.
TEST(RenderScenes, ClosedEnclosuresGiveClosedForms) {
    for (auto [name, value] :
         {std::pair<const char*, double>{"furnace_box", 1.5}, {"sphere_interior", 0.8}}) {
        auto r = request(name, json{{"width", 16}, {"height", 16}});
        ASSERT_TRUE(r);
        RenderScene rs;
        rs.build(*r->scene, r->accel);
        RenderEstimator e;
        e.strategy = RadianceStrategy::CosineHemisphere;
        e.name = "cosine_hemisphere";
        RenderSettings st;
        st.width = st.height = 16;
        st.spp = 4;
        RenderImage im = render_image(rs, e, st);
        int matches = 0;
        for (size_t k = 0; k < im.rgb.size(); ++k)
            if (std::fabs(im.rgb[k] - value) < 1e-9) ++matches;
        // The furnace is seen everywhere; the sphere's own (emitting, black) pixels return 1.
        EXPECT_GE(matches, name == std::string("furnace_box") ? int(im.rgb.size()) : 3 * 16)
            << name;
    }
}

TEST(RenderScenes, BadSceneFilesGetClearErrors) {
    json good = scene_json("quad_light_floor");
    struct Case {
        json scene;
        std::string message;
    };
    auto with = [&](const char* key, json value) {
        json s = good;
        s["render"][key] = value;
        return s;
    };
    json no_gltf = good;
    no_gltf["render"].erase("gltf");
    const Case cases[] = {
        {with("gltf", "missing.gltf"), "scene.render.gltf: "},
        {no_gltf, "scene.render.gltf: missing"},
        {with("gltf", 3), "expected a file name or a glTF object"},
        {with("width", 0), "scene.render.width: must be in 1..4096"},
        {with("spp_max", 0), "scene.render.spp_max"},
        {with("reps", 1), "scene.render.reps: must be in 2..1024"},
        {with("estimators", json::array()), "scene.render.estimators: expected a non-empty array"},
        {with("estimators", {"light_areaa"}), "unknown estimator 'light_areaa'"},
        {with("estimators", {{{"strategy", "bsdf"}, {"max_depth", 3}}}),
         "only the 'path' strategy has bounces"},
        {with("estimators", {"bsdf", {{"strategy", "path"}}}), "one study compares estimators"},
        {with("estimators", {{{"strategy", "light_area"}, {"light_selection", "random"}}}),
         "light_selection: unknown value 'random'"},
        {with("estimators", {"bsdf", "bsdf"}), "duplicate estimator name 'bsdf'"},
        {with("reference", {{"file", "nope.hdr"}}), ""},
        {with("colour", 1), "unknown field 'colour'"},
    };
    for (const Case& c : cases) {
        std::string text = c.scene.dump();
        json options{{"base_dir", kScenes}, {"spp_max", 2}, {"width", 4}, {"height", 4}};
        char* out = nullptr;
        int st = mcp_render_study_run(text.c_str(), options.dump().c_str(), nullptr, nullptr, &out);
        EXPECT_EQ(st, MCP_ERROR_SCENE) << c.message;
        EXPECT_EQ(out, nullptr);
        if (c.message.empty())
            EXPECT_NE(std::string(mcp_last_error()).find("nope.hdr"), std::string::npos)
                << mcp_last_error();
        else
            EXPECT_NE(std::string(mcp_last_error()).find(c.message), std::string::npos)
                << "expected '" << c.message << "', got '" << mcp_last_error() << "'";
    }
    char* out = nullptr;
    EXPECT_EQ(mcp_render_study_run("{\"name\": 1}", nullptr, nullptr, nullptr, &out),
              MCP_ERROR_SCENE);
    EXPECT_EQ(mcp_render_image("{", nullptr, &out), MCP_ERROR_SCENE);
    json bad_spp{{"spp", -1}, {"base_dir", kScenes}};
    EXPECT_EQ(mcp_render_image(good.dump().c_str(), bad_spp.dump().c_str(), &out),
              MCP_ERROR_ARGUMENT);
    EXPECT_NE(std::string(mcp_last_error()).find("options.spp"), std::string::npos);
}

// A glTF's extras.mcplay carries study settings; the scene file's own values win.
TEST(RenderScenes, GltfExtrasCarrySettings) {
    json gltf = json::parse(read(kScenes + "/quad_light_floor.gltf"));
    gltf["scenes"][0]["extras"]["mcplay"] = {{"width", 5}, {"height", 7}, {"estimators", {"bsdf"}}};
    json scene{{"name", "x"}, {"render", {{"gltf", gltf}, {"height", 9}}}};
    char* info = nullptr;
    ASSERT_EQ(mcp_render_scene_info(scene.dump().c_str(), nullptr, &info), MCP_OK)
        << mcp_last_error();
    json j = json::parse(info);
    mcp_free(info);
    EXPECT_EQ(j["width"], 5);
    EXPECT_EQ(j["height"], 9);
    ASSERT_EQ(j["estimators"].size(), 1u);
    EXPECT_EQ(j["estimators"][0]["name"], "bsdf");
    gltf["scenes"][0]["extras"]["mcplay"]["spp"] = 3;
    scene["render"]["gltf"] = gltf;
    EXPECT_EQ(mcp_render_scene_info(scene.dump().c_str(), nullptr, &info), MCP_ERROR_SCENE);
    EXPECT_NE(std::string(mcp_last_error()).find("extras.mcplay: unknown field 'spp'"),
              std::string::npos)
        << mcp_last_error();
}

// The reference: rendered once, then read back from the cache with the same numbers; or
// read from a Radiance HDR file of the right size (and refused at the wrong size).
TEST(RenderScenes, ReferenceFromCacheAndFromHdrFile) {
    char dir_template[] = "/tmp/mcplay_ref_XXXXXX";
    ASSERT_NE(mkdtemp(dir_template), nullptr);
    const std::string dir = dir_template;
    json options{{"width", 8},
                 {"height", 6},
                 {"spp_min", 1},
                 {"spp_max", 2},
                 {"reps", 2},
                 {"estimators", {"light_area"}},
                 {"reference", {{"spp", 64}}},
                 {"cache_dir", dir}};
    json first = study("quad_light_floor", options);
    json second = study("quad_light_floor", options);
    EXPECT_EQ(first["scene"]["reference"]["source"], "rendered");
    EXPECT_EQ(second["scene"]["reference"]["source"], "cache");
    EXPECT_EQ(first["estimators"][0]["levels"][1]["variance"],
              second["estimators"][0]["levels"][1]["variance"]);

    auto r = request("quad_light_floor", json{{"width", 8}, {"height", 6}});
    ASSERT_TRUE(r);
    RenderScene rs;
    rs.build(*r->scene, r->accel);
    RenderSettings st;
    st.width = 8;
    st.height = 6;
    st.spp = 64;
    RenderImage im = render_image(rs, r->estimators.front(), st);
    const std::string hdr = dir + "/ref.hdr";
    {
        std::ofstream out(hdr, std::ios::binary);
        out << encode_hdr(im);
    }
    options["reference"] = {{"file", hdr}};
    json from_file = study("quad_light_floor", options);
    EXPECT_EQ(from_file["scene"]["reference"]["source"], "file");
    // The file's image is `im` through RGBE, which keeps 8 bits of each pixel's largest
    // channel (the others lose at most 2^-8 of it): its mean luminance is within 1% of im's.
    // (The rendered reference is another, independent image: its mean differs by noise.)
    const double written = mean_luminance(im);
    EXPECT_NEAR(from_file["scene"]["reference"]["mean_luminance"].get<double>(), written,
                0.01 * written);
    options["width"] = 9;
    std::string text = read(kScenes + "/quad_light_floor.json");
    options["base_dir"] = kScenes;
    char* out = nullptr;
    EXPECT_EQ(mcp_render_study_run(text.c_str(), options.dump().c_str(), nullptr, nullptr, &out),
              MCP_ERROR_SCENE);
    EXPECT_NE(std::string(mcp_last_error()).find("the image is 8x6 but the render is 9x6"),
              std::string::npos)
        << mcp_last_error();
}

// mcp_render_image: the images come back as PNG / Radiance HDR bytes (base64).
TEST(RenderScenes, RenderImageReturnsImages) {
    std::string text = read(kScenes + "/quad_light_floor.json");
    json options{{"base_dir", kScenes},
                 {"width", 8},
                 {"height", 6},
                 {"spp", 4},
                 {"estimator", "light_solid_angle"},
                 {"outputs", {"png", "hdr", "error_png"}},
                 {"reference", {{"spp", 64}}}};
    char* out = nullptr;
    ASSERT_EQ(mcp_render_image(text.c_str(), options.dump().c_str(), &out), MCP_OK)
        << mcp_last_error();
    json j = json::parse(out);
    mcp_free(out);
    EXPECT_EQ(j["images"]["png"].get<std::string>().substr(0, 8), "iVBORw0K"); // \x89PNG\r\n
    EXPECT_EQ(j["images"]["hdr"].get<std::string>().substr(0, 4), "Iz9S");     // "#?R"
    EXPECT_EQ(j["images"]["error_png"].get<std::string>().substr(0, 8), "iVBORw0K");
    EXPECT_EQ(j["diagnostics"]["samples"], 8 * 6 * 4);
    EXPECT_TRUE(j["relative_mse"].is_number());
}

// Without an estimator, an image is rendered with the scene's best (the power-heuristic MIS of
// its reference), not its list's first (here uniform hemisphere sampling): on the quad light at 4
// spp its relative MSE is far below the uniform hemisphere's.
TEST(RenderScenes, RenderImageDefaultsToTheBestEstimator) {
    const std::string text = read(kScenes + "/quad_light_floor.json");
    auto image = [&](const json& extra) {
        json options{{"base_dir", kScenes},
                     {"width", 16},
                     {"height", 12},
                     {"spp", 4},
                     {"outputs", json::array({"error_png"})},
                     {"reference", {{"spp", 256}}}};
        options.update(extra);
        char* out = nullptr;
        EXPECT_EQ(mcp_render_image(text.c_str(), options.dump().c_str(), &out), MCP_OK)
            << mcp_last_error();
        json j = out ? json::parse(out) : json();
        mcp_free(out);
        return j;
    };
    const json best = image(json::object());
    EXPECT_EQ(best["estimator"]["strategy"], "mis_power");
    const json uniform = image({{"estimator", "uniform_hemisphere"}});
    EXPECT_EQ(uniform["estimator"]["strategy"], "uniform_hemisphere");
    EXPECT_LT(best["relative_mse"].get<double>(), 0.25 * uniform["relative_mse"].get<double>());
}

// --- Issue 10: honest render numbers ------------------------------------------------------

/// Runs a study of an inline scene; the status, the error and the result.
struct Call {
    int status = 0;
    std::string error;
    json result;
};
Call study_text(const json& scene, json options) {
    char* out = nullptr;
    Call c;
    c.status =
        mcp_render_study_run(scene.dump().c_str(), options.dump().c_str(), nullptr, nullptr, &out);
    if (c.status != MCP_OK) c.error = mcp_last_error();
    if (out) c.result = json::parse(out);
    mcp_free(out);
    return c;
}

Call merge_text(const json& parts) {
    char* out = nullptr;
    Call c;
    c.status = mcp_render_study_merge(parts.dump().c_str(), &out);
    if (c.status != MCP_OK) c.error = mcp_last_error();
    if (out) c.result = json::parse(out);
    mcp_free(out);
    return c;
}

// Issue 48: a level's relative MSE is the raw one less the reference's noise, so it lies in
// -floor..rel_mse_raw and goes negative once an image is closer to the truth than the reference
// can tell (docs/render-scenes.md). The merge of a split study took any negative value for a
// malformed part ("rel_mse: out of range: expected 0..-, got -2.1e-05"); now it accepts that
// range and still refuses what lies outside it.
TEST(RenderSplit, MergeAcceptsANegativeRelativeMseDownToTheFloor) {
    const json scene = json::parse(read(kScenes + "/quad_light_floor.json"));
    json o{{"base_dir", kScenes},
           {"width", 8},
           {"height", 6},
           {"spp_min", 1},
           {"spp_max", 2},
           {"reps", 2},
           {"seed", 3},
           {"estimators", {"light_solid_angle"}},
           {"reference", {{"spp", 16}}}};
    json parts = json::array();
    for (int i = 0; i < 2; ++i) {
        o["part"] = i;
        o["parts"] = 2;
        const Call c = study_text(scene, o);
        ASSERT_EQ(c.status, MCP_OK) << c.error;
        parts.push_back(c.result);
    }
    const double floor = parts[0]["reference_summary"]["relative_mse_floor"].get<double>();
    ASSERT_GT(floor, 0.0);
    const double raw =
        parts[0]["estimators"][0]["levels"][0]["images"][0]["rel_mse_raw"].get<double>();
    auto merge_with = [&](double rel_mse) {
        json p = parts;
        p[0]["estimators"][0]["levels"][0]["images"][0]["rel_mse"] = rel_mse;
        return merge_text(json{{"parts", p}});
    };
    // Right: negative down to -floor (an image at least as close as the reference's noise).
    for (double rel_mse : {-0.5 * floor, -floor, std::min(raw, 0.0)}) {
        const Call ok = merge_with(rel_mse);
        EXPECT_EQ(ok.status, MCP_OK) << rel_mse << ": " << ok.error;
    }
    // Wrong: below -floor, or above the raw relative MSE it was corrected from.
    for (double rel_mse : {-1.01 * floor - 1e-12, raw * 1.01 + 1e-12}) {
        const Call bad = merge_with(rel_mse);
        EXPECT_EQ(bad.status, MCP_ERROR_ARGUMENT) << rel_mse;
        EXPECT_NE(bad.error.find("images[0].rel_mse: out of range"), std::string::npos)
            << bad.error;
    }
}

// A study split over processes (the page's workers) by replicate: its parts, merged, are the
// whole study, every level's numbers, the fit and the warnings bit for bit; only seconds (and
// what divides by them) are each run's own. Parts that do not belong together are refused.
TEST(RenderSplit, PartsMergeToTheWholeStudy) {
    const json options{{"base_dir", kScenes},
                       {"width", 16},
                       {"height", 12},
                       {"spp_min", 1},
                       {"spp_max", 8},
                       {"reps", 6},
                       {"seed", 5},
                       {"estimators", {"light_solid_angle", "bsdf"}},
                       {"reference", {{"spp", 64}}}};
    const json scene = json::parse(read(kScenes + "/cornell_box.json"));
    auto run = [&](const json& o) { return study_text(scene, o); };
    const Call whole = run(options);
    ASSERT_EQ(whole.status, MCP_OK) << whole.error;
    EXPECT_FALSE(whole.result.contains("part"));
    EXPECT_FALSE(whole.result["estimators"][0]["levels"][0].contains("images"));
    // Each level times its images as an integration level times its replicates: a spread and a
    // median interval that brackets the median (the equal-time comparison tests against them).
    for (const json& est : whole.result["estimators"])
        for (const json& l : est["levels"]) {
            ASSERT_TRUE(l["time_std_s"].is_number()) << l.dump();
            EXPECT_GT(l["time_std_s"].get<double>(), 0.0) << l.dump();
            const json& ci = l["time_median_ci95_s"];
            ASSERT_TRUE(ci.is_array() && ci.size() == 2 && l["time_median_s"].is_number());
            EXPECT_LE(ci[0].get<double>(), l["time_median_s"].get<double>());
            EXPECT_GE(ci[1].get<double>(), l["time_median_s"].get<double>());
            EXPECT_LT(ci[0].get<double>(), ci[1].get<double>());
        }
    const char* const kTimed[] = {"time_mean_s",        "time_std_s",   "time_median_s",
                                  "time_median_ci95_s", "time_total_s", "efficiency"};
    for (int k : {3, 4}) {
        json parts = json::array();
        for (int i = 0; i < k; ++i) {
            json o = options;
            o["part"] = i;
            o["parts"] = k;
            Call c = run(o);
            ASSERT_EQ(c.status, MCP_OK) << c.error;
            ASSERT_EQ(c.result["part"], (json{{"index", i}, {"of", k}}));
            // replicates i, i + k, ... of every level
            const json& images = c.result["estimators"][0]["levels"][0]["images"];
            ASSERT_EQ(images.size(), size_t((6 - i + k - 1) / k));
            EXPECT_EQ(images[0]["replicate"], i);
            parts.push_back(c.result);
        }
        std::reverse(parts.begin(), parts.end()); // the order the parts come in is free
        const Call merged = merge_text(json{{"parts", parts}});
        ASSERT_EQ(merged.status, MCP_OK) << merged.error;
        ASSERT_EQ(merged.result["estimators"].size(), whole.result["estimators"].size());
        for (size_t e = 0; e < whole.result["estimators"].size(); ++e) {
            json a = whole.result["estimators"][e], b = merged.result["estimators"][e];
            EXPECT_EQ(a["fit"], b["fit"]) << k;
            EXPECT_EQ(a["warnings"], b["warnings"]) << k;
            ASSERT_EQ(a["levels"].size(), b["levels"].size());
            for (size_t i = 0; i < a["levels"].size(); ++i) {
                json la = a["levels"][i], lb = b["levels"][i];
                for (const char* key : kTimed) {
                    la.erase(key);
                    lb.erase(key);
                }
                EXPECT_EQ(la, lb) << "parts " << k << ", estimator " << e << ", level " << i;
            }
        }
        EXPECT_FALSE(merged.result.contains("part"));
        EXPECT_EQ(merged.result["settings"]["reps"], 6);

        // Refused: a part missing, a part twice, parts of different studies, not parts at all.
        json missing = parts;
        missing.erase(missing.begin());
        Call bad = merge_text(json{{"parts", missing}});
        EXPECT_EQ(bad.status, MCP_ERROR_ARGUMENT);
        EXPECT_NE(bad.error.find("part.of"), std::string::npos) << bad.error;
        json twice = parts;
        twice[1] = twice[0];
        bad = merge_text(json{{"parts", twice}});
        EXPECT_EQ(bad.status, MCP_ERROR_ARGUMENT);
        EXPECT_NE(bad.error.find("must be given once"), std::string::npos) << bad.error;
        json other = parts;
        other[0]["reference_summary"]["mean_luminance"] = 1.0;
        bad = merge_text(json{{"parts", other}});
        EXPECT_NE(bad.error.find("different references"), std::string::npos) << bad.error;
        json broken = parts;
        broken[0]["estimators"][0]["levels"][1]["images"][0]["top"] = json::array({-1.0});
        bad = merge_text(json{{"parts", broken}});
        EXPECT_EQ(bad.status, MCP_ERROR_ARGUMENT);
        EXPECT_NE(bad.error.find("top[0]: expected a number >= 0"), std::string::npos) << bad.error;
    }
    // Every value of a part's JSON replaced by something else (calls from JavaScript may pass
    // anything): an answer or a named error, never a crash. Previews are left out (size).
    {
        json o = options;
        o["part"] = 0;
        o["parts"] = 2;
        json p0 = run(o).result, p1;
        o["part"] = 1;
        p1 = run(o).result;
        for (json* p : {&p0, &p1})
            for (json& e : (*p)["estimators"]) e["levels"] = json::array({e["levels"][0]});
        ASSERT_EQ(merge_text(json{{"parts", {p0, p1}}}).status, MCP_OK);
        // Refused, naming the field: a part of another seed, a part whose images were emptied,
        // an image's coverage out of 0..1.
        o["seed"] = 9;
        json seed9 = run(o).result;
        for (json& e : seed9["estimators"]) e["levels"] = json::array({e["levels"][0]});
        Call bad_merge = merge_text(json{{"parts", {p0, seed9}}});
        EXPECT_EQ(bad_merge.status, MCP_ERROR_ARGUMENT);
        EXPECT_NE(bad_merge.error.find("settings.seed: is 9, part 0's is 5"), std::string::npos)
            << bad_merge.error;
        json emptied = p1;
        emptied["estimators"][0]["levels"][0]["images"] = json::array();
        bad_merge = merge_text(json{{"parts", {p0, emptied}}});
        EXPECT_EQ(bad_merge.status, MCP_ERROR_ARGUMENT);
        EXPECT_NE(bad_merge.error.find("images: expected the 3 images"), std::string::npos)
            << bad_merge.error;
        json coverage = p1;
        coverage["estimators"][0]["levels"][0]["images"][0]["coverage"] = 7;
        bad_merge = merge_text(json{{"parts", {p0, coverage}}});
        EXPECT_EQ(bad_merge.status, MCP_ERROR_ARGUMENT);
        EXPECT_NE(bad_merge.error.find("coverage: out of range"), std::string::npos)
            << bad_merge.error;
        coverage["estimators"][0]["levels"][0]["images"][0]["coverage"] = 1;
        EXPECT_EQ(merge_text(json{{"parts", {p0, coverage}}}).status, MCP_OK);
        // Progress lines (the page merges them level by level) carry no settings or scene: the
        // replicates are counted from the images, and an emptied part is still refused.
        json line0 = p0, line1 = p1;
        for (json* p : {&line0, &line1}) {
            p->erase("settings");
            p->erase("scene");
        }
        EXPECT_EQ(merge_text(json{{"parts", {line0, line1}}}).status, MCP_OK);
        line1["estimators"][0]["levels"][0]["images"] = json::array();
        bad_merge = merge_text(json{{"parts", {line0, line1}}});
        EXPECT_EQ(bad_merge.status, MCP_ERROR_ARGUMENT);
        EXPECT_NE(bad_merge.error.find("images"), std::string::npos) << bad_merge.error;
        // What the merge reads: the part, its reference summary, the estimators' names, the
        // fields of an image (one element of its sample list), and the containers.
        std::vector<std::string> keys = {"/part",
                                         "/reference_summary",
                                         "/estimators",
                                         "/estimators/0",
                                         "/estimators/0/levels",
                                         "/estimators/0/levels/0",
                                         "/estimators/0/levels/0/images",
                                         "/estimators/0/levels/0/images/0",
                                         "/settings"};
        const json flat = p0.flatten();
        for (auto it = flat.begin(); it != flat.end(); ++it) {
            const std::string& key = it.key();
            const bool read = key.rfind("/part", 0) == 0 ||
                              key.rfind("/reference_summary", 0) == 0 ||
                              key.rfind("/estimators/0/levels/0/images/0/", 0) == 0 ||
                              key.substr(key.size() - 5) == "/name" || key == "/settings/threads" ||
                              key == "/cancelled" || key == "/wall_time_s";
            if (read &&
                !(key.find("/top/") != std::string::npos && key.substr(key.size() - 2) != "/0"))
                keys.push_back(key);
        }
        const json replacements[] = {nullptr, -1, 1e308, "x", json::array(), json::object(), 0};
        int answered = 0, refused = 0;
        for (const std::string& key : keys) {
            for (const json& r : replacements) {
                json f = p0;
                f[json::json_pointer(key)] = r;
                const Call c = merge_text(json{{"parts", {f, p1}}});
                ASSERT_TRUE(c.status == MCP_OK || c.status == MCP_ERROR_ARGUMENT)
                    << key << " = " << r.dump() << ": " << c.error;
                if (c.status == MCP_OK) {
                    ++answered;
                } else {
                    ++refused;
                    EXPECT_FALSE(c.error.empty());
                }
            }
        }
        EXPECT_GT(answered, 0);
        EXPECT_GT(refused, 0);
    }
    Call bad = merge_text(json{{"parts", json::array({whole.result})}});
    EXPECT_EQ(bad.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(bad.error.find("not a part of a split study"), std::string::npos) << bad.error;
    EXPECT_EQ(merge_text(json{{"parts", json::array()}}).status, MCP_ERROR_ARGUMENT);
    EXPECT_EQ(merge_text(json::array()).status, MCP_ERROR_ARGUMENT);
    json o = options;
    o["parts"] = 7;
    Call c = run(o);
    EXPECT_EQ(c.status, MCP_ERROR_ARGUMENT);
    EXPECT_EQ(c.error, "options.parts: must be in 1..reps = 6, got 7");
    o["parts"] = 2;
    o["part"] = 2;
    c = run(o);
    EXPECT_EQ(c.error, "options.part: must be in 0..parts - 1 = 1, got 2");
}

/// quad_light_floor with its glTF inline, edited by `edit`.
template <class Edit> json quad_scene(Edit edit, const std::string& name = "q") {
    json gltf = json::parse(read(kScenes + "/quad_light_floor.gltf"));
    edit(gltf);
    return json{{"name", name}, {"render", {{"gltf", gltf}}}};
}

const json kTiny{{"width", 4},
                 {"height", 4},
                 {"spp_min", 1},
                 {"spp_max", 2},
                 {"reps", 2},
                 {"estimators", {"light_area", "bsdf"}},
                 {"reference", {{"spp", 16}}}};

json info_of(const json& scene) {
    char* info = nullptr;
    EXPECT_EQ(mcp_render_scene_info(scene.dump().c_str(), nullptr, &info), MCP_OK)
        << mcp_last_error();
    json j = info ? json::parse(info) : json();
    mcp_free(info);
    return j;
}

// No light at all: the scene says so, and relative MSE against the black reference is null
// with a warning, never a triumphant 0.
TEST(RenderHonesty, NoLightsWarnAndRelativeMseIsNull) {
    json scene = quad_scene([](json& g) { g["materials"][1]["emissiveFactor"] = {0, 0, 0}; });
    json info = info_of(scene);
    EXPECT_EQ(info["lights"], 0);
    EXPECT_TRUE(has_code(info["warnings"], "no_lights")) << info["warnings"].dump();
    Call c = study_text(scene, kTiny);
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    EXPECT_TRUE(has_code(c.result["scene"]["warnings"], "no_lights"));
    EXPECT_TRUE(has_code(c.result["scene"]["warnings"], "black_reference"));
    EXPECT_TRUE(c.result["scene"]["reference"]["relative_mse_floor"].is_null());
    for (const json& e : c.result["estimators"])
        for (const json& l : e["levels"]) {
            EXPECT_TRUE(l["relative_mse"].is_null()) << l.dump();
            EXPECT_TRUE(l["efficiency"].is_null());
        }
}

// A zero-area emissive triangle is reported, not dropped silently: a light mesh of one
// triangle with collinear vertices (float32 positions in a data: buffer).
TEST(RenderHonesty, DegenerateLightsAreReported) {
    json scene = quad_scene([](json& g) {
        const float p[9] = {0.0f, 1.0f, 0.0f, 0.5f, 1.0f, 0.0f, 1.0f, 1.0f, 0.0f};
        std::string bytes(reinterpret_cast<const char*>(p), sizeof p);
        size_t buffer = g["buffers"].size(), view = g["bufferViews"].size(),
               accessor = g["accessors"].size(), mesh = g["meshes"].size();
        g["buffers"].push_back(
            {{"byteLength", sizeof p},
             {"uri", "data:application/octet-stream;base64," + base64_encode(bytes)}});
        g["bufferViews"].push_back({{"buffer", buffer}, {"byteLength", sizeof p}});
        g["accessors"].push_back({{"bufferView", view},
                                  {"componentType", 5126},
                                  {"count", 3},
                                  {"type", "VEC3"},
                                  {"min", {0, 1, 0}},
                                  {"max", {1, 1, 0}}});
        g["meshes"].push_back(
            {{"primitives", {{{"attributes", {{"POSITION", accessor}}}, {"material", 1}}}}});
        g["nodes"].push_back({{"name", "flat_light"}, {"mesh", mesh}});
        g["scenes"][0]["nodes"].push_back(g["nodes"].size() - 1);
    });
    json info = info_of(scene);
    EXPECT_EQ(info["lights"], 2);
    EXPECT_EQ(info["degenerate_lights"], 1);
    EXPECT_TRUE(has_code(info["warnings"], "degenerate_lights")) << info["warnings"].dump();
    EXPECT_FALSE(has_code(info["warnings"], "no_lights"));
}

// Emission the float32 images cannot hold (1e308 once rendered every pixel as inf, black in the
// PNG, with no warning) is refused naming the material; 1e30 on the small quad scene fits, is
// still sampled (no light sample misses it) and gives finite pixels with no flag.
TEST(RenderHonesty, EmissionBeyondFloat32IsRefusedAndLargeEmissionRenders) {
    auto with_strength = [](double strength) {
        return quad_scene([strength](json& g) {
            g["materials"][1]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] =
                strength;
        });
    };
    json options{{"width", 4}, {"height", 4}, {"spp", 4}, {"estimator", "light_area"}};
    char* out = nullptr;
    EXPECT_NE(mcp_render_image(with_strength(1e308).dump().c_str(), options.dump().c_str(), &out),
              MCP_OK);
    const std::string error = mcp_last_error();
    EXPECT_NE(error.find("materials[1]"), std::string::npos) << error;
    EXPECT_NE(error.find("beyond the float32 range of the images (at most 3.4e38)"),
              std::string::npos)
        << error;
    ASSERT_EQ(mcp_render_image(with_strength(1e30).dump().c_str(), options.dump().c_str(), &out),
              MCP_OK)
        << mcp_last_error();
    json j = json::parse(out);
    mcp_free(out);
    EXPECT_EQ(j["scene"]["lights"], 2);
    EXPECT_EQ(j["diagnostics"]["light_misses"], 0) << j["diagnostics"].dump();
    EXPECT_EQ(j["diagnostics"]["discarded_nonfinite"], 0) << j["diagnostics"].dump();
    EXPECT_EQ(j["diagnostics"]["pixels_beyond_float32"], 0) << j["diagnostics"].dump();
    EXPECT_FALSE(has_code(j["warnings"], "nonfinite")) << j["warnings"].dump();
}

// A pixel finite in double but beyond float32 is counted (it is inf in the HDR/PFM images); a
// discarded (NaN) pixel and the largest float are not.
TEST(RenderHonesty, PixelsBeyondFloat32AreCounted) {
    RenderImage im;
    im.width = 2;
    im.height = 2;
    im.rgb.assign(12, 1.0);
    im.variance.assign(12, 0.0);
    EXPECT_EQ(pixels_beyond_float32(im), 0u);
    im.rgb[1] = double(std::numeric_limits<float>::max()); // pixel 0: representable
    im.rgb[3] = NAN;                                       // pixel 1: discarded
    im.rgb[8] = 1e39;                                      // pixel 2: beyond
    im.rgb[9] = -1e300;                                    // pixel 3: beyond
    EXPECT_EQ(pixels_beyond_float32(im), 2u);
}

// The reference cache's file name is a hash alone: a scene name with "../" cannot place it
// outside the cache folder. A corrupt cache file is ignored and the reference rendered again.
TEST(RenderHonesty, CacheNameIsAHashAndCorruptCachesAreIgnored) {
    char dir_template[] = "/tmp/mcplay_cache_XXXXXX";
    ASSERT_NE(mkdtemp(dir_template), nullptr);
    const std::string dir = dir_template;
    const std::string escape = "mcplay_escape_" + dir.substr(dir.size() - 6);
    json scene = quad_scene([](json&) {}, "../../../../../../tmp/" + escape);
    json options = kTiny;
    options["cache_dir"] = dir + "/sub";
    ASSERT_EQ(mkdir((dir + "/sub").c_str(), 0700), 0);
    Call first = study_text(scene, options);
    ASSERT_EQ(first.status, MCP_OK) << first.error;
    EXPECT_EQ(first.result["scene"]["reference"]["source"], "rendered");
    std::string file = first.result["scene"]["reference"]["file"];
    std::string base = file.substr(file.rfind('/') + 1);
    EXPECT_EQ(file.substr(0, file.rfind('/')), dir + "/sub");
    ASSERT_EQ(base.size(), 16u + 6u) << base;
    EXPECT_EQ(base.find_first_not_of("0123456789abcdef"), 16u) << base;
    EXPECT_EQ(base.substr(16), ".mcref");
    EXPECT_EQ(std::string(escape).find('/'), std::string::npos);
    std::ifstream outside("/tmp/" + escape);
    EXPECT_FALSE(outside.good());
    EXPECT_EQ(study_text(scene, options).result["scene"]["reference"]["source"], "cache");
    // Truncated, then the right size with a wrong magic: both ignored, rendered again.
    std::string bytes = read(file);
    for (const std::string& bad :
         {bytes.substr(0, bytes.size() - 8), "XXXXXXXX" + bytes.substr(8)}) {
        {
            std::ofstream out(file, std::ios::binary | std::ios::trunc);
            out << bad;
        }
        Call again = study_text(scene, options);
        ASSERT_EQ(again.status, MCP_OK) << again.error;
        EXPECT_EQ(again.result["scene"]["reference"]["source"], "rendered");
        EXPECT_EQ(again.result["estimators"][0]["levels"][1]["variance"],
                  first.result["estimators"][0]["levels"][1]["variance"]);
    }
    EXPECT_EQ(read(file), bytes); // rewritten whole
}

TEST(RenderHonesty, ReferenceCacheReaderChecksEverything) {
    char dir_template[] = "/tmp/mcplay_cache_XXXXXX";
    ASSERT_NE(mkdtemp(dir_template), nullptr);
    const std::string dir = dir_template, file = dir + "/c.mcref";
    RenderImage im;
    im.width = 3;
    im.height = 2;
    im.spp = 64;
    im.rgb.assign(18, 0.5);
    im.variance.assign(18, 0.01);
    const uint64_t key = 0x1234abcd5678ef90ull;
    ASSERT_TRUE(write_reference_cache(file, im, key));
    RenderImage back;
    ASSERT_TRUE(read_reference_cache(file, key, &back));
    EXPECT_EQ(back.rgb, im.rgb);
    EXPECT_EQ(back.variance, im.variance);
    EXPECT_EQ(back.spp, 64u);
    const std::string good = read(file);
    auto rejected = [&](const std::string& bytes) {
        {
            std::ofstream out(file, std::ios::binary | std::ios::trunc);
            out << bytes;
        }
        RenderImage x;
        x.width = 7;
        bool ok = read_reference_cache(file, key, &x);
        EXPECT_EQ(x.width, 7); // untouched
        return !ok;
    };
    auto with_header = [&](int64_t w, int64_t h, int64_t spp) {
        std::string b = good;
        int64_t head[3] = {w, h, spp};
        b.replace(16, sizeof head, reinterpret_cast<const char*>(head), sizeof head);
        return b;
    };
    EXPECT_TRUE(rejected(good.substr(0, good.size() - 1))); // truncated
    EXPECT_TRUE(rejected(good + "x"));                      // trailing bytes
    EXPECT_TRUE(rejected(good.substr(0, 20)));              // no header
    EXPECT_TRUE(rejected(with_header(5000, 1, 64)));        // too wide
    EXPECT_TRUE(rejected(with_header(-3, -2, 64)));         // negative sizes
    EXPECT_TRUE(rejected(with_header(3, 2, 0)));            // no spp
    std::string inf = good;
    double big = INFINITY;
    std::memcpy(&inf[40], &big, sizeof big);
    EXPECT_TRUE(rejected(inf)); // an infinite mean
    // A NaN variance beside a finite mean (the renderer writes none at spp > 1) would be read
    // as 0 by the relative MSE: refused, naming the pixel. Beside a NaN mean (every sample
    // discarded) it is what the renderer writes, and accepted.
    const size_t variances = 40 + 18 * sizeof(double);
    const double nan = NAN;
    std::string nan_var = good;
    std::memcpy(&nan_var[variances + 4 * sizeof(double)], &nan, sizeof nan); // pixel 1, green
    EXPECT_TRUE(rejected(nan_var));
    std::string why;
    RenderImage y;
    EXPECT_FALSE(decode_reference(nan_var, key, &y, &why));
    EXPECT_EQ(why, "pixel (1, 0) has a NaN variance (in channel 1)");
    std::string discarded = nan_var;
    std::memcpy(&discarded[40 + 4 * sizeof(double)], &nan, sizeof nan);
    EXPECT_TRUE(decode_reference(discarded, key, &y));
    // At 1 sample per pixel no pixel has a variance: NaN is what the renderer writes.
    EXPECT_TRUE(decode_reference(with_header(3, 2, 1).replace(variances, sizeof nan,
                                                              reinterpret_cast<const char*>(&nan),
                                                              sizeof nan),
                                 key, &y));
    EXPECT_TRUE(rejected(good.substr(0, 8) + std::string(8, 'k') + good.substr(16))); // other key
    RenderImage x;
    EXPECT_FALSE(read_reference_cache(dir, key, &x)); // a directory
}

// Base64 as RFC 4648 defines it, both ways, and nothing else decoded.
TEST(RenderHonesty, Base64RoundTripsAndRefusesWhatIsNotBase64) {
    for (const std::string& bytes :
         {std::string(), std::string("f"), std::string("fo"), std::string("foo"),
          std::string("foob"), std::string("\0\xff\x10\x80", 4)}) {
        std::string back = "x";
        ASSERT_TRUE(base64_decode(base64_encode(bytes), &back)) << base64_encode(bytes);
        EXPECT_EQ(back, bytes);
    }
    std::string out;
    EXPECT_TRUE(base64_decode("Zm9vYg==", &out));
    EXPECT_EQ(out, "foob");
    for (const char* bad : {"Zm9", "Zm9v!A==", "Zg===", "====", "Z===", "Zm=v", "Zm9v\n"})
        EXPECT_FALSE(base64_decode(bad, &out)) << bad;
}

/// The reference of `scene` under `options` through mcp_render_reference (with progress lines
/// kept in `lines` when given).
Call reference_call(const json& scene, const json& options, std::vector<json>* lines = nullptr) {
    char* out = nullptr;
    Call c;
    auto on_line = [](const char* text, void* user) {
        static_cast<std::vector<json>*>(user)->push_back(json::parse(text));
        return 0;
    };
    c.status = mcp_render_reference(scene.dump().c_str(), options.dump().c_str(),
                                    lines ? +on_line : nullptr, lines, &out);
    if (c.status != MCP_OK) c.error = mcp_last_error();
    if (out) c.result = json::parse(out);
    mcp_free(out);
    return c;
}

// A reference made once (mcplay reference; the site ships them for its scenes) gives a study
// exactly the result it would have rendered itself; one made for another image size is not
// used and the result says so; bytes that are not a reference are an error naming the option.
// The study's seed never changes the reference: its own seed does.
TEST(RenderHonesty, SuppliedReferencesAreUsedOnlyForTheirOwnSettings) {
    json scene = quad_scene([](json&) {});
    json options = kTiny;
    options["reference"]["spp"] = 64;
    options["width"] = 6;
    options["height"] = 5;
    std::vector<json> lines;
    Call ref = reference_call(scene, options, &lines);
    ASSERT_EQ(ref.status, MCP_OK) << ref.error;
    EXPECT_EQ(ref.result["kind"], "render_reference");
    EXPECT_EQ(ref.result["source"], "rendered");
    EXPECT_EQ(ref.result["spp"], 64);
    ASSERT_FALSE(lines.empty());
    for (const json& l : lines) EXPECT_EQ(l["kind"], "render_reference") << l.dump();
    EXPECT_EQ(lines.back()["rows"], 5);
    EXPECT_LE(lines.back()["rows_done"].get<int>(), 5);

    Call rendered = study_text(scene, options);
    ASSERT_EQ(rendered.status, MCP_OK) << rendered.error;
    json with = options;
    with["reference_data"] = ref.result["reference_data"];
    Call supplied = study_text(scene, with);
    ASSERT_EQ(supplied.status, MCP_OK) << supplied.error;
    EXPECT_EQ(supplied.result["scene"]["reference"]["source"], "supplied");
    for (size_t e = 0; e < 2; ++e)
        for (size_t k = 0; k < 2; ++k)
            EXPECT_EQ(supplied.result["estimators"][e]["levels"][k]["relative_mse"],
                      rendered.result["estimators"][e]["levels"][k]["relative_mse"]);

    // The plan knows it will not render the reference.
    char* plan = nullptr;
    ASSERT_EQ(mcp_render_study_plan(scene.dump().c_str(), with.dump().c_str(), &plan), MCP_OK);
    EXPECT_EQ(json::parse(plan)["reference"]["source"], "supplied");
    mcp_free(plan);

    // Another study seed: the same reference (its floor is a property of the reference alone).
    json seeded = with;
    seeded["seed"] = 99;
    Call other_seed = study_text(scene, seeded);
    ASSERT_EQ(other_seed.status, MCP_OK) << other_seed.error;
    EXPECT_EQ(other_seed.result["scene"]["reference"]["source"], "supplied");
    EXPECT_EQ(other_seed.result["scene"]["reference"]["relative_mse_floor"],
              rendered.result["scene"]["reference"]["relative_mse_floor"]);
    // The reference's own seed, another image size: rendered again, and said so.
    for (auto edit :
         {+[](json& o) { o["reference"]["seed"] = 7; }, +[](json& o) { o["width"] = 7; }}) {
        json changed = with;
        edit(changed);
        Call c = study_text(scene, changed);
        ASSERT_EQ(c.status, MCP_OK) << c.error;
        EXPECT_EQ(c.result["scene"]["reference"]["source"], "rendered");
        EXPECT_TRUE(
            c.result["scene"]["reference"]["supplied"].get<std::string>().find("not used") == 0);
    }
    // Not base64, base64 of something else, and the right key with a wrong length.
    std::string bytes;
    ASSERT_TRUE(base64_decode(ref.result["reference_data"].get<std::string>(), &bytes));
    for (const std::string& bad : {std::string("not base64!"), base64_encode("MCREF01\nshort"),
                                   base64_encode(bytes.substr(0, bytes.size() - 8))}) {
        json b = options;
        b["reference_data"] = bad;
        Call c = study_text(scene, b);
        EXPECT_NE(c.status, MCP_OK);
        EXPECT_NE(c.error.find("options.reference_data"), std::string::npos) << c.error;
    }
    // A NaN variance beside a finite mean is refused naming the pixel (it once moved the
    // relative MSE silently): the last pixel's blue channel.
    std::string nan_var = bytes;
    const double nan = NAN;
    std::memcpy(&nan_var[nan_var.size() - sizeof nan], &nan, sizeof nan);
    json b = options;
    b["reference_data"] = base64_encode(nan_var);
    Call c = study_text(scene, b);
    EXPECT_NE(c.status, MCP_OK);
    EXPECT_NE(c.error.find("options.reference_data: a corrupt reference image: pixel ("),
              std::string::npos)
        << c.error;
    EXPECT_NE(c.error.find("has a NaN variance (in channel 2)"), std::string::npos) << c.error;
}

// The reference image itself as PNG and HDR through mcp_render_image (the page's image exports):
// the supplied reference when it fits, decoded back to the same size; it goes alone.
TEST(RenderHonesty, ReferenceImageExports) {
    json scene = quad_scene([](json&) {});
    json options = kTiny;
    options["reference"]["spp"] = 32;
    Call ref = reference_call(scene, options);
    ASSERT_EQ(ref.status, MCP_OK) << ref.error;
    json o = options;
    o["reference_data"] = ref.result["reference_data"];
    o["outputs"] = {"reference_png", "reference_hdr"};
    char* out = nullptr;
    ASSERT_EQ(mcp_render_image(scene.dump().c_str(), o.dump().c_str(), &out), MCP_OK)
        << mcp_last_error();
    json j = json::parse(out);
    mcp_free(out);
    EXPECT_EQ(j["reference"]["source"], "supplied");
    std::string hdr, png;
    ASSERT_TRUE(base64_decode(j["images"]["reference_hdr"].get<std::string>(), &hdr));
    ASSERT_TRUE(base64_decode(j["images"]["reference_png"].get<std::string>(), &png));
    EXPECT_EQ(png.substr(1, 3), "PNG");
    RenderImage back;
    std::string error;
    ASSERT_TRUE(decode_hdr(hdr, &back, &error)) << error;
    EXPECT_EQ(back.width, 4);
    EXPECT_EQ(back.height, 4);
    o["outputs"] = {"png", "reference_hdr"};
    EXPECT_EQ(mcp_render_image(scene.dump().c_str(), o.dump().c_str(), &out), MCP_ERROR_ARGUMENT);
    mcp_free(out);
    EXPECT_NE(std::string(mcp_last_error()).find("go alone"), std::string::npos);
}

// PFM output: the header, then float32 RGB, little-endian, bottom row first.
TEST(RenderHonesty, PfmIsFloatRgbBottomUp) {
    RenderImage im;
    im.width = 2;
    im.height = 2;
    im.rgb = {0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 1e-9, 1e9, -0.25};
    im.variance.assign(12, 0.0);
    const std::string pfm = encode_pfm(im);
    const std::string head = "PF\n2 2\n-1.0\n";
    ASSERT_EQ(pfm.size(), head.size() + 12 * 4);
    EXPECT_EQ(pfm.substr(0, head.size()), head);
    auto at = [&](size_t k) { // the k-th float after the header
        uint32_t u = 0;
        for (int b = 0; b < 4; ++b)
            u |= uint32_t(uint8_t(pfm[head.size() + 4 * k + size_t(b)])) << (8 * b);
        float f;
        std::memcpy(&f, &u, 4);
        return f;
    };
    // bottom row (y = 1) first: pixels 2 and 3
    EXPECT_EQ(at(0), 6.0f);
    EXPECT_EQ(at(3), 1e-9f);
    EXPECT_EQ(at(5), -0.25f);
    EXPECT_EQ(at(6), 0.5f);
    EXPECT_EQ(at(11), 5.0f);
}

// The default reference's spp follows the scene's spp_max, not a study's smaller one (so that a
// shorter study keeps the scene's cached or shipped reference); a study of more than a quarter
// of it gets 16 x its own spp_max.
TEST(RenderHonesty, DefaultReferenceSppFollowsTheScene) {
    json scene = quad_scene([](json&) {});
    scene["render"]["spp_max"] = 16;
    auto reference_spp = [&](const json& options) {
        char* out = nullptr;
        EXPECT_EQ(mcp_render_scene_info(scene.dump().c_str(), options.dump().c_str(), &out), MCP_OK)
            << mcp_last_error();
        uint64_t spp = json::parse(out)["reference"]["spp"];
        mcp_free(out);
        return spp;
    };
    EXPECT_EQ(reference_spp(json::object()), 256u);
    EXPECT_EQ(reference_spp(json{{"spp_max", 2}}), 256u);
    EXPECT_EQ(reference_spp(json{{"spp_max", 64}}), 256u);
    EXPECT_EQ(reference_spp(json{{"spp_max", 128}}), 2048u);
}

// A progress callback that returns non-zero while the reference renders cancels the study
// before any level, with MCP_ERROR_CANCELLED.
TEST(RenderHonesty, ReferenceProgressCanCancel) {
    json scene = quad_scene([](json&) {});
    json options = kTiny;
    options["height"] = 40;
    options["reference"]["spp"] = 256;
    int calls = 0;
    auto stop = [](const char* text, void* user) {
        json line = json::parse(text);
        EXPECT_EQ(line["kind"], "render_reference") << text;
        return ++*static_cast<int*>(user) >= 2 ? 1 : 0;
    };
    char* out = nullptr;
    int status =
        mcp_render_study_run(scene.dump().c_str(), options.dump().c_str(), +stop, &calls, &out);
    EXPECT_EQ(status, MCP_ERROR_CANCELLED);
    EXPECT_EQ(calls, 2);
    mcp_free(out);
}

// Radiance HDR references: truncated data, a bad size line, sizes over the limits and
// corrupt run-length data are refused with messages that quote nothing of the file.
TEST(RenderHonesty, HdrReferencesAreChecked) {
    for (int w : {16, 4}) { // run-length scanlines, and flat ones (width < 8)
        RenderImage im;
        im.width = w;
        im.height = 8;
        im.rgb.assign(size_t(w) * 8 * 3, 0.0);
        for (size_t k = 0; k < im.rgb.size(); ++k) im.rgb[k] = 0.1 * double(k % 17);
        im.variance.assign(im.rgb.size(), 0.0);
        std::string hdr = encode_hdr(im);
        RenderImage out;
        std::string err;
        ASSERT_TRUE(decode_hdr(hdr, &out, &err)) << err;
        EXPECT_EQ(out.width, w);
        EXPECT_EQ(out.height, 8);
        EXPECT_FALSE(decode_hdr(hdr.substr(0, hdr.size() - 1), &out, &err));
        EXPECT_EQ(err, "the HDR data ends after 7 of 8 scanlines");
        size_t data = hdr.find("+X ");
        data = hdr.find('\n', data) + 1;
        EXPECT_FALSE(decode_hdr(hdr.substr(0, data), &out, &err));
        EXPECT_EQ(err, "the HDR data ends after 0 of 8 scanlines");
    }
    const std::string head = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n";
    const std::string pixels(16 * 4, '\x40');
    std::string err;
    RenderImage out;
    for (const char* size_line : {"-Y -4 +X 4\n", "-Y 4 +X -4\n", "+Y 4 +X 4\n", "-Y 4 +X 4",
                                  "-Y 0 +X 4\n", "-Y 99999999999 +X 4\n", "-Y 4 -X 4\n"}) {
        EXPECT_FALSE(decode_hdr(head + size_line + pixels, &out, &err)) << size_line;
        EXPECT_EQ(err, "the HDR header's size line is invalid: expected '-Y <height> +X <width>' "
                       "with positive whole sizes (other orientations are not read)")
            << size_line;
    }
    EXPECT_FALSE(decode_hdr(head + "-Y 4097 +X 1\n" + pixels, &out, &err));
    EXPECT_NE(err.find("the HDR image is 1x4097, larger than a reference may be"),
              std::string::npos)
        << err;
    EXPECT_FALSE(decode_hdr(head + "-Y 4096 +X 4096\n" + pixels, &out, &err));
    EXPECT_NE(err.find("larger than a reference may be"), std::string::npos) << err;
    EXPECT_FALSE(decode_hdr("P6\n4 4\n255\n" + pixels, &out, &err));
    EXPECT_NE(err.find("not a Radiance HDR file"), std::string::npos) << err;
    EXPECT_FALSE(decode_hdr("#?RADIANCE\n\n-Y 4 +X 4\n" + pixels, &out, &err));
    EXPECT_NE(err.find("no 'FORMAT=32-bit_rle_rgbe' line"), std::string::npos) << err;
    EXPECT_FALSE(decode_hdr("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", &out, &err));
    EXPECT_NE(err.find("does not end"), std::string::npos) << err;
    // A run-length scanline of width 8 whose first run is longer than the scanline.
    std::string rle = head + "-Y 1 +X 8\n" + std::string("\x02\x02\x00\x08", 4) + "\xff\x40";
    EXPECT_FALSE(decode_hdr(rle, &out, &err));
    EXPECT_EQ(err, "the HDR data is corrupt in scanline 1 of 1 (bad run-length encoding)");
    // stb_image ends the header at a line starting with NUL: such a line must not let it read
    // another size line than the one checked (fuzz/findings/hdr/nul_header_line_size_bypass).
    std::string nul = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n" + std::string(1, '\0') +
                      "\n-Y 10 +X 16777215\n\n-Y 1 +X 4\n" + std::string(16, '\x40');
    EXPECT_FALSE(decode_hdr(nul, &out, &err));
    EXPECT_EQ(err, "the HDR header has a control character (byte 34)");
}

// A study whose spp approaches the reference's is refused before anything is rendered; the
// floor is reported with the reference.
TEST(RenderHonesty, ReferenceNoiseFloorIsReportedAndGuarded) {
    json scene = quad_scene([](json&) {});
    json options = kTiny;
    options["spp_max"] = 8;
    options["reference"] = {{"spp", 16}};
    Call c = study_text(scene, options);
    EXPECT_EQ(c.status, MCP_ERROR_SCENE);
    EXPECT_EQ(c.error, "scene.render.reference.spp: expected at least 4 x spp_max = 32, got 16: "
                       "a reference with fewer samples is too noisy to judge the images");
    options["reference"] = {{"spp", 32}};
    c = study_text(scene, options);
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    const json& ref = c.result["scene"]["reference"];
    ASSERT_TRUE(ref["relative_mse_floor"].is_number()) << ref.dump();
    EXPECT_GT(ref["relative_mse_floor"].get<double>(), 0.0);
    for (const json& e : c.result["estimators"])
        for (const json& l : e["levels"]) {
            bool below = l["below_reference_noise"].get<bool>();
            if (l["relative_mse"].get<double>() < ref["relative_mse_floor"].get<double>()) {
                EXPECT_TRUE(below);
                EXPECT_TRUE(has_code(l["warnings"], "below_reference_noise"));
            } else {
                EXPECT_FALSE(below);
            }
        }
}

// Work and memory are bounded before anything is rendered.
TEST(RenderHonesty, WorkIsBoundedUpFront) {
    json scene = quad_scene([](json&) {});
    json big{{"width", 2048},      {"height", 2048}, {"spp_min", 1},
             {"spp_max", 1048576}, {"reps", 2},      {"estimators", {"bsdf"}}};
    Call c = study_text(scene, big);
    EXPECT_EQ(c.status, MCP_ERROR_SCENE);
    EXPECT_NE(c.error.find("scene.render: this needs"), std::string::npos) << c.error;
    EXPECT_NE(c.error.find("more than the limit of 4.4e+12"), std::string::npos) << c.error;
    big["spp_max"] = 1;
    big["estimators"] = {"bsdf", "light_area", "mis_power", "mis_balance"};
    c = study_text(scene, big);
    EXPECT_EQ(c.status, MCP_ERROR_SCENE);
    EXPECT_EQ(c.error, "scene.render: 6 images of 2048x2048 pixels held at once need 1152 MiB, "
                       "more than the limit of 1024 MiB: lower the image size or the number of "
                       "estimators");
    json one{{"width", 2048}, {"height", 2048}, {"spp", 1048576}, {"outputs", {"error_png"}}};
    char* out = nullptr;
    EXPECT_EQ(mcp_render_image(scene.dump().c_str(), one.dump().c_str(), &out), MCP_ERROR_SCENE);
    EXPECT_NE(std::string(mcp_last_error()).find("scene.render: this needs"), std::string::npos)
        << mcp_last_error();
}

// The plan of a study validates like the study, counts its samples exactly and predicts a
// positive time from its pilot, without rendering the study.
TEST(RenderHonesty, StudyPlanCountsTheWorkBeforeItStarts) {
    auto plan = [](const json& scene, const json& options) {
        char* out = nullptr;
        Call c;
        c.status = mcp_render_study_plan(scene.dump().c_str(), options.dump().c_str(), &out);
        if (c.status != MCP_OK) c.error = mcp_last_error();
        if (out) c.result = json::parse(out);
        mcp_free(out);
        return c;
    };
    json scene = quad_scene([](json&) {});
    json options = kTiny;
    options["spp_max"] = 8;
    Call bad = plan(scene, options); // the reference's 16 spp are too few for spp_max = 8
    EXPECT_EQ(bad.status, MCP_ERROR_SCENE);
    EXPECT_EQ(bad.error, study_text(scene, options).error);
    options["reference"] = {{"spp", 64}};
    Call c = plan(scene, options);
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    const double pixels = 4 * 4;
    // spp 1, 2, 4, 8 with 2 replicates for each of 2 estimators, plus the 64-spp reference.
    EXPECT_EQ(c.result["samples"].get<double>(), pixels * (15 * 2 * 2 + 64));
    EXPECT_EQ(c.result["reference"]["source"], "rendered");
    EXPECT_EQ(c.result["estimators"].size(), 2u);
    for (const json& e : c.result["estimators"]) {
        EXPECT_EQ(e["samples"].get<double>(), pixels * 15 * 2);
        EXPECT_GT(e["seconds_per_sample"].get<double>(), 0.0);
    }
    EXPECT_GT(c.result["predicted_seconds"].get<double>(), 0.0);
    EXPECT_EQ(c.result["levels"], json({1, 2, 4, 8}));
}

} // namespace
} // namespace mcp
