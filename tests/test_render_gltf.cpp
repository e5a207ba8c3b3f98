// glTF loading: the generated render scenes (counts, bounds, emitter winding, cameras, closed
// forms they are built for), transforms and winding of node hierarchies, index types and
// topologies, materials, textures, GLB and external buffers, warnings for ignored features,
// and a table of malformed files that must fail with an error naming the offending element.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <stb_image_write.h>

#include "core/rng.h"
#include "render_api/gltf_scene.h"

using namespace mcp;
using json = nlohmann::json;

namespace {

constexpr double kPi = 3.14159265358979323846;

// --- Helpers ---------------------------------------------------------------------------------

std::string scene_path(const std::string& name) {
    return std::string(MCPLAY_SOURCE_DIR) + "/scenes/" + name;
}

bool has_substring(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

std::string joined(const std::vector<std::string>& lines) {
    std::string s;
    for (const std::string& l : lines) s += l + "\n";
    return s;
}

double area(const Mesh& m, size_t t) {
    return 0.5 * glm::length(m.cross_normal(t));
}

Vec3 centroid(const Mesh& m, size_t t) {
    return (m.vertex(t, 0) + m.vertex(t, 1) + m.vertex(t, 2)) / 3.0;
}

/// Möller-Trumbore ray-triangle distance, or infinity.
double intersect(const Mesh& m, size_t t, const Vec3& o, const Vec3& d) {
    const Vec3 &p0 = m.vertex(t, 0), &p1 = m.vertex(t, 1), &p2 = m.vertex(t, 2);
    Vec3 e1 = p1 - p0, e2 = p2 - p0;
    Vec3 p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    if (std::fabs(det) < 1e-300) return INFINITY;
    Vec3 s = o - p0;
    double b1 = glm::dot(s, p) / det;
    Vec3 q = glm::cross(s, e1);
    double b2 = glm::dot(d, q) / det;
    double dist = glm::dot(e2, q) / det;
    if (b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || !(dist > 1e-9)) return INFINITY;
    return dist;
}

/// The first triangle a ray hits (brute force), or -1.
long first_hit(const Mesh& m, const Vec3& o, const Vec3& d) {
    double best = INFINITY;
    long hit = -1;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
        double dist = intersect(m, t, o, d);
        if (dist < best) best = dist, hit = long(t);
    }
    return hit;
}

/// Direction of the camera ray through image point (sx, sy) in [-1, 1]^2 for an aspect ratio.
Vec3 camera_ray(const Camera& c, double sx, double sy, double aspect) {
    double h = std::tan(0.5 * c.yfov);
    return glm::normalize(c.forward + c.right * (sx * h * aspect) + c.up * (sy * h));
}

/// Every directed edge of a closed, consistently wound mesh appears once, its reverse once.
bool closed_and_consistent(const Mesh& m) {
    // Positions are welded by value: the generator shares vertices only within a face.
    std::map<std::array<double, 3>, uint32_t> ids;
    auto id = [&ids](const Vec3& p) {
        auto key = std::array<double, 3>{p.x, p.y, p.z};
        return ids.emplace(key, uint32_t(ids.size())).first->second;
    };
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t t = 0; t < m.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k) ++edges[{id(m.vertex(t, k)), id(m.vertex(t, (k + 1) % 3))}];
    for (const auto& e : edges) {
        if (e.second != 1) return false;
        auto rev = edges.find({e.first.second, e.first.first});
        if (rev == edges.end() || rev->second != 1) return false;
    }
    return true;
}

// --- The generated scenes --------------------------------------------------------------------

struct SceneSpec {
    const char* file;
    size_t triangles, emissive_triangles;
    Vec3 lo, hi;      ///< bounding box of all vertices
    Vec3 centre;      ///< a point every emitter must face
    Vec3 eye, target; ///< camera, as the generator places it
    double yfov;
};

std::vector<SceneSpec> scene_specs() {
    const double d2 = 2.0 * kPi / 180.0;
    // Triangle counts from the constructions in scenes/tools/make_render_scenes.mjs: a quad is
    // 2 triangles, an n x n grid 2 n^2, a bottomless box 5 faces, the level-3 icosphere 20 * 4^3.
    const double mirror_light_dy = 0.15 * 0.6 / std::hypot(0.6, 1.19);
    return {
        {"quad_light_floor.gltf",
         2 + 2,
         2,
         {-2, 0, -2},
         {2, 1, 2},
         {0, 0, 0},
         {0, 0.95, 1.6},
         {0, 0, 1.6 - 0.95 / std::tan(34.0 * kPi / 180.0)},
         0.6},
        {"cornell_box.gltf",
         5 * 2 * 16 * 16 + 2 * 5 * 2 * 4 * 4 + 2,
         2,
         {-0.5, 0, -0.5},
         {0.5, 1, 0.5},
         {0, 0.5, 0},
         {0, 0.5, 1.94},
         {0, 0.5, 0},
         39.3 * kPi / 180.0},
        {"veach_mis.gltf",
         4 * 2 + 4 * 2 + 2 + 2,
         4 * 2,
         {-10, -4, -4},
         {10, 8, 16},
         {0, -3, 1.7},
         {0, 2, 15},
         {0, -2.2, 2.5},
         0.46},
        {"tiny_bright_light.gltf",
         2 + 5 * 2 + 2,
         2,
         {-2, 0, -2},
         {2, 1.5, 2},
         {0, 0, 0},
         {0, 1.6, 2.6},
         {0, 0.2, 0},
         0.7},
        {"near_mirror.gltf",
         2 + 2 + 2,
         2,
         {-2, 0, -2},
         {2, 1.2 + mirror_light_dy, 2},
         {0, 0.01, 0},
         {0, 0, 0},
         {0, 0.01, 0},
         0.6}, // eye checked separately
        {"grazing_light.gltf",
         2 * 20 * 2 + 2,
         2,
         {-1, 0, -10},
         {1, 0.05 + 0.5 * std::sin(d2), 0.7 + 0.5 * std::cos(d2)},
         {0, 0, -5},
         {0, 1.2, 2},
         {0, 0, -2.5},
         0.7},
        {"touching_light.gltf",
         2 + 2,
         2,
         {-1, 0, -1},
         {1, 1e-4, 1},
         {0, 0, 0},
         {0, 0.9, 1.3},
         {0, 0, 0.15},
         0.6},
        {"perpendicular_plates.gltf",
         2 + 2,
         2,
         {0, 0, 0},
         {1, 1, 1},
         {0.5, 0, 0.5},
         {0.5, 1.3, 2.3},
         {0.5, 0.1, 0.45},
         0.7},
        {"furnace_box.gltf",
         6 * 2 * 4 * 4,
         6 * 2 * 4 * 4,
         {-1, -1, -1},
         {1, 1, 1},
         {0, 0, 0},
         {0, 0, 0.5},
         {0, 0, -1},
         1.0},
        {"sphere_interior.gltf",
         20 * 64 + 2,
         20 * 64,
         {-1, -1, -1},
         {1, 1, 1},
         {0, 0, 0},
         {0, 0, 0.6},
         {0, 0, 0},
         0.5},
    };
}

GltfLoadResult load_scene(const std::string& file) {
    return load_gltf_file(scene_path(file));
}

