// Small scenes built in code for the renderer's tests: quads and closed boxes with known
// answers (no glTF involved).
#pragma once

#include "render/renderer.h"
#include "render/scene.h"

namespace mcp::test {

/// A w x h render of spp samples per pixel on `threads` threads, its random streams keyed by
/// `stream`.
inline RenderSettings render_settings(int w, int h, uint64_t spp, uint64_t stream,
                                      int threads = 1) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.spp = spp;
    s.stream = stream;
    s.threads = threads;
    return s;
}

/// Appends the quad p0 p1 p2 p3 (counter-clockwise seen from its front) as two triangles.
inline void add_quad(Scene& s, Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, uint32_t material) {
    uint32_t base = uint32_t(s.mesh.position.size());
    for (const Vec3& p : {p0, p1, p2, p3}) s.mesh.position.push_back(p);
    s.mesh.index.push_back({base, base + 1, base + 2});
    s.mesh.index.push_back({base, base + 2, base + 3});
    s.mesh.material.push_back(material);
    s.mesh.material.push_back(material);
}

/// Appends an n x n grid of quads over the parallelogram corner, corner + a, corner + b
/// (front side towards a x b).
inline void add_grid(Scene& s, Vec3 corner, Vec3 a, Vec3 b, int n, uint32_t material) {
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            Vec3 p = corner + a * (double(i) / n) + b * (double(j) / n);
            Vec3 da = a / double(n), db = b / double(n);
            add_quad(s, p, p + da, p + da + db, p + db, material);
        }
}

inline Material diffuse(double albedo) {
    Material m;
    m.base_color = Vec3(albedo);
    m.metallic = 0.0;
    m.roughness = 1.0;
    m.specular = 0.0; // Lambertian: no Fresnel layer
    return m;
}

inline Camera look_at(Vec3 eye, Vec3 target, Vec3 up, double yfov) {
    Camera c;
    c.position = eye;
    c.forward = glm::normalize(target - eye);
    c.right = glm::normalize(glm::cross(c.forward, up));
    c.up = glm::cross(c.right, c.forward);
    c.yfov = yfov;
    return c;
}

/// A 4 x 4 m diffuse floor (albedo 0.5) at y = 0 under a 1 x 1 m light of radiance Le at
/// height h facing down; the camera looks straight down from below the light.
inline Scene quad_light_scene(double Le, double h = 1.0) {
    Scene s;
    s.materials.push_back(diffuse(0.5));
    Material light = diffuse(0.0);
    light.emission = Vec3(Le);
    s.materials.push_back(light);
    add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);                 // faces +y
    add_quad(s, {-0.5, h, -0.5}, {0.5, h, -0.5}, {0.5, h, 0.5}, {-0.5, h, 0.5}, 1); // faces -y
    s.camera = look_at({0, 0.5 * h, 0.01}, {0, 0, 0}, {0, 0, -1}, 1.2);
    return s;
}

/// A closed cube [-1, 1]^3 seen from inside, each face an n x n grid, every face diffuse with
/// the given albedo and emitting radiance Le towards the inside (a furnace).
inline Scene furnace_box(double albedo, double Le, int n) {
    Scene s;
    Material m = diffuse(albedo);
    m.emission = Vec3(Le);
    s.materials.push_back(m);
    // Each face: corner and edges ordered so that a x b points inwards.
    add_grid(s, {-1, -1, -1}, {0, 0, 2}, {2, 0, 0}, n, 0); // floor y = -1, normal +y
    add_grid(s, {-1, 1, -1}, {2, 0, 0}, {0, 0, 2}, n, 0);  // ceiling, normal -y
    add_grid(s, {-1, -1, -1}, {0, 2, 0}, {0, 0, 2}, n, 0); // x = -1, normal +x
    add_grid(s, {1, -1, -1}, {0, 0, 2}, {0, 2, 0}, n, 0);  // x = 1, normal -x
    add_grid(s, {-1, -1, -1}, {2, 0, 0}, {0, 2, 0}, n, 0); // z = -1, normal +z
    add_grid(s, {-1, -1, 1}, {0, 2, 0}, {2, 0, 0}, n, 0);  // z = 1, normal -z
    s.camera = look_at({0.1, 0.2, 0.3}, {0.5, -0.3, -1}, {0, 1, 0}, 1.4);
    return s;
}

} // namespace mcp::test
