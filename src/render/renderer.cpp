// One image (renderer.h): its rows shared among worker threads, each pixel's Welford moments
// and the sample diagnostics, with the integrator compiled for the scene's surfaces.
#include "render/renderer.h"

#include "core/parallel.h"
#include "core/points.h" // u63_to_double

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

#include "estimators/estimator.h" // kTopWeights

namespace mcp {

namespace {

/// Keeps the kTopWeights largest values seen, as a min-heap.
void push_top(std::vector<double>& heap, double x) {
    if (heap.size() < kTopWeights) {
        heap.push_back(x);
        std::push_heap(heap.begin(), heap.end(), std::greater<double>());
    } else if (x > heap.front()) {
        std::pop_heap(heap.begin(), heap.end(), std::greater<double>());
        heap.back() = x;
        std::push_heap(heap.begin(), heap.end(), std::greater<double>());
    }
}

/// How far an image is, shared by its workers.
struct RowProgress {
    std::atomic<int> rows_done{0};
    std::atomic<bool> stop{false}; ///< the progress callback asked to cancel
};

/// Renders rows first_row, first_row + step, ... into the image, with the integrator compiled
/// for the scene's surfaces (kernel K).
template <SurfaceKernel K>
void render_rows(const RenderScene& rs, const RenderEstimator& est, const RenderSettings& st,
                 int first_row, int step, RenderImage& image, RenderDiagnostics& diag,
                 RowProgress& progress) {
    PixelSampler sampler;
    sampler.configure(est.pixel_sampler, st.spp, st.width, st.height, st.stream);
    const CameraRays camera = camera_rays(rs.scene->camera, st.width, st.height);
    for (int y = first_row; y < st.height; y += step) {
        if (st.cancel && st.cancel->load(std::memory_order_relaxed)) return;
        if (progress.stop.load(std::memory_order_relaxed)) return;
        if (y > first_row) {
            const int done = progress.rows_done.fetch_add(1) + 1;
            // Only the calling thread (worker 0) reports, so the callback needs no lock.
            if (first_row == 0 && st.progress && !st.progress(done, st.height)) {
                progress.stop = true;
                return;
            }
        }
        for (int x = 0; x < st.width; ++x) {
            size_t pixel = size_t(y) * size_t(st.width) + size_t(x);
            sampler.start_pixel(x, y);
            // Welford moments per channel [Welford62]; samples are few enough per pixel
            // that plain double sums of them are exact to far below their noise.
            Vec3 mean(0.0), m2(0.0);
            double lum_sum = 0.0, lum_max = 0.0;
            uint64_t kept = 0;
            SampleCounters counters;
            for (uint64_t i = 0; i < st.spp; ++i) {
                sampler.start_sample(i);
                Vec2 jitter = st.jitter_pixels ? sampler.get_2d() : Vec2(0.5);
                Ray ray = ray_through(camera, x + jitter.x, y + jitter.y);
                RadianceSample rad = sample_radiance_with<K>(rs, est, ray, sampler, counters);
                Vec3 L = rad.total();
                if (!std::isfinite(L.x) || !std::isfinite(L.y) || !std::isfinite(L.z)) {
                    ++diag.discarded_nonfinite;
                    continue;
                }
                ++kept;
                Vec3 delta = L - mean;
                mean += delta / u63_to_double(kept);
                m2 += delta * (L - mean);
                double lum = std::fabs(luminance(L));
                lum_sum += lum;
                lum_max = std::max(lum_max, lum);
                double reflected = std::fabs(luminance(rad.reflected));
                if (reflected > 0.0) push_top(diag.top, reflected);
            }
            diag.samples += st.spp;
            diag.rays += counters.rays;
            diag.light_misses += counters.light_misses;
            if (st.spp >= 16 && lum_sum > 0.0) {
                double share = lum_max / lum_sum;
                diag.max_sample_share = std::max(diag.max_sample_share, share);
                if (share > 0.5) ++diag.dominated_pixels;
            }
            Vec3 var_mean =
                kept > 1 ? m2 / (u63_to_double(kept) * u63_to_double(kept - 1)) : Vec3(NAN);
            for (int c = 0; c < 3; ++c) {
                image.rgb[pixel * 3 + size_t(c)] = kept > 0 ? mean[c] : NAN;
                image.variance[pixel * 3 + size_t(c)] = var_mean[c];
            }
        }
    }
    progress.rows_done.fetch_add(1);
}

} // namespace

void RenderDiagnostics::merge(const RenderDiagnostics& o) {
    samples += o.samples;
    discarded_nonfinite += o.discarded_nonfinite;
    rays += o.rays;
    light_misses += o.light_misses;
    dominated_pixels += o.dominated_pixels;
    max_sample_share = std::max(max_sample_share, o.max_sample_share);
    for (double x : o.top) push_top(top, x);
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
    auto start = std::chrono::steady_clock::now();
    RenderImage image;
    image.width = settings.width;
    image.height = settings.height;
    image.spp = settings.spp;
    image.rgb.assign(image.pixel_count() * 3, 0.0);
    image.variance.assign(image.pixel_count() * 3, 0.0);
    int threads = std::max(1, std::min(settings.threads, settings.height));
#if !MCPLAY_HAS_THREADS
    threads = 1; // one worker renders every row
#endif
    std::vector<RenderDiagnostics> diags(static_cast<size_t>(threads));
    RowProgress progress;
    // The integrator version for the scene's surfaces, chosen once for the whole image.
    const SurfaceKernel kernel =
        settings.specialize ? surface_kernel(*rs.scene) : SurfaceKernel::GeneralTextured;
    auto rows = &render_rows<SurfaceKernel::GeneralTextured>; // serves every scene
    switch (kernel) {
    case SurfaceKernel::GeneralTextured: break;
    case SurfaceKernel::General: rows = &render_rows<SurfaceKernel::General>; break;
    case SurfaceKernel::LambertianTextured:
        rows = &render_rows<SurfaceKernel::LambertianTextured>;
        break;
    case SurfaceKernel::Lambertian: rows = &render_rows<SurfaceKernel::Lambertian>; break;
    }
    run_workers(threads, [&](int t) {
        rows(rs, est, settings, t, threads, image, diags[size_t(t)], progress);
    });
    for (const auto& d : diags) image.diagnostics.merge(d);
    std::sort(image.diagnostics.top.begin(), image.diagnostics.top.end(), std::greater<double>());
    image.cancelled = (settings.cancel && settings.cancel->load()) || progress.stop.load();
    image.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return image;
}

} // namespace mcp
