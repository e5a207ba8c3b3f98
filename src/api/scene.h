// Scene JSON -> problem, estimators and study settings (docs/scene-format.md): the scene-file
// reader (api/scene.cpp) and the presets on a problem. Internal to the C API. The report API
// (results -> JSON, table, CSV) is api/report.h.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/caller_functions.h"
#include "api/json_read.h"
#include "core/made.h"
#include "estimators/diagnostics.h"
#include "estimators/registry.h"
#include "estimators/study.h"

namespace mcp {

using Json = nlohmann::json;

struct SceneRequest {
    Problem problem;
    std::vector<EstimatorSpec> estimators;
    StudySettings settings;
};

/// Builds a study request from a scene and optional overrides (either may be null JSON). With
/// the caller's functions, the scene may name them, and the problem carries their control.
Made<SceneRequest> build_request(const Json& scene, const Json& options,
                                 const CallerFunctions* functions = nullptr);

/// "" when no typed warp among the estimators' proposals put a point outside its domain during
/// the run just done, else the error naming the estimator and the point (WarpEscape).
std::string warp_escape_error(const SceneRequest& req);

/// The estimator a preset name gives on a problem (as options.estimators would run it),
/// without building the scene again; an error when it does not apply.
Made<EstimatorSpec> preset_estimator(const Problem& problem, const std::string& name);

} // namespace mcp