TEST(RenderGltfScenes, LoadWithCountsBoundsEmittersAndCameras) {
    for (const SceneSpec& spec : scene_specs()) {
        SCOPED_TRACE(spec.file);
        GltfLoadResult r = load_scene(spec.file);
        ASSERT_TRUE(r.ok) << r.error;
        EXPECT_TRUE(r.warnings.empty()) << joined(r.warnings);
        EXPECT_TRUE(r.has_camera);
        EXPECT_TRUE(has_substring(r.extras_json, "description")) << r.extras_json;
        const Mesh& m = r.scene.mesh;
        ASSERT_EQ(m.triangle_count(), spec.triangles);
        ASSERT_EQ(m.material.size(), spec.triangles);
        EXPECT_TRUE(m.normal.empty()); // the generator writes flat geometry only
        EXPECT_TRUE(m.uv.empty());

        Vec3 lo(INFINITY), hi(-INFINITY);
        for (const Vec3& p : m.position) lo = glm::min(lo, p), hi = glm::max(hi, p);
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(lo[k], spec.lo[k], 1e-6) << "axis " << k;
            EXPECT_NEAR(hi[k], spec.hi[k], 1e-6) << "axis " << k;
        }

        // Non-metals are pure Lambertian (no Fresnel layer), metals keep the default.
        for (const Material& mat : r.scene.materials)
            EXPECT_EQ(mat.specular, mat.metallic == 0.0 ? 0.0 : 1.0) << mat.name;

        size_t emissive = 0;
        for (size_t t = 0; t < m.triangle_count(); ++t) {
            ASSERT_LT(m.material[t], r.scene.materials.size());
            EXPECT_GT(area(m, t), 0.0);
            if (!r.scene.materials[m.material[t]].is_emissive()) continue;
            ++emissive;
            EXPECT_GT(glm::dot(m.cross_normal(t), spec.centre - centroid(m, t)), 0.0)
                << "emitter triangle " << t << " faces away from the scene";
        }
        EXPECT_EQ(emissive, spec.emissive_triangles);

        const Camera& c = r.scene.camera;
        EXPECT_NEAR(c.yfov, spec.yfov, 1e-12);
        EXPECT_NEAR(glm::length(c.forward), 1.0, 1e-12);
        EXPECT_NEAR(glm::length(c.right), 1.0, 1e-12);
        EXPECT_NEAR(glm::length(c.up), 1.0, 1e-12);
        EXPECT_NEAR(glm::dot(c.forward, c.up), 0.0, 1e-12);
        EXPECT_NEAR(glm::dot(c.forward, c.right), 0.0, 1e-12);
        EXPECT_LT(glm::length(glm::cross(c.right, c.up) + c.forward), 1e-12); // right-handed
        EXPECT_NEAR(c.right.y, 0.0, 1e-12); // no roll: the generator's up is +y
        EXPECT_GT(c.up.y, 0.0);
        if (std::string(spec.file) != "near_mirror.gltf") {
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(c.position[k], spec.eye[k], 1e-12);
            Vec3 f = glm::normalize(spec.target - spec.eye);
            EXPECT_LT(glm::length(c.forward - f), 1e-9);
        }
    }
}

const Material& material_named(const Scene& s, const std::string& name) {
    for (const Material& m : s.materials)
        if (m.name == name) return m;
    ADD_FAILURE() << "no material " << name;
    static Material none;
    return none;
}

TEST(RenderGltfScenes, QuadLightFloorCameraSeesOnlyTheFloor) {
    GltfLoadResult r = load_scene("quad_light_floor.gltf");
    ASSERT_TRUE(r.ok) << r.error;
    const Scene& s = r.scene;
    EXPECT_EQ(material_named(s, "light").emission, Vec3(5.0));
    EXPECT_EQ(material_named(s, "light").base_color, Vec3(0.0));
    const Material& floor = material_named(s, "floor");
    EXPECT_EQ(floor.base_color, Vec3(0.5));
    EXPECT_EQ(floor.metallic, 0.0);
    EXPECT_EQ(floor.roughness, 1.0);
    // Rays over the whole image (aspect 1.5) all hit the floor first.
    for (int i = 0; i <= 8; ++i)
        for (int j = 0; j <= 8; ++j) {
            Vec3 d = camera_ray(s.camera, i / 4.0 - 1.0, j / 4.0 - 1.0, 1.5);
            long t = first_hit(s.mesh, s.camera.position, d);
            ASSERT_GE(t, 0) << i << "," << j;
            EXPECT_EQ(s.materials[s.mesh.material[size_t(t)]].name, "floor") << i << "," << j;
        }
    // The light: 1 x 1 m at height 1.
    double light_area = 0.0;
    for (size_t t = 0; t < s.mesh.triangle_count(); ++t)
        if (s.materials[s.mesh.material[t]].is_emissive()) {
            light_area += area(s.mesh, t);
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.mesh.vertex(t, k).y, 1.0, 1e-7);
        }
    EXPECT_NEAR(light_area, 1.0, 1e-6);
}

TEST(RenderGltfScenes, CornellBoxMaterialsAndView) {
    GltfLoadResult r = load_scene("cornell_box.gltf");
    ASSERT_TRUE(r.ok) << r.error;
    const Scene& s = r.scene;
    EXPECT_LT(glm::length(material_named(s, "light").emission - Vec3(17, 12, 4)), 1e-12);
    EXPECT_EQ(material_named(s, "white").base_color, Vec3(0.73));
    EXPECT_EQ(material_named(s, "red").base_color, Vec3(0.63, 0.065, 0.05));
    EXPECT_EQ(material_named(s, "green").base_color, Vec3(0.14, 0.45, 0.09));
    // The centre ray hits the back wall (white) at z = -0.5; rays to the left and right image
    // edges at mid height hit the red and green walls.
    auto hit_material = [&s](const Vec3& d, double* z) {
        long t = first_hit(s.mesh, s.camera.position, d);
        if (t < 0) return std::string("none");
        if (z) *z = centroid(s.mesh, size_t(t)).z;
        return s.materials[s.mesh.material[size_t(t)]].name;
    };
    double z = 0.0;
    EXPECT_EQ(hit_material(camera_ray(s.camera, 0.0, 0.3, 1.0), &z), "white");
    EXPECT_NEAR(z, -0.5, 1e-6);
    EXPECT_EQ(hit_material(camera_ray(s.camera, -0.9, 0.2, 1.0), nullptr), "red");
    EXPECT_EQ(hit_material(camera_ray(s.camera, 0.9, 0.2, 1.0), nullptr), "green");
    // The blocks stand on the floor, inside the box, and do not intersect each other: their
    // top faces (white, normal +y, below the ceiling) are at 0.3 and 0.6 m.
    std::set<double> tops;
    for (size_t t = 0; t < s.mesh.triangle_count(); ++t) {
        Vec3 n = glm::normalize(s.mesh.cross_normal(t));
        double y = centroid(s.mesh, t).y;
        if (n.y > 0.999 && y > 0.01 && y < 0.99) tops.insert(std::round(y * 1e6) / 1e6);
    }
    EXPECT_EQ(tops, (std::set<double>{0.3, 0.6}));
}

TEST(RenderGltfScenes, VeachPlatesMirrorEveryLightAndLightsHaveEqualPower) {
    GltfLoadResult r = load_scene("veach_mis.gltf");
    ASSERT_TRUE(r.ok) << r.error;
    const Scene& s = r.scene;
    const Mesh& m = s.mesh;
    // Power of each light: area x radiance (white) must be the same, 1.44 W/sr.
    std::map<uint32_t, double> power;
    std::map<uint32_t, Vec3> light_centre;
    std::map<uint32_t, int> light_tris;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
        const Material& mat = s.materials[m.material[t]];
        if (!mat.is_emissive()) continue;
        EXPECT_EQ(mat.emission.x, mat.emission.z);
        power[m.material[t]] += area(m, t) * mat.emission.x;
        light_centre[m.material[t]] += centroid(m, t);
        ++light_tris[m.material[t]];
    }
    ASSERT_EQ(power.size(), 4u);
    for (const auto& p : power) EXPECT_NEAR(p.second, 1.44, 1.44 * 1e-5);
    // Plate roughness = sqrt(alpha), alpha = 0.005, 0.02, 0.05, 0.1.
    const double alphas[4] = {0.005, 0.02, 0.05, 0.1};
    for (int i = 0; i < 4; ++i) {
        std::string name = "plate " + std::to_string(i) + " (alpha ";
        const Material* plate = nullptr;
        for (const Material& mat : s.materials)
            if (mat.name.compare(0, name.size(), name) == 0) plate = &mat;
        ASSERT_NE(plate, nullptr) << name;
        EXPECT_NEAR(plate->roughness * plate->roughness, alphas[i], 1e-15);
        EXPECT_EQ(plate->metallic, 1.0);
    }
    // Each plate mirrors the centre of each light toward the camera: the camera mirrored in
    // the plate's plane sees the light's centre through the plate, and the camera sees that
    // point of the plate directly.
    std::map<uint32_t, std::vector<size_t>> plates;
    for (size_t t = 0; t < m.triangle_count(); ++t)
        if (s.materials[m.material[t]].metallic == 1.0) plates[m.material[t]].push_back(t);
    ASSERT_EQ(plates.size(), 4u);
    for (const auto& plate : plates) {
        size_t t0 = plate.second[0];
        Vec3 n = glm::normalize(m.cross_normal(t0));
        Vec3 p0 = m.vertex(t0, 0);
        Vec3 eye = s.camera.position;
        Vec3 mirrored = eye - 2.0 * glm::dot(eye - p0, n) * n;
        for (const auto& light : light_centre) {
            Vec3 c = light.second / double(light_tris[light.first]);
            Vec3 d = c - mirrored;
            double dist = INFINITY;
            for (size_t t : plate.second) dist = std::fmin(dist, intersect(m, t, mirrored, d));
            ASSERT_LT(dist, 1.0) << "plate material " << plate.first << " misses a light";
            Vec3 point = mirrored + dist * d;
            long seen = first_hit(m, eye, point - eye);
            ASSERT_GE(seen, 0);
            EXPECT_EQ(m.material[size_t(seen)], plate.first);
        }
    }
}

