// The glTF 2.0 loader's entry points [glTF2]: load_gltf_memory checks the data's size, the GLB
// container and the JSON (syntax, nesting, property types) before tinygltf parses it with the
// loader's file callbacks, names the element a tinygltf error is about, then converts the model
// (gltf_internal.h lists the files of each stage); the checks of the whole file are here too.
#include "api/files.h"
#include "api/json_read.h"
#include "render_api/gltf_internal.h"

#include <utility>

namespace mcp {
namespace gltf {

namespace {

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

bool Converter::check_extensions() {
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

bool Converter::check_buffers() {
    uint64_t total = 0;
    for (const tinygltf::Buffer& b : m_.buffers) total += b.data.size();
    if (total > kGltfMaxBufferBytes)
        return log_.fail("buffers: " + num(total) + " bytes in all exceed the limit of " +
                         num(kGltfMaxBufferBytes));
    return true;
}

bool Converter::finish() {
    if (r_.scene.mesh.index.empty()) {
        std::string scene =
            scene_index_ >= 0 ? "scenes[" + num(scene_index_) + "]" : std::string("the root nodes");
        return log_.fail(instances_.empty() ? "no triangles: " + scene + " has no node with a mesh"
                                            : "no triangles: the meshes of " + scene +
                                                  " have no non-degenerate triangle");
    }
    // extras.mcplay on the scene, else on the root (docs/render-scenes.md): a scene's extras
    // without "mcplay" (a description, other tools' data) do not hide the root's. Without
    // "mcplay" anywhere, the scene's extras (else the root's) are kept as they are.
    const tinygltf::Value* scene_extras =
        scene_index_ >= 0 ? &m_.scenes[size_t(scene_index_)].extras : nullptr;
    const bool scene_has = scene_extras && scene_extras->IsObject() && scene_extras->Has("mcplay");
    const bool root_has = m_.extras.IsObject() && m_.extras.Has("mcplay");
    if (scene_has || (!root_has && scene_extras && scene_extras->IsObject()))
        r_.extras_json = m_.scenes[size_t(scene_index_)].extras_json_string;
    else if (m_.extras.IsObject())
        r_.extras_json = m_.extras_json_string;
    return true;
}

} // namespace gltf

GltfLoadResult load_gltf_memory(const std::string& bytes, const std::string& base_dir,
                                const std::string& root) {
    GltfLoadResult result;
    gltf::Log log;
    auto done = [&result, &log]() -> GltfLoadResult {
        result.ok = log.error.empty();
        result.error = log.error;
        result.warnings = std::move(log.warnings);
        if (log.dropped)
            result.warnings.push_back(gltf::num(uint64_t(log.dropped)) + " more warnings");
        if (!result.ok) {
            result.scene = Scene();
            result.extras_json.clear();
            result.has_camera = false;
        }
        return std::move(result);
    };
    if (bytes.size() > kGltfMaxInputBytes) {
        log.fail("the glTF data has " + gltf::num(uint64_t(bytes.size())) +
                 " bytes, more than the limit of " + gltf::num(kGltfMaxInputBytes));
        return done();
    }
    const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    if (binary && !gltf::check_glb(bytes, log)) return done();
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
        std::string wrong_type;
        if (!gltf::check_property_types(tree, &wrong_type)) {
            log.fail(wrong_type);
            return done();
        }
    }

    tinygltf::Model model;
    gltf::LoadContext ctx;
    ctx.model = &model;
    ctx.base_dir = base_dir;
    ctx.root = root.empty() ? base_dir : root;
    tinygltf::TinyGLTF loader;
    gltf::set_callbacks(loader, ctx);
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
        std::string where = gltf::locate_tinygltf_error(err, model);
        if (where.empty()) where = "images: ";
        log.fail(where + "uri " + ctx.path_problem);
        return done();
    }
    if (!loaded) {
        std::string message = gltf::one_line(err);
        if (gltf::contains(err, "Failed to decode 'uri'") && gltf::contains(err, "in Buffer"))
            message = "the data URI is not base64 of byteLength bytes";
        log.fail(gltf::locate_tinygltf_error(err, model) +
                 (message.empty() ? "tinygltf could not load the file" : message));
        return done();
    }
    gltf::Converter converter(model, ctx, result, log);
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
