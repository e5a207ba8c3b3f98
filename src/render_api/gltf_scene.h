// glTF 2.0 (.gltf with embedded or external buffers, or .glb) to mcp::Scene: the default scene's
// node tree flattened into one world-space triangle mesh, its metallic-roughness materials
// (emission = emissiveFactor x KHR_materials_emissive_strength, Fresnel layer scaled by
// KHR_materials_specular's specularFactor), base colour textures (sRGB decoded to linear) and
// the first perspective camera. Malformed input gives ok = false and a one-line error naming
// the offending element; it never crashes. Features that can be ignored safely (other textures
// and extensions, alpha, skins, morph targets, animations, punctual lights) give warnings
// instead. Specification: Khronos glTF 2.0 [glTF2].
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/scene.h"

namespace mcp {

struct GltfLoadResult {
    bool ok = false;
    /// One line naming what is wrong, e.g. "meshes[0].primitives[1]: mode 1 (LINES) is not
    /// supported; only TRIANGLES (4)".
    std::string error;
    /// Unsupported but ignorable features, each naming the feature and where it is used.
    std::vector<std::string> warnings;
    Scene scene;
    /// The loaded scene's "extras" object as JSON text if it has one, else the root "extras"
    /// object, else "".
    std::string extras_json;
    /// False when no node of the scene has a camera (scene.camera is then the default).
    bool has_camera = false;
};

/// Limits above which loading fails (untrusted input must not exhaust memory).
constexpr uint64_t kGltfMaxTriangles = 10000000;       ///< triangles after flattening instances
constexpr uint64_t kGltfMaxBufferBytes = 256ull << 20; ///< all buffers together
constexpr uint64_t kGltfMaxInputBytes = 384ull << 20;  ///< the .gltf/.glb itself (base64 buffers)
constexpr uint64_t kGltfMaxTexels = 1ull << 24;        ///< all decoded base colour textures
/// Largest |coordinate| of a vertex or the camera in world space (after the node transforms).
/// A hit point is interpolated from its triangle's vertices and carries their rounding error,
/// about 2e-15 of their magnitude (render/integrator.cpp): up to 1e9 that is below 1e-5, so a
/// scene of metre-sized features renders right; a 1e15 floor under a 1 m light does not.
constexpr double kGltfMaxCoordinate = 1e9;

/// Loads a .gltf or .glb file; external buffers and images are resolved relative to its folder
/// and must lie inside it.
GltfLoadResult load_gltf_file(const std::string& path);

/// Same, from the bytes of a .gltf (JSON text) or .glb (detected by its "glTF" magic);
/// relative URIs are resolved against base_dir ("" or "." for the current folder), and every
/// file they name must resolve, symbolic links included, to a regular file inside `root`
/// (default: base_dir); data: URIs are always allowed.
GltfLoadResult load_gltf_memory(const std::string& bytes, const std::string& base_dir,
                                const std::string& root = "");

} // namespace mcp
