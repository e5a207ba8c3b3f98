// Passes over an image band (progressive.h): the rows shared among worker threads, each
// pixel's Welford moments carried from pass to pass, with the integrator compiled for the
// scene's surfaces.
#include "render/progressive.h"

#include "core/parallel.h"
#include "core/points.h" // u63_to_double

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

#include "estimators/estimator.h" // kTopWeights

namespace mcp {

namespace {

/// How far a pass is, shared by its workers.
struct RowProgress {
    std::atomic<int> rows_done{0};
    std::atomic<bool> stop{false}; ///< cancelled (settings.cancel or the progress callback)
};

/// Adds samples [band.spp, st.spp) to rows row_begin + first, row_begin + first + step, ... of
/// the band, with the integrator compiled for the scene's surfaces (kernel K).
template <SurfaceKernel K>
void render_rows(const RenderScene& rs, const RenderEstimator& est, const RenderSettings& st,
                 int first, int step, ImageBand& band, RenderDiagnostics& diag,
                 RowProgress& progress) {
    PixelSampler sampler;
    sampler.configure(est.pixel_sampler, st.spp, st.width, st.height, st.stream);
    const CameraRays camera = camera_rays(rs.scene->camera, st.width, st.height);
    const bool keeps_generator = !band.generators.empty();
    const uint64_t first_sample = band.spp;
    const int rows = band.rows();
    // Camera rays per sample for the emission seen directly (0, "auto" unresolved, as 1; none
    // without lights or without jitter, where every ray of the pixel is the same).
    const int n_emission =
        st.jitter_pixels && !rs.lights_uniform.empty() ? std::max(1, est.emission_samples) : 1;
    for (int r = first; r < rows; r += step) {
        if (st.cancel && st.cancel->load(std::memory_order_relaxed)) progress.stop = true;
        if (progress.stop.load(std::memory_order_relaxed)) return;
        if (r > first) {
            const int done = progress.rows_done.fetch_add(1) + 1;
            // Only the calling thread (worker 0) reports, so the callback needs no lock.
            if (first == 0 && st.progress && !st.progress(done, rows)) {
                progress.stop = true;
                return;
            }
        }
        const int y = band.row_begin + r;
        for (int x = band.column_first; x < st.width; x += std::max(1, band.column_step)) {
            const size_t p = size_t(r) * size_t(st.width) + size_t(x);
            if (keeps_generator && first_sample > 0)
                sampler.resume_pixel(x, y, band.generators[p]);
            else
                sampler.start_pixel(x, y);
            // Welford moments per channel [Welford62]; samples are few enough per pixel
            // that plain double sums of them are exact to far below their noise.
            Vec3 mean(band.mean[3 * p], band.mean[3 * p + 1], band.mean[3 * p + 2]);
            Vec3 m2(band.m2[3 * p], band.m2[3 * p + 1], band.m2[3 * p + 2]);
            double lum_sum = band.lum_sum[p], lum_max = band.lum_max[p];
            uint64_t kept = band.kept[p];
            SampleCounters counters;
            // emission_samples where the emission seen at the pixel's four corners differs (an
            // emitter's edge or an occluder's crosses it): a choice fixed by the geometry,
            // independent of the samples, so each pixel's mean stays unbiased whatever it is.
            // Probed in the pixel's first pass and kept for the next (the live view's, an
            // adaptive image's second).
            int n_pixel = 1;
            if (n_emission > 1) {
                uint8_t& edge = band.emission_edge[p];
                if (edge == kEdgeUnknown) {
                    edge = kEdgeNone;
                    const Vec3 e0 = emitted_along(rs, ray_through(camera, x, y), counters);
                    for (const Vec2 corner : {Vec2(1, 0), Vec2(0, 1), Vec2(1, 1)}) {
                        const Ray probe = ray_through(camera, x + corner.x, y + corner.y);
                        if (emitted_along(rs, probe, counters) != e0) edge = kEdgeCrosses;
                    }
                }
                if (edge == kEdgeCrosses) n_pixel = n_emission;
            }
            // The pixel's own count (adaptive.h) or the pass's.
            const uint64_t end = st.pixel_spp != nullptr
                                     ? std::max<uint64_t>(first_sample, (*st.pixel_spp)[p])
                                     : st.spp;
            for (uint64_t i = first_sample; i < end; ++i) {
                sampler.start_sample(i);
                Vec2 jitter = st.jitter_pixels ? sampler.get_2d() : Vec2(0.5);
                Ray ray = ray_through(camera, x + jitter.x, y + jitter.y);
                RadianceSample rad = sample_radiance_with<K>(rs, est, ray, sampler, counters);
                if (n_pixel > 1) { // emission_samples: the emission seen directly, split
                    Vec3 emitted = rad.emitted;
                    for (int j = 1; j < n_pixel; ++j) {
                        const Vec2 s = shifted_jitter(jitter, j, n_pixel);
                        emitted +=
                            emitted_along(rs, ray_through(camera, x + s.x, y + s.y), counters);
                    }
                    rad.emitted = emitted / double(n_pixel);
                }
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
                if (reflected > 0.0) push_top_weight(diag.top, reflected);
            }
            diag.samples += end - first_sample;
            diag.rays += counters.rays;
            diag.light_misses += counters.light_misses;
            for (int c = 0; c < 3; ++c) {
                band.mean[3 * p + size_t(c)] = mean[c];
                band.m2[3 * p + size_t(c)] = m2[c];
            }
            band.kept[p] = kept;
            band.lum_sum[p] = lum_sum;
            band.lum_max[p] = lum_max;
            if (keeps_generator) band.generators[p] = sampler.pixel_rng();
        }
    }
    progress.rows_done.fetch_add(1);
}

} // namespace

ImageBand make_band(int width, int height, int row_begin, int row_end, PixelSamplerKind kind) {
    ImageBand b;
    b.width = width;
    b.height = height;
    b.row_begin = row_begin;
    b.row_end = row_end;
    const size_t n = b.pixel_count();
    b.mean.assign(3 * n, 0.0);
    b.m2.assign(3 * n, 0.0);
    b.kept.assign(n, 0);
    b.lum_sum.assign(n, 0.0);
    b.lum_max.assign(n, 0.0);
    b.emission_edge.assign(n, kEdgeUnknown);
    if (kind == PixelSamplerKind::Independent || kind == PixelSamplerKind::Stratified)
        b.generators.resize(n);
    return b;
}

std::string check_pass(const ImageBand& band, const RenderEstimator& est, uint64_t spp) {
    if (band.torn)
        return "a pass over this image was cancelled part-way: its rows have different spp";
    if (spp < band.spp)
        return "the image already has " + std::to_string(band.spp) + " spp, more than " +
               std::to_string(spp);
    if (band.spp > 0 && !sampler_extends(est.pixel_sampler))
        return std::string("the '") + pixel_sampler_name(est.pixel_sampler) +
               "' pixel sampler cannot add samples to an image (its samples depend on the final "
               "spp): use 'padded_sobol' or 'independent'";
    return "";
}

bool render_pass(const RenderScene& rs, const RenderEstimator& est, const RenderSettings& settings,
                 ImageBand& band) {
    if (settings.spp == band.spp) return true;
    auto start = std::chrono::steady_clock::now();
    int threads = std::max(1, std::min(settings.threads, band.rows()));
#if !MCPLAY_HAS_THREADS
    threads = 1; // one worker renders every row
#endif
    std::vector<RenderDiagnostics> diags(static_cast<size_t>(threads));
    RowProgress progress;
    // The integrator version for the scene's surfaces, chosen once for the whole pass.
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
        rows(rs, est, settings, t, threads, band, diags[size_t(t)], progress);
    });
    for (const auto& d : diags) band.diagnostics.merge(d);
    band.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (progress.stop.load() || (settings.cancel && settings.cancel->load())) {
        band.torn = true;
        return false;
    }
    band.spp = settings.spp;
    return true;
}

