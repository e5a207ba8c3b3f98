// Adaptive allocation of an image's samples over its pixels (adaptive.h): the neighbours'
// error, the counts by water-filling per checkerboard colour, and the two passes.
#include "render/adaptive.h"

#include "core/points.h" // u63_to_double

#include <algorithm>
#include <chrono>
#include <cmath>

namespace mcp {

namespace {

/// What a pixel's first pass shows of its error: its channels' sample variances over
/// (mean^2 + eps), averaged, with eps = 1e-2 (mean luminance)^2 as in the relative MSE
/// [RousselleKnausZwicker11]. Negative: unknown (fewer than two samples kept).
double relative_variance(const ImageBand& b, size_t p, double eps) {
    const uint64_t kept = b.kept[p];
    if (kept < 2) return -1.0;
    double sum = 0.0;
    for (size_t c = 0; c < 3; ++c) {
        const double mean = b.mean[3 * p + c];
        const double variance = b.m2[3 * p + c] / u63_to_double(kept - 1);
        sum += variance / (mean * mean + eps);
    }
    return sum / 3.0;
}

/// Counts lo 2^k_i (a pixel's samples stay a whole Sobol' net of the padded_sobol sampler,
/// whose first lo samples the first pass took), at most hi, with 2^k_i nearest to
/// lambda s_i / lo in the logarithm: Neyman's allocation [Neyman34] rounded to nets. lambda is
/// the largest (bisection on its logarithm) whose counts sum to at most `budget`; the few
/// samples left over are not rendered. With no error shown anywhere, budget / n everywhere
/// (as the uniform image's spp).
std::vector<uint32_t> allocate_nets(const std::vector<double>& s, uint64_t lo, uint64_t hi,
                                    double budget, uint64_t even) {
    int k_max = 0;
    while ((lo << (k_max + 1)) <= hi) ++k_max;
    // In base-2 logarithms: k_i = round(L + l_i) clamped to [0, k_max], l_i = log2(s_i / lo),
    // L = log2(lambda); a pixel that shows no error (s_i = 0) keeps lo.
    std::vector<double> l(s.size(), -INFINITY);
    double l_min = INFINITY, l_max = -INFINITY;
    for (size_t i = 0; i < s.size(); ++i)
        if (s[i] > 0.0) {
            l[i] = std::log2(s[i] / double(lo));
            l_min = std::min(l_min, l[i]);
            l_max = std::max(l_max, l[i]);
        }
    std::vector<uint32_t> counts(s.size(), uint32_t(even));
    if (!(l_max > -INFINITY)) return counts;
    auto k_of = [&](double L, double li) {
        return int(std::clamp(std::floor(L + li + 0.5), 0.0, double(k_max)));
    };
    auto total = [&](double L) {
        double t = 0.0;
        for (double li : l) t += double(lo << k_of(L, li));
        return t;
    };
    // At L = -l_max - 1 every count is lo (within budget); at k_max + 1 - l_min every pixel
    // with error is at hi.
    double L_lo = -l_max - 1.0, L_hi = double(k_max) + 1.0 - l_min;
    if (total(L_hi) <= budget) {
        L_lo = L_hi;
    } else {
        for (int it = 0; it < 40; ++it) { // total(L_lo) <= budget < total(L_hi)
            const double mid = 0.5 * (L_lo + L_hi);
            (total(mid) <= budget ? L_lo : L_hi) = mid;
        }
    }
    for (size_t i = 0; i < s.size(); ++i) counts[i] = uint32_t(lo << k_of(L_lo, l[i]));
    return counts;
}

} // namespace

uint64_t adaptive_first_pass_spp(uint64_t spp) {
    return std::max<uint64_t>(4, spp / 2);
}

std::vector<uint32_t> allocate_pixel_samples(const ImageBand& first, uint64_t spp,
                                             PixelSamplerKind kind, double* predicted_gain) {
    const int w = first.width, h = first.rows();
    const size_t pixels = first.pixel_count();
    std::vector<uint32_t> counts(pixels, uint32_t(spp));
    // Mean luminance of each colour's pixels ((x + y) & 1) from their first pass.
    double lum_sum[2] = {0.0, 0.0};
    uint64_t lum_count[2] = {0, 0};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * size_t(w) + size_t(x);
            if (first.kept[p] == 0) continue;
            const Vec3 m(first.mean[3 * p], first.mean[3 * p + 1], first.mean[3 * p + 2]);
            lum_sum[(x + y) & 1] += luminance(m);
            ++lum_count[(x + y) & 1];
        }
    const bool qmc = kind == PixelSamplerKind::PaddedSobol;
    double gain_uniform = 0.0, gain_adaptive = 0.0;
    const uint64_t hi = spp * kAdaptiveMaxFactor;
    for (int colour = 0; colour < 2; ++colour) {
        // This colour's counts come from the other colour's first pass alone.
        const int other = 1 - colour;
        const double mean_lum =
            lum_count[other] > 0 ? lum_sum[other] / u63_to_double(lum_count[other]) : 0.0;
        const double eps = std::max(1e-2 * mean_lum * mean_lum, 1e-300);
        std::vector<size_t> members;
        // Each member's share of the samples: the neighbours' mean relative variance v to
        // the power 1/2 for independent samples (Neyman: error v / n), 1/4 for the padded
        // Sobol' sampler, whose pixel error falls as fast as n^-3 where the pixel is smooth
        // [Owen97b] (for error c n^-a the optimum is n proportional to c^(1 / (1 + a))).
        std::vector<double> score, relative; // the share's base, and v itself
        for (int y = 0; y < h; ++y)
            for (int x = (y + colour) & 1; x < w; x += 2) {
                double sum = 0.0;
                int known = 0;
                const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
                for (int k = 0; k < 4; ++k) {
                    if (nx[k] < 0 || nx[k] >= w || ny[k] < 0 || ny[k] >= h) continue;
                    const double r =
                        relative_variance(first, size_t(ny[k]) * size_t(w) + size_t(nx[k]), eps);
                    if (r < 0.0 || !std::isfinite(r)) continue;
                    sum += r;
                    ++known;
                }
                if (known == 0) continue; // nothing known around it: it keeps spp
                members.push_back(size_t(y) * size_t(w) + size_t(x));
                const double v = sum / known;
                relative.push_back(v);
                score.push_back(qmc ? std::sqrt(std::sqrt(v)) : std::sqrt(v));
            }
        if (members.empty()) continue;
        const std::vector<uint32_t> n =
            allocate_nets(score, first.spp, hi, double(spp) * double(members.size()), spp);
        double uniform = 0.0, spread = 0.0;
        for (size_t i = 0; i < members.size(); ++i) {
            uniform += relative[i] / double(spp);
            spread += relative[i] / double(n[i]);
        }
        // Where the pixels' errors hardly differ, moving samples gains less than the rounding
        // to nets and the first pass's noise cost: every pixel of the colour takes spp. Decided
        // per colour, from the other colour's first pass like the counts themselves.
        const bool spread_pays = spread > 0.0 && uniform >= kAdaptiveMinGain * spread;
        for (size_t i = 0; i < members.size(); ++i)
            counts[members[i]] = spread_pays ? n[i] : uint32_t(spp);
        gain_uniform += uniform;
        gain_adaptive += spread_pays ? spread : uniform;
    }
    *predicted_gain = gain_adaptive > 0.0 ? gain_uniform / gain_adaptive : 1.0;
    return counts;
}

