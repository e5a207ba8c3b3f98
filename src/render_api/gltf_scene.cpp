// glTF 2.0 loader [glTF2]. tinygltf parses the JSON and loads the buffers; every index, count,
// offset and stride it hands over is checked here before a byte is read, because tinygltf
// checks few of them. This is the project's only translation unit with the tinygltf and stb
// implementations.
#include "render_api/gltf_scene.h"
#include "api/files.h"
#include "api/json_read.h"

#include <fstream> // tiny_gltf.h 2.7.0 uses std::ofstream without including it

#include <algorithm>
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <utility>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <tiny_gltf.h>

namespace mcp {
namespace {

using Mat3 = glm::dmat3;
using Mat4 = glm::dmat4;

constexpr uint64_t kMaxElements = 3 * kGltfMaxTriangles; // per accessor, and vertices in all
constexpr size_t kMaxWarnings = 64;
constexpr double kPiValue = 3.14159265358979323846;

// glTF component types (accessor.componentType).
constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123,
              kUnsignedInt = 5125, kFloat = 5126;

std::string num(uint64_t v) {
    return std::to_string(v);
}
std::string num(int v) {
    return std::to_string(v);
}
std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

/// Text from the file, made safe for a one-line message: control characters replaced, long
/// runs (data URIs) cut.
std::string quoted(const std::string& s, size_t max_chars = 40) {
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

/// tinygltf's multi-line messages as one line: lines joined by "; ", any run of more than 48
/// non-space characters (a data URI, a long path) cut to 48 and "...", 300 characters at most.
std::string one_line(const std::string& text) {
    std::string out;
    size_t run = 0;
    bool cut = false;
    auto trim = [&out]() {
        while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
    };
    for (char ch : text) {
        if (ch == '\n' || ch == '\r') {
            trim();
            if (!out.empty()) out += "; ";
            run = 0;
            cut = false;
        } else if (ch == ' ' || ch == '\t') {
            if (!out.empty() && out.back() != ' ') out += ' ';
            run = 0;
            cut = false;
        } else if (++run > 48) {
            if (!cut) out += "...";
            cut = true;
        } else {
            out += static_cast<unsigned char>(ch) < 0x20 ? '?' : ch;
        }
    }
    trim();
    if (out.size() > 300) out = out.substr(0, 297) + "...";
    return out;
}

bool contains(const std::string& s, const char* part) {
    return s.find(part) != std::string::npos;
}

int component_size(int type) {
    switch (type) {
    case kByte:
    case kUnsignedByte: return 1;
    case kShort:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0; // INT (5124) and DOUBLE (5130) are not glTF 2.0 accessor types
    }
}

std::string component_name(int type) {
    const char* name = "invalid";
    switch (type) {
    case kByte: name = "BYTE"; break;
    case kUnsignedByte: name = "UNSIGNED_BYTE"; break;
    case kShort: name = "SHORT"; break;
    case kUnsignedShort: name = "UNSIGNED_SHORT"; break;
    case kUnsignedInt: name = "UNSIGNED_INT"; break;
    case kFloat: name = "FLOAT"; break;
    default: break;
    }
    return std::string(name) + " (" + num(type) + ")";
}

const char* type_name(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "invalid";
    }
}

int type_components(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

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

/// sRGB transfer function to linear [IEC99].
double srgb_to_linear(double c) {
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// --- Collecting the first error and the warnings ---------------------------------------------

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

// --- tinygltf callbacks: bounded file reads, images kept encoded until a material needs them --

struct LoadContext {
    const tinygltf::Model* model = nullptr; ///< filled by tinygltf while the callbacks run
    std::string base_dir;
    std::string root;                         ///< every file read must lie inside this folder
    std::string path_problem;                 ///< the first URI refused for lying outside `root`
    uint64_t bytes_read = 0;                  ///< by external buffer and image reads together
    std::map<int, std::string> image_problem; ///< image index -> why it has no bytes
};

bool fs_file_exists(const std::string& path, void* user) {
    const auto* ctx = static_cast<const LoadContext*>(user);
    // tinygltf also looks in "./": only when the base folder is the current one.
    if (path.compare(0, 2, "./") == 0 && !ctx->base_dir.empty() && ctx->base_dir != ".")
        return false;
    // Existence only (never opened here: opening a FIFO blocks); fs_read_whole_file decides.
    struct stat st;
    return ::stat(path.c_str(), &st) == 0;
}

std::string fs_expand_path(const std::string& path, void*) {
    return path; // no shell expansion of names taken from the file
}

bool fs_read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                        void* user) {
    auto* ctx = static_cast<LoadContext*>(user);
    // A URI may only name a regular file inside the scene's folder, symbolic links resolved.
    std::string why;
    if (!file_is_inside(ctx->root, path, &why)) {
        std::string uri = path;
        if (!ctx->base_dir.empty() &&
            path.compare(0, ctx->base_dir.size() + 1, ctx->base_dir + "/") == 0)
            uri = path.substr(ctx->base_dir.size() + 1);
        *err = "'" + quoted(uri, 200) + "' " + why;
        if (ctx->path_problem.empty()) ctx->path_problem = *err;
        return false;
    }
    uint64_t left =
        kGltfMaxBufferBytes > ctx->bytes_read ? kGltfMaxBufferBytes - ctx->bytes_read : 0;
    std::string bytes;
    if (!read_regular_file(path, left, &bytes, err)) return false;
    out->assign(bytes.begin(), bytes.end());
    ctx->bytes_read += out->size();
    return true;
}

bool fs_write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&,
                         void*) {
    *err = "writing files is disabled";
    return false;
}

/// Image callback: keeps the encoded bytes (decoded later, and only for base colour textures
/// in use). tinygltf does not check an image's bufferView against its buffer, so do it here.
bool keep_image_bytes(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void* user) {
    auto* ctx = static_cast<LoadContext*>(user);
    image->image.clear();
    if (image->bufferView >= 0) {
        const tinygltf::Model& m = *ctx->model;
        const auto& views = m.bufferViews;
        if (size_t(image->bufferView) >= views.size() ||
            size_t(views[size_t(image->bufferView)].buffer) >= m.buffers.size()) {
            ctx->image_problem[index] = "bufferView " + num(image->bufferView) + " is invalid";
            return true;
        }
        const tinygltf::BufferView& view = views[size_t(image->bufferView)];
        uint64_t length = m.buffers[size_t(view.buffer)].data.size();
        if (view.byteOffset > length || view.byteLength > length - view.byteOffset) {
            ctx->image_problem[index] = "bufferViews[" + num(image->bufferView) +
                                        "] lies outside buffers[" + num(view.buffer) + "]";
            return true;
        }
    }
    if (!bytes || size <= 0) {
        ctx->image_problem[index] = "no image data";
        return true;
    }
    image->image.assign(bytes, bytes + size);
    image->as_is = true;
    return true;
}

/// Checks a GLB container's header and chunk table (tinygltf 2.7.0 lets the BIN chunk run 8
/// bytes past the end of the data).
bool check_glb(const std::string& bytes, Log& log) {
    auto u32 = [&bytes](size_t at) {
        uint32_t v = 0;
        for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
        return v;
    };
    if (bytes.size() < 20)
        return log.fail("GLB: " + num(uint64_t(bytes.size())) +
                        " bytes is shorter than the 20-byte header");
    if (u32(4) != 2)
        return log.fail("GLB: container version " + num(uint64_t(u32(4))) + " is not 2");
    uint64_t length = u32(8), json_length = u32(12);
    if (length > bytes.size())
        return log.fail("GLB: header length " + num(length) + " exceeds the data size " +
                        num(uint64_t(bytes.size())));
    if (u32(16) != 0x4E4F534Au || json_length == 0 || 20 + json_length > length)
        return log.fail("GLB: the first chunk is not a JSON chunk inside the data");
    uint64_t end = 20 + json_length;
    if (end < length) {
        if (end + 8 > length) return log.fail("GLB: truncated BIN chunk header");
        uint64_t bin_length = u32(size_t(end));
        if (end + 8 + bin_length > length)
            return log.fail("GLB: BIN chunk of " + num(bin_length) +
                            " bytes runs past the end of the data");
    }
    return true;
}

// --- Property types --------------------------------------------------------------------------

/// tinygltf 2.7.0 silently replaces a property of the wrong type by its default ("roughnessFactor":
/// "rough" reads as 1): the properties this loader uses are checked against the glTF 2.0 schema
/// [glTF2] first, so a careless file gets an error naming the property instead of another scene.
struct GltfTypeChecker {
    using Json = nlohmann::json;
    std::string error;