RenderImage band_image(const ImageBand& band) {
    RenderImage image;
    image.width = band.width;
    image.height = band.rows();
    image.spp = band.spp;
    image.seconds = band.seconds;
    image.cancelled = band.torn;
    const size_t n = band.pixel_count();
    image.rgb.assign(3 * n, 0.0);
    image.variance.assign(3 * n, 0.0);
    image.diagnostics = band.diagnostics;
    for (size_t p = 0; p < n; ++p) {
        const uint64_t kept = band.kept[p];
        for (size_t c = 0; c < 3; ++c) {
            image.rgb[3 * p + c] = kept > 0 ? band.mean[3 * p + c] : NAN;
            image.variance[3 * p + c] =
                kept > 1 ? band.m2[3 * p + c] / (u63_to_double(kept) * u63_to_double(kept - 1))
                         : NAN;
        }
        // A pixel owes more than half its value to one sample [renderer.h]; its own count, as
        // an adaptive image's pixels have different counts.
        if (band.kept[p] >= 16 && band.lum_sum[p] > 0.0) {
            const double share = band.lum_max[p] / band.lum_sum[p];
            image.diagnostics.max_sample_share =
                std::max(image.diagnostics.max_sample_share, share);
            if (share > 0.5) ++image.diagnostics.dominated_pixels;
        }
    }
    std::sort(image.diagnostics.top.begin(), image.diagnostics.top.end(), std::greater<double>());
    return image;
}

bool merge_bands(const std::vector<const ImageBand*>& bands, RenderImage* image,
                 std::string* error) {
    if (bands.empty()) {
        *error = "no bands to merge";
        return false;
    }
    const ImageBand& first = *bands.front();
    std::vector<const ImageBand*> sorted(bands);
    std::sort(sorted.begin(), sorted.end(),
              [](const ImageBand* a, const ImageBand* b) { return a->row_begin < b->row_begin; });
    int next_row = 0;
    for (const ImageBand* b : sorted) {
        if (b->width != first.width || b->height != first.height || b->spp != first.spp) {
            *error = "the bands are of different images or spp";
            return false;
        }
        if (b->torn) {
            *error = "a band's pass was cancelled part-way";
            return false;
        }
        if (b->row_begin != next_row) {
            *error = "the bands leave out or repeat rows from row " + std::to_string(next_row);
            return false;
        }
        next_row = b->row_end;
    }
    if (next_row != first.height) {
        *error = "the bands end at row " + std::to_string(next_row) + " of " +
                 std::to_string(first.height);
        return false;
    }
    RenderImage whole;
    whole.width = first.width;
    whole.height = first.height;
    whole.spp = first.spp;
    std::vector<double> top;
    for (const ImageBand* b : sorted) {
        RenderImage part = band_image(*b);
        whole.rgb.insert(whole.rgb.end(), part.rgb.begin(), part.rgb.end());
        whole.variance.insert(whole.variance.end(), part.variance.begin(), part.variance.end());
        top.insert(top.end(), part.diagnostics.top.begin(), part.diagnostics.top.end());
        part.diagnostics.top.clear();
        whole.diagnostics.merge(part.diagnostics);
        whole.seconds = std::max(whole.seconds, part.seconds); // the bands render side by side
    }
    std::sort(top.begin(), top.end(), std::greater<double>());
    if (top.size() > kTopWeights) top.resize(kTopWeights);
    whole.diagnostics.top = std::move(top);
    *image = std::move(whole);
    return true;
}

} // namespace mcp
