// The counts chosen by measured efficiency ("auto" light_samples, candidates and
// emission_samples, integrator.h). More light samples per shading point (splitting
// [ArvoKirk90; Veach97, 9.2]), more RIS candidates [Talbot05, 4] or more camera rays for the
// emission seen directly lower the variance of a camera sample and raise its cost; the best
// count is the one of the largest efficiency 1 / (V C). With independent pixels
// V(n) = V_rest + V_light / n and n* = sqrt((V_light / V_rest) (c_rest / c_light))
// (optimal_split), but the render's own pixel sampler changes V: Sobol' pixels make the error of
// a smooth integrand fall faster than 1 / spp, by a different amount for each count (a single
// light sample per camera sample is stratified over the pixel's net; RIS's pick and shifted
// candidates keep little of that), so a model read with other pixels chooses wrongly (M = 2-4
// candidates on the Cornell box, where M = 1 is 2-3x as efficient with Sobol' pixels).
//
// The pilot measures instead, with the estimator's own pixel sampler: it renders a lattice of
// pixels spread over the image (spacing s in rows and columns, each row's columns shifted by 3
// from the row above's) at the image's spp up to 16, twice with independent randomizations, at
// counts 1, 2, 4, ... (up to 64). Its pixels are 1/96 of the image's (at least 256), times
// spp / 16 past 16 spp (the same share of the image's samples). V per count: the relative
// variance of the pixel estimates from the two renders ((a - b)^2 / 2, unbiased for any
// randomized sampler; independent pixels take each pixel's within-pixel variance, less noisy),
// weighted as the images' relative MSE (over the squared pixel mean at count 1 + 1e-2 of the
// squared mean luminance). A heavy tail's rare large samples (terms past 1000 times the mean of
// the terms below their 99th percentile) fall into a pilot this small in a few renders only, a
// lottery per count; their excess is pooled over the counts tried, each scaled to count 1 by the
// 1 / n of averaging n samples, and count n's V is its body plus the pooled tail / n. C: the
// processor seconds of the renders (both on two threads when the image has them). The count
// kept is the one of the least V C, a larger one only where it is at least 10 % more efficient
// than the one kept so far. The ladder stops two counts past the best, or when the pilot's
// processor time with the next count's (estimated at twice the last's) would pass 30 % of the
// image's at count 1. The pilot's time is counted in the image's; what it costs and chooses on
// the bench's scenes: docs/performance-notes.md#sampling-and-shading.
#pragma once

#include "render/renderer.h"

namespace mcp {

/// The estimator with light_samples chosen by the pilot (and its figures in split_pilot)
/// when light_samples is 0 ("auto"), and likewise candidates (RIS, candidate_pilot; chosen
/// first, with one light sample), then emission_samples (camera rays for the emission seen
/// directly, emission_pilot, with the other counts chosen); any other estimator unchanged.
/// `image` gives the image size, spp, stream and threads of the render that follows; the
/// pilot renders with the estimator's own pixel sampler at image.spp.
RenderEstimator resolve_split(const RenderScene& rs, const RenderEstimator& est,
                              const RenderSettings& image);

/// The count of a pilot's least measured relative variance times seconds, a larger count only
/// where that product is at least 10 % below every smaller count's (1 if none is finite).
int pilot_choice(const SplitPilot& p);

/// n* of the formula above (independent pixels), rounded to the better neighbour and kept
/// in 1..kMaxSplitSamples (the largest where V_rest or c_light is not positive).
int optimal_split(double variance_rest, double variance_light, double seconds_rest,
                  double seconds_light);

} // namespace mcp