    bool fail(const std::string& where, const std::string& what) {
        if (error.empty()) error = where + ": expected " + what;
        return false;
    }
    static std::string at(const std::string& path, size_t i) {
        return path + "[" + std::to_string(i) + "]";
    }
    // kind: 'n' number, 'i' non-negative integer, 's' string, 'b' boolean, 'o' object.
    bool is(const Json& v, char kind) const {
        switch (kind) {
        case 'n': return v.is_number();
        case 'i': return v.is_number_unsigned() || (v.is_number_integer() && v.get<int64_t>() >= 0);
        case 's': return v.is_string();
        case 'b': return v.is_boolean();
        default: return v.is_object();
        }
    }
    static const char* word(char kind) {
        switch (kind) {
        case 'n': return "a number";
        case 'i': return "a non-negative integer";
        case 's': return "a string";
        case 'b': return "true or false";
        default: return "an object";
        }
    }
    /// `props`: "name:k" for a scalar of kind k, "name:kN" for an array of N of them ("kN"
    /// with N = 0 for any length).
    bool fields(const Json& obj, const std::string& path,
                std::initializer_list<const char*> props) {
        if (!obj.is_object()) return fail(path, "an object");
        for (const char* prop : props) {
            const std::string spec = prop;
            const size_t colon = spec.find(':');
            const std::string name = spec.substr(0, colon);
            const char kind = spec[colon + 1];
            auto it = obj.find(name);
            if (it == obj.end()) continue;
            const std::string where = path + "." + name;
            if (spec.size() == colon + 2) {
                if (!is(*it, kind)) return fail(where, word(kind));
                continue;
            }
            const size_t count = std::strtoul(spec.c_str() + colon + 2, nullptr, 10);
            if (!it->is_array() || (count && it->size() != count))
                return fail(where, "an array of " + (count ? std::to_string(count) + " " : "") +
                                       "values, each " + word(kind));
            for (size_t i = 0; i < it->size(); ++i)
                if (!is((*it)[i], kind)) return fail(at(where, i), word(kind));
        }
        return true;
    }
    /// Each element of the array `key` of the root, checked by `each`.
    template <class F> bool each(const Json& root, const char* key, F check) {
        auto it = root.find(key);
        if (it == root.end()) return true;
        if (!it->is_array()) return fail(key, "an array");
        for (size_t i = 0; i < it->size(); ++i)
            if (!check((*it)[i], at(key, i))) return false;
        return true;
    }