TEST(RenderGltfScenes, SpecialGeometry) {
    {
        GltfLoadResult r = load_scene("tiny_bright_light.gltf");
        ASSERT_TRUE(r.ok) << r.error;
        double a = 0.0, le = 0.0;
        for (size_t t = 0; t < r.scene.mesh.triangle_count(); ++t)
            if (r.scene.materials[r.scene.mesh.material[t]].is_emissive()) {
                a += area(r.scene.mesh, t);
                le = r.scene.materials[r.scene.mesh.material[t]].emission.x;
            }
        EXPECT_NEAR(a, 1e-6, 1e-9); // 1 mm square (float32 positions near 1.5 m)
        EXPECT_EQ(le, 1e6);
    }
    {
        GltfLoadResult r = load_scene("near_mirror.gltf");
        ASSERT_TRUE(r.ok) << r.error;
        const Material& plate = material_named(r.scene, "near mirror");
        double alpha = plate.roughness * plate.roughness;
        EXPECT_GT(alpha, 1e-3);
        EXPECT_LT(alpha, 1.5e-3);
        EXPECT_EQ(plate.metallic, 1.0);
        // The camera sits on the mirror direction of the light's centre about the plate.
        const Camera& c = r.scene.camera;
        Vec3 light(-0.6, 1.2, 0.0), centre(0.0, 0.01, 0.0);
        Vec3 in = glm::normalize(centre - light);
        Vec3 out(in.x, -in.y, in.z);
        EXPECT_LT(glm::length(c.position - (centre + 2.0 * out)), 1e-12);
        EXPECT_LT(glm::length(c.forward + out), 1e-9);
    }
    {
        GltfLoadResult r = load_scene("grazing_light.gltf");
        ASSERT_TRUE(r.ok) << r.error;
        for (size_t t = 0; t < r.scene.mesh.triangle_count(); ++t)
            if (r.scene.materials[r.scene.mesh.material[t]].is_emissive()) {
                Vec3 n = glm::normalize(r.scene.mesh.cross_normal(t));
                EXPECT_NEAR(std::acos(-n.y) * 180.0 / kPi, 2.0, 1e-4); // 2 degrees off the floor
            }
    }
    {
        GltfLoadResult r = load_scene("touching_light.gltf");
        ASSERT_TRUE(r.ok) << r.error;
        for (size_t t = 0; t < r.scene.mesh.triangle_count(); ++t) {
            if (!r.scene.materials[r.scene.mesh.material[t]].is_emissive()) continue;
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(r.scene.mesh.vertex(t, k).y, 1e-4, 1e-11); // float32 of 1e-4
        }
    }
    {
        GltfLoadResult r = load_scene("perpendicular_plates.gltf");
        ASSERT_TRUE(r.ok) << r.error;
        // The shared edge y = z = 0 is in view (aspect 1).
        const Camera& c = r.scene.camera;
        Vec3 v = Vec3(0.5, 0.0, 0.0) - c.position;
        double h = std::tan(0.5 * c.yfov) * glm::dot(v, c.forward);
        EXPECT_LT(std::fabs(glm::dot(v, c.up)), h);
        EXPECT_LT(std::fabs(glm::dot(v, c.right)), h);
    }
    {
        GltfLoadResult r = load_scene("furnace_box.gltf");
        ASSERT_TRUE(r.ok) << r.error;
        ASSERT_EQ(r.scene.materials.size(), 1u);
        EXPECT_EQ(r.scene.materials[0].emission, Vec3(1.0));
        EXPECT_EQ(r.scene.materials[0].base_color, Vec3(0.5));
        EXPECT_TRUE(closed_and_consistent(r.scene.mesh));
    }
    {
        GltfLoadResult r = load_scene("sphere_interior.gltf");
        ASSERT_TRUE(r.ok) << r.error;
        Mesh sphere;
        for (size_t t = 0; t < r.scene.mesh.triangle_count(); ++t) {
            const Material& mat = r.scene.materials[r.scene.mesh.material[t]];
            if (!mat.is_emissive()) {
                EXPECT_EQ(mat.base_color, Vec3(0.8));
                continue;
            }
            EXPECT_EQ(mat.base_color, Vec3(0.0));
            uint32_t base = uint32_t(sphere.position.size());
            for (int k = 0; k < 3; ++k) {
                sphere.position.push_back(r.scene.mesh.vertex(t, k));
                EXPECT_NEAR(glm::length(r.scene.mesh.vertex(t, k)), 1.0, 1e-6);
            }
            sphere.index.push_back({base, base + 1, base + 2});
        }
        EXPECT_EQ(sphere.triangle_count(), 1280u);
        EXPECT_TRUE(closed_and_consistent(sphere));
    }
}

TEST(RenderGltfScenes, GeneratorOutputIsDeterministicText) {
    // The checked-in files parse as JSON with embedded buffers only (self-contained).
    for (const SceneSpec& spec : scene_specs()) {
        FILE* f = std::fopen(scene_path(spec.file).c_str(), "rb");
        ASSERT_NE(f, nullptr) << spec.file;
        std::string text;
        char buf[4096];
        size_t n;
        while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
        std::fclose(f);
        json j = json::parse(text);
        ASSERT_EQ(j["buffers"].size(), 1u);
        EXPECT_EQ(j["buffers"][0]["uri"].get<std::string>().rfind("data:", 0), 0u);
        EXPECT_EQ(j["extensionsUsed"],
                  json::array({"KHR_materials_emissive_strength", "KHR_materials_specular"}));
        for (const json& mat : j["materials"]) {
            if (!mat.contains("emissiveFactor")) continue;
            for (const json& x : mat["emissiveFactor"]) EXPECT_LE(x.get<double>(), 1.0);
        }
    }
}

