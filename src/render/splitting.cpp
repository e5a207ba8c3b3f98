// The timed pilot behind light_samples "auto" (splitting.h).
#include "render/splitting.h"

#include "render/progressive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

namespace mcp {

namespace {

/// The pilot's second count: large enough that its extra shadow rays stand out of the timing
/// noise, small enough that the pilot stays short.
constexpr int kPilotSplit = 5;
constexpr int kPilotCandidates = 8; ///< the pilot's second count of RIS candidates
constexpr int kPilotEmission = 8;   ///< and of camera rays for the emission seen directly
constexpr int kPilotReach = 4;      ///< the chosen count is at most this times the second
constexpr uint64_t kPilotSpp = 2;
constexpr int kPilotRuns = 1; ///< per count, the shortest time kept (interleaved runs)
/// The pilot's rows: kPilotBands bands spread over the image, an eighth of its rows in all, at
/// the image's own pixel size (a coarser pixel would count the image's detail within it as
/// camera-sample variance).
constexpr int kPilotBands = 8;

/// The variance of one camera sample, relative to each pixel's squared mean as the studies'
/// relative MSE is (eps = 1e-2 of the squared mean luminance), summed over the pixels and
/// channels of `a` (means from a and b, same pixels), and the number of terms.
void add_relative_variance(const RenderImage& a, const RenderImage& b, double eps, double* sum,
                           double* terms) {
    for (size_t i = 0; i < a.rgb.size(); ++i) {
        double m = 0.5 * (a.rgb[i] + b.rgb[i]);
        if (std::isfinite(a.variance[i]) && std::isfinite(m)) {
            *sum += a.variance[i] * double(a.spp) / (m * m + eps);
            *terms += 1.0;
        }
    }
}

/// The pilot's bands of one estimator and the processor seconds they took (one thread).
std::vector<RenderImage> pilot_bands(const RenderScene& rs, const RenderEstimator& est,
                                     const RenderSettings& pilot, double* seconds) {
    std::vector<RenderImage> out;
    const int rows = std::max(1, pilot.height / (8 * kPilotBands));
    const std::clock_t begin = std::clock();
    for (int k = 0; k < kPilotBands; ++k) {
        const int first = std::min(pilot.height - rows, k * pilot.height / kPilotBands);
        ImageBand band =
            make_band(pilot.width, pilot.height, std::max(0, first),
                      std::min(pilot.height, std::max(0, first) + rows), est.pixel_sampler);
        render_pass(rs, est, pilot, band);
        out.push_back(band_image(band));
    }
    *seconds = double(std::clock() - begin) / CLOCKS_PER_SEC;
    return out;
}

} // namespace

int optimal_split(double variance_rest, double variance_light, double seconds_rest,
                  double seconds_light) {
    if (!(variance_light > 0.0)) return 1;
    if (!(variance_rest > 0.0) || !(seconds_light > 0.0)) return kMaxSplitSamples;
    const double rest = std::max(seconds_rest, 0.0);
    double n = std::sqrt(variance_light / variance_rest * rest / seconds_light);
    n = std::clamp(n, 1.0, double(kMaxSplitSamples));
    auto cost = [&](int k) {
        return (variance_rest + variance_light / k) * (rest + k * seconds_light);
    };
    int lo = int(std::floor(n)), hi = std::min(lo + 1, kMaxSplitSamples);
    return cost(hi) < cost(lo) ? hi : lo;
}

namespace {

/// Which count a pilot chooses: light_samples (splitting) or candidates (RIS).
enum class PilotCount { LightSamples, Candidates, EmissionSamples };

/// The pilot of one count: estimates with the count at 1 and at k, the variance model
/// V(n) = V_rest + V_light / n and cost c_rest + n c_light read from the two, and n* chosen.
/// RIS's variance with M candidates falls as V_target + (V(1) - V_target) / M to first order
/// [Talbot05, 4], so the same model serves its candidates (c_light: one candidate's cost).
RenderEstimator run_pilot(const RenderScene& rs, const RenderEstimator& est,
                          const RenderSettings& image, PilotCount what) {
    const auto start = std::chrono::steady_clock::now();
    RenderSettings pilot = image;
    pilot.spp = kPilotSpp;
    pilot.stream = image.stream ^ 0x9e3779b97f4a7c15ull; // numbers of its own
    pilot.progress = nullptr;
    pilot.cancel = nullptr;
    // One thread, timed by the processor time it uses: other processes on the machine do not
    // enter the costs (wall time under load once made a shadow ray look free).
    pilot.threads = 1;
    // A candidate costs far less than a shadow ray: a larger second count stands out of the
    // timing noise.
    const int k_count = what == PilotCount::Candidates        ? kPilotCandidates
                        : what == PilotCount::EmissionSamples ? kPilotEmission
                                                              : kPilotSplit;
    RenderEstimator one = est, many = est;
    const auto count_of = [what](RenderEstimator& e) -> int& {
        return what == PilotCount::Candidates        ? e.candidates
               : what == PilotCount::EmissionSamples ? e.emission_samples
                                                     : e.light_samples;
    };
    count_of(one) = 1;
    count_of(many) = k_count;
    // The other counts, if they are still "auto", at 1 during this pilot.
    if (one.light_samples == 0) one.light_samples = many.light_samples = 1;
    if (one.candidates == 0) one.candidates = many.candidates = 1;
    if (one.emission_samples == 0) one.emission_samples = many.emission_samples = 1;
    one.pixel_sampler = many.pixel_sampler = PixelSamplerKind::Independent;
    std::vector<RenderImage> a, b;
    double t1 = 1e300, t2 = 1e300;
    for (int run = 0; run < kPilotRuns; ++run) {
        double t = 0.0;
        a = pilot_bands(rs, one, pilot, &t);
        t1 = std::min(t1, t);
        b = pilot_bands(rs, many, pilot, &t);
        t2 = std::min(t2, t);
    }
    double lum = 0.0, count = 0.0, samples = 0.0;
    for (size_t k = 0; k < a.size(); ++k) {
        for (size_t i = 0; i < a[k].rgb.size(); ++i) lum += a[k].rgb[i] + b[k].rgb[i];
        count += 2.0 * double(a[k].rgb.size());
        samples += double(a[k].pixel_count()) * double(pilot.spp);
    }
    const double eps = 1e-2 * (lum / count) * (lum / count);
    double v1 = 0.0, vk = 0.0, terms = 0.0, unused = 0.0;
    for (size_t k = 0; k < a.size(); ++k) {
        add_relative_variance(a[k], b[k], eps, &v1, &terms);
        add_relative_variance(b[k], a[k], eps, &vk, &unused);
    }
    v1 /= std::max(1.0, terms);
    vk /= std::max(1.0, terms);
    // V(1) = V_rest + V_light and V(k) = V_rest + V_light / k.
    const double k = k_count;
    SplitPilot p;
    p.ran = true;
    p.samples = uint64_t(samples);
    p.variance_light = std::max(0.0, (v1 - vk) * k / (k - 1.0));
    p.variance_rest = std::max(0.0, v1 - p.variance_light);
    p.seconds_light = std::max(0.0, (t2 - t1) / ((k - 1.0) * samples));
    p.seconds_rest = std::max(0.0, t1 / samples - p.seconds_light);
    RenderEstimator out = est;
    // The model is measured at 1 and k only: n* is not taken past kPilotReach k, where a
    // V_rest lost in the pilot's noise would send it to the largest count.
    const int n =
        std::min(optimal_split(p.variance_rest, p.variance_light, p.seconds_rest, p.seconds_light),
                 kPilotReach * k_count);
    p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (what == PilotCount::Candidates) {
        out.candidates = std::min(n, kMaxRisCandidates);
        out.candidate_pilot = p;
    } else if (what == PilotCount::EmissionSamples) {
        out.emission_samples = n;
        out.emission_pilot = p;
    } else {
        out.light_samples = n;
        out.split_pilot = p;
    }
    return out;
}

} // namespace

RenderEstimator resolve_split(const RenderScene& rs, const RenderEstimator& est,
                              const RenderSettings& image) {
    RenderEstimator out = est;
    // The candidates first (with one light sample), then the light samples of that estimator.
    if (out.candidates == 0) out = run_pilot(rs, out, image, PilotCount::Candidates);
    if (out.light_samples == 0) out = run_pilot(rs, out, image, PilotCount::LightSamples);
    // Then the camera rays for the emission seen directly, with the shading's counts fixed.
    if (out.emission_samples == 0) out = run_pilot(rs, out, image, PilotCount::EmissionSamples);
    return out;
}

} // namespace mcp
