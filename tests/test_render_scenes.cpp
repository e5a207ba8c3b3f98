// The render scenes in scenes/ through the render API: they load, stiff scenes give finite
// pixels, the diagnostics flag infinite variance where theory says it is, MIS is never worse
// than the worse of its parts, and bad render scene files get clear errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "render_api/image_io.h"
#include "render_api/mcplay_render.h"
#include "render_api/render_request.h"

namespace mcp {
namespace {

using nlohmann::json;

const std::string kScenes = std::string(MCPLAY_SOURCE_DIR) + "/scenes";

std::string read(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

json scene_json(const std::string& name) {
    return json::parse(read(kScenes + "/" + name + ".json"));
}

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

bool has_warning(const json& estimator, const std::string& code) {
    for (const json& w : estimator["warnings"])
        if (w["code"] == code) return true;
    return false;
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
    "perpendicular_plates", "furnace_box", "sphere_interior",
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
        {with("gltf", "missing.gltf"), "scene.render.gltf: cannot read"},
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
    // RGBE keeps 8 bits of mantissa: the reference is within 1% of the render's mean.
    EXPECT_NEAR(from_file["scene"]["reference"]["mean_luminance"].get<double>(),
                first["scene"]["reference"]["mean_luminance"].get<double>(),
                0.02 * first["scene"]["reference"]["mean_luminance"].get<double>());
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

} // namespace
} // namespace mcp