// --- Synthetic files -------------------------------------------------------------------------

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        uint32_t v = (uint32_t(bytes[i]) << 16) | (uint32_t(bytes[i + 1]) << 8) | bytes[i + 2];
        for (int k = 3; k >= 0; --k) out += abc[(v >> (6 * k)) & 63];
    }
    if (i + 1 == bytes.size()) {
        uint32_t v = uint32_t(bytes[i]) << 16;
        out += abc[(v >> 18) & 63];
        out += abc[(v >> 12) & 63];
        out += "==";
    } else if (i + 2 == bytes.size()) {
        uint32_t v = (uint32_t(bytes[i]) << 16) | (uint32_t(bytes[i + 1]) << 8);
        out += abc[(v >> 18) & 63];
        out += abc[(v >> 12) & 63];
        out += abc[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

/// A glTF document under construction: JSON plus one binary buffer.
struct Doc {
    json j;
    std::vector<unsigned char> bin;

    Doc() {
        j = {{"asset", {{"version", "2.0"}}},
             {"scene", 0},
             {"scenes", json::array({{{"nodes", json::array()}}})},
             {"nodes", json::array()},
             {"meshes", json::array()},
             {"accessors", json::array()},
             {"bufferViews", json::array()},
             {"materials", json::array()}};
    }
    int view(const void* data, size_t bytes) {
        while (bin.size() % 4) bin.push_back(0);
        size_t offset = bin.size();
        bin.resize(offset + bytes);
        std::memcpy(bin.data() + offset, data, bytes);
        j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
        return int(j["bufferViews"].size()) - 1;
    }
    int accessor(int view_index, int component_type, size_t count, const char* type) {
        j["accessors"].push_back({{"bufferView", view_index},
                                  {"componentType", component_type},
                                  {"count", count},
                                  {"type", type}});
        return int(j["accessors"].size()) - 1;
    }
    int vec3(const std::vector<Vec3>& v) {
        std::vector<float> f;
        for (const Vec3& p : v) f.insert(f.end(), {float(p.x), float(p.y), float(p.z)});
        return accessor(view(f.data(), f.size() * 4), 5126, v.size(), "VEC3");
    }
    int vec2(const std::vector<Vec2>& v) {
        std::vector<float> f;
        for (const Vec2& p : v) f.insert(f.end(), {float(p.x), float(p.y)});
        return accessor(view(f.data(), f.size() * 4), 5126, v.size(), "VEC2");
    }
    int indices(const std::vector<uint32_t>& idx, int component_type) {
        std::vector<unsigned char> raw;
        for (uint32_t i : idx) {
            int size = component_type == 5121 ? 1 : component_type == 5123 ? 2 : 4;
            for (int k = 0; k < size; ++k) raw.push_back((unsigned char)(i >> (8 * k)));
        }
        return accessor(view(raw.data(), raw.size()), component_type, idx.size(), "SCALAR");
    }
    int add(const char* array, json value) {
        if (!j.contains(array)) j[array] = json::array();
        j[array].push_back(std::move(value));
        return int(j[array].size()) - 1;
    }
    void root(int node) { j["scenes"][0]["nodes"].push_back(node); }
    std::string data_uri() const { return "data:application/octet-stream;base64," + base64(bin); }
    json finished() const {
        json out = j;
        if (!out.contains("buffers"))
            out["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", data_uri()}}});
        return out;
    }
    std::string text() const { return finished().dump(); }
};

const std::vector<Vec3> kTriangle = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

/// One triangle (accessors 0: POSITION, 1: u16 indices; bufferViews 0 and 1), material 0,
/// nodes[0] with the mesh, nodes[1] with a perspective camera.
Doc triangle_doc() {
    Doc d;
    int pos = d.vec3(kTriangle);
    int idx = d.indices({0, 1, 2}, 5123);
    d.add("materials", {{"name", "grey"},
                        {"pbrMetallicRoughness",
                         {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}},
                          {"metallicFactor", 0.0},
                          {"roughnessFactor", 0.5}}}});
    d.add("meshes",
          {{"primitives",
            json::array(
                {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"material", 0}}})}});
    d.root(d.add("nodes", {{"mesh", 0}}));
    d.add("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.01}}}});
    d.root(d.add("nodes", {{"camera", 0}, {"translation", {0, 0, 5}}}));
    return d;
}

GltfLoadResult load(const Doc& d) {
    return load_gltf_memory(d.text(), "");
}

TEST(RenderGltf, TriangleDocLoads) {
    GltfLoadResult r = load(triangle_doc());
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_TRUE(r.error.empty());
    EXPECT_TRUE(r.warnings.empty()) << joined(r.warnings);
    ASSERT_EQ(r.scene.mesh.triangle_count(), 1u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(r.scene.mesh.vertex(0, k), kTriangle[size_t(k)]);
    ASSERT_EQ(r.scene.materials.size(), 1u);
    EXPECT_EQ(r.scene.materials[0].name, "grey");
    EXPECT_EQ(r.scene.materials[0].roughness, 0.5);
    EXPECT_EQ(r.scene.materials[0].metallic, 0.0);
    EXPECT_FALSE(r.scene.materials[0].is_emissive());
    EXPECT_TRUE(r.has_camera);
    EXPECT_EQ(r.scene.camera.position, Vec3(0, 0, 5));
    EXPECT_EQ(r.scene.camera.forward, Vec3(0, 0, -1));
    EXPECT_EQ(r.scene.camera.yfov, 0.7);
    EXPECT_EQ(r.extras_json, "");
}

/// Rotation by `angle` about the unit axis as a glTF quaternion (x, y, z, w).
json quaternion(Vec3 axis, double angle) {
    double s = std::sin(0.5 * angle);
    return {axis.x * s, axis.y * s, axis.z * s, std::cos(0.5 * angle)};
}

TEST(RenderGltf, NodeHierarchyTransformsPositionsNormalsAndWinding) {
    // Parent: translation (10, 0, 0). Child: T (1, 2, 3), R 90 degrees about z, S (2, 3, 4).
    // p -> (10, 0, 0) + T + Rz(S p) with Rz(x, y, z) = (-y, x, z).
    for (bool use_matrix : {false, true}) {
        SCOPED_TRACE(use_matrix ? "matrix" : "TRS");
        Doc d = triangle_doc();
        Vec3 n0 = glm::normalize(Vec3(1, 1, 1));
        int nrm = d.vec3({n0, n0, n0});
        d.j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = nrm;
        json child = {{"mesh", 0}};
        if (use_matrix)
            child["matrix"] = {0, 2, 0, 0, -3, 0, 0, 0, 0, 0, 4, 0, 1, 2, 3, 1}; // column-major
        else
            child.update({{"translation", {1, 2, 3}},
                          {"rotation", quaternion({0, 0, 1}, kPi / 2)},
                          {"scale", {2, 3, 4}}});
        d.j["nodes"][0] = {{"translation", {10, 0, 0}}, {"children", {2}}};
        d.add("nodes", child);
        GltfLoadResult r = load(d);
        ASSERT_TRUE(r.ok) << r.error;
        const Mesh& m = r.scene.mesh;
        ASSERT_EQ(m.triangle_count(), 1u);
        const Vec3 expected[3] = {{11, 4, 3}, {8, 2, 3}, {11, 2, 7}};
        for (int k = 0; k < 3; ++k)
            EXPECT_LT(glm::length(m.vertex(0, k) - expected[k]), 1e-12) << k;
        // Normals: inverse transpose R S^-1 (1, 1, 1) = (-1/3, 1/2, 1/4), renormalised; the
        // winding keeps the front on the same side.
        Vec3 nw = glm::normalize(Vec3(-1.0 / 3.0, 0.5, 0.25));
        ASSERT_EQ(m.normal.size(), 3u);
        for (int k = 0; k < 3; ++k) EXPECT_LT(glm::length(m.normal[size_t(k)] - nw), 1e-12);
        EXPECT_GT(glm::dot(glm::normalize(m.cross_normal(0)), nw), 0.99);
    }
}

TEST(RenderGltf, NegativeScaleMirrorsAndKeepsFrontFaces) {
    Doc d = triangle_doc();
    Vec3 n0 = glm::normalize(Vec3(1, 1, 1));
    d.j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = d.vec3({n0, n0, n0});
    d.j["nodes"][0]["scale"] = {-1, 1, 1};
    GltfLoadResult r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    const Mesh& m = r.scene.mesh;
    ASSERT_EQ(m.triangle_count(), 1u);
    // Mirrored positions; the shading normal is (-1, 1, 1)/sqrt 3 and the flipped winding
    // makes the geometric front agree with it (without the flip it would be opposite).
    std::multiset<std::array<double, 3>> got, want = {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int k = 0; k < 3; ++k) got.insert({m.vertex(0, k).x, m.vertex(0, k).y, m.vertex(0, k).z});
    EXPECT_EQ(got, want);
    Vec3 nw = glm::normalize(Vec3(-1, 1, 1));
    EXPECT_LT(glm::length(m.normal[0] - nw), 1e-12);
    EXPECT_GT(glm::dot(m.cross_normal(0), nw), 0.0);
    // The unmirrored triangle's front is +(1, 1, 1).
    GltfLoadResult plain = load(triangle_doc());
    ASSERT_TRUE(plain.ok);
    EXPECT_GT(glm::dot(plain.scene.mesh.cross_normal(0), Vec3(1, 1, 1)), 0.0);
}

TEST(RenderGltf, IndexTypesTopologiesAndNonIndexed) {
    // A unit square in z = 0 with front +z, as 2 triangles in different encodings.
    const std::vector<Vec3> quad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const std::vector<uint32_t> list = {0, 1, 2, 0, 2, 3};
    struct Case {
        const char* name;
        int component_type; ///< 0: non-indexed
        int mode;
        std::vector<Vec3> vertices;
        std::vector<uint32_t> idx;
    };
    std::vector<Vec3> soup;
    for (uint32_t i : list) soup.push_back(quad[i]);
    const std::vector<Case> cases = {
        {"u8", 5121, 4, quad, list},
        {"u16", 5123, 4, quad, list},
        {"u32", 5125, 4, quad, list},
        {"non-indexed", 0, 4, soup, {}},
        {"strip", 5123, 5, quad, {0, 1, 3, 2}}, // (0,1,3), (1,2,3) per glTF's odd-triangle rule
        {"non-indexed strip", 0, 5, {quad[0], quad[1], quad[3], quad[2]}, {}},
        {"fan", 5121, 6, quad, {0, 1, 2, 3}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        Doc d;
        int pos = d.vec3(c.vertices);
        json prim = {{"attributes", {{"POSITION", pos}}}, {"mode", c.mode}};
        if (c.component_type) prim["indices"] = d.indices(c.idx, c.component_type);
        d.add("meshes", {{"primitives", json::array({prim})}});
        d.root(d.add("nodes", {{"mesh", 0}}));
        GltfLoadResult r = load(d);
        ASSERT_TRUE(r.ok) << r.error;
        const Mesh& m = r.scene.mesh;
        ASSERT_EQ(m.triangle_count(), 2u);
        double total = 0.0;
        for (size_t t = 0; t < 2; ++t) {
            EXPECT_GT(m.cross_normal(t).z, 0.0) << "triangle " << t << " is back-facing";
            total += area(m, t);
        }
        EXPECT_NEAR(total, 1.0, 1e-15);
        EXPECT_FALSE(r.has_camera);
        ASSERT_EQ(r.scene.materials.size(), 1u); // the default material, with a warning
        EXPECT_EQ(r.scene.materials[0].base_color, Vec3(1.0));
        EXPECT_EQ(r.scene.materials[0].metallic, 1.0);
        EXPECT_EQ(r.scene.materials[0].roughness, 1.0);
        EXPECT_TRUE(has_substring(joined(r.warnings), "default material")) << joined(r.warnings);
    }
}

TEST(RenderGltf, ManyPrimitivesShareOneMeshWithPerTriangleMaterials) {
    Doc d = triangle_doc();
    int pos = d.vec3({{0, 0, 2}, {1, 0, 2}, {0, 1, 2}});
    d.add("materials",
          {{"name", "lamp"},
           {"emissiveFactor", {1.0, 0.5, 0.25}},
           {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8.0}}}}},
           {"doubleSided", true}});
    d.j["materials"][0]["extensions"] = {{"KHR_materials_specular", {{"specularFactor", 0.25}}}};
    d.j["extensionsUsed"] = {"KHR_materials_emissive_strength", "KHR_materials_specular"};
    d.j["extensionsRequired"] = {"KHR_materials_emissive_strength", "KHR_materials_specular"};
    d.j["meshes"][0]["primitives"].push_back(
        {{"attributes", {{"POSITION", pos}}}, {"material", 1}});
    // The same mesh instanced twice: the second instance moved up by 10.
    d.root(d.add("nodes", {{"mesh", 0}, {"translation", {0, 10, 0}}}));
    d.j["scenes"][0]["extras"] = {{"exposure", 2}};
    GltfLoadResult r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_TRUE(r.warnings.empty()) << joined(r.warnings);
    const Mesh& m = r.scene.mesh;
    ASSERT_EQ(m.triangle_count(), 4u);
    ASSERT_EQ(r.scene.materials.size(), 2u);
    EXPECT_EQ(m.material, (std::vector<uint32_t>{0, 1, 0, 1}));
    EXPECT_EQ(m.vertex(2, 0), kTriangle[0] + Vec3(0, 10, 0));
    const Material& lamp = r.scene.materials[1];
    EXPECT_EQ(lamp.emission, Vec3(8, 4, 2));
    EXPECT_TRUE(lamp.double_sided);
    EXPECT_EQ(lamp.base_color, Vec3(1.0)); // glTF defaults
    EXPECT_EQ(lamp.metallic, 1.0);
    EXPECT_EQ(lamp.specular, 1.0);
    EXPECT_EQ(r.scene.materials[0].specular, 0.25);
    EXPECT_EQ(json::parse(r.extras_json), json({{"exposure", 2}}));
}

