// Internal to the glTF loader (its interface is gltf_scene.h): what the loader's translation
// units share. Its files, in the order the data goes through them:
//   gltf_scene.cpp      load_gltf_memory / load_gltf_file: the size, the GLB container and the
//                       JSON checked, tinygltf run, its errors located; whole-file checks
//   gltf_types.cpp      property types checked against the glTF 2.0 schema, before tinygltf
//   gltf_files.cpp      tinygltf's file and image callbacks: URIs inside the scene's folder,
//                       bounded reads, images kept encoded
//   gltf_tinygltf.cpp   the tinygltf and stb implementations (the only TU that has them)
//   gltf_nodes.cpp      the node tree: transforms, mesh instances, the camera
//   gltf_materials.cpp  materials and base colour textures
//   gltf_accessors.cpp  accessors checked against their buffers, and read
//   gltf_mesh.cpp       primitives flattened into the world-space triangle mesh
// tinygltf parses the JSON and loads the buffers; every index, count, offset and stride it
// hands over is checked before a byte is read, because tinygltf checks few of them.
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "render_api/gltf_scene.h"

namespace mcp {
namespace gltf {

using Mat3 = glm::dmat3;
using Mat4 = glm::dmat4;

constexpr uint64_t kMaxElements = 3 * kGltfMaxTriangles; // per accessor, and vertices in all
constexpr size_t kMaxWarnings = 64;

// glTF component types (accessor.componentType).
constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123,
              kUnsignedInt = 5125, kFloat = 5126;

// --- Messages --------------------------------------------------------------------------------

inline std::string num(uint64_t v) {
    return std::to_string(v);
}
inline std::string num(int v) {
    return std::to_string(v);
}
inline std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

/// Text from the file, made safe for a one-line message: control characters replaced, long
/// runs (data URIs) cut.
inline std::string quoted(const std::string& s, size_t max_chars = 40) {
    std::string out;
    for (char ch : s) {
        if (out.size() >= max_chars) {
            out += "...";
            break;
        }
        out += (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ? '?' : ch;
    }
    return out;
}

/// The first error and the warnings (each once, at most kMaxWarnings, the rest counted).
struct Log {
    std::string error;
    std::vector<std::string> warnings;
    std::set<std::string> seen;
    size_t dropped = 0;

    bool fail(const std::string& message) {
        if (error.empty()) error = message;
        return false;
    }
    void warn(const std::string& message) {
        if (!seen.insert(message).second) return;
        if (warnings.size() < kMaxWarnings)
            warnings.push_back(message);
        else
            ++dropped;
    }
};

// --- Before and during tinygltf's parse (gltf_types.cpp, gltf_files.cpp) ---------------------

/// Checks the types of the properties the loader uses against the glTF 2.0 schema [glTF2]:
/// tinygltf 2.7.0 silently replaces a property of the wrong type by its default
/// ("roughnessFactor": "rough" reads as 1), so a careless file gets an error naming the
/// property instead of another scene. False with *error set at the first wrong one.
bool check_property_types(const nlohmann::json& gltf, std::string* error);

/// What tinygltf's callbacks share with the loader.
struct LoadContext {
    const tinygltf::Model* model = nullptr; ///< filled by tinygltf while the callbacks run
    std::string base_dir;
    std::string root;                         ///< every file read must lie inside this folder
    std::string path_problem;                 ///< the first URI refused for lying outside `root`
    uint64_t bytes_read = 0;                  ///< by external buffer and image reads together
    std::map<int, std::string> image_problem; ///< image index -> why it has no bytes
};

/// Gives `loader` the callbacks of gltf_files.cpp: bounded reads of files inside ctx.root
/// only, no writes, images kept encoded until a material needs them. `ctx` must outlive the
/// load.
void set_callbacks(tinygltf::TinyGLTF& loader, LoadContext& ctx);

// --- Accessors (gltf_accessors.cpp) ----------------------------------------------------------

/// A validated accessor: every element lies inside its buffer.
struct AccessorView {
    std::string name;                    ///< "accessors[3] (POSITION of meshes[0].primitives[1])"
    const unsigned char* data = nullptr; ///< first element; null: no bufferView, all zeros
    uint64_t stride = 0, count = 0;
    int component_type = 0, components = 0;
    bool normalized = false;

    const unsigned char* element(uint64_t i) const { return data + i * stride; }
};

/// Validates accessor `index`, used as `role` (e.g. "POSITION of meshes[0].primitives[1]"),
/// against the expected type and component types.
bool view_accessor(const tinygltf::Model& m, int index, const std::string& role, int type,
                   const std::vector<int>& component_types, AccessorView* out, Log& log);
/// Reads `n` components per element as doubles; non-finite values are an error.
bool read_doubles(const AccessorView& v, std::vector<double>* out, Log& log);
/// Reads vertex indices, each below `vertex_count`.
bool read_indices(const AccessorView& v, uint64_t vertex_count, std::vector<uint32_t>* out,
                  Log& log);

// --- The conversion --------------------------------------------------------------------------

/// Turns the model tinygltf parsed into result.scene, stage by stage; the first failure stops
/// it (log.error), warnings collect in the log.
class Converter {
  public:
    Converter(const tinygltf::Model& model, const LoadContext& ctx, GltfLoadResult& result,
              Log& log)
        : m_(model), ctx_(ctx), r_(result), log_(log) {}

    bool run() {
        return check_extensions() && check_buffers() && collect_instances() &&
               convert_materials() && build_mesh() && finish();
    }

  private:
    struct Instance {
        Mat4 world;
        int node = 0, mesh = 0;
    };

    const tinygltf::Model& m_;
    const LoadContext& ctx_;
    GltfLoadResult& r_;
    Log& log_;
    int scene_index_ = -1;
    std::vector<Instance> instances_;
    std::map<int, uint32_t> material_map_; ///< glTF material -> Scene::materials index
    uint32_t default_material_ = 0;
    std::vector<int> uv_set_;        ///< per scene material: TEXCOORD_n of its texture, or -1
    std::map<int, int> texture_map_; ///< glTF image -> Scene::textures index
    uint64_t texels_ = 0;
    bool use_normals_ = true;
    bool use_uv_ = false;

    static std::string mesh_ref(int mesh, size_t prim) {
        return "meshes[" + num(mesh) + "].primitives[" + num(uint64_t(prim)) + "]";
    }
    std::string material_ref(int index) const {
        std::string s = "materials[" + num(index) + "]";
        const std::string& name = m_.materials[size_t(index)].name;
        return name.empty() ? s : s + " (" + quoted(name) + ")";
    }

    // The whole file (gltf_scene.cpp).
    bool check_extensions();
    bool check_buffers();
    bool finish();
    // The node tree (gltf_nodes.cpp).
    bool collect_instances();
    bool set_camera(int index, int node, const Mat4& world);
    // Materials and textures (gltf_materials.cpp).
    bool convert_materials();
    bool factor(double value, const std::string& what, double* out);
    bool convert_material(int index, Material* out, int* uv_set);
    bool convert_specular(const tinygltf::Value& ext, const std::string& where, Material* out);
    bool convert_texture(int index, const std::string& material, int* out);
    // The triangle mesh (gltf_mesh.cpp).
    bool build_mesh();
    bool append_normals(const tinygltf::Primitive& p, const std::string& ref, uint64_t n,
                        const Mat3& normal_matrix);
    bool append_uvs(const tinygltf::Primitive& p, const std::string& ref, uint64_t n, int set);
};

} // namespace gltf
} // namespace mcp