    bool run(const Json& g) {
        if (!g.is_object()) return fail("the glTF", "a JSON object");
        auto asset = g.find("asset");
        if (asset == g.end() || !asset->is_object() || !asset->contains("version") ||
            !(*asset)["version"].is_string())
            return fail("asset.version", "a string (\"2.0\")");
        const std::string version = (*asset)["version"].get<std::string>();
        if (version.compare(0, 2, "2.") != 0) {
            error = "asset.version: '" + quoted(version, 20) + "': only glTF 2.x is supported";
            return false;
        }
        if (!fields(g, "glTF", {"scene:i", "extensionsUsed:s0", "extensionsRequired:s0"}))
            return false;
        return each(g, "scenes",
                    [&](const Json& s, const std::string& p) {
                        return fields(s, p, {"nodes:i0", "name:s"});
                    }) &&
               each(g, "nodes",
                    [&](const Json& n, const std::string& p) {
                        return fields(n, p,
                                      {"camera:i", "mesh:i", "children:i0", "matrix:n16",
                                       "translation:n3", "rotation:n4", "scale:n3", "name:s"});
                    }) &&
               each(g, "cameras",
                    [&](const Json& c, const std::string& p) {
                        return fields(c, p, {"type:s", "perspective:o", "orthographic:o"}) &&
                               (!c.contains("perspective") ||
                                fields(c["perspective"], p + ".perspective",
                                       {"yfov:n", "znear:n", "zfar:n", "aspectRatio:n"}));
                    }) &&
               each(g, "meshes",
                    [&](const Json& m, const std::string& p) {
                        if (!fields(m, p, {"name:s"})) return false;
                        auto prims = m.find("primitives");
                        if (prims == m.end() || !prims->is_array())
                            return fail(p + ".primitives", "an array");
                        for (size_t i = 0; i < prims->size(); ++i) {
                            const Json& q = (*prims)[i];
                            const std::string pp = at(p + ".primitives", i);
                            if (!fields(q, pp,
                                        {"mode:i", "material:i", "indices:i", "attributes:o"}))
                                return false;
                            if (q.contains("attributes"))
                                for (auto a = q["attributes"].begin(); a != q["attributes"].end();
                                     ++a)
                                    if (!is(*a, 'i'))
                                        return fail(pp + ".attributes." + quoted(a.key(), 40),
                                                    word('i'));
                        }
                        return true;
                    }) &&
               each(g, "materials",
                    [&](const Json& m, const std::string& p) {
                        return fields(m, p,
                                      {"pbrMetallicRoughness:o", "emissiveFactor:n3", "alphaMode:s",
                                       "alphaCutoff:n", "doubleSided:b", "name:s",
                                       "extensions:o"}) &&
                               (!m.contains("pbrMetallicRoughness") ||
                                fields(m["pbrMetallicRoughness"], p + ".pbrMetallicRoughness",
                                       {"baseColorFactor:n4", "metallicFactor:n",
                                        "roughnessFactor:n", "baseColorTexture:o"}));
                    }) &&
               each(g, "accessors",
                    [&](const Json& a, const std::string& p) {
                        return fields(a, p,
                                      {"bufferView:i", "byteOffset:i", "componentType:i", "count:i",
                                       "type:s", "normalized:b", "min:n0", "max:n0"});
                    }) &&
               each(g, "bufferViews",
                    [&](const Json& v, const std::string& p) {
                        return fields(v, p,
                                      {"buffer:i", "byteOffset:i", "byteLength:i", "byteStride:i",
                                       "target:i"});
                    }) &&
               each(g, "buffers",
                    [&](const Json& b, const std::string& p) {
                        return fields(b, p, {"byteLength:i", "uri:s"});
                    }) &&
               each(g, "images",
                    [&](const Json& im, const std::string& p) {
                        return fields(im, p, {"uri:s", "bufferView:i", "mimeType:s"});
                    }) &&
               each(g, "textures", [&](const Json& t, const std::string& p) {
                   return fields(t, p, {"source:i", "sampler:i"});
               });
    }
};

// --- Accessors -------------------------------------------------------------------------------

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
                   const std::vector<int>& component_types, AccessorView* out, Log& log) {
    if (index < 0 || size_t(index) >= m.accessors.size())
        return log.fail(role + ": accessor " + num(index) + " does not exist (the file has " +
                        num(uint64_t(m.accessors.size())) + " accessors)");
    const tinygltf::Accessor& a = m.accessors[size_t(index)];
    out->name = "accessors[" + num(index) + "] (" + role + ")";
    const std::string& name = out->name;
    if (a.sparse.isSparse) return log.fail(name + ": sparse accessors are not supported");
    if (a.type != type)
        return log.fail(name + ": type " + type_name(a.type) + " is not the expected " +
                        type_name(type));
    if (std::find(component_types.begin(), component_types.end(), a.componentType) ==
        component_types.end()) {
        std::string allowed;
        for (size_t k = 0; k < component_types.size(); ++k)
            allowed += (k ? " or " : "") + component_name(component_types[k]);
        return log.fail(name + ": component type " + component_name(a.componentType) +
                        " is not allowed here; expected " + allowed);
    }
    uint64_t count = a.count;
    if (count > kMaxElements)
        return log.fail(name + ": count " + num(count) + " exceeds the limit of " +
                        num(kMaxElements));
    out->count = count;
    out->component_type = a.componentType;
    out->components = type_components(a.type);
    out->normalized = a.normalized;
    uint64_t element_size = uint64_t(component_size(a.componentType)) * out->components;
    out->stride = element_size;
    if (a.bufferView == -1) {
        out->data = nullptr; // glTF: an accessor without a bufferView is all zeros
        return true;
    }
    if (a.bufferView < 0 || size_t(a.bufferView) >= m.bufferViews.size())
        return log.fail(name + ": bufferView " + num(a.bufferView) + " does not exist");
    const tinygltf::BufferView& view = m.bufferViews[size_t(a.bufferView)];
    std::string view_name = "bufferViews[" + num(a.bufferView) + "]";
    if (view.buffer < 0 || size_t(view.buffer) >= m.buffers.size())
        return log.fail(view_name + ": buffer " + num(view.buffer) + " does not exist");
    const std::vector<unsigned char>& buffer = m.buffers[size_t(view.buffer)].data;
    uint64_t buffer_size = buffer.size();
    if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset)
        return log.fail(view_name + ": byteOffset " + num(uint64_t(view.byteOffset)) +
                        " + byteLength " + num(uint64_t(view.byteLength)) + " exceeds the length " +
                        num(buffer_size) + " of buffers[" + num(view.buffer) + "]");
    if (view.byteStride != 0) {
        if (view.byteStride < element_size ||
            view.byteStride % uint64_t(component_size(a.componentType)) != 0)
            return log.fail(view_name + ": byteStride " + num(uint64_t(view.byteStride)) +
                            " does not fit the " + num(element_size) + "-byte elements of " + name);
        out->stride = view.byteStride;
    }
    if (a.byteOffset > view.byteLength)
        return log.fail(name + ": byteOffset " + num(uint64_t(a.byteOffset)) +
                        " lies past the end of " + view_name + " (" +
                        num(uint64_t(view.byteLength)) + " bytes)");
    if (count > 0) {
        // count <= 3e7 and stride <= 2^32: no overflow in 64 bits.
        uint64_t need = (count - 1) * out->stride + element_size;
        if (need > view.byteLength - a.byteOffset)
            return log.fail(name + ": " + num(count) + " elements (stride " + num(out->stride) +
                            ") from byteOffset " + num(uint64_t(a.byteOffset)) + " need " +
                            num(need + a.byteOffset) + " bytes, but " + view_name + " has " +
                            num(uint64_t(view.byteLength)));
    }
    out->data = buffer.data() + view.byteOffset + a.byteOffset;
    return true;
}