// Coordinates up to 1e9 load (a 1e3-unit scene is sane); beyond, the bad_cases below refuse
// them naming the node.
TEST(RenderGltf, LargeButBoundedCoordinatesLoad) {
    for (double scale : {1e3, 1e8}) {
        Doc d = triangle_doc();
        d.j["nodes"][0]["scale"] = {scale, scale, scale};
        d.j["nodes"][1]["translation"] = {0, 0, 5 * scale};
        GltfLoadResult r = load(d);
        ASSERT_TRUE(r.ok) << scale << ": " << r.error;
        EXPECT_EQ(r.scene.camera.position, Vec3(0, 0, 5 * scale));
    }
}

// extras.mcplay is read from the scene, else the root: a scene's extras without "mcplay" (other
// tools' data) once hid the root's settings.
TEST(RenderGltf, RootMcplayExtrasAreReadBesideOtherSceneExtras) {
    const json root_settings = {{"mcplay", {{"spp", 3}}}, {"author", "x"}};
    Doc d = triangle_doc();
    d.j["extras"] = root_settings;
    d.j["scenes"][0]["extras"] = {{"note", "from another tool"}};
    GltfLoadResult r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(json::parse(r.extras_json), root_settings);
    // The scene's own extras.mcplay wins over the root's.
    d.j["scenes"][0]["extras"] = {{"mcplay", {{"spp", 5}}}};
    r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(json::parse(r.extras_json), json({{"mcplay", {{"spp", 5}}}}));
    // No extras.mcplay anywhere: the scene's extras, as before.
    d.j["scenes"][0]["extras"] = {{"note", "x"}};
    d.j["extras"] = {{"author", "x"}};
    r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(json::parse(r.extras_json), json({{"note", "x"}}));
}

TEST(RenderGltf, CameraFromRotatedScaledNode) {
    Doc d = triangle_doc();
    // Rotated 90 degrees about y (looks along -x), with a non-uniform scale that must not leak
    // into the frame; under a parent translated by (0, 1, 0).
    d.j["nodes"][1] = {{"camera", 0},
                       {"translation", {2, 0, 0}},
                       {"scale", {3, 0.5, 2}},
                       {"rotation", quaternion({0, 1, 0}, kPi / 2)}};
    d.j["scenes"][0]["nodes"] = {0, 2};
    d.add("nodes", {{"translation", {0, 1, 0}}, {"children", {1}}});
    GltfLoadResult r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    const Camera& c = r.scene.camera;
    EXPECT_LT(glm::length(c.position - Vec3(2, 1, 0)), 1e-15);
    EXPECT_LT(glm::length(c.forward - Vec3(-1, 0, 0)), 1e-15);
    EXPECT_LT(glm::length(c.up - Vec3(0, 1, 0)), 1e-15);
    EXPECT_LT(glm::length(c.right - Vec3(0, 0, -1)), 1e-15);
}

TEST(RenderGltf, NoScenesUsesRootNodesAndSecondCameraWarns) {
    Doc d = triangle_doc();
    d.j.erase("scenes");
    d.j.erase("scene");
    d.add("nodes", {{"camera", 0}, {"translation", {0, 0, 9}}});
    GltfLoadResult r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(r.scene.mesh.triangle_count(), 1u);
    EXPECT_EQ(r.scene.camera.position, Vec3(0, 0, 5)); // the first in traversal order
    EXPECT_TRUE(has_substring(joined(r.warnings), "nodes[2]: cameras[0] is ignored"))
        << joined(r.warnings);
}

