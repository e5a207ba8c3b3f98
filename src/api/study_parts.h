// Integration studies and stopping runs split over processes (mcp_study_run with options.part
// and options.parts, then mcp_study_merge): a part runs the replicates r with r % K == I and
// writes every replicate's RunResult (or stopping result) exactly, so that the merge recomputes
// every level, fit and warning as one process would have. Internal to the C API.
#pragma once

#include "api/json_read.h"
#include "api/scene.h"

namespace mcp {

/// Most parts of one study (and of one merge).
constexpr int kMaxStudyParts = 1024;

/// Runs part `part` of `parts` of the request (settings checked, parts in 1..reps): the
/// replicates r with r % parts == part of every estimator at every N (or run to the tolerance).
/// `scene` and `options` (without part and parts) are carried in the part for the merge.
Json run_study_part(const SceneRequest& req, const Json& scene, const Json& options, int part,
                    int parts);

/// Checks the parts ({"parts": [each part's result]}: same scene, options, kind; every
/// replicate exactly once; every number in range) and merges them into the result one run of
/// the whole study gives (study_to_json or stopping_to_json).
bool merge_study_parts(Ctx& c, const Json& in, Json* out);

/// Whether a parsed result is a part of a split integration study or stopping run.
bool is_study_part(const Json& j);

} // namespace mcp
