// The timed pilot behind the "auto" counts (splitting.h).
#include "render/splitting.h"

#include "core/parallel.h"
#include "render/progressive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

namespace mcp {

namespace {

/// The pilot's pixels: 1/kPilotShare of the image's samples (at least kPilotMinPixels pixels'),
/// at the image's spp up to kPilotMaxSpp; past it at kPilotMaxSpp on proportionally more pixels.
/// The rare large samples of a heavy-tailed estimator, which the pixel sampler does not
/// stratify away, rule its error at every spp; they are measured by the number of pixels and
/// samples, so more pixels at fewer spp see more of them for the same time.
constexpr size_t kPilotMinPixels = 256;
constexpr size_t kPilotShare = 96;
constexpr uint64_t kPilotMaxSpp = 16;
/// A larger count must be this much more efficient than the best smaller one to replace it:
/// where efficiency is flat in the count (splitting's often is near its optimum) the pilot keeps
/// the smaller, cheaper one and stops early, and its noise does not send the count up.
constexpr double kPilotGain = 1.1;
/// The pilot renders count 1 and 2, then larger counts only while its processor time, with the
/// next count's (estimated at twice the last's), stays within this share of the image's at
/// count 1 (projected from the pilot's seconds per camera sample).
constexpr double kPilotBudget = 0.3;

/// The pilot's pixels: a lattice of spacing s in rows and columns (s = sqrt(image / pilot
/// pixels)), each row's columns shifted by 3 more than the row above's (modulo s), so that the
/// pixels spread over the whole image.
struct PilotPixels {
    int spacing = 1;
    std::vector<int> rows, first_columns;
    size_t pixels = 0;
};

PilotPixels pilot_pixels(int width, int height, uint64_t spp_ratio) {
    PilotPixels out;
    const size_t w = size_t(std::max(1, width)), h = size_t(std::max(1, height));
    const size_t pixels =
        std::min(w * h, std::max(kPilotMinPixels, w * h / kPilotShare) * size_t(spp_ratio));
    out.spacing = std::max(1, int(std::floor(std::sqrt(double(w * h) / double(pixels)))));
    const int s = out.spacing;
    for (int k = 0, y = s / 2; y < int(h); ++k, y += s) {
        const int first = (s / 2 + 3 * k) % s;
        out.rows.push_back(y);
        out.first_columns.push_back(first);
        out.pixels += (w - size_t(first) + size_t(s) - 1) / size_t(s);
    }
    return out;
}

/// One estimator on the pilot's pixels: two renders at the image's own spp and pixel sampler,
/// independently randomized (streams `streams[0]`, `streams[1]`), on two threads when the
/// image has them; the processor seconds of both.
struct PilotRenders {
    std::vector<RenderImage> a, b; ///< per pilot row (NaN off the lattice)
    double seconds = 0.0;
};

PilotRenders pilot_renders(const RenderScene& rs, const RenderEstimator& est,
                           const RenderSettings& pilot, const PilotPixels& px,
                           const uint64_t streams[2], int threads) {
    PilotRenders out;
    out.a.resize(px.rows.size());
    out.b.resize(px.rows.size());
    const std::clock_t begin = std::clock();
    auto replica = [&](int r) {
        RenderSettings s = pilot;
        s.stream = streams[r];
        std::vector<RenderImage>& images = r == 0 ? out.a : out.b;
        for (size_t k = 0; k < px.rows.size(); ++k) {
            ImageBand band =
                make_band(pilot.width, pilot.height, px.rows[k], px.rows[k] + 1, est.pixel_sampler);
            band.column_first = px.first_columns[k];
            band.column_step = px.spacing;
            render_pass(rs, est, s, band);
            images[k] = band_image(band);
        }
    };
    // run_workers returns the workers it ran (1 in a build without threads).
    const int ran = threads >= 2 ? run_workers(2, replica) : 0;
    for (int r = ran; r < 2; ++r) replica(r);
    out.seconds = double(std::clock() - begin) / CLOCKS_PER_SEC;
    return out;
}

/// Terms of the relative variance past this many times the mean of the terms below their 99th
/// percentile are a heavy tail's rare large samples (a firefly: 1e4-1e5 times a pixel's
/// ordinary term on the Veach scene, where those spread over 1-2 orders of magnitude).
constexpr double kTailFactor = 1000.0;

/// The relative variance of one pixel estimate, averaged over the pilot's pixels and channels as
/// the images' relative MSE is (each term over the squared pixel mean `mean` + eps), split into
/// the body (each term up to the cut, kTailFactor times the mean of the terms below their 99th
/// percentile) and the tail (what lies beyond). With independent pixels the variance comes from
/// each pixel's own samples (both renders'); with any other sampler, whose samples are not
/// independent within a pixel, from the two independently randomized renders: E[(a - b)^2 / 2] =
/// Var(a).
struct RelativeVariance {
    double body = 0.0, tail = 0.0;
};

RelativeVariance relative_variance(const PilotRenders& r,
                                   const std::vector<std::vector<double>>& mean, double eps,
                                   bool within_pixel) {
    std::vector<double> terms;
    for (size_t k = 0; k < r.a.size(); ++k)
        for (size_t i = 0; i < r.a[k].rgb.size(); ++i) {
            const double d = r.a[k].rgb[i] - r.b[k].rgb[i];
            const double v =
                within_pixel ? 0.5 * (r.a[k].variance[i] + r.b[k].variance[i]) : 0.5 * d * d;
            const double m = mean[k][i];
            if (std::isfinite(v) && std::isfinite(m)) terms.push_back(v / (m * m + eps));
        }
    RelativeVariance out;
    if (terms.empty()) return out;
    // The cut: kTailFactor times the mean of the terms below their 99th percentile.
    std::vector<double> sorted = terms;
    std::sort(sorted.begin(), sorted.end());
    const size_t below = std::max<size_t>(1, sorted.size() * 99 / 100);
    double lower = 0.0;
    for (size_t i = 0; i < below; ++i) lower += sorted[i];
    const double cut = kTailFactor * lower / double(below);
    for (double t : terms) {
        out.body += std::min(t, cut);
        out.tail += std::max(0.0, t - cut);
    }
    out.body /= double(terms.size());
    out.tail /= double(terms.size());
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

/// The index in p.counts of the count pilot_choice takes, -1 if no cost is finite.
int pilot_best(const SplitPilot& p) {
    int best = -1;
    double best_cost = 0.0;
    for (int i = 0; i < p.tried; ++i) {
        const double cost = p.relative_variance[i] * p.sample_seconds[i];
        if (!std::isfinite(cost)) continue;
        if (best < 0 || cost * kPilotGain < best_cost) {
            best = i;
            best_cost = cost;
        }
    }
    return best;
}

} // namespace

int pilot_choice(const SplitPilot& p) {
    const int best = pilot_best(p);
    return best < 0 ? 1 : p.counts[best];
}

namespace {

/// Which count a pilot chooses: light_samples (splitting), candidates (RIS) or emission_samples.
enum class PilotCount { LightSamples, Candidates, EmissionSamples };

/// The pilot of one count: the estimator rendered on the pilot's rows at counts 1, 2, 4, ...,
/// each twice, at the image's own spp and pixel sampler, and the count of the largest measured
/// efficiency 1 / (V C) kept (pilot_choice). The ladder stops two counts past the best so far
/// or at the largest count.
RenderEstimator run_pilot(const RenderScene& rs, const RenderEstimator& est,
                          const RenderSettings& image, PilotCount what) {
    const auto start = std::chrono::steady_clock::now();
    RenderSettings pilot = image;
    const uint64_t spp = std::max<uint64_t>(1, image.spp);
    pilot.spp = std::min(spp, kPilotMaxSpp); // a power of two where spp is (Sobol' pixels)
    pilot.progress = nullptr;
    pilot.cancel = nullptr;
    // Each render on one thread, timed by the processor time the pilot uses: other processes on
    // the machine do not enter the costs (wall time under load once made a shadow ray look free).
    pilot.threads = 1;
    const uint64_t streams[2] = {image.stream ^ 0x9e3779b97f4a7c15ull, // numbers of its own
                                 image.stream ^ 0xc2b2ae3d27d4eb4full};
    const PilotPixels px = pilot_pixels(image.width, image.height, spp / pilot.spp);
    const int largest = what == PilotCount::Candidates ? kMaxRisCandidates : kMaxSplitSamples;
    const bool within_pixel = est.pixel_sampler == PixelSamplerKind::Independent;
    RenderEstimator e = est;
    // The other counts, if they are still "auto", at 1 during this pilot.
    if (e.light_samples == 0) e.light_samples = 1;
    if (e.candidates == 0) e.candidates = 1;
    if (e.emission_samples == 0) e.emission_samples = 1;
    int& count = what == PilotCount::Candidates        ? e.candidates
                 : what == PilotCount::EmissionSamples ? e.emission_samples
                                                       : e.light_samples;
    SplitPilot p;
    p.ran = true;
    std::vector<std::vector<double>> mean; // count 1's pixel means: the same weights for all
    double eps = 0.0, samples = 0.0;
    double body[SplitPilot::kMaxTried] = {}, tail[SplitPilot::kMaxTried] = {};
    const double image_samples =
        double(std::max(1, image.width)) * double(std::max(1, image.height)) * double(spp);
    double spent = 0.0, last_seconds = 0.0; // the pilot's processor seconds, its last count's
    for (int n = 1; n <= largest && p.tried < SplitPilot::kMaxTried; n *= 2) {
        if (n > 2) {
            const double image_seconds = p.sample_seconds[0] * image_samples; // at count 1
            if (spent + 2.0 * last_seconds > kPilotBudget * image_seconds) break;
        }
        count = n;
        const PilotRenders r = pilot_renders(rs, e, pilot, px, streams, image.threads);
        spent += r.seconds;
        last_seconds = r.seconds;
        if (n == 1) {
            double lum = 0.0, terms = 0.0;
            for (size_t k = 0; k < r.a.size(); ++k) {
                mean.emplace_back(r.a[k].rgb.size());
                for (size_t i = 0; i < r.a[k].rgb.size(); ++i) {
                    mean[k][i] = 0.5 * (r.a[k].rgb[i] + r.b[k].rgb[i]);
                    if (!std::isfinite(mean[k][i])) continue; // off the lattice
                    lum += mean[k][i];
                    terms += 1.0;
                }
            }
            samples = double(px.pixels) * double(pilot.spp);
            lum /= std::max(1.0, terms);
            eps = 1e-2 * lum * lum;
            if (!(eps > 0.0)) eps = 1e-300;
        }
        const int i = p.tried++;
        p.counts[i] = n;
        const RelativeVariance v = relative_variance(r, mean, eps, within_pixel);
        body[i] = v.body;
        tail[i] = v.tail;
        p.sample_seconds[i] = 0.5 * r.seconds / std::max(1.0, samples);
        // The tail: rare samples no pixel sampler stratifies, seen by a pilot this small in a
        // few of its renders only (a lottery per count). Pooled over the counts tried, each
        // scaled to count 1 by the 1 / n of averaging n samples: T_1 = mean_j (T_j n_j).
        p.tail = 0.0;
        for (int j = 0; j <= i; ++j) p.tail += tail[j] * p.counts[j] / double(i + 1);
        // Per camera sample: the pixel estimate's variance times spp.
        for (int j = 0; j <= i; ++j)
            p.relative_variance[j] = (body[j] + p.tail / p.counts[j]) * double(pilot.spp);
        p.tail *= double(pilot.spp);
        if (i - std::max(0, pilot_best(p)) >= 2) break; // two counts past the best so far
    }
    // The two-point model V(n) = V_rest + V_light / n, C(n) = c_rest + n c_light read from
    // count 1 and the largest count tried, for the record (the choice is the measured best).
    const int last = p.tried - 1;
    const double k = p.counts[last];
    if (k > 1.0) {
        const double v1 = p.relative_variance[0], vk = p.relative_variance[last];
        p.variance_light = std::max(0.0, (v1 - vk) * k / (k - 1.0));
        p.variance_rest = std::max(0.0, v1 - p.variance_light);
        p.seconds_light = std::max(0.0, (p.sample_seconds[last] - p.sample_seconds[0]) / (k - 1.0));
        p.seconds_rest = std::max(0.0, p.sample_seconds[0] - p.seconds_light);
    }
    p.samples = uint64_t(samples);
    p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int n = pilot_choice(p);
    RenderEstimator out = est;
    if (what == PilotCount::Candidates) {
        out.candidates = n;
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