TEST(RenderGltf, MissingNormalsDropShadingNormalsWithAWarning) {
    Doc d = triangle_doc();
    Vec3 n0(0, 0, 1);
    d.j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = d.vec3({n0, n0, n0});
    d.j["meshes"][0]["primitives"].push_back(
        {{"attributes", {{"POSITION", d.vec3(kTriangle)}}}, {"material", 0}});
    GltfLoadResult r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(r.scene.mesh.triangle_count(), 2u);
    EXPECT_TRUE(r.scene.mesh.normal.empty());
    EXPECT_TRUE(has_substring(joined(r.warnings), "meshes[0].primitives[1] has no NORMAL"))
        << joined(r.warnings);
}

void write_to_string(void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

std::string data_uri_png(int w, int h, const std::vector<unsigned char>& rgb) {
    std::string png;
    EXPECT_TRUE(stbi_write_png_to_func(&write_to_string, &png, w, h, 3, rgb.data(), w * 3));
    return "data:image/png;base64," + base64(std::vector<unsigned char>(png.begin(), png.end()));
}

double srgb_decode(double c) {
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

TEST(RenderGltf, BaseColourTextureDecodedToLinearOthersWarn) {
    Doc d = triangle_doc();
    const std::vector<unsigned char> texels = {0, 128, 255, 10, 20, 30, 200, 100, 50, 1, 2, 3};
    d.add("images", {{"uri", data_uri_png(2, 2, texels)}});
    d.add("images", {{"uri", "data:image/png;base64,AAAAAAAA"}}); // not a PNG, never used
    d.add("textures", {{"source", 0}});
    d.add("textures", {{"source", 1}});
    d.j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] =
        d.vec2({{0, 0}, {1, 0}, {0.25, 0.75}});
    // No material uses a texture yet: no texture coordinates, no textures.
    GltfLoadResult plain = load(d);
    ASSERT_TRUE(plain.ok) << plain.error;
    EXPECT_TRUE(plain.scene.mesh.uv.empty());
    EXPECT_TRUE(plain.scene.textures.empty());
    json& mat = d.j["materials"][0];
    mat["name"] = "glass";
    mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    mat["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", 0}};
    mat["normalTexture"] = {{"index", 0}};
    mat["occlusionTexture"] = {{"index", 0}};
    mat["emissiveTexture"] = {{"index", 0}};
    mat["alphaMode"] = "BLEND";
    mat["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                         {"KHR_materials_specular", {{"specularColorFactor", {1, 0.5, 1}}}}};
    d.j["extensionsUsed"] = {"KHR_materials_transmission", "EXT_unknown_thing"};
    GltfLoadResult r = load(d);
    ASSERT_TRUE(r.ok) << r.error;
    ASSERT_EQ(r.scene.textures.size(), 1u);
    const Texture& t = r.scene.textures[0];
    ASSERT_EQ(t.width, 2);
    ASSERT_EQ(t.height, 2);
    ASSERT_EQ(t.rgb.size(), texels.size());
    EXPECT_EQ(r.scene.materials[0].specular, 1.0); // specularFactor absent: the default
    for (size_t k = 0; k < texels.size(); ++k)
        EXPECT_EQ(t.rgb[k], float(srgb_decode(texels[k] / 255.0))) << k;
    EXPECT_EQ(r.scene.materials[0].base_color_texture, 0);
    ASSERT_EQ(r.scene.mesh.uv.size(), 3u);
    EXPECT_EQ(r.scene.mesh.uv[2], Vec2(0.25, 0.75));
    const std::string w = joined(r.warnings);
    for (const char* expected :
         {"materials[0] (glass): KHR_materials_transmission is not supported and is ignored",
          "materials[0] (glass): metallicRoughnessTexture is not supported",
          "materials[0] (glass): normalTexture is not supported",
          "materials[0] (glass): occlusionTexture is not supported",
          "materials[0] (glass): emissiveTexture is not supported",
          "materials[0] (glass): alpha (alphaMode BLEND", "EXT_unknown_thing",
          "materials[0] (glass): KHR_materials_specular.specularColorFactor is not supported"})
        EXPECT_TRUE(has_substring(w, expected)) << expected << "\n" << w;

    // The broken image fails once a material uses it.
    d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 1;
    GltfLoadResult bad = load(d);
    EXPECT_FALSE(bad.ok);
    EXPECT_TRUE(has_substring(bad.error, "images[1]: cannot decode")) << bad.error;
}

/// The triangle document with a 2 x 2 PNG stored in a bufferView as its base colour texture.
Doc textured_by_buffer_view() {
    Doc d = triangle_doc();
    const std::vector<unsigned char> texels = {0, 128, 255, 10, 20, 30, 200, 100, 50, 1, 2, 3};
    std::string png;
    EXPECT_TRUE(stbi_write_png_to_func(&write_to_string, &png, 2, 2, 3, texels.data(), 6));
    int view = d.view(png.data(), png.size());
    d.add("images", {{"bufferView", view}, {"mimeType", "image/png"}});
    d.add("textures", {{"source", 0}});
    d.j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] =
        d.vec2({{0, 0}, {1, 0}, {0, 1}});
    d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    return d;
}

TEST(RenderGltf, TextureFromABufferView) {
    GltfLoadResult r = load(textured_by_buffer_view());
    ASSERT_TRUE(r.ok) << r.error;
    ASSERT_EQ(r.scene.textures.size(), 1u);
    EXPECT_EQ(r.scene.textures[0].width, 2);
    EXPECT_EQ(r.scene.textures[0].rgb[2], 1.0f); // texel (0, 0) blue 255
}

