// The reference image of a render study: the key of everything it is rendered from, where it
// is cached, and obtaining it (from its HDR file, options.reference_data, the cache, or a
// render that is then cached). Internal to the render C API.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "api/json_read.h"
#include "render/renderer.h"
#include "render_api/mcplay_render.h"
#include "render_api/render_call.h"

namespace mcp {

/// The hash of everything a rendered reference depends on: the glTF, the scene's name, the
/// image size, the reference's estimator, spp and seed, and the renderer's version. It names
/// the cache file and is stored in it (and in a supplied reference): nothing of the scene's
/// text reaches a path.
uint64_t reference_key(const RenderRequest& r);

/// Where a rendered reference is cached ("" without a cache folder).
std::string reference_cache_file(const RenderRequest& r);

/// Called with the rows of the reference rendered so far and the image's rows; false cancels.
using ReferenceProgress = std::function<bool(int rows_done, int rows)>;

/// Progress lines {"kind": kind, "rows_done", "rows"} of an image being rendered, at most one
/// per percent, for a C API callback; sets *cancelled when the callback asks to stop. nullptr
/// without a callback.
ReferenceProgress rows_progress(mcp_progress_fn progress, void* user, const char* kind,
                                bool* cancelled);

/// The reference image: read from the scene's HDR file, taken from options.reference_data
/// when it was made from the same scene and settings, read from the cache, or rendered (and
/// then cached). `source` says which; a supplied reference that is not used says why. With
/// may_render false, a reference that would have to be rendered is not: true with `source`
/// "none" and an empty image (width 0).
bool obtain_reference(const LoadedRender& l, RenderImage* ref, Json* info, std::string* error,
                      const ReferenceProgress& progress = nullptr, bool may_render = true);

/// obtain_reference for a C API call with a progress callback: MCP_OK, or the status to fail
/// with (MCP_ERROR_CANCELLED when the callback stopped it, else MCP_ERROR_SCENE; `error` says).
int obtain_reference_reporting(const LoadedRender& l, mcp_progress_fn progress, void* user,
                               RenderImage* ref, Json* info, std::string* error,
                               bool may_render = true);

} // namespace mcp
