// Images rendered in passes: each pixel keeps its running moments (Welford's mean and sum of
// squared deviations, the luminance sum and largest luminance of its samples, and its generator
// where the pixel sampler has one), so that a pass adds samples [spp_done, spp) to every pixel
// and leaves the image exactly as one render of spp samples would (bit for bit: the same samples
// in the same order through the same arithmetic). render_image is one pass from 0.
//
// An ImageBand is rows [row_begin, row_end) of a width x height image: the page's workers each
// render a band of every pass, and the bands merged (merge_bands) are the image one worker
// rendering every row would give. Adding samples to a pixel needs a pixel sampler whose first n
// samples do not depend on the spp (sampler_extends: independent, padded_sobol); the stratified
// and sobol samplers render a band in one pass only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/renderer.h"

namespace mcp {

/// ImageBand::emission_edge's values.
constexpr uint8_t kEdgeUnknown = 0, kEdgeNone = 1, kEdgeCrosses = 2;

struct ImageBand {
    int width = 0, height = 0;      ///< the whole image's
    int row_begin = 0, row_end = 0; ///< the band's rows, [row_begin, row_end)
    /// The columns rendered: column_first, column_first + column_step, ... (a timed pilot's
    /// sparse pixels, splitting.h); the others keep 0 samples (NaN in band_image).
    int column_first = 0, column_step = 1;
    uint64_t spp = 0;     ///< samples per pixel so far
    double seconds = 0.0; ///< rendering time of all passes so far
    /// A pass was cancelled part-way: some rows have more samples than others, and the band
    /// takes no more passes.
    bool torn = false;
    // Per pixel of the band, rows from the top (structure of arrays):
    std::vector<double> mean, m2;  ///< 3 per pixel: Welford's running mean and M2 [Welford62]
    std::vector<uint64_t> kept;    ///< finite samples (NaN/Inf radiance is dropped)
    std::vector<double> lum_sum;   ///< sum of |luminance| of the kept samples
    std::vector<double> lum_max;   ///< largest |luminance| of a kept sample
    std::vector<Pcg32> generators; ///< the pixel sampler's generator (independent, stratified)
    /// Whether an emitter's or occluder's edge crosses the pixel (emission_samples' probe of
    /// its four corners, made once): kEdgeUnknown, kEdgeNone or kEdgeCrosses.
    std::vector<uint8_t> emission_edge;
    /// Summed over passes; dominated_pixels and max_sample_share are left at 0 here and
    /// computed from the pixels by band_image.
    RenderDiagnostics diagnostics;

    int rows() const { return row_end - row_begin; }
    size_t pixel_count() const { return size_t(width) * size_t(rows()); }
};

/// An empty band (0 spp) of rows [row_begin, row_end) of a width x height image for `kind`'s
/// pixel sampler. The caller bounds the sizes (the render API's limits).
ImageBand make_band(int width, int height, int row_begin, int row_end, PixelSamplerKind kind);

/// Why a band cannot be taken to `spp` samples per pixel with this estimator ("" when it can):
/// fewer than it has, a torn band, a second pass with a sampler that does not extend.
std::string check_pass(const ImageBand& band, const RenderEstimator& est, uint64_t spp);

/// Adds samples [band.spp, settings.spp) to every pixel of the band (settings.width, height
/// must be the band's image size; settings.stream keys the image and must be the same for
/// every pass and band). check_pass must have passed. Cancelled part-way (settings.cancel,
/// settings.progress), the band is torn; returns false then.
bool render_pass(const RenderScene& rs, const RenderEstimator& est, const RenderSettings& settings,
                 ImageBand& band);

/// The band as an image of width x rows() pixels: means, variances of the means, and the
/// diagnostics with the pixels' dominated_pixels and max_sample_share.
RenderImage band_image(const ImageBand& band);

/// Bands of one image at one spp, in any order, that cover its rows exactly once: the whole
/// image (as render_image gives it). "" or why they cannot be merged (into *error).
bool merge_bands(const std::vector<const ImageBand*>& bands, RenderImage* image,
                 std::string* error);

} // namespace mcp