std::vector<unsigned char> glb(const Doc& d) {
    json j = d.j;
    j["buffers"] = json::array({{{"byteLength", d.bin.size()}}});
    std::string text = j.dump();
    while (text.size() % 4) text += ' ';
    std::vector<unsigned char> bin = d.bin;
    while (bin.size() % 4) bin.push_back(0);
    std::vector<unsigned char> out = {'g', 'l', 'T', 'F'};
    auto u32 = [&out](uint32_t v) {
        for (int k = 0; k < 4; ++k) out.push_back((unsigned char)(v >> (8 * k)));
    };
    u32(2);
    u32(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    u32(uint32_t(text.size()));
    u32(0x4E4F534Au);
    out.insert(out.end(), text.begin(), text.end());
    u32(uint32_t(bin.size()));
    u32(0x004E4942u);
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
}

TEST(RenderGltf, GlbAndExternalBuffersAndFiles) {
    Doc d = triangle_doc();
    std::vector<unsigned char> g = glb(d);
    GltfLoadResult r = load_gltf_memory(std::string(g.begin(), g.end()), "");
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(r.scene.mesh.vertex(0, 1), kTriangle[1]);
    // A GLB whose BIN chunk claims 8 more bytes than there are.
    std::vector<unsigned char> cut(g.begin(), g.end() - 8);
    cut[8] = (unsigned char)(cut.size() & 255), cut[9] = (unsigned char)(cut.size() >> 8);
    GltfLoadResult bad = load_gltf_memory(std::string(cut.begin(), cut.end()), "");
    EXPECT_FALSE(bad.ok);
    EXPECT_TRUE(has_substring(bad.error, "GLB")) << bad.error;

    // A .gltf with an external .bin, loaded from a file in a temporary folder, and the same
    // folder's .glb.
    std::string dir = testing::TempDir();
    if (!dir.empty() && dir.back() != '/') dir += '/';
    std::string stem = dir + "mcplay_test_render_gltf";
    json j = d.j;
    j["buffers"] =
        json::array({{{"byteLength", d.bin.size()}, {"uri", "mcplay_test_render_gltf.bin"}}});
    auto write = [](const std::string& path, const std::string& bytes) {
        FILE* f = std::fopen(path.c_str(), "wb");
        ASSERT_NE(f, nullptr) << path;
        std::fwrite(bytes.data(), 1, bytes.size(), f);
        std::fclose(f);
    };
    write(stem + ".gltf", j.dump());
    write(stem + ".bin", std::string(d.bin.begin(), d.bin.end()));
    write(stem + ".glb", std::string(g.begin(), g.end()));
    GltfLoadResult from_file = load_gltf_file(stem + ".gltf");
    ASSERT_TRUE(from_file.ok) << from_file.error;
    EXPECT_EQ(from_file.scene.mesh.vertex(0, 2), kTriangle[2]);
    GltfLoadResult from_glb = load_gltf_file(stem + ".glb");
    ASSERT_TRUE(from_glb.ok) << from_glb.error;
    EXPECT_EQ(from_glb.scene.mesh.position, from_file.scene.mesh.position);
    // The .bin one byte short: its size no longer matches byteLength.
    write(stem + ".bin", std::string(d.bin.begin(), d.bin.end() - 1));
    GltfLoadResult short_bin = load_gltf_file(stem + ".gltf");
    EXPECT_FALSE(short_bin.ok);
    EXPECT_TRUE(has_substring(short_bin.error, "buffers[0]")) << short_bin.error;
    std::remove((stem + ".gltf").c_str());
    std::remove((stem + ".bin").c_str());
    std::remove((stem + ".glb").c_str());
    GltfLoadResult missing = load_gltf_file(stem + ".gltf");
    EXPECT_FALSE(missing.ok);
    EXPECT_TRUE(has_substring(missing.error, "mcplay_test_render_gltf.gltf")) << missing.error;
}

// --- Malformed input -------------------------------------------------------------------------

struct BadCase {
    const char* name;
    std::function<std::string()> text; ///< the file's bytes
    std::vector<std::string> expected; ///< substrings of the error
};

std::string mutated(const std::function<void(Doc&)>& change) {
    Doc d = triangle_doc();
    change(d);
    return d.text();
}

std::vector<BadCase> bad_cases() {
    auto set_float = [](Doc& d, size_t offset, float value) {
        std::memcpy(d.bin.data() + offset, &value, 4);
    };
    return {
        {"invalid JSON",
         [] { return std::string("{\"asset\": {\"version\": \"2.0\"},, }"); },
         {"invalid JSON", "line 1"}},
        {"empty input", [] { return std::string(); }, {"JSON"}},
        {"missing buffer",
         [] { return mutated([](Doc& d) { d.j["buffers"] = json::array(); }); },
         {"bufferViews[0]", "buffer 0 does not exist"}},
        {"uri to a missing file",
         [] {
             return mutated([](Doc& d) {
                 d.j["buffers"] = json::array(
                     {{{"byteLength", d.bin.size()}, {"uri", "no_such_file_here.bin"}}});
             });
         },
         {"buffers[0]", "no_such_file_here.bin"}},
        {"truncated base64",
         [] {
             return mutated([](Doc& d) {
                 std::string uri = d.data_uri();
                 d.j["buffers"] = json::array(
                     {{{"byteLength", d.bin.size()}, {"uri", uri.substr(0, uri.size() / 2)}}});
             });
         },
         {"buffers[0]"}},
        {"accessor past the end of its bufferView",
         [] { return mutated([](Doc& d) { d.j["accessors"][0]["count"] = 4; }); },
         {"accessors[0] (POSITION of meshes[0].primitives[0])", "bufferViews[0] has 36"}},
        {"accessor offset past the end",
         [] { return mutated([](Doc& d) { d.j["accessors"][1]["byteOffset"] = 1000; }); },
         {"accessors[1] (indices of meshes[0].primitives[0])", "byteOffset 1000"}},
        {"bufferView past the end of the buffer",
         [] { return mutated([](Doc& d) { d.j["bufferViews"][1]["byteLength"] = 1000; }); },
         {"bufferViews[1]", "exceeds the length"}},
        {"index out of range",
         [] { return mutated([](Doc& d) { d.j["accessors"][0]["count"] = 2; }); },
         {"accessors[1]", "index 2", "out of range"}},
        {"mode LINES",
         [] { return mutated([](Doc& d) { d.j["meshes"][0]["primitives"][0]["mode"] = 1; }); },
         {"meshes[0].primitives[0]: mode 1 (LINES) is not supported"}},
        {"mode POINTS",
         [] { return mutated([](Doc& d) { d.j["meshes"][0]["primitives"][0]["mode"] = 0; }); },
         {"meshes[0].primitives[0]: mode 0 (POINTS)"}},
        {"sparse accessor",
         [] {
             return mutated([](Doc& d) {
                 d.j["accessors"][0]["sparse"] = {
                     {"count", 1},
                     {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
                     {"values", {{"bufferView", 0}}}};
             });
         },
         {"accessors[0]", "sparse"}},
        {"NaN position",
         [set_float] {
             return mutated([set_float](Doc& d) {
                 set_float(d, 16, std::numeric_limits<float>::quiet_NaN());
             });
         },
         {"accessors[0] (POSITION", "element 1 is not finite"}},
        {"infinite position",
         [set_float] {
             return mutated(
                 [set_float](Doc& d) { set_float(d, 32, std::numeric_limits<float>::infinity()); });
         },
         {"accessors[0] (POSITION", "element 2 is not finite"}},
        {"orthographic camera",
         [] {
             return mutated([](Doc& d) {
                 d.j["cameras"][0] = {
                     {"type", "orthographic"},
                     {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0}, {"zfar", 10}}}};
             });
         },
         {"cameras[0]", "orthographic"}},
        {"bad yfov",
         [] { return mutated([](Doc& d) { d.j["cameras"][0]["perspective"]["yfov"] = 4.0; }); },
         {"cameras[0]", "yfov"}},
        {"unsupported required extension",
         [] {
             return mutated(
                 [](Doc& d) { d.j["extensionsRequired"] = {"KHR_draco_mesh_compression"}; });
         },
         {"extensionsRequired", "KHR_draco_mesh_compression"}},
        {"no meshes",
         [] {
             return mutated([](Doc& d) {
                 d.j.erase("meshes");
                 d.j["nodes"][0].erase("mesh");
             });
         },
         {"no triangles"}},
        {"only degenerate triangles",
         [] {
             return mutated([](Doc& d) {
                 uint16_t zero = 0;
                 std::memcpy(d.bin.data() + 36 + 2, &zero, 2); // indices 0, 0, 2
             });
         },
         {"no triangles"}},
        {"absurd count",
         [] { return mutated([](Doc& d) { d.j["accessors"][0]["count"] = 4000000000u; }); },
         {"accessors[0]", "count 4000000000"}},
        {"wrong component type for POSITION",
         [] { return mutated([](Doc& d) { d.j["accessors"][0]["componentType"] = 5123; }); },
         {"accessors[0] (POSITION", "UNSIGNED_SHORT (5123)", "FLOAT (5126)"}},
        {"float indices",
         [] { return mutated([](Doc& d) { d.j["accessors"][1]["componentType"] = 5126; }); },
         {"accessors[1] (indices", "FLOAT (5126)"}},
        {"wrong type for POSITION",
         [] { return mutated([](Doc& d) { d.j["accessors"][0]["type"] = "VEC2"; }); },
         {"accessors[0] (POSITION", "VEC2"}},
        {"byteStride smaller than the element",
         [] { return mutated([](Doc& d) { d.j["bufferViews"][0]["byteStride"] = 4; }); },
         {"bufferViews[0]", "byteStride 4"}},
        {"byteStride not a multiple of 4",
         [] { return mutated([](Doc& d) { d.j["bufferViews"][0]["byteStride"] = 7; }); },
         {"bufferViews[0]", "byteStride"}},
        {"no POSITION",
         [] {
             return mutated([](Doc& d) {
                 d.j["meshes"][0]["primitives"][0]["attributes"] = {{"TEXCOORD_0", 0}};
             });
         },
         {"meshes[0].primitives[0]: no POSITION"}},
        {"material out of range",
         [] { return mutated([](Doc& d) { d.j["meshes"][0]["primitives"][0]["material"] = 9; }); },
         {"meshes[0].primitives[0]", "material 9"}},
        {"scene node out of range",
         [] { return mutated([](Doc& d) {
                  d.j["scenes"][0]["nodes"] = {0, 7};
              }); },
         {"scenes[0].nodes[1]", "node 7"}},
        {"node cycle",
         [] { return mutated([](Doc& d) { d.j["nodes"][1]["children"] = {1}; }); },
         {"nodes[1]", "tree"}},
        {"default scene out of range",
         [] { return mutated([](Doc& d) { d.j["scene"] = 3; }); },
         {"scene 3"}},
        {"index count not a multiple of 3",
         [] { return mutated([](Doc& d) { d.j["accessors"][1]["count"] = 2; }); },
         {"meshes[0].primitives[0]", "multiple of 3"}},
        {"non-affine matrix",
         [] {
             return mutated([](Doc& d) {
                 d.j["nodes"][0]["matrix"] = {1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
             });
         },
         {"nodes[0]", "affine"}},
        {"transform overflowing to infinity",
         [] {
             return mutated([](Doc& d) {
                 d.j["nodes"][0]["scale"] = {1e308, 1, 1};
                 d.j["nodes"][0]["translation"] = {1.7e308, 0, 0};
             });
         },
         {"nodes[0]", "accessors[0]", "infinity"}},
        {"coordinates beyond 1e9",
         [] { return mutated([](Doc& d) {
                  d.j["nodes"][0]["scale"] = {1e30, 1, 1e30};
              }); },
         {"nodes[0]", "to a coordinate of", "beyond 1e9"}},
        {"camera beyond 1e9",
         [] {
             return mutated([](Doc& d) {
                 for (json& n : d.j["nodes"])
                     if (n.contains("camera")) n["translation"] = {0, 0, 1e30};
             });
         },
         {"the camera is at a coordinate of", "beyond 1e9"}},
        {"zero quaternion",
         [] { return mutated([](Doc& d) {
                  d.j["nodes"][0]["rotation"] = {0, 0, 0, 0};
              }); },
         {"nodes[0]", "rotation"}},
        {"negative emission",
         [] { return mutated([](Doc& d) {
                  d.j["materials"][0]["emissiveFactor"] = {1, -1, 0};
              }); },
         {"materials[0] (grey)", "emissiveFactor[1]"}},
        {"emission beyond float32",
         [] {
             return mutated([](Doc& d) {
                 d.j["materials"][0]["emissiveFactor"] = {1, 0, 0};
                 d.j["materials"][0]["extensions"] = {
                     {"KHR_materials_emissive_strength", {{"emissiveStrength", 1e300}}}};
             });
         },
         {"materials[0] (grey)", "emissiveFactor[0]", "float32 range"}},
        {"emissive strength not a number",
         [] {
             return mutated([](Doc& d) {
                 d.j["materials"][0]["extensions"] = {
                     {"KHR_materials_emissive_strength", {{"emissiveStrength", "bright"}}}};
             });
         },
         {"materials[0] (grey)", "emissiveStrength"}},
        {"image bufferView outside its buffer",
         [] {
             Doc d = textured_by_buffer_view();
             d.j["bufferViews"][d.j["images"][0]["bufferView"].get<int>()]["byteOffset"] = 100000;
             return d.text();
         },
         {"images[0]", "outside buffers[0]"}},
        {"negative emissive strength",
         [] {
             return mutated([](Doc& d) {
                 d.j["materials"][0]["extensions"] = {
                     {"KHR_materials_emissive_strength", {{"emissiveStrength", -2}}}};
             });
         },
         {"materials[0] (grey)", "emissiveStrength -2"}},
        {"specular factor not a number",
         [] {
             return mutated([](Doc& d) {
                 d.j["materials"][0]["extensions"] = {
                     {"KHR_materials_specular", {{"specularFactor", {1}}}}};
             });
         },
         {"materials[0] (grey)", "specularFactor"}},
        {"truncated GLB",
         [] {
             std::vector<unsigned char> g = glb(triangle_doc());
             return std::string(g.begin(), g.begin() + 30);
         },
         {"GLB"}},
    };
}

TEST(RenderGltf, MalformedFilesFailWithAnErrorNamingTheElement) {
    std::vector<BadCase> cases = bad_cases();
    EXPECT_GE(cases.size(), 15u);
    for (const BadCase& c : cases) {
        SCOPED_TRACE(c.name);
        GltfLoadResult r = load_gltf_memory(c.text(), "");
        EXPECT_FALSE(r.ok);
        EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
        EXPECT_LE(r.error.size(), 400u) << r.error;
        EXPECT_TRUE(r.scene.mesh.position.empty());
        for (const std::string& part : c.expected)
            EXPECT_TRUE(has_substring(r.error, part)) << "'" << part << "' not in: " << r.error;
    }
}

/// The triangle document with most supported features, for mutation: a texture, normals,
/// a strip primitive, a mirrored child node, a strided bufferView and material extensions.
Doc rich_doc() {
    Doc d = textured_by_buffer_view();
    Vec3 n0(0, 0, 1);
    d.j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = d.vec3({n0, n0, n0});
    d.j["meshes"][0]["primitives"].push_back(
        {{"attributes", {{"POSITION", d.vec3({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}})}}},
         {"mode", 5},
         {"material", 1}});
    d.add("materials", {{"emissiveFactor", {1, 1, 0.5}},
                        {"extensions",
                         {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}},
                          {"KHR_materials_specular", {{"specularFactor", 0}}}}}});
    d.j["nodes"][0]["children"] = {2};
    d.add("nodes", {{"mesh", 0}, {"scale", {-1, 2, 1}}, {"rotation", {0, 0.6, 0, 0.8}}});
    d.j["bufferViews"][0]["byteStride"] = 12;
    d.j["scenes"][0]["extras"] = {{"note", "x"}};
    return d;
}

