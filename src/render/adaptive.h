// Adaptive allocation of an image's samples over its pixels. A first pass gives every pixel
// adaptive_first_pass_spp samples; the rest go where they lower the image's relative MSE the
// most. For independent pixel means of variance sigma_i^2 / n_i weighted by 1 / (R_i^2 + eps),
// a fixed total is best spent with n_i proportional to sigma_i / sqrt(R_i^2 + eps) (Neyman's
// allocation [Neyman34], as MISER spends its samples over boxes [PressFarrar90]; the error
// measure is the relative MSE of [RousselleKnausZwicker11]). Each count is the first pass's
// times a power of two, so that a pixel's samples stay a whole net of the padded Sobol'
// sampler, and at most kAdaptiveMaxFactor x the image's spp.
//
// Unbiased by construction: a pixel's count depends only on the first pass of the pixels of
// the other colour of a checkerboard (its four edge neighbours' error, that colour's mean
// luminance, whether the spread pays for its colour at all), never on its own samples; its mean of
// n_i samples is then unbiased given n_i. A count taken from the pixel's own first pass would tie
// how many samples it gets to what they showed (a pixel whose first samples happened to be quiet
// would stop early).
//
// The pixel sampler must extend a pixel's samples (independent, padded_sobol: sampler_extends).
#pragma once

#include <cstdint>
#include <vector>

#include "render/progressive.h"

namespace mcp {

/// Below this spp every pixel takes the image's spp (a first pass of fewer than 4 samples
/// shows too little of a pixel's variance).
constexpr uint64_t kAdaptiveMinSpp = 8;
/// A pixel takes at most this many times the image's spp.
constexpr uint64_t kAdaptiveMaxFactor = 64;

/// Below this predicted gain a checkerboard colour's pixels take the image's spp
/// (allocate_pixel_samples).
constexpr double kAdaptiveMinGain = 1.1;

/// The first pass's samples per pixel for an adaptive image of `spp`: half, at least 4 (a
/// quarter gained less: a pixel left at a quarter pays for every rare sample it then meets).
uint64_t adaptive_first_pass_spp(uint64_t spp);

/// Each pixel's samples (rows from the top) for an image of `spp` samples per pixel on
/// average, from `first`, a first pass over the whole image (first.spp samples per pixel,
/// fewer than spp). Each colour of the checkerboard spends at most spp x its pixels (what the
/// rounding to nets leaves over is not rendered). `kind`: the pixel sampler (how fast its
/// error falls sets how far the counts spread). A colour whose counts promise less than
/// kAdaptiveMinGain x lower relative MSE (each pixel's error as its neighbours show it, falling
/// as 1 / n) keeps spp everywhere. *predicted_gain: the relative MSE of spp everywhere over the
/// counts', the same way.
std::vector<uint32_t> allocate_pixel_samples(const ImageBand& first, uint64_t spp,
                                             PixelSamplerKind kind, double* predicted_gain);

/// render_image for an estimator with pixel_allocation adaptive (renderer.h): the first pass,
/// the counts, the second pass. settings.spp >= kAdaptiveMinSpp, a sampler that extends.
RenderImage render_adaptive(const RenderScene& rs, const RenderEstimator& est,
                            const RenderSettings& settings);

} // namespace mcp