RenderImage render_adaptive(const RenderScene& rs, const RenderEstimator& est,
                            const RenderSettings& settings) {
    ImageBand band =
        make_band(settings.width, settings.height, 0, settings.height, est.pixel_sampler);
    RenderSettings first = settings;
    first.spp = adaptive_first_pass_spp(settings.spp);
    first.pixel_spp = nullptr;
    // Progress runs once over the rows: the first pass is its first half, the second its rest.
    if (settings.progress)
        first.progress = [&](int done, int rows) { return settings.progress(done / 2, rows); };
    if (!render_pass(rs, est, first, band)) return band_image(band); // cancelled
    const auto start = std::chrono::steady_clock::now();
    double gain = 1.0;
    const std::vector<uint32_t> counts =
        allocate_pixel_samples(band, settings.spp, est.pixel_sampler, &gain);
    band.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const auto [lowest, highest] = std::minmax_element(counts.begin(), counts.end());
    RenderSettings rest = settings;
    rest.spp = *highest; // the sampler's bound; each pixel stops at its own count
    rest.pixel_spp = &counts;
    if (settings.progress)
        rest.progress = [&](int done, int rows) {
            return settings.progress(rows / 2 + (done + 1) / 2, rows);
        };
    render_pass(rs, est, rest, band);
    RenderImage image = band_image(band);
    image.spp = settings.spp;
    image.allocation.adaptive = true;
    image.allocation.first_pass_spp = first.spp;
    image.allocation.min_spp = *lowest;
    image.allocation.max_spp = *highest;
    image.allocation.predicted_gain = gain;
    return image;
}

} // namespace mcp
