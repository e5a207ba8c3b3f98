// Renders an image with one radiance estimator: spp samples per pixel, each pixel's numbers
// addressed by (image stream, pixel, sample, dimension) through its pixel sampler (so images
// are identical for any thread count), with per-pixel means, variances of the means, and the
// sample-level diagnostics of the integration estimators.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "render/integrator.h"

namespace mcp {

struct RenderSettings {
    int width = 64, height = 64;
    uint64_t spp = 16;   ///< a power of two for the Sobol' pixel sampler (check_pixel_sampler_spp)
    uint64_t stream = 1; ///< keys every pixel's random stream (seed, estimator, spp, replicate)
    int threads = 1;     ///< worker threads (1 where the build has none)
    bool jitter_pixels = true; ///< false: every sample's camera ray passes through the pixel centre
    /// true: the integrator compiled for the scene's surfaces (surface_kernel); false: the
    /// general one, whatever the scene (tests compare the two).
    bool specialize = true;
    const std::atomic<bool>* cancel = nullptr; ///< checked once per row
    /// Told the rows done so far (of `height`) after each row the calling thread renders, on
    /// that thread; returning false cancels. For long renders (a reference) that show progress.
    std::function<bool(int rows_done, int rows)> progress;
    /// Per pixel of the band (rows from the top): the samples it is to have after the pass,
    /// each at least the band's spp and at most `spp` (adaptive.h); null: `spp` everywhere.
    const std::vector<uint32_t>* pixel_spp = nullptr;
};

/// How an adaptive image spread its samples over its pixels (adaptive.h).
struct PixelAllocationInfo {
    bool adaptive = false;             ///< false: every pixel has the image's spp
    uint64_t first_pass_spp = 0;       ///< every pixel's samples before the allocation
    uint64_t min_spp = 0, max_spp = 0; ///< over the pixels
    /// Relative MSE of uniform allocation over the allocation's, as the first pass predicts
    /// it (each pixel's error as its neighbours show it; sample variance over n).
    double predicted_gain = 1.0;
};

/// Problems found while rendering, summed over the image.
struct RenderDiagnostics {
    uint64_t samples = 0;
    uint64_t discarded_nonfinite = 0; ///< samples whose radiance was NaN or infinite: dropped
    uint64_t rays = 0;
    uint64_t light_misses = 0;     ///< light samples with no valid point (degenerate, pdf 0)
    uint64_t dominated_pixels = 0; ///< pixels of >= 16 samples where one carries > half the sum
    double max_sample_share = 0.0; ///< over pixels of >= 16 samples: largest sample / pixel sum
    /// The kTopWeights largest luminances of the samples' reflected part (the emission seen
    /// directly is not random given the camera ray), decreasing: for Hill's tail index.
    std::vector<double> top;

    /// Adds o's counts; top must be a min-heap (as push_top_weight keeps it) and o.top any
    /// order.
    void merge(const RenderDiagnostics& o);
};

/// Keeps the kTopWeights largest values pushed in `heap`, a min-heap.
void push_top_weight(std::vector<double>& heap, double x);

struct RenderImage {
    int width = 0, height = 0;
    uint64_t spp = 0;
    std::vector<double> rgb;      ///< pixel means, 3 per pixel, rows from the top
    std::vector<double> variance; ///< variance of each pixel mean, 3 per pixel
    RenderDiagnostics diagnostics;
    PixelAllocationInfo allocation;
    double seconds = 0.0;
    bool cancelled = false;

    size_t pixel_count() const { return size_t(width) * size_t(height); }
};

/// The camera ray through image position (x, y) in pixels from the top-left corner.
Ray camera_ray(const Camera& camera, int width, int height, double x, double y);

/// camera_ray's constants for one image (one tan per image, not per ray): ray_through gives
/// the same rays, bit for bit.
struct CameraRays {
    Vec3 origin{0.0}, forward{0.0, 0.0, -1.0}, right{1.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
    double tan_half = 1.0, aspect = 1.0, width = 1.0, height = 1.0;
};
CameraRays camera_rays(const Camera& camera, int width, int height);
Ray ray_through(const CameraRays& c, double x, double y);

/// The image in one pass (progressive.h) from 0 to settings.spp samples per pixel, or, for an
/// estimator with pixel_allocation adaptive, in two (adaptive.h).
RenderImage render_image(const RenderScene& rs, const RenderEstimator& est,
                         const RenderSettings& settings);

} // namespace mcp