double read_component(const unsigned char* p, int type, bool normalized) {
    switch (type) {
    case kFloat: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
    }
    case kUnsignedByte: return normalized ? p[0] / 255.0 : p[0];
    case kUnsignedShort: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
    }
    case kByte: {
        int8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? std::fmax(v / 127.0, -1.0) : v;
    }
    case kShort: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::fmax(v / 32767.0, -1.0) : v;
    }
    case kUnsignedInt: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    default: return 0.0;
    }
}

/// Reads `n` components per element as doubles; non-finite values are an error.
bool read_doubles(const AccessorView& v, std::vector<double>* out, Log& log) {
    const int n = v.components;
    const uint64_t size = uint64_t(component_size(v.component_type));
    out->assign(size_t(v.count * n), 0.0);
    if (!v.data) return true;
    for (uint64_t i = 0; i < v.count; ++i) {
        const unsigned char* e = v.element(i);
        for (int c = 0; c < n; ++c) {
            double x = read_component(e + c * size, v.component_type, v.normalized);
            if (!std::isfinite(x))
                return log.fail(v.name + ": element " + num(i) + " is not finite (NaN or Inf)");
            (*out)[size_t(i * n + c)] = x;
        }
    }
    return true;
}

bool read_indices(const AccessorView& v, uint64_t vertex_count, std::vector<uint32_t>* out,
                  Log& log) {
    out->assign(size_t(v.count), 0u);
    if (!v.data) return true;
    for (uint64_t i = 0; i < v.count; ++i) {
        double x = read_component(v.element(i), v.component_type, false);
        if (x >= double(vertex_count))
            return log.fail(v.name + ": index " + num(uint64_t(x)) + " at element " + num(i) +
                            " is out of range (the primitive has " + num(vertex_count) +
                            " vertices)");
        (*out)[size_t(i)] = uint32_t(x);
    }
    return true;
}

// --- Node transforms -------------------------------------------------------------------------

bool finite_all(const std::vector<double>& v) {
    for (double x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

/// The node's local transform: its matrix, or T R S [glTF2 3.5.3].
bool local_transform(const tinygltf::Node& n, int index, Mat4* out, Log& log) {
    const std::string where = "nodes[" + num(index) + "]";
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16 || !finite_all(n.matrix))
            return log.fail(where + ": matrix must be 16 finite numbers");
        Mat4 m(1.0);
        for (int k = 0; k < 16; ++k) m[k / 4][k % 4] = n.matrix[size_t(k)]; // column-major
        if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
            return log.fail(where + ": matrix is not affine (its last row must be 0 0 0 1)");
        *out = m;
        return true;
    }
    if ((!n.translation.empty() && n.translation.size() != 3) || !finite_all(n.translation))
        return log.fail(where + ": translation must be 3 finite numbers");
    if ((!n.scale.empty() && n.scale.size() != 3) || !finite_all(n.scale))
        return log.fail(where + ": scale must be 3 finite numbers");
    if ((!n.rotation.empty() && n.rotation.size() != 4) || !finite_all(n.rotation))
        return log.fail(where + ": rotation must be 4 finite numbers (a quaternion x, y, z, w)");
    Vec3 t = n.translation.empty() ? Vec3(0.0)
                                   : Vec3(n.translation[0], n.translation[1], n.translation[2]);
    Vec3 s = n.scale.empty() ? Vec3(1.0) : Vec3(n.scale[0], n.scale[1], n.scale[2]);
    double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
    if (!n.rotation.empty()) {
        x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
        double len = std::sqrt(x * x + y * y + z * z + w * w);
        if (!(len > 0.0) || !std::isfinite(len))
            return log.fail(where + ": rotation is not a unit quaternion");
        x /= len, y /= len, z /= len, w /= len;
    }
    // Rotation matrix of the unit quaternion (x, y, z, w), r[row][col].
    const double r[3][3] = {
        {1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)},
        {2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)},
        {2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)}};
    Mat4 m(1.0);
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row) m[col][row] = r[row][col] * s[col];
    m[3] = glm::dvec4(t, 1.0);
    *out = m;
    return true;
}

