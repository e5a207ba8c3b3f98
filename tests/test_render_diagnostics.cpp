// Render diagnostics judged both ways (issue 48): estimators whose per-sample contributions are
// bounded by construction (docs/render-scenes.md, "Bounded contributions") never get heavy_tail
// as a warning, and area sampling of a light that touches what it lights (infinite variance) is
// still flagged. The contact test itself is judged on scenes built in code.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/contribution_bound.h"
#include "render/render_study.h"
#include "render/renderer.h"
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

ContributionBound bound_of(RadianceStrategy strategy, const LightContacts& c) {
    RenderEstimator e;
    e.strategy = strategy;
    return contribution_bound(e, c);
}

bool bounded(RadianceStrategy strategy, const LightContacts& c) {
    return bound_of(strategy, c).bounded;
}

/// The bundled furnace's view (docs/render-scenes.md): from (0, 0, 0.5) down -z with a
/// vertical field of view of 1 rad, it sees only the inside of the back wall, 0.18 from the
/// other walls.
Camera back_wall_view() {
    return test::look_at({0, 0, 0.5}, {0, 0, -1}, {0, 1, 0}, 1.0);
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
    EXPECT_TRUE(
        contacts_of(floor_and_light({0, 1e-6, 0}, {1, 1e-6, 0}, {1, 1, 0}, {0, 1, 0})).contact);
    // A light facing the floor 1e-4 above it (touching_light): a contact for area sampling,
    // but not within the vertices' rounding of the light's inside: solid angles stay below
    // 2 pi by far more than 1e-12, and solid-angle sampling stays bounded.
    const LightContacts hovering = contacts_of(floor_and_light(
        {0.25, 1e-4, 0.25}, {0.75, 1e-4, 0.25}, {0.75, 1e-4, 0.75}, {0.25, 1e-4, 0.75}));
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
    const LightContacts through = contacts_of(
        floor_and_light({0.2, -0.5, 0.5}, {0.8, -0.5, 0.5}, {0.8, 0.5, 0.5}, {0.2, 0.5, 0.5}));
    EXPECT_TRUE(through.contact);
    EXPECT_TRUE(through.interior_contact);
    EXPECT_FALSE(bounded(RadianceStrategy::LightSolidAngle, through));
    // BSDF sampling and MIS are bounded whatever the contacts.
    for (RadianceStrategy s : {RadianceStrategy::Bsdf, RadianceStrategy::MisBalance,
                               RadianceStrategy::MisPower, RadianceStrategy::CosineHemisphere,
                               RadianceStrategy::UniformHemisphere, RadianceStrategy::Path})
        EXPECT_TRUE(bounded(s, through)) << strategy_name(s);
}

