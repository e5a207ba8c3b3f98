// Render results as JSON (docs/result-schema.md, "Render studies"): estimators, spp levels and
// their error concentration, the flags of the core worded as warnings, the scene, the settings,
// and what a part of a split study adds. Internal to the render C API.
#pragma once

#include <cstddef>

#include "api/json_read.h"
#include "render/render_study.h"
#include "render_api/render_call.h"

namespace mcp {

/// How an image spread its samples over its pixels (render_image's "pixel_allocation"):
/// {"adaptive": false} or {"adaptive": true, "first_pass_spp", "min_spp", "max_spp",
/// "predicted_gain"}.
Json pixel_allocation_to_json(const PixelAllocationInfo& a);

/// {"name", "strategy", "light_selection", "light_sampling", "pixel_sampler"}, and the depths
/// of a path tracer.
Json estimator_to_json(const RenderEstimator& e);

/// Warnings about an estimator over the whole study (the levels carry their own): the
/// render flags of the core (render_study.h), worded.
Json render_warnings(const RenderEstimatorStudy& s, double floor);

/// A level's JSON: relative_mse (null when undefined, see render_study.h), its median over the
/// images and where its largest (pixel, image) term lies, and a flag and a warning when it lies
/// below the reference's relative-MSE floor or one pixel of one image carries most of it.
Json render_level_to_json(const LevelStats& l, const ErrorConcentration& c, double floor);

/// What the scene holds: triangles, lights, materials, accelerator, loader warnings.
Json render_scene_to_json(const LoadedRender& l);

/// The study settings of a result, with the threads it ran on.
Json render_settings_to_json(const RenderStudySettings& s, int threads);

/// What a part of a split study adds to its result and progress lines.
void add_part(Json* j, const RenderStudySettings& s, const ReferenceSummary& ref);

/// An estimator's study: its warnings, its levels (all, or only `level` for a progress line),
/// its fit, its rays per second and, with `previews`, its last image and error image as PNG.
Json estimator_study_to_json(const RenderEstimatorStudy& s, bool previews, double exposure,
                             const RenderImage* reference, double floor, bool all_levels,
                             size_t level);

/// The warning of a result whose reference is black (relative MSE undefined, null).
Json black_reference_warning();

} // namespace mcp