// --- The conversion --------------------------------------------------------------------------

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

    bool check_extensions() {
        for (const std::string& e : m_.extensionsRequired)
            if (e != "KHR_materials_emissive_strength" && e != "KHR_materials_specular")
                return log_.fail("extensionsRequired: " + quoted(e, 80) +
                                 " is not supported (only KHR_materials_emissive_strength and "
                                 "KHR_materials_specular)");
        for (const std::string& e : m_.extensionsUsed) {
            // Material and texture extensions are reported where they are used.
            if (e == "KHR_materials_emissive_strength" || e.compare(0, 14, "KHR_materials_") == 0 ||
                e == "KHR_texture_transform" || e == "KHR_lights_punctual")
                continue;
            log_.warn("extensionsUsed: " + quoted(e, 80) + " is not supported and is ignored");
        }
        if (!m_.lights.empty())
            log_.warn("KHR_lights_punctual: " + num(uint64_t(m_.lights.size())) +
                      " punctual lights are ignored (only emissive triangles emit light)");
        if (!m_.animations.empty())
            log_.warn("animations: " + num(uint64_t(m_.animations.size())) +
                      " animations are ignored (the scene is loaded at rest)");
        return true;
    }

    bool check_buffers() {
        uint64_t total = 0;
        for (const tinygltf::Buffer& b : m_.buffers) total += b.data.size();
        if (total > kGltfMaxBufferBytes)
            return log_.fail("buffers: " + num(total) + " bytes in all exceed the limit of " +
                             num(kGltfMaxBufferBytes));
        return true;
    }

    /// Walks the scene's node tree depth first (children in order), composing transforms;
    /// records mesh instances and the first camera.
    bool collect_instances() {
        const auto& nodes = m_.nodes;
        std::vector<int> roots;
        std::string roots_ref;
        if (!m_.scenes.empty()) {
            int s = m_.defaultScene == -1 ? 0 : m_.defaultScene;
            if (s < 0 || size_t(s) >= m_.scenes.size())
                return log_.fail("scene: scene " + num(s) + " does not exist (the file has " +
                                 num(uint64_t(m_.scenes.size())) + " scenes)");
            scene_index_ = s;
            roots = m_.scenes[size_t(s)].nodes;
            roots_ref = "scenes[" + num(s) + "].nodes";
        } else {
            // No scenes: every node that is nobody's child is a root.
            std::vector<char> is_child(nodes.size(), 0);
            for (size_t i = 0; i < nodes.size(); ++i)
                for (size_t k = 0; k < nodes[i].children.size(); ++k) {
                    int c = nodes[i].children[k];
                    if (c < 0 || size_t(c) >= nodes.size())
                        return log_.fail("nodes[" + num(uint64_t(i)) + "].children[" +
                                         num(uint64_t(k)) + "]: node " + num(c) +
                                         " does not exist");
                    is_child[size_t(c)] = 1;
                }
            for (size_t i = 0; i < nodes.size(); ++i)
                if (!is_child[i]) roots.push_back(int(i));
            roots_ref = "root nodes";
        }

        struct Item {
            int node, parent; ///< parent -1: a root
            size_t slot;      ///< position in the parent's children (or in the roots)
            Mat4 parent_world;
        };
        std::vector<Item> stack;
        for (size_t k = roots.size(); k-- > 0;) stack.push_back({roots[k], -1, k, Mat4(1.0)});
        std::vector<char> visited(nodes.size(), 0);
        int camera_node = -1;
        while (!stack.empty()) {
            Item it = stack.back();
            stack.pop_back();
            if (it.node < 0 || size_t(it.node) >= nodes.size()) {
                std::string ref = it.parent < 0 ? roots_ref + "[" + num(uint64_t(it.slot)) + "]"
                                                : "nodes[" + num(it.parent) + "].children[" +
                                                      num(uint64_t(it.slot)) + "]";
                return log_.fail(ref + ": node " + num(it.node) + " does not exist");
            }
            const std::string where = "nodes[" + num(it.node) + "]";
            if (visited[size_t(it.node)])
                return log_.fail(where + " is reached twice from " + roots_ref +
                                 " (the node hierarchy must be a tree)");
            visited[size_t(it.node)] = 1;
            const tinygltf::Node& n = nodes[size_t(it.node)];
            Mat4 local;
            if (!local_transform(n, it.node, &local, log_)) return false;
            Mat4 world = it.parent_world * local;
            if (n.skin != -1) log_.warn(where + ": skin is ignored (the mesh is used unskinned)");
            if (n.extensions.count("KHR_lights_punctual"))
                log_.warn(where + ": KHR_lights_punctual light is ignored");
            if (n.camera != -1) {
                if (n.camera < 0 || size_t(n.camera) >= m_.cameras.size())
                    return log_.fail(where + ": camera " + num(n.camera) + " does not exist");
                if (camera_node < 0) {
                    if (!set_camera(n.camera, it.node, world)) return false;
                    camera_node = it.node;
                } else {
                    log_.warn(where + ": cameras[" + num(n.camera) +
                              "] is ignored; the first camera in the scene, on nodes[" +
                              num(camera_node) + "], is used");
                }
            }
            if (n.mesh != -1) {
                if (n.mesh < 0 || size_t(n.mesh) >= m_.meshes.size())
                    return log_.fail(where + ": mesh " + num(n.mesh) + " does not exist");
                instances_.push_back({world, it.node, n.mesh});
            }
            for (size_t k = n.children.size(); k-- > 0;)
                stack.push_back({n.children[k], it.node, k, world});
        }
        return true;
    }

    /// Camera of glTF 3.10: looks along the node's -z with y up; the frame is orthonormalised
    /// (scale and shear of the node are dropped).
    bool set_camera(int index, int node, const Mat4& world) {
        const tinygltf::Camera& c = m_.cameras[size_t(index)];
        const std::string where = "cameras[" + num(index) + "] (used by nodes[" + num(node) + "])";
        if (c.type == "orthographic")
            return log_.fail(where + ": orthographic cameras are not supported; only perspective");
        if (c.type != "perspective")
            return log_.fail(where + ": type '" + quoted(c.type) + "' is not perspective");
        double yfov = c.perspective.yfov;
        if (!(yfov > 0.0 && yfov < kPiValue))
            return log_.fail(where + ": yfov " + num(yfov) + " is not in (0, pi)");
        Vec3 back(world[2]), up(world[1]);
        double lb = glm::length(back), lu = glm::length(up);
        Vec3 forward = -back / lb;
        Vec3 right = glm::cross(forward, up / lu);
        double lr = glm::length(right);
        if (!(lb > 0.0 && lu > 0.0 && lr > 1e-9) || !std::isfinite(lb + lu + lr))
            return log_.fail("nodes[" + num(node) + "]: the camera's transform is singular");
        right /= lr;
        Camera& cam = r_.scene.camera;
        cam.position = Vec3(world[3]);
        cam.forward = forward;
        cam.right = right;
        cam.up = glm::cross(right, forward);
        cam.yfov = yfov;
        r_.has_camera = true;
        return true;
    }

    /// Converts the materials the scene's primitives use (in glTF order, the default material
    /// last) and decides whether shading normals and texture coordinates are loaded.
    bool convert_materials() {
        std::set<int> used;
        bool use_default = false;
        std::string first_default, first_without_normals;
        uint64_t defaults = 0;
        bool some_normals = false;
        for (const Instance& inst : instances_) {
            const tinygltf::Mesh& mesh = m_.meshes[size_t(inst.mesh)];
            for (size_t j = 0; j < mesh.primitives.size(); ++j) {
                const tinygltf::Primitive& p = mesh.primitives[j];
                if (p.material == -1) {
                    use_default = true;
                    if (defaults++ == 0) first_default = mesh_ref(inst.mesh, j);
                } else if (p.material < 0 || size_t(p.material) >= m_.materials.size()) {
                    return log_.fail(mesh_ref(inst.mesh, j) + ": material " + num(p.material) +
                                     " does not exist");
                } else {
                    used.insert(p.material);
                }
                if (p.attributes.count("NORMAL")) {
                    some_normals = true;
                } else if (use_normals_) {
                    use_normals_ = false;
                    first_without_normals = mesh_ref(inst.mesh, j);
                }
            }
        }
        if (!use_normals_ && some_normals)
            log_.warn(first_without_normals +
                      " has no NORMAL: shading normals are dropped for the whole scene "
                      "(geometric normals are used)");
        for (int index : used) {
            material_map_[index] = uint32_t(r_.scene.materials.size());
            Material out;
            int uv_set = -1;
            if (!convert_material(index, &out, &uv_set)) return false;
            r_.scene.materials.push_back(out);
            uv_set_.push_back(uv_set);
            if (uv_set >= 0) use_uv_ = true;
        }
        if (use_default) {
            default_material_ = uint32_t(r_.scene.materials.size());
            Material def; // glTF defaults: base colour 1, metallic 1, roughness 1
            def.name = "default";
            r_.scene.materials.push_back(def);
            uv_set_.push_back(-1);
            log_.warn(
                first_default +
                (defaults > 1 ? " and " + num(defaults - 1) + " more primitives have" : " has") +
                " no material; the glTF default material (base colour 1, metallic 1, "
                "roughness 1) is used");
        }
        return true;
    }

    bool factor(double value, const std::string& what, double* out) {
        if (!std::isfinite(value)) return log_.fail(what + " is not finite");
        if (value < 0.0 || value > 1.0)
            log_.warn(what + " = " + num(value) + " is clamped to [0, 1]");
        *out = std::fmin(std::fmax(value, 0.0), 1.0);
        return true;
    }

    bool convert_material(int index, Material* out, int* uv_set) {
        const tinygltf::Material& mat = m_.materials[size_t(index)];
        const std::string where = material_ref(index);
        const tinygltf::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
        out->name = mat.name;
        if (pbr.baseColorFactor.size() != 4)
            return log_.fail(where + ": baseColorFactor must have 4 numbers");
        for (int k = 0; k < 3; ++k)
            if (!factor(pbr.baseColorFactor[size_t(k)], where + ": baseColorFactor[" + num(k) + "]",
                        &out->base_color[k]))
                return false;
        double alpha = pbr.baseColorFactor[3];
        if (!std::isfinite(alpha)) return log_.fail(where + ": baseColorFactor[3] is not finite");
        if (alpha < 1.0 || mat.alphaMode != "OPAQUE")
            log_.warn(where + ": alpha (alphaMode " + quoted(mat.alphaMode) +
                      ", baseColorFactor alpha " + num(alpha) +
                      ") is ignored; the material is opaque");
        if (!factor(pbr.metallicFactor, where + ": metallicFactor", &out->metallic) ||
            !factor(pbr.roughnessFactor, where + ": roughnessFactor", &out->roughness))
            return false;
        if (mat.emissiveFactor.size() != 3)
            return log_.fail(where + ": emissiveFactor must have 3 numbers");
        double strength = 1.0;
        for (const auto& ext : mat.extensions) {
            if (ext.first == "KHR_materials_emissive_strength") {
                if (!ext.second.IsObject())
                    return log_.fail(where + ": KHR_materials_emissive_strength is not an object");
                if (ext.second.Has("emissiveStrength")) {
                    const tinygltf::Value& s = ext.second.Get("emissiveStrength");
                    if (!s.IsNumber())
                        return log_.fail(where + ": KHR_materials_emissive_strength."
                                                 "emissiveStrength is not a number");
                    strength = s.GetNumberAsDouble();
                }
                if (!(strength >= 0.0) || !std::isfinite(strength))
                    return log_.fail(where + ": emissiveStrength " + num(strength) +
                                     " is not a finite number >= 0");
            } else if (ext.first == "KHR_materials_specular") {
                if (!convert_specular(ext.second, where, out)) return false;
            } else {
                log_.warn(where + ": " + quoted(ext.first, 80) +
                          " is not supported and is ignored");
            }
        }
        for (int k = 0; k < 3; ++k) {
            double e = mat.emissiveFactor[size_t(k)];
            if (!(e >= 0.0) || !std::isfinite(e))
                return log_.fail(where + ": emissiveFactor[" + num(k) + "] = " + num(e) +
                                 " is not a finite number >= 0");
            out->emission[k] = e * strength;
            if (!std::isfinite(out->emission[k]))
                return log_.fail(where + ": emissiveFactor[" + num(k) +
                                 "] x emissiveStrength = " + num(e) + " x " + num(strength) +
                                 " overflows; the emitted radiance must be a finite number");
        }
        out->double_sided = mat.doubleSided;

        if (pbr.metallicRoughnessTexture.index >= 0)
            log_.warn(where + ": metallicRoughnessTexture is not supported and is ignored");
        if (mat.normalTexture.index >= 0)
            log_.warn(where + ": normalTexture is not supported and is ignored");
        if (mat.occlusionTexture.index >= 0)
            log_.warn(where + ": occlusionTexture is not supported and is ignored");
        if (mat.emissiveTexture.index >= 0)
            log_.warn(where + ": emissiveTexture is not supported and is ignored");
        const tinygltf::TextureInfo& info = pbr.baseColorTexture;
        if (info.index != -1) {
            for (const auto& ext : info.extensions)
                log_.warn(where + ": baseColorTexture." + quoted(ext.first, 80) +
                          " is not supported and is ignored");
            if (info.texCoord < 0)
                return log_.fail(where + ": baseColorTexture.texCoord " + num(info.texCoord) +
                                 " is invalid");
            int texture = -1;
            if (!convert_texture(info.index, where, &texture)) return false;
            out->base_color_texture = texture;
            if (texture >= 0) *uv_set = info.texCoord;
        }
        return true;
    }

    /// KHR_materials_specular: specularFactor (default 1) scales the dielectric Fresnel layer;
    /// the specular colour and textures are not supported.
    bool convert_specular(const tinygltf::Value& ext, const std::string& where, Material* out) {
        const std::string name = where + ": KHR_materials_specular";
        if (!ext.IsObject()) return log_.fail(name + " is not an object");
        if (ext.Has("specularFactor")) {
            const tinygltf::Value& f = ext.Get("specularFactor");
            if (!f.IsNumber()) return log_.fail(name + ".specularFactor is not a number");
            if (!factor(f.GetNumberAsDouble(), name + ".specularFactor", &out->specular))
                return false;
        }
        if (ext.Has("specularColorFactor")) {
            const tinygltf::Value& c = ext.Get("specularColorFactor");
            bool white = c.IsArray() && c.ArrayLen() == 3;
            for (size_t k = 0; white && k < 3; ++k)
                white = c.Get(int(k)).IsNumber() && c.Get(int(k)).GetNumberAsDouble() == 1.0;
            if (!white) log_.warn(name + ".specularColorFactor is not supported and is ignored");
        }
        for (const char* texture : {"specularTexture", "specularColorTexture"})
            if (ext.Has(texture))
                log_.warn(name + "." + texture + " is not supported and is ignored");
        return true;
    }

    /// Decodes the texture's image into Scene::textures (once per image); *out = -1 when the
    /// texture is ignored (with a warning).
    bool convert_texture(int index, const std::string& material, int* out) {
        const std::string where = material + ": baseColorTexture";
        if (index < 0 || size_t(index) >= m_.textures.size())
            return log_.fail(where + ": texture " + num(index) + " does not exist");
        const tinygltf::Texture& tex = m_.textures[size_t(index)];
        const std::string tex_ref = "textures[" + num(index) + "]";
        if (tex.source == -1) {
            log_.warn(tex_ref +
                      " has no source image that can be read (image formats in "
                      "extensions are not supported); " +
                      where + " is ignored");
            return true;
        }
        if (tex.source < 0 || size_t(tex.source) >= m_.images.size())
            return log_.fail(tex_ref + ": source image " + num(tex.source) + " does not exist");
        if (tex.sampler >= 0 && size_t(tex.sampler) < m_.samplers.size()) {
            const tinygltf::Sampler& s = m_.samplers[size_t(tex.sampler)];
            if (s.wrapS != TINYGLTF_TEXTURE_WRAP_REPEAT || s.wrapT != TINYGLTF_TEXTURE_WRAP_REPEAT)
                log_.warn(tex_ref + ": sampler wrap modes other than REPEAT are ignored");
        }
        auto found = texture_map_.find(tex.source);
        if (found != texture_map_.end()) {
            *out = found->second;
            return true;
        }
        const tinygltf::Image& image = m_.images[size_t(tex.source)];
        std::string image_ref = "images[" + num(tex.source) + "]";
        if (!image.uri.empty() && image.uri.compare(0, 5, "data:") != 0)
            image_ref += " ('" + quoted(image.uri, 80) + "')";
        if (image.image.empty()) {
            auto problem = ctx_.image_problem.find(tex.source);
            return log_.fail(image_ref + ": " +
                             (problem != ctx_.image_problem.end() ? problem->second
                                                                  : "the image could not be read"));
        }
        if (image.image.size() > size_t(INT32_MAX))
            return log_.fail(image_ref + ": encoded image is too large");
        const auto* bytes = image.image.data();
        const int size = int(image.image.size());
        int w = 0, h = 0, channels = 0;
        if (!stbi_info_from_memory(bytes, size, &w, &h, &channels))
            return log_.fail(image_ref + ": cannot decode (" + stbi_failure_reason() + ")");
        uint64_t texels = uint64_t(w) * uint64_t(h);
        if (w <= 0 || h <= 0 || texels > kGltfMaxTexels - texels_)
            return log_.fail(image_ref + ": " + num(w) + " x " + num(h) +
                             " texels exceed the limit of " + num(kGltfMaxTexels) +
                             " texels for all textures");
        Texture t;
        t.width = w;
        t.height = h;
        t.rgb.resize(size_t(texels) * 3);
        if (stbi_is_16_bit_from_memory(bytes, size)) {
            stbi_us* px = stbi_load_16_from_memory(bytes, size, &w, &h, &channels, 3);
            if (!px || uint64_t(w) * uint64_t(h) != texels) {
                stbi_image_free(px);
                return log_.fail(image_ref + ": cannot decode (" + stbi_failure_reason() + ")");
            }
            for (size_t k = 0; k < t.rgb.size(); ++k)
                t.rgb[k] = float(srgb_to_linear(px[k] / 65535.0));
            stbi_image_free(px);
        } else {
            stbi_uc* px = stbi_load_from_memory(bytes, size, &w, &h, &channels, 3);
            if (!px || uint64_t(w) * uint64_t(h) != texels) {
                stbi_image_free(px);
                return log_.fail(image_ref + ": cannot decode (" + stbi_failure_reason() + ")");
            }
            float table[256];
            for (int k = 0; k < 256; ++k) table[k] = float(srgb_to_linear(k / 255.0));
            for (size_t k = 0; k < t.rgb.size(); ++k) t.rgb[k] = table[px[k]];
            stbi_image_free(px);
        }
        texels_ += texels;
        *out = int(r_.scene.textures.size());
        texture_map_[tex.source] = *out;
        r_.scene.textures.push_back(std::move(t));
        return true;
    }

    /// Flattens every primitive of every instance into the world-space mesh.
    bool build_mesh() {
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
                    log_.warn(ref + ": " + quoted(ext.first, 80) +
                              " is not supported and is ignored");
                auto pos = p.attributes.find("POSITION");
                if (pos == p.attributes.end()) return log_.fail(ref + ": no POSITION attribute");
                AccessorView pv;
                if (!view_accessor(m_, pos->second, "POSITION of " + ref, TINYGLTF_TYPE_VEC3,
                                   {kFloat}, &pv, log_) ||
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
                    mesh.position.push_back(w);
                }
                if (use_normals_ && !append_normals(p, ref, n, normal_matrix)) return false;
                uint32_t material =
                    p.material == -1 ? default_material_ : material_map_[p.material];
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

    bool append_normals(const tinygltf::Primitive& p, const std::string& ref, uint64_t n,
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
            return log_.fail(v.name + ": count " + num(v.count) + " differs from POSITION's " +
                             num(n));
        for (uint64_t i = 0; i < n; ++i) {
            Vec3 w = normal_matrix * Vec3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
            double len = glm::length(w);
            if (!(len > 0.0) || !std::isfinite(len))
                return log_.fail(v.name + ": element " + num(i) + " has zero length");
            r_.scene.mesh.normal.push_back(w / len);
        }
        return true;
    }

    bool append_uvs(const tinygltf::Primitive& p, const std::string& ref, uint64_t n, int set) {
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
            return log_.fail(v.name + ": count " + num(v.count) + " differs from POSITION's " +
                             num(n));
        for (uint64_t i = 0; i < n; ++i) uv.push_back(Vec2(values[2 * i], values[2 * i + 1]));
        return true;
    }

    bool finish() {
        if (r_.scene.mesh.index.empty()) {
            std::string scene = scene_index_ >= 0 ? "scenes[" + num(scene_index_) + "]"
                                                  : std::string("the root nodes");
            return log_.fail(instances_.empty()
                                 ? "no triangles: " + scene + " has no node with a mesh"
                                 : "no triangles: the meshes of " + scene +
                                       " have no non-degenerate triangle");
        }
        if (scene_index_ >= 0 && m_.scenes[size_t(scene_index_)].extras.IsObject())
            r_.extras_json = m_.scenes[size_t(scene_index_)].extras_json_string;
        else if (m_.extras.IsObject())
            r_.extras_json = m_.extras_json_string;
        return true;
    }
};

