// libFuzzer target: .gltf / .glb bytes -> mcp::load_gltf_memory (src/render_api/gltf_scene.h),
// with relative URIs resolved against an empty temporary folder.
// Besides the sanitizers it checks the loaded scene's invariants (every index in range, finite
// positions, texture sizes) and that no URI escapes the folder: a file "escape.bin" beside the
// folder holds one triangle with a coordinate of 31337; seeing it in a scene means the loader
// read outside its folder (e.g. through "../escape.bin").
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "render_api/gltf_scene.h"

namespace {

std::string g_base; // the empty folder

[[noreturn]] void violation(const char* what) {
    std::fprintf(stderr, "fuzz_gltf: %s\n", what);
    std::abort();
}

void make_folders() {
    char tmpl[] = "/tmp/mcplay_fuzz_gltf.XXXXXX";
    const char* root = mkdtemp(tmpl);
    if (!root) violation("mkdtemp failed");
    g_base = std::string(root) + "/base";
    if (mkdir(g_base.c_str(), 0700) != 0) violation("mkdir failed");
    const float tri[9] = {31337.0f, 0, 0, 0, 31337.0f, 0, 0, 0, 31337.0f};
    for (const char* name : {"escape.bin", "escape.glb", "escape.png"}) {
        FILE* f = std::fopen((std::string(root) + "/" + name).c_str(), "wb");
        if (!f) violation("cannot write the escape sentinel");
        std::fwrite(tri, sizeof tri, 1, f);
        std::fclose(f);
    }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    make_folders();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    mcp::GltfLoadResult r = mcp::load_gltf_memory(bytes, g_base);
    if (!r.ok) {
        if (r.error.empty()) violation("failure without a message");
        return 0;
    }
    const mcp::Scene& s = r.scene;
    const mcp::Mesh& m = s.mesh;
    if (m.material.size() != m.index.size()) violation("one material per triangle expected");
    if (!m.normal.empty() && m.normal.size() != m.position.size()) violation("normal count");
    if (!m.uv.empty() && m.uv.size() != m.position.size()) violation("uv count");
    for (const auto& p : m.position) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            violation("a vertex position is not finite");
        if (p.x == 31337.0 || p.y == 31337.0 || p.z == 31337.0)
            violation("PATH ESCAPE: the loader read escape.bin outside its folder");
    }
    for (const auto& t : m.index)
        for (uint32_t v : t)
            if (v >= m.position.size()) violation("a vertex index is out of range");
    for (uint32_t mat : m.material)
        if (mat >= s.materials.size()) violation("a material index is out of range");
    for (const mcp::Material& mat : s.materials) {
        if (mat.base_color_texture >= int(s.textures.size()))
            violation("texture index out of range");
        if (!std::isfinite(mat.roughness) || !std::isfinite(mat.metallic))
            violation("a material parameter is not finite");
    }
    for (const mcp::Texture& t : s.textures)
        if (t.width <= 0 || t.height <= 0 || t.rgb.size() != size_t(t.width) * size_t(t.height) * 3)
            violation("a texture's size does not match its texels");
    return 0;
}