// Where area sampling's variance is infinite (docs/render-scenes.md, "Bounded contributions"):
// a light touching a surface that reflects, facing it, where the camera sees it. The furnace's
// walls touch at every edge: infinite seen from inside the corner, bounded seen only facing a
// wall's middle (its edges out of view). Two emitting facets at a shallow angle (the sphere
// interior's in miniature): infinite when they reflect, no contact at all when they are black.
TEST(RenderBounds, ContactsCountWhereTheCameraSeesThemAndTheyReflect) {
    Scene corner = test::furnace_box(0.5, 1.0, 4); // its camera sees the floor's far edges
    const LightContacts seen = contacts_of(corner);
    EXPECT_TRUE(seen.contact);
    EXPECT_TRUE(seen.seen_contact);
    const ContributionBound area = bound_of(RadianceStrategy::LightArea, seen);
    EXPECT_FALSE(area.bounded);
    EXPECT_TRUE(area.infinite_variance) << area.reason;
    Scene wall = corner;
    wall.camera = back_wall_view();
    const LightContacts unseen = contacts_of(wall);
    EXPECT_FALSE(unseen.contact);
    EXPECT_FALSE(unseen.seen_contact);
    EXPECT_GT(unseen.ignored, 0u);
    EXPECT_TRUE(bounded(RadianceStrategy::LightArea, unseen));
    EXPECT_FALSE(bound_of(RadianceStrategy::LightArea, unseen).infinite_variance);
    // A wider view of the same wall reaches its edges.
    wall.camera.yfov = 2.0;
    EXPECT_TRUE(contacts_of(wall).seen_contact);

    // Facets y = 0 and one tilted by 10 degrees about their shared edge x = 0, both facing up
    // and emitting, seen from above the crease.
    auto facets = [](Material m) {
        Scene s;
        m.emission = Vec3(1.0);
        s.materials = {m};
        const double c = std::cos(0.1745), sn = std::sin(0.1745);
        add_quad(s, {-1, 0, 0}, {-1, 0, 1}, {0, 0, 1}, {0, 0, 0}, 0);
        add_quad(s, {0, 0, 0}, {0, 0, 1}, {c, sn, 1}, {c, sn, 0}, 0);
        s.camera = test::look_at({0, 1, 0.5}, {0, 0, 0.5}, {0, 0, -1}, 1.0);
        return s;
    };
    const LightContacts reflecting = contacts_of(facets(diffuse(0.5)));
    EXPECT_TRUE(reflecting.seen_contact);
    EXPECT_TRUE(bound_of(RadianceStrategy::LightArea, reflecting).infinite_variance);
    const LightContacts black = contacts_of(facets(diffuse(0.0)));
    EXPECT_FALSE(black.contact);
    EXPECT_GT(black.ignored, 0u);
    EXPECT_TRUE(bounded(RadianceStrategy::LightArea, black));

    // The perpendicular plates' wall light turned to face away from the floor: a contact in
    // view, but nothing it emits reaches the floor near it: not infinite by construction (the
    // tail estimate decides).
    const LightContacts back =
        contacts_of(floor_and_light({0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}));
    EXPECT_TRUE(back.contact);
    EXPECT_FALSE(back.seen_contact);
    // ... and facing it, but the camera turned away from the contact.
    Scene away = floor_and_light({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
    EXPECT_TRUE(contacts_of(away).seen_contact);
    away.camera = test::look_at({0.5, 1, 2}, {0.5, 1, 4}, {0, 1, 0}, 1.0);
    EXPECT_FALSE(contacts_of(away).contact);
}

/// Area sampling's flags over a study of `s` (size x size pixels, 1 to spp, 2 images) against a
/// reference rendered by MIS at 256 spp; its tail index at the deepest level in *tail_index.
std::vector<Flag> area_flags(const Scene& s, double* tail_index, int size = 16, uint64_t spp = 16) {
    RenderScene rs;
    rs.build(s);
    RenderEstimator mis;
    mis.strategy = RadianceStrategy::MisPower;
    RenderSettings ref;
    ref.width = ref.height = size;
    ref.spp = 256;
    ref.threads = 1;
    const RenderImage reference = render_image(rs, mis, ref);
    RenderEstimator area;
    area.strategy = RadianceStrategy::LightArea;
    area.name = "light_area";
    RenderStudySettings st;
    st.width = st.height = size;
    st.spp_min = 1;
    st.spp_max = spp;
    st.reps = 2;
    st.threads = 1;
    const RenderStudyResult r = run_render_study(rs, {area}, st, reference);
    *tail_index = r.estimators[0].levels.back().tail_index;
    return render_flags(r.estimators[0], r.relative_mse_floor);
}

Severity severity_of(const std::vector<Flag>& flags, FlagCode code) {
    for (const Flag& f : flags)
        if (f.code == code) return f.severity;
    return Severity::Info; // absent: no more than info
}

bool has(const std::vector<Flag>& flags, FlagCode code) {
    for (const Flag& f : flags)
        if (f.code == code) return true;
    return false;
}

/// A triangular light standing on its tip on the unit floor, leaning over it and facing it,
/// seen from inside the wedge between them: a corner contact, where the second moment of area
/// sampling diverges as a logarithm (docs/render-scenes.md).
Scene light_on_its_tip() {
    Scene s;
    s.materials = {diffuse(0.5), emitter()};
    add_quad(s, {0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, 0);
    for (const Vec3& p : {Vec3(0.5, 0, 0.5), Vec3(0.8, 0.4, 0.1), Vec3(0.2, 0.4, 0.1)})
        s.mesh.position.push_back(p);
    s.mesh.index.push_back({4, 5, 6}); // faces (0, -1, -1): the floor below it
    s.mesh.material.push_back(1);
    s.camera = test::look_at({0.5, 0.2, 0.0}, {0.5, 0, 0.5}, {0, 1, 0}, 1.0);
    return s;
}

// Infinite by construction, flagged whatever the tail estimate reads: the furnace seen from
// inside a corner (the tail reads below 2 as well), and the light on its tip in a study too
// small for a tail estimate (4 x 4 pixels, 2 spp, 2 images: 64 samples, Hill's estimate needs
// 128), where only the construction can say it. Seen facing one wall's middle, the furnace is
// bounded and gets no heavy_tail warning.
TEST(RenderBounds, InfiniteByConstructionIsFlaggedWhateverTheTailReads) {
    double tail = 0.0;
    const std::vector<Flag> corner = area_flags(test::furnace_box(0.5, 1.0, 4), &tail);
    ASSERT_TRUE(has(corner, FlagCode::HeavyTail));
    EXPECT_EQ(severity_of(corner, FlagCode::HeavyTail), Severity::Warning);
    const Scene tip = light_on_its_tip();
    ASSERT_TRUE(contacts_of(tip).seen_contact);
    const std::vector<Flag> small = area_flags(tip, &tail, 4, 2);
    EXPECT_FALSE(tail < 2.0) << "the tail estimate sees it: the test judges nothing";
    ASSERT_TRUE(has(small, FlagCode::HeavyTail));
    EXPECT_EQ(severity_of(small, FlagCode::HeavyTail), Severity::Warning);
    Scene wall = test::furnace_box(0.5, 1.0, 4);
    wall.camera = back_wall_view();
    EXPECT_NE(severity_of(area_flags(wall, &tail), FlagCode::HeavyTail), Severity::Warning);
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
    for (const char* name :
         {"light_area", "light_solid_angle", "bsdf", "mis_balance", "mis_power"}) {
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
    EXPECT_TRUE(area["contribution_bound"]["infinite_variance"].get<bool>());
    EXPECT_EQ(heavy_tail_severity(area), "warning") << area["warnings"].dump();
    for (const char* name : {"light_solid_angle", "mis_power", "cosine_hemisphere"})
        EXPECT_NE(heavy_tail_severity(estimator(plates, name)), "warning") << name;
}

// The bundled furnace and sphere interior (docs/render-scenes.md): the furnace's camera sees
// only the back wall's middle, the sphere's emitting facets are black and its square is far
// from them: area sampling is bounded on both, and neither gets heavy_tail as a warning.
TEST(RenderBounds, BundledFurnaceAndSphereAreBounded) {
    for (const char* name : {"furnace_box", "sphere_interior"}) {
        const json r = study(name, json{{"seed", 1}, {"estimators", {"light_area"}}});
        const json& area = estimator(r, "light_area");
        EXPECT_TRUE(area["contribution_bound"]["bounded"].get<bool>()) << name;
        EXPECT_FALSE(area["contribution_bound"]["infinite_variance"].get<bool>()) << name;
        EXPECT_NE(heavy_tail_severity(area), "warning") << name;
    }
}

/// The severity of the estimator's warning `code`, or "" without one.
std::string severity(const json& estimator, const std::string& code) {
    for (const json& w : estimator["warnings"])
        if (w["code"] == code) return w["severity"];
    return "";
}

// The tail-type flags judged against the bound: bounded samples make terms of finite variance,
// so rare_large_errors and slow_convergence are info on them (Veach's scene and the touching
// light at their default studies raise both on bounded estimators); area sampling at the
// touching light (not bounded) and at the perpendicular plates' edge (infinite variance) keeps
// them as warnings.
TEST(RenderBounds, TailTypeFlagsAreInfoForBoundedSamples) {
    const std::vector<std::string> tail_type = {"heavy_tail", "rare_large_errors",
                                                "slow_convergence"};
    std::map<std::string, int> raised;
    for (const char* scene : {"veach_mis", "touching_light"}) {
        const json r = study(scene, json{{"seed", 1}});
        for (const json& e : r["estimators"]) {
            if (!e["contribution_bound"]["bounded"].get<bool>()) continue;
            for (const std::string& code : tail_type) {
                EXPECT_NE(severity(e, code), "warning") << scene << " " << e["name"] << code;
                raised[code] += severity(e, code) == "info";
            }
        }
        if (std::string(scene) == "touching_light") {
            const json& area = estimator(r, "light_area");
            ASSERT_FALSE(area["contribution_bound"]["bounded"].get<bool>());
            for (const char* code : {"heavy_tail", "rare_large_errors"})
                EXPECT_EQ(severity(area, code), "warning") << code << area["warnings"].dump();
        }
    }
    // slow_convergence of the touching light's area sampling at seed 2 (at seed 1 its fit is
    // within 3 standard errors of -1).
    const json touching = study("touching_light", json{{"seed", 2}});
    EXPECT_EQ(severity(estimator(touching, "light_area"), "slow_convergence"), "warning");
    for (const std::string& code : tail_type)
        EXPECT_GE(raised[code], 1) << code << " no longer fires: the test judges nothing";
    const json plates = study("perpendicular_plates", json{{"seed", 1}});
    EXPECT_EQ(severity(estimator(plates, "light_area"), "rare_large_errors"), "warning");
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
// the perpendicular plates' area sampling stays infinite by construction, solid-angle sampling
// bounded. A malformed bound in a part is refused, naming it.
TEST(RenderBounds, MergedPartsKeepTheBound) {
    const std::string scene = test::read(test::kScenes + "/perpendicular_plates.json");
    json parts = json::array();
    for (int part = 0; part < 2; ++part) {
        const json options{{"base_dir", test::kScenes},
                           {"width", 8},
                           {"height", 8},
                           {"spp_max", 4},
                           {"reps", 2},
                           {"part", part},
                           {"parts", 2},
                           {"reference", {{"spp", 64}}},
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
        estimator(merged, "light_area")["contribution_bound"]["infinite_variance"].get<bool>());
    EXPECT_TRUE(
        estimator(merged, "light_solid_angle")["contribution_bound"]["bounded"].get<bool>());
    // Bounded and infinite at once, or a bound that is not a boolean, is refused.
    for (json& p : parts) p["estimators"][0]["contribution_bound"]["bounded"] = true;
    const json both = merge();
    ASSERT_TRUE(both.contains("error"));
    EXPECT_NE(both["error"].get<std::string>().find("not both true"), std::string::npos)
        << both["error"];
    for (json& p : parts) p["estimators"][0]["contribution_bound"]["bounded"] = "yes";
    const json refused = merge();
    ASSERT_TRUE(refused.contains("error"));
    EXPECT_NE(refused["error"].get<std::string>().find("contribution_bound"), std::string::npos)
        << refused["error"];
}

} // namespace
} // namespace mcp
