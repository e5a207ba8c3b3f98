// A renderable scene: one world-space triangle mesh, its materials, the camera, and the
// textures its materials use. The glTF loader (src/render_api/gltf_scene.h) fills it; the
// renderer only reads it. Everything is world space and double precision.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "render/geometry.h"

namespace mcp {

/// glTF 2.0 metallic-roughness material, with emission = emissiveFactor times
/// KHR_materials_emissive_strength. Emissive triangles are one-sided area lights: they emit
/// on the side their counter-clockwise winding faces (glTF front face), and on both sides
/// when the material is double-sided.
struct Material {
    std::string name;
    Vec3 base_color{1.0};  ///< linear RGB factor
    double metallic = 1.0; ///< glTF defaults
    double roughness = 1.0;
    /// KHR_materials_specular specularFactor: scales the dielectric's Fresnel layer; 0 leaves
    /// a pure Lambertian base (the analytic scenes' diffuse surfaces).
    double specular = 1.0;
    Vec3 emission{0.0}; ///< emitted radiance, linear RGB
    bool double_sided = false;
    int base_color_texture = -1; ///< index into Scene::textures, -1: none

    bool is_emissive() const { return emission.x > 0.0 || emission.y > 0.0 || emission.z > 0.0; }
};

/// Linear RGB texels, row-major from the top row (glTF uv (0,0) is the top-left corner).
struct Texture {
    int width = 0, height = 0;
    std::vector<float> rgb; ///< 3 floats per texel, already converted from sRGB
};

/// One triangle mesh in world space; per-triangle arrays are indexed by triangle id.
struct Mesh {
    std::vector<Vec3> position;                 ///< vertices
    std::vector<Vec3> normal;                   ///< per vertex shading normals, or empty
    std::vector<Vec2> uv;                       ///< per vertex, or empty (no textures)
    std::vector<std::array<uint32_t, 3>> index; ///< per triangle: three vertex ids
    std::vector<uint32_t> material;             ///< per triangle: index into Scene::materials

    size_t triangle_count() const { return index.size(); }
    const Vec3& vertex(size_t triangle, int k) const { return position[index[triangle][k]]; }
    /// Unnormalised geometric normal (p1 - p0) x (p2 - p0): its length is twice the area and
    /// it points to the front (counter-clockwise) side.
    Vec3 cross_normal(size_t triangle) const {
        const Vec3& p0 = vertex(triangle, 0);
        return glm::cross(vertex(triangle, 1) - p0, vertex(triangle, 2) - p0);
    }
};

/// Perspective pinhole camera (glTF camera.perspective): looks along -z of its node, y up.
struct Camera {
    Vec3 position{0.0};
    Vec3 right{1.0, 0.0, 0.0}, up{0.0, 1.0, 0.0}, forward{0.0, 0.0, -1.0}; ///< orthonormal
    double yfov = 0.8; ///< vertical field of view, radians
    /// The glTF's aspectRatio (width / height) when it gives one, else 0: the live view's
    /// image shape (a render's own width and height decide its rays).
    double aspect_ratio = 0.0;
};

struct Scene {
    Mesh mesh;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    Camera camera;
};

} // namespace mcp
