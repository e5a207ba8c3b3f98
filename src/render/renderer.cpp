// One image (renderer.h): one pass over all its rows (progressive.cpp) or an adaptive image's
// two (adaptive.cpp), the diagnostics' merge, and the camera's rays.
#include "render/renderer.h"

#include "render/adaptive.h"
#include "render/progressive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

#include "estimators/estimator.h" // kTopWeights

namespace mcp {

/// Keeps the kTopWeights largest values seen, as a min-heap.
void push_top_weight(std::vector<double>& heap, double x) {
    if (heap.size() < kTopWeights) {
        heap.push_back(x);
        std::push_heap(heap.begin(), heap.end(), std::greater<double>());
    } else if (x > heap.front()) {
        std::pop_heap(heap.begin(), heap.end(), std::greater<double>());
        heap.back() = x;
        std::push_heap(heap.begin(), heap.end(), std::greater<double>());
    }
}

void RenderDiagnostics::merge(const RenderDiagnostics& o) {
    samples += o.samples;
    discarded_nonfinite += o.discarded_nonfinite;
    rays += o.rays;
    light_misses += o.light_misses;
    dominated_pixels += o.dominated_pixels;
    max_sample_share = std::max(max_sample_share, o.max_sample_share);
    for (double x : o.top) push_top_weight(top, x);
}

CameraRays camera_rays(const Camera& camera, int width, int height) {
    CameraRays c;
    c.origin = camera.position;
    c.forward = camera.forward;
    c.right = camera.right;
    c.up = camera.up;
    c.tan_half = std::tan(0.5 * camera.yfov);
    c.aspect = double(width) / double(height);
    c.width = width;
    c.height = height;
    return c;
}

Ray ray_through(const CameraRays& c, double x, double y) {
    double sx = (2.0 * x / c.width - 1.0) * c.tan_half * c.aspect;
    double sy = (1.0 - 2.0 * y / c.height) * c.tan_half;
    Ray r;
    r.origin = c.origin;
    r.direction = glm::normalize(c.forward + sx * c.right + sy * c.up);
    return r;
}

Ray camera_ray(const Camera& camera, int width, int height, double x, double y) {
    return ray_through(camera_rays(camera, width, height), x, y);
}

RenderImage render_image(const RenderScene& rs, const RenderEstimator& est,
                         const RenderSettings& settings) {
    // Below kAdaptiveMinSpp, or with a sampler that cannot add samples to a pixel (the render
    // API refuses that pairing), the same spp everywhere; image.allocation says which.
    if (est.pixel_allocation == PixelAllocation::Adaptive && settings.spp >= kAdaptiveMinSpp &&
        settings.pixel_spp == nullptr && sampler_extends(est.pixel_sampler))
        return render_adaptive(rs, est, settings);
    ImageBand band =
        make_band(settings.width, settings.height, 0, settings.height, est.pixel_sampler);
    render_pass(rs, est, settings, band);
    return band_image(band);
}

} // namespace mcp
