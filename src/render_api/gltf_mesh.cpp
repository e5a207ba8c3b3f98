// The glTF loader's mesh flattening: every triangle primitive of every mesh instance taken to
// world space (positions by the node's transform, normals by its inverse transpose, winding
// flipped under a mirroring transform) and appended to the Scene's one triangle mesh with its
// material and texture coordinates [glTF2 3.7.2].
#include "render_api/gltf_internal.h"

#include <cmath>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace mcp {
namespace gltf {

namespace {

const char* mode_name(int mode) {
    switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    case TINYGLTF_MODE_TRIANGLES: return "TRIANGLES";
    case TINYGLTF_MODE_TRIANGLE_STRIP: return "TRIANGLE_STRIP";
    case TINYGLTF_MODE_TRIANGLE_FAN: return "TRIANGLE_FAN";
    default: return "invalid";
    }
}

} // namespace

/// Flattens every primitive of every instance into the world-space mesh.
bool Converter::build_mesh() {
    Mesh& mesh = r_.scene.mesh;
    uint64_t triangles = 0;
    std::vector<double> values;
    std::vector<uint32_t> indices;
    for (const Instance& inst : instances_) {
        const Mat3 a(inst.world);
        const double det = glm::determinant(a);
        if (!(std::fabs(det) > 0.0) || !std::isfinite(det)) {
            log_.warn("nodes[" + num(inst.node) +
                      "]: the transform is singular (zero scale) or not finite; its mesh is "
                      "skipped");
            continue;
        }
        const Mat3 normal_matrix = glm::transpose(glm::inverse(a));
        const bool flip = det < 0.0; // mirrored: clockwise is the front [glTF2 3.7.4]
        const tinygltf::Mesh& gm = m_.meshes[size_t(inst.mesh)];
        for (size_t j = 0; j < gm.primitives.size(); ++j) {
            const tinygltf::Primitive& p = gm.primitives[j];
            const std::string ref = mesh_ref(inst.mesh, j);
            int mode = p.mode == -1 ? TINYGLTF_MODE_TRIANGLES : p.mode;
            if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP)
                return log_.fail(ref + ": mode " + num(mode) + " (" + mode_name(mode) +
                                 ") is not supported; only TRIANGLES (4), TRIANGLE_STRIP "
                                 "(5) and TRIANGLE_FAN (6)");
            if (mode < 0 || mode > TINYGLTF_MODE_TRIANGLE_FAN)
                return log_.fail(ref + ": mode " + num(mode) + " is not a glTF mode");
            if (!p.targets.empty()) log_.warn(ref + ": morph targets are ignored");
            for (const auto& ext : p.extensions)
                log_.warn(ref + ": " + quoted(ext.first, 80) + " is not supported and is ignored");
            auto pos = p.attributes.find("POSITION");
            if (pos == p.attributes.end()) return log_.fail(ref + ": no POSITION attribute");
            AccessorView pv;
            if (!view_accessor(m_, pos->second, "POSITION of " + ref, TINYGLTF_TYPE_VEC3, {kFloat},
                               &pv, log_) ||
                !read_doubles(pv, &values, log_))
                return false;
            const uint64_t n = pv.count;
            const uint64_t base = mesh.position.size();
            if (base + n > kMaxElements)
                return log_.fail(ref + ": the scene has more than " + num(kMaxElements) +
                                 " vertices");
            for (uint64_t i = 0; i < n; ++i) {
                glm::dvec4 q(values[3 * i], values[3 * i + 1], values[3 * i + 2], 1.0);
                Vec3 w(inst.world * q);
                if (!std::isfinite(w.x + w.y + w.z))
                    return log_.fail("nodes[" + num(inst.node) + "]: its transform takes " +
                                     pv.name + " element " + num(i) + " to infinity");
                const double largest =
                    std::fmax(std::fabs(w.x), std::fmax(std::fabs(w.y), std::fabs(w.z)));
                if (largest > kGltfMaxCoordinate)
                    return log_.fail("nodes[" + num(inst.node) + "]: its transform takes " +
                                     pv.name + " element " + num(i) + " to a coordinate of " +
                                     num(largest) +
                                     ", beyond 1e9, the largest rendered right in "
                                     "double precision (hit points carry about 2e-15 of their "
                                     "vertices' coordinates in error): rescale the scene");
                mesh.position.push_back(w);
            }
            if (use_normals_ && !append_normals(p, ref, n, normal_matrix)) return false;
            uint32_t material = p.material == -1 ? default_material_ : material_map_[p.material];
            if (use_uv_ && !append_uvs(p, ref, n, uv_set_[material])) return false;

            if (p.indices != -1) {
                AccessorView iv;
                if (!view_accessor(m_, p.indices, "indices of " + ref, TINYGLTF_TYPE_SCALAR,
                                   {kUnsignedByte, kUnsignedShort, kUnsignedInt}, &iv, log_) ||
                    !read_indices(iv, n, &indices, log_))
                    return false;
            } else {
                indices.resize(size_t(n));
                for (uint64_t i = 0; i < n; ++i) indices[size_t(i)] = uint32_t(i);
            }
            const uint64_t count = indices.size();
            uint64_t tris = 0;
            if (mode == TINYGLTF_MODE_TRIANGLES) {
                if (count % 3 != 0)
                    return log_.fail(ref + ": " + num(count) +
                                     " vertex indices is not a multiple of 3 (TRIANGLES)");
                tris = count / 3;
            } else {
                tris = count >= 3 ? count - 2 : 0;
            }
            if (triangles + tris > kGltfMaxTriangles)
                return log_.fail(ref + ": the scene has more than " + num(kGltfMaxTriangles) +
                                 " triangles");
            triangles += tris;
            for (uint64_t t = 0; t < tris; ++t) {
                uint64_t i0, i1, i2; // glTF2 3.7.2.1 topology types
                if (mode == TINYGLTF_MODE_TRIANGLES) {
                    i0 = 3 * t, i1 = 3 * t + 1, i2 = 3 * t + 2;
                } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                    i0 = t, i1 = t + 1 + t % 2, i2 = t + 2 - t % 2;
                } else {
                    i0 = t + 1, i1 = t + 2, i2 = 0;
                }
                uint32_t a0 = indices[size_t(i0)], a1 = indices[size_t(i1)],
                         a2 = indices[size_t(i2)];
                if (a0 == a1 || a1 == a2 || a0 == a2) continue; // degenerate (strip joins)
                if (flip) std::swap(a1, a2);
                mesh.index.push_back(
                    {uint32_t(base + a0), uint32_t(base + a1), uint32_t(base + a2)});
                mesh.material.push_back(material);
            }
        }
    }
    return true;
}

