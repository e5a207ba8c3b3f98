// Render scene JSON (docs/render-scenes.md) -> the loaded glTF scene, the estimators, the
// study settings and the reference. Internal to the render C API.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "api/json_read.h"
#include "core/made.h"
#include "render/render_study.h"

namespace mcp {

struct ReferenceSpec {
    RenderEstimator estimator;
    uint64_t spp = 1024;
    uint64_t seed = 0; ///< its own: a study's seed changes the estimators' images, never it
    std::string file;  ///< a Radiance .hdr file instead of a render ("" = render it)
};

struct RenderRequest {
    std::string name, description;
    std::string gltf_path;             ///< "" when the glTF was inline
    uint64_t gltf_hash = 0;            ///< of the glTF text, for the reference cache
    std::unique_ptr<Scene> scene;      ///< heap-held: RenderScene keeps a pointer to it
    std::vector<std::string> warnings; ///< from the loader and the scene file
    RenderStudySettings settings;
    std::vector<RenderEstimator> estimators;
    ReferenceSpec reference;
    AccelKind accel = AccelKind::Auto;
    double exposure = 0.0; ///< stops, for PNG output
    std::string cache_dir; ///< where high-spp references are cached ("" = no cache)
    /// options.reference_data decoded: a reference made earlier (encode_reference), used when
    /// it was made from the same scene and settings ("" = none).
    std::string supplied_reference;
};

/// The live view (mcp_render_live_open, options.live): its image's longer side by default and
/// its bounds, the largest camera aspect ratio it takes (either way), and its reference's spp
/// at most (the scene's reference spp when lower): 256 spp at the live size keep a site's
/// shipped references to about a minute of rendering for all bundled scenes.
constexpr int kLiveDefaultLongSide = 256;
constexpr int kLiveMinLongSide = 16, kLiveMaxLongSide = 4096;
constexpr double kLiveMaxAspect = 8.0;
constexpr uint64_t kLiveReferenceSpp = 256;

/// The live view's image size for a longer side of `long_side` pixels: the camera's aspect
/// ratio (the glTF's aspectRatio, else the scene's width / height), the shorter side rounded
/// and at least 1. False (and why) for an aspect beyond kLiveMaxAspect either way.
bool live_image_size(const Camera& camera, int scene_width, int scene_height, int long_side,
                     int* width, int* height, std::string* error);

/// Does this scene JSON describe a render scene (it has a "render" object)?
bool is_render_scene(const Json& scene);

/// Parses the scene and the option overrides, and loads the glTF. `options.base_dir`
/// resolves a relative glTF path (the CLI passes the scene file's folder).
Made<std::shared_ptr<RenderRequest>> build_render_request(const Json& scene, const Json& options);

/// One estimator, a strategy name or an estimator object, as mcp_render_image's
/// options.estimator names one that is not in the scene's list; errors start with `path`.
Made<RenderEstimator> parse_render_estimator(const Json& j, const std::string& path);

/// "" or why the estimator's pixel_allocation cannot be rendered with its pixel sampler
/// (adaptive adds samples to pixels, which the stratified and sobol samplers cannot).
std::string check_pixel_allocation(const RenderEstimator& e);

} // namespace mcp
