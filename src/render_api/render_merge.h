// The parts of a render study split over processes, merged (mcp_render_study_merge): each
// part's images read back and checked, and every level, fit and warning recomputed as one
// process would have computed them. Internal to the render C API.
#pragma once

#include "api/json_read.h"

namespace mcp {

/// Checks the parts of a split study ({"parts": [the results of each part]}) and merges them
/// into *out.
bool merge_render_parts(Ctx& c, const Json& in, Json* out);

} // namespace mcp