bool Converter::append_normals(const tinygltf::Primitive& p, const std::string& ref, uint64_t n,
                               const Mat3& normal_matrix) {
    AccessorView v;
    std::vector<double> values;
    auto it = p.attributes.find("NORMAL");
    if (it == p.attributes.end()) return log_.fail(ref + ": no NORMAL attribute");
    if (!view_accessor(m_, it->second, "NORMAL of " + ref, TINYGLTF_TYPE_VEC3, {kFloat}, &v,
                       log_) ||
        !read_doubles(v, &values, log_))
        return false;
    if (v.count != n)
        return log_.fail(v.name + ": count " + num(v.count) + " differs from POSITION's " + num(n));
    for (uint64_t i = 0; i < n; ++i) {
        Vec3 w = normal_matrix * Vec3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
        double len = glm::length(w);
        if (!(len > 0.0) || !std::isfinite(len))
            return log_.fail(v.name + ": element " + num(i) + " has zero length");
        r_.scene.mesh.normal.push_back(w / len);
    }
    return true;
}

bool Converter::append_uvs(const tinygltf::Primitive& p, const std::string& ref, uint64_t n,
                           int set) {
    std::vector<Vec2>& uv = r_.scene.mesh.uv;
    const std::string name = "TEXCOORD_" + num(set < 0 ? 0 : set);
    auto it = p.attributes.find(name);
    if (it == p.attributes.end()) {
        if (set >= 0)
            log_.warn(ref +
                      ": its material has a base colour texture but the primitive has "
                      "no " +
                      name + "; uv (0, 0) is used");
        uv.insert(uv.end(), size_t(n), Vec2(0.0));
        return true;
    }
    AccessorView v;
    std::vector<double> values;
    if (!view_accessor(m_, it->second, name + " of " + ref, TINYGLTF_TYPE_VEC2,
                       {kFloat, kUnsignedByte, kUnsignedShort}, &v, log_))
        return false;
    if (v.component_type != kFloat && !v.normalized)
        return log_.fail(v.name + ": integer texture coordinates must be normalized");
    if (!read_doubles(v, &values, log_)) return false;
    if (v.count != n)
        return log_.fail(v.name + ": count " + num(v.count) + " differs from POSITION's " + num(n));
    for (uint64_t i = 0; i < n; ++i) uv.push_back(Vec2(values[2 * i], values[2 * i + 1]));
    return true;
}

} // namespace gltf
} // namespace mcp
