// Render diagnostics judged both ways (issue 48): estimators whose per-sample contributions are
// bounded by construction (docs/render-scenes.md, "Bounded contributions") never get heavy_tail
// as a warning, and area sampling of a light that touches what it lights (infinite variance) is
// still flagged. The contact test itself is judged on scenes built in code.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "render/contribution_bound.h"
#include "render_api/mcplay_render.h"
#include "render_scenes.h"
#include "scene_files.h"

namespace mcp {
namespace {

using nlohmann::json;
using test::add_quad;
using test::diffuse;

Material emitter() {
    Material m = diffuse(0.0);
    m.emission = Vec3(1.0);
    return m;
}

/// A unit floor at y = 0 (facing +y) and a unit light quad given by its corners.
Scene floor_and_light(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3) {
    Scene s;
    s.materials = {diffuse(0.5), emitter()};
    add_quad(s, {0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, 0);
    add_quad(s, p0, p1, p2, p3, 1);
    s.camera = test::look_at({0.5, 1, 2}, {0.5, 0, 0.5}, {0, 1, 0}, 1.0);
    return s;
}

LightContacts contacts_of(const Scene& s) {
    RenderScene rs;
    rs.build(s);
    return light_contacts(rs);
}

bool bounded(RadianceStrategy strategy, const LightContacts& c) {
    RenderEstimator e;
    e.strategy = strategy;
    return contribution_bound(e, c).bounded;
}

TEST(RenderBounds, ContactsAreFoundWhereLightsTouchWhatTheyLight) {
    // A wall light standing on the floor's edge z = 0 (the perpendicular plates): an edge
    // contact. Area sampling is unbounded there, solid-angle sampling is not.
    const LightContacts plates =
        contacts_of(floor_and_light({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}));
    ASSERT_TRUE(plates.checked);
    EXPECT_TRUE(plates.contact);
    EXPECT_FALSE(plates.interior_contact);
    EXPECT_FALSE(bounded(RadianceStrategy::LightArea, plates));
    EXPECT_TRUE(bounded(RadianceStrategy::LightSolidAngle, plates));
    // The same light 0.01 above the floor (0.005 of the scene's extent): away from it.
    const LightContacts lifted =
        contacts_of(floor_and_light({0, 0.01, 0}, {1, 0.01, 0}, {1, 1, 0}, {0, 1, 0}));
    EXPECT_FALSE(lifted.contact);
    EXPECT_TRUE(bounded(RadianceStrategy::LightArea, lifted));
    // ... and 1e-6 above it (touching_light's gap is 5e-5 of its extent): a contact.
    EXPECT_TRUE(contacts_of(floor_and_light({0, 1e-6, 0}, {1, 1e-6, 0}, {1, 1, 0}, {0, 1, 0}))
                    .contact);
    // A light facing the floor 1e-4 above it (touching_light): a contact for area sampling,
    // but not within the vertices' rounding of the light's inside: solid angles stay below
    // 2 pi by far more than 1e-12, and solid-angle sampling stays bounded.
    const LightContacts hovering =
        contacts_of(floor_and_light({0.25, 1e-4, 0.25}, {0.75, 1e-4, 0.25}, {0.75, 1e-4, 0.75},
                                    {0.25, 1e-4, 0.75}));
    EXPECT_TRUE(hovering.contact);
    EXPECT_FALSE(hovering.interior_contact);
    EXPECT_TRUE(bounded(RadianceStrategy::LightSolidAngle, hovering));
    // A light in the floor's own plane, beside it: nothing it emits reaches the floor.
    const LightContacts coplanar =
        contacts_of(floor_and_light({1, 0, 0}, {1, 0, 1}, {2, 0, 1}, {2, 0, 0}));
    EXPECT_FALSE(coplanar.contact);
    EXPECT_TRUE(bounded(RadianceStrategy::LightArea, coplanar));
    // A light through the floor: the floor crosses the light's interior, where solid-angle
    // sampling falls back to area sampling.
    const LightContacts through =
        contacts_of(floor_and_light({0.2, -0.5, 0.5}, {0.8, -0.5, 0.5}, {0.8, 0.5, 0.5},
                                    {0.2, 0.5, 0.5}));
    EXPECT_TRUE(through.contact);
    EXPECT_TRUE(through.interior_contact);
    EXPECT_FALSE(bounded(RadianceStrategy::LightSolidAngle, through));
    // BSDF sampling and MIS are bounded whatever the contacts.
    for (RadianceStrategy s : {RadianceStrategy::Bsdf, RadianceStrategy::MisBalance,
                               RadianceStrategy::MisPower, RadianceStrategy::CosineHemisphere,
                               RadianceStrategy::UniformHemisphere, RadianceStrategy::Path})
        EXPECT_TRUE(bounded(s, through)) << strategy_name(s);
}

json study(const std::string& name, json options) {
    options["base_dir"] = test::kScenes;
    char* out = nullptr;
    const std::string scene = test::read(test::kScenes + "/" + name + ".json");
    const int st =
        mcp_render_study_run(scene.c_str(), options.dump().c_str(), nullptr, nullptr, &out);
    EXPECT_EQ(st, MCP_OK) << mcp_last_error();
    json j = out ? json::parse(out) : json();
    mcp_free(out);
    return j;
}

/// The severity of the estimator's heavy_tail warning, or "" without one.
std::string heavy_tail_severity(const json& estimator) {
    for (const json& w : estimator["warnings"])
        if (w["code"] == "heavy_tail") return w["severity"];
    return "";
}

const json& estimator(const json& result, const std::string& name) {
    for (const json& e : result["estimators"])
        if (e["name"] == name) return e;
    static const json none;
    ADD_FAILURE() << "no estimator " << name;
    return none;
}

// The false alarms of issue 48 (Veach's scene and the touching light at their default studies
// flagged MIS, solid-angle and (Veach) area sampling at warning, tail indices 1.1-1.6): their
// contributions are bounded, so heavy_tail is at most info; the tail estimate still reads below
// 2 on some of them, which is what the test needs to be judged. Area sampling of the light that
// touches the floor keeps the warning.
TEST(RenderBounds, BoundedEstimatorsGetNoHeavyTailWarning) {
    const json veach = study("veach_mis", json{{"seed", 1}});
    int read_heavy = 0;
    for (const char* name : {"light_area", "light_solid_angle", "bsdf", "mis_balance",
                             "mis_power"}) {
        const json& e = estimator(veach, name);
        EXPECT_TRUE(e["contribution_bound"]["bounded"].get<bool>()) << name;
        EXPECT_NE(heavy_tail_severity(e), "warning") << name << e["warnings"].dump();
        read_heavy += heavy_tail_severity(e) == "info";
    }
    EXPECT_GE(read_heavy, 2) << "the tail estimate no longer reads heavy: the test judges nothing";
    const json touching = study("touching_light", json{{"seed", 1}});
    for (const char* name : {"light_solid_angle", "mis_power", "bsdf", "cosine_hemisphere"})
        EXPECT_NE(heavy_tail_severity(estimator(touching, name)), "warning") << name;
    const json& area = estimator(touching, "light_area");
    EXPECT_FALSE(area["contribution_bound"]["bounded"].get<bool>());
    EXPECT_EQ(heavy_tail_severity(area), "warning") << area["warnings"].dump();
}

// Infinite variance, provably: area sampling at the perpendicular plates' shared edge (tail
// index 1.5, docs/render-scenes.md) is flagged at warning at the scene's default study.
TEST(RenderBounds, AreaSamplingAtAContactEdgeIsFlagged) {
    const json plates = study("perpendicular_plates", json{{"seed", 1}});
    const json& area = estimator(plates, "light_area");
    EXPECT_FALSE(area["contribution_bound"]["bounded"].get<bool>());
    EXPECT_EQ(heavy_tail_severity(area), "warning") << area["warnings"].dump();
    for (const char* name : {"light_solid_angle", "mis_power", "cosine_hemisphere"})
        EXPECT_NE(heavy_tail_severity(estimator(plates, name)), "warning") << name;
}

/// The result of a C API call that writes `out` (mcp_render_study_run, _merge), or the error.
template <class F> json call(F&& f) {
    char* out = nullptr;
    const int status = f(&out);
    json j = status == MCP_OK && out ? json::parse(out) : json{{"error", mcp_last_error()}};
    mcp_free(out);
    return j;
}

// A split study's parts carry the bound, and their merge keeps it (the page merges parts):
// the perpendicular plates' area sampling stays unbounded, solid-angle sampling bounded. A
// malformed bound in a part is refused, naming it.
TEST(RenderBounds, MergedPartsKeepTheBound) {
    const std::string scene = test::read(test::kScenes + "/perpendicular_plates.json");
    json parts = json::array();
    for (int part = 0; part < 2; ++part) {
        const json options{{"base_dir", test::kScenes}, {"width", 8},     {"height", 8},
                           {"spp_max", 4},              {"reps", 2},      {"part", part},
                           {"parts", 2},                {"reference", {{"spp", 64}}},
                           {"estimators", {"light_area", "light_solid_angle"}}};
        parts.push_back(call([&](char** out) {
            return mcp_render_study_run(scene.c_str(), options.dump().c_str(), nullptr, nullptr,
                                        out);
        }));
        ASSERT_FALSE(parts.back().contains("error")) << parts.back()["error"];
    }
    auto merge = [&] {
        const std::string text = json{{"parts", parts}}.dump();
        return call([&](char** out) { return mcp_render_study_merge(text.c_str(), out); });
    };
    const json merged = merge();
    ASSERT_FALSE(merged.contains("error")) << merged["error"];
    EXPECT_FALSE(estimator(merged, "light_area")["contribution_bound"]["bounded"].get<bool>());
    EXPECT_TRUE(
        estimator(merged, "light_solid_angle")["contribution_bound"]["bounded"].get<bool>());
    for (json& p : parts) p["estimators"][0]["contribution_bound"]["bounded"] = "yes";
    const json refused = merge();
    ASSERT_TRUE(refused.contains("error"));
    EXPECT_NE(refused["error"].get<std::string>().find("contribution_bound"), std::string::npos)
        << refused["error"];
}

} // namespace
} // namespace mcp