/// Names the element a tinygltf parse error is about: tinygltf parses buffers, then
/// bufferViews, then accessors, and stops at the first bad one, so the failing index is the
/// count of those already parsed.
std::string locate_tinygltf_error(const std::string& message, const tinygltf::Model& m) {
    static const char* const buffer_words[] = {
        "Buffer",        "File not found", "File size mismatch", "File read error",
        "File is empty", "binary size",    "'uri' is missing"};
    for (const char* w : buffer_words)
        if (contains(message, w)) return "buffers[" + num(uint64_t(m.buffers.size())) + "]: ";
    if (contains(message, "byteStride") || contains(message, "BufferView"))
        return "bufferViews[" + num(uint64_t(m.bufferViews.size())) + "]: ";
    if (contains(message, "Accessor") || contains(message, "accessor object") ||
        contains(message, "componentType") || contains(message, "SparseAccessor"))
        return "accessors[" + num(uint64_t(m.accessors.size())) + "]: ";
    return "";
}

} // namespace

GltfLoadResult load_gltf_memory(const std::string& bytes, const std::string& base_dir,
                                const std::string& root) {
    GltfLoadResult result;
    Log log;
    auto done = [&result, &log]() -> GltfLoadResult {
        result.ok = log.error.empty();
        result.error = log.error;
        result.warnings = std::move(log.warnings);
        if (log.dropped) result.warnings.push_back(num(uint64_t(log.dropped)) + " more warnings");
        if (!result.ok) {
            result.scene = Scene();
            result.extras_json.clear();
            result.has_camera = false;
        }
        return std::move(result);
    };
    if (bytes.size() > kGltfMaxInputBytes) {
        log.fail("the glTF data has " + num(uint64_t(bytes.size())) +
                 " bytes, more than the limit of " + num(kGltfMaxInputBytes));
        return done();
    }
    const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    if (binary && !check_glb(bytes, log)) return done();
    // The JSON is checked (syntax, nesting, repeated keys) before tinygltf, whose recursive
    // conversion of deeply nested "extras" would exhaust the stack.
    {
        uint32_t json_length = 0;
        if (binary)
            for (int k = 3; k >= 0; --k)
                json_length =
                    (json_length << 8) | static_cast<unsigned char>(bytes[12 + size_t(k)]);
        const std::string problem = binary ? check_json_text(bytes.data() + 20, json_length)
                                           : check_json_text(bytes.data(), bytes.size());
        if (!problem.empty()) {
            log.fail("invalid JSON: " + problem);
            return done();
        }
        const nlohmann::json tree =
            binary ? nlohmann::json::parse(bytes.data() + 20, bytes.data() + 20 + json_length,
                                           nullptr, false)
                   : nlohmann::json::parse(bytes, nullptr, false);
        GltfTypeChecker types;
        if (!types.run(tree)) {
            log.fail(types.error);
            return done();
        }
    }

    tinygltf::Model model;
    LoadContext ctx;
    ctx.model = &model;
    ctx.base_dir = base_dir;
    ctx.root = root.empty() ? base_dir : root;
    tinygltf::TinyGLTF loader;
    tinygltf::FsCallbacks fs;
    fs.FileExists = &fs_file_exists;
    fs.ExpandFilePath = &fs_expand_path;
    fs.ReadWholeFile = &fs_read_whole_file;
    fs.WriteWholeFile = &fs_write_whole_file;
    fs.user_data = &ctx;
    loader.SetFsCallbacks(fs);
    loader.SetImageLoader(&keep_image_bytes, &ctx);
    loader.SetStoreOriginalJSONForExtrasAndExtensions(true);
    std::string err, warn;
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    bool loaded =
        binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data,
                                             static_cast<unsigned int>(bytes.size()), base_dir)
               : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                            static_cast<unsigned int>(bytes.size()), base_dir);
    if (!ctx.path_problem.empty()) {
        // A refused URI: name the element it belongs to (images fail with a warning only).
        std::string where = locate_tinygltf_error(err, model);
        if (where.empty()) where = "images: ";
        log.fail(where + "uri " + ctx.path_problem);
        return done();
    }
    if (!loaded) {
        std::string message = one_line(err);
        if (contains(err, "Failed to decode 'uri'") && contains(err, "in Buffer"))
            message = "the data URI is not base64 of byteLength bytes";
        log.fail(locate_tinygltf_error(err, model) +
                 (message.empty() ? "tinygltf could not load the file" : message));
        return done();
    }
    Converter converter(model, ctx, result, log);
    converter.run();
    return done();
}

GltfLoadResult load_gltf_file(const std::string& path) {
    std::string data, err;
    if (!read_regular_file(path, kGltfMaxInputBytes, &data, &err)) {
        GltfLoadResult result;
        result.error = err;
        return result;
    }
    size_t slash = path.find_last_of('/');
    std::string base_dir = slash == std::string::npos ? "." : path.substr(0, slash);
    if (slash == 0) base_dir = "/";
    return load_gltf_memory(data, base_dir, base_dir);
}

} // namespace mcp