TEST(RenderGltf, MutatedFilesNeverCrash) {
    // Random edits of the triangle document: numbers replaced by other values (negative, huge,
    // fractional, wrong types), keys dropped, and the text truncated or bytes flipped. Each
    // load must return either a scene or an error.
    const std::string base = rich_doc().text();
    const json doc = json::parse(base);
    std::vector<json::json_pointer> leaves;
    std::function<void(const json&, const json::json_pointer&)> walk =
        [&](const json& v, const json::json_pointer& p) {
            if (v.is_object())
                for (auto it = v.begin(); it != v.end(); ++it) walk(it.value(), p / it.key());
            else if (v.is_array())
                for (size_t i = 0; i < v.size(); ++i) walk(v[i], p / i);
            if (!p.empty()) leaves.push_back(p);
        };
    walk(doc, json::json_pointer());
    const json replacements[] = {-1,
                                 0,
                                 1,
                                 2,
                                 3,
                                 7,
                                 65535,
                                 4294967295u,
                                 -2147483648,
                                 1e300,
                                 0.5,
                                 "x",
                                 nullptr,
                                 json::array(),
                                 json::object(),
                                 json::array({1, 2, 3})};
    Pcg32 rng(20240611u, 7u);
    int loaded = 0, failed = 0;
    for (int iter = 0; iter < 1500; ++iter) {
        std::string text;
        uint32_t kind = rng.next_u32() % 4;
        if (kind <= 1) {
            json j = doc;
            const json::json_pointer& p = leaves[rng.next_u32() % leaves.size()];
            if (kind == 0)
                j[p] = replacements[rng.next_u32() % (sizeof replacements / sizeof *replacements)];
            else if (j.contains(p)) {
                json& parent = j[p.parent_pointer()];
                if (parent.is_object()) parent.erase(p.back());
            }
            text = j.dump();
        } else if (kind == 2) {
            text = base.substr(0, rng.next_u32() % base.size());
        } else {
            text = base;
            for (int k = 0; k < 3; ++k)
                text[rng.next_u32() % text.size()] = char(rng.next_u32() & 255);
        }
        GltfLoadResult r = load_gltf_memory(text, "");
        if (r.ok) {
            ++loaded;
            EXPECT_TRUE(r.error.empty());
            for (const auto& tri : r.scene.mesh.index)
                for (uint32_t i : tri) ASSERT_LT(i, r.scene.mesh.position.size());
            ASSERT_EQ(r.scene.mesh.material.size(), r.scene.mesh.index.size());
            for (uint32_t m : r.scene.mesh.material) ASSERT_LT(m, r.scene.materials.size());
        } else {
            ++failed;
            EXPECT_FALSE(r.error.empty());
        }
    }
    EXPECT_GT(loaded, 50);
    EXPECT_GT(failed, 50);
}

} // namespace
