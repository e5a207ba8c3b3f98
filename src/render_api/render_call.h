// The start of every render C API call: the scene JSON and the options parsed, the glTF loaded
// and built (accelerator, lights), and the work and memory the call asks for checked against
// the limits before anything is rendered. Internal to the render C API.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "api/json_read.h"
#include "render/integrator.h"
#include "render_api/render_request.h"

namespace mcp {

/// Work and memory bounds, checked before anything is rendered: samples of a whole call
/// (every image of the study and the reference), and bytes of the images held at once
/// (each estimator's preview, the reference and the image being rendered, 48 bytes a pixel).
constexpr double kMaxCallSamples = 4398046511104.0; // 2^42
constexpr double kMaxImageBytes = 1073741824.0;     // 1 GiB
/// A rendered reference needs at least this many times the study's largest spp.
constexpr uint64_t kReferenceSppRatio = 4;

/// A render scene loaded for one call: the request and the scene built from it.
struct LoadedRender {
    std::shared_ptr<RenderRequest> request;
    RenderScene scene;
};

/// The out-parameter checked and cleared, then the scene loaded: MCP_OK, or the status the
/// call fails with (mcp_last_error says why).
int begin_render_call(const char* function, char** out, const char* scene_json,
                      const char* options_json, LoadedRender* loaded, Json* options);

/// Checks the work and memory of a call before anything is rendered: the samples per pixel of
/// all its estimator images together (one image's spp, or the study's ladder times its
/// replicates and estimators), plus the reference's spp when it is rendered, and `held`
/// images in memory at once.
bool check_render_work(const RenderRequest& r, double image_samples_per_pixel, size_t held,
                       bool reference_rendered, std::string* error);

/// Samples per pixel of one estimator's study images: the spp ladder times the replicates.
double study_spp_per_estimator(const RenderStudySettings& s);

/// The checks of a study before anything is rendered: a rendered reference must have many
/// more samples than the study's images, or its own noise is what the study measures
/// (docs/render-scenes.md, "The reference's noise"); then the work and memory.
bool check_render_study(const RenderRequest& r, std::string* error);

} // namespace mcp
