// glTF materials for the loader: metallic-roughness factors, emission (emissiveFactor x
// KHR_materials_emissive_strength), the Fresnel layer's KHR_materials_specular factor, and
// base colour textures decoded by stb_image and turned from sRGB to linear; what is not
// supported is named in a warning.
#include "render_api/gltf_internal.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include <stb_image.h>

namespace mcp {
namespace gltf {

namespace {

/// sRGB transfer function to linear [IEC99].
double srgb_to_linear(double c) {
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

} // namespace

/// Converts the materials the scene's primitives use (in glTF order, the default material
/// last) and decides whether shading normals and texture coordinates are loaded.
bool Converter::convert_materials() {
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
        log_.warn(first_default +
                  (defaults > 1 ? " and " + num(defaults - 1) + " more primitives have" : " has") +
                  " no material; the glTF default material (base colour 1, metallic 1, "
                  "roughness 1) is used");
    }
    return true;
}

bool Converter::factor(double value, const std::string& what, double* out) {
    if (!std::isfinite(value)) return log_.fail(what + " is not finite");
    if (value < 0.0 || value > 1.0) log_.warn(what + " = " + num(value) + " is clamped to [0, 1]");
    *out = std::fmin(std::fmax(value, 0.0), 1.0);
    return true;
}

bool Converter::convert_material(int index, Material* out, int* uv_set) {
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
                  ", baseColorFactor alpha " + num(alpha) + ") is ignored; the material is opaque");
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
            log_.warn(where + ": " + quoted(ext.first, 80) + " is not supported and is ignored");
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
        // The images are float32 (HDR, PFM, the page's pixels): a light brighter than float32
        // holds would show as inf (black in the PNG) wherever it is seen.
        if (out->emission[k] > double(std::numeric_limits<float>::max()))
            return log_.fail(where + ": emissiveFactor[" + num(k) +
                             "] x emissiveStrength = " + num(out->emission[k]) +
                             " is beyond the float32 range of the images (at most 3.4e38)");
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
bool Converter::convert_specular(const tinygltf::Value& ext, const std::string& where,
                                 Material* out) {
    const std::string name = where + ": KHR_materials_specular";
    if (!ext.IsObject()) return log_.fail(name + " is not an object");
    if (ext.Has("specularFactor")) {
        const tinygltf::Value& f = ext.Get("specularFactor");
        if (!f.IsNumber()) return log_.fail(name + ".specularFactor is not a number");
        if (!factor(f.GetNumberAsDouble(), name + ".specularFactor", &out->specular)) return false;
    }
    if (ext.Has("specularColorFactor")) {
        const tinygltf::Value& c = ext.Get("specularColorFactor");
        bool white = c.IsArray() && c.ArrayLen() == 3;
        for (size_t k = 0; white && k < 3; ++k)
            white = c.Get(int(k)).IsNumber() && c.Get(int(k)).GetNumberAsDouble() == 1.0;
        if (!white) log_.warn(name + ".specularColorFactor is not supported and is ignored");
    }
    for (const char* texture : {"specularTexture", "specularColorTexture"})
        if (ext.Has(texture)) log_.warn(name + "." + texture + " is not supported and is ignored");
    return true;
}

/// Decodes the texture's image into Scene::textures (once per image); *out = -1 when the
/// texture is ignored (with a warning).
bool Converter::convert_texture(int index, const std::string& material, int* out) {
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
        for (size_t k = 0; k < t.rgb.size(); ++k) t.rgb[k] = float(srgb_to_linear(px[k] / 65535.0));
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

} // namespace gltf
} // namespace mcp
