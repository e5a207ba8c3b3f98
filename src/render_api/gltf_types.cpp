// The glTF loader's first look at a file's JSON: the types of the properties it uses checked
// against the glTF 2.0 schema [glTF2] before tinygltf reads them, since tinygltf 2.7.0 silently
// replaces a property of the wrong type by its default.
#include "render_api/gltf_internal.h"

#include <cstdlib>

namespace mcp {
namespace gltf {

namespace {

/// The checks of check_property_types (gltf_internal.h); `error` keeps the first failure.
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
    /// A perspective camera's aspectRatio, when given, is > 0 [glTF2, camera.perspective]:
    /// tinygltf reads 0 as "not given", which would silently use the scene's own ratio.
    bool positive_aspect(const Json& perspective, const std::string& path) {
        auto it = perspective.find("aspectRatio");
        if (it == perspective.end() || it->get<double>() > 0.0) return true;
        return fail(path + ".aspectRatio", "a number > 0, got " + it->dump() +
                                               " (leave it out to use the scene's width / height)");
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
                                (fields(c["perspective"], p + ".perspective",
                                        {"yfov:n", "znear:n", "zfar:n", "aspectRatio:n"}) &&
                                 positive_aspect(c["perspective"], p + ".perspective")));
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

} // namespace

bool check_property_types(const nlohmann::json& gltf, std::string* error) {
    GltfTypeChecker types;
    if (types.run(gltf)) return true;
    *error = types.error;
    return false;
}

} // namespace gltf
} // namespace mcp
