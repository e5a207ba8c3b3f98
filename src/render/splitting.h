// The number of light samples per camera sample chosen by measured cost (light_samples
// "auto", integrator.h). With n light samples per shading point, the variance of one camera
// sample is V(n) = V_rest + V_light / n and its cost C(n) = c_rest + n c_light, so the
// efficiency 1 / (V C) is largest at n* = sqrt((V_light / V_rest) (c_rest / c_light)), the
// classic optimal splitting factor [ArvoKirk90; Veach97, 9.2]. A pilot renders an eighth of
// the image's rows (8 bands, the image's own pixels, 2 samples per pixel) with n = 1 and n = 5
// on one thread, timed by the processor time it uses, and reads V_rest, V_light from the two
// images' pixel variances and c_rest, c_light from the two times.
#pragma once

#include "render/renderer.h"

namespace mcp {

/// The estimator with light_samples chosen by the pilot (and its figures in split_pilot)
/// when light_samples is 0 ("auto"), and likewise candidates (RIS, candidate_pilot; chosen
/// first, with one light sample, the pilot's second count 8), then emission_samples (camera rays
/// for the emission seen directly, emission_pilot, with the other counts chosen; second count
/// 8: V_light is then the emission's variance per camera sample, c_light one such ray's cost);
/// any other estimator unchanged.
/// The count is at most 4 times the pilot's second count (20 light samples, 32 candidates):
/// the model is measured at 1 and k only.
/// `image` gives the image size, stream and threads of the render that follows.
RenderEstimator resolve_split(const RenderScene& rs, const RenderEstimator& est,
                              const RenderSettings& image);

/// n* of the formula above, rounded to the better neighbour and kept in 1..kMaxSplitSamples
/// (the largest where V_rest or c_light is not positive).
int optimal_split(double variance_rest, double variance_light, double seconds_rest,
                  double seconds_light);

} // namespace mcp
