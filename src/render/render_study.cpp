// Render convergence studies (render_study.h): an image's error against the reference, a
// level's statistics, flags and error concentration, the fitted order, and the study's loop
// over the spp ladder and the replicates.
#include "render/render_study.h"
#include "render/splitting.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/rng.h"
#include "core/special.h"
#include "core/stats.h"

namespace mcp {

namespace {

/// The reference's mean luminance, the scale every pixel is divided by before squaring
/// (so that neither 1e-200 nor 1e300 radiances underflow or overflow), or 0 when the
/// reference is black (or has no finite positive mean): relative MSE is then undefined.
double reference_scale(const RenderImage& reference) {
    double m = mean_luminance(reference, nullptr);
    return m > 0.0 && std::isfinite(m) ? m : 0.0;
}

/// eps of the relative MSE's denominator in units of the reference's squared mean.
constexpr double kRelEps = 1e-2;

} // namespace

ImageError image_error(const RenderImage& image, const RenderImage& reference) {
    ImageError e;
    size_t n = std::min(image.pixel_count(), reference.pixel_count());
    // relMSE = mean of ((I - R)^2 - v) / (R^2 + eps), eps = 1e-2 mean(R)^2
    // [RousselleKnausZwicker11], evaluated on I / mean(R) and R / mean(R).
    double scale = reference_scale(reference);
    double sum = 0.0, sum_raw = 0.0;
    double worst = -1.0, squares_raw = 0.0;
    size_t worst_pixel = 0;
    uint64_t covered = 0, counted = 0;
    for (size_t p = 0; p < n; ++p) {
        double pixel_raw = 0.0;
        for (int c = 0; c < 3; ++c) {
            size_t k = p * 3 + size_t(c);
            double d = image.rgb[k] - reference.rgb[k];
            double v_ref = std::isfinite(reference.variance[k]) ? reference.variance[k] : 0.0;
            if (scale > 0.0) {
                double ds = d / scale, r = reference.rgb[k] / scale;
                double vs = v_ref / scale / scale;
                double denom = r * r + kRelEps;
                pixel_raw += ds * ds / denom;
                sum += (ds * ds - vs) / denom;
            }
            double v = image.variance[k];
            if (std::isfinite(v) && std::isfinite(d)) {
                ++counted;
                if (std::fabs(d) <= 1.959963984540054 * std::sqrt(v + v_ref)) ++covered;
            }
        }
        sum_raw += pixel_raw;
        squares_raw += pixel_raw * pixel_raw;
        if (pixel_raw > worst) {
            worst = pixel_raw;
            worst_pixel = p;
        }
    }
    double m = n ? double(3 * n) : 1.0;
    if (scale > 0.0 && n > 0 && image.width > 0) {
        e.worst_pixel_term = worst / m;
        e.pixel_term_squares = squares_raw / m / m;
        e.worst_x = int(worst_pixel % size_t(image.width));
        e.worst_y = int(worst_pixel / size_t(image.width));
    }
    // A black reference: relative error has no scale, the relative MSE is undefined (NaN,
    // null in JSON) rather than a triumphant 0.
    e.rel_mse = scale > 0.0 ? sum / m : NAN;
    e.rel_mse_raw = scale > 0.0 ? sum_raw / m : NAN;
    e.coverage = counted ? double(covered) / double(counted) : NAN;
    e.mean_luminance = mean_luminance(image, &e.mean_luminance_se);
    return e;
}

ErrorSums band_error_sums(const RenderImage& band, const RenderImage& reference, int row_begin) {
    ErrorSums s;
    const double scale = reference_scale(reference);
    const size_t first = size_t(std::max(row_begin, 0)) * size_t(reference.width);
    const size_t available = reference.pixel_count() > first ? reference.pixel_count() - first : 0;
    const size_t n = std::min(band.pixel_count(), available);
    s.terms = 3 * uint64_t(n);
    if (!(scale > 0.0)) {
        s.sum = s.sum_raw = NAN;
        return s;
    }
    // The terms of image_error, in the same order.
    for (size_t p = 0; p < n; ++p) {
        double pixel_raw = 0.0;
        for (size_t c = 0; c < 3; ++c) {
            const size_t k = 3 * p + c, kr = 3 * (first + p) + c;
            const double d = band.rgb[k] - reference.rgb[kr];
            const double v_ref =
                std::isfinite(reference.variance[kr]) ? reference.variance[kr] : 0.0;
            const double ds = d / scale, r = reference.rgb[kr] / scale;
            const double vs = v_ref / scale / scale;
            const double denom = r * r + kRelEps;
            pixel_raw += ds * ds / denom;
            s.sum += (ds * ds - vs) / denom;
        }
        s.sum_raw += pixel_raw;
    }
    return s;
}

double mean_luminance(const RenderImage& image, double* se) {
    size_t n = image.pixel_count();
    double dn = n ? double(n) : 1.0;
    double sum = 0.0, var = 0.0;
    for (size_t p = 0; p < n; ++p) {
        Vec3 c(image.rgb[p * 3], image.rgb[p * 3 + 1], image.rgb[p * 3 + 2]);
        Vec3 v(image.variance[p * 3], image.variance[p * 3 + 1], image.variance[p * 3 + 2]);
        // Each term divided first: no overflow for radiances up to the largest double.
        if (std::isfinite(luminance(c))) sum += luminance(c) / dn;
        // Channels of one pixel share their samples; the luminance variance is bounded by
        // (sum_c w_c sd_c)^2, which is what an error bar may honestly claim without the
        // covariances.
        double sd = 0.2126 * std::sqrt(v.x) + 0.7152 * std::sqrt(v.y) + 0.0722 * std::sqrt(v.z);
        if (std::isfinite(sd)) var += (sd / dn) * (sd / dn);
    }
    if (se) *se = std::sqrt(var);
    return sum;
}

double relative_mse_floor(const RenderImage& reference) {
    double scale = reference_scale(reference);
    if (!(scale > 0.0)) return NAN;
    size_t n = reference.pixel_count() * 3;
    double sum = 0.0;
    for (size_t k = 0; k < n; ++k) {
        double v = reference.variance[k];
        if (!std::isfinite(v)) continue; // as in image_error: no correction where unknown
        double r = reference.rgb[k] / scale;
        sum += v / scale / scale / (r * r + kRelEps);
    }
    return n ? sum / double(n) : NAN;
}

bool below_reference_noise(const LevelStats& level, double floor) {
    return std::isfinite(level.variance) && (level.variance < 0.0 || level.variance < floor);
}

bool few_error_terms(const ErrorConcentration& c) {
    return c.effective_terms < kFewErrorTerms;
}

std::vector<Flag> render_level_flags(const LevelStats& level, const ErrorConcentration& c,
                                     double floor) {
    std::vector<Flag> flags;
    if (below_reference_noise(level, floor)) {
        Flag f(FlagCode::BelowReferenceNoise);
        f.n = level.n;
        f.value = level.variance;
        f.threshold = floor;
        flags.push_back(f);
    }
    if (few_error_terms(c)) {
        Flag f(FlagCode::FewPixelErrors);
        f.n = level.n;
        f.value = c.effective_terms;
        f.threshold = kFewErrorTerms;
        flags.push_back(f);
    }
    return flags;
}

std::vector<Flag> render_flags(const RenderEstimatorStudy& s, double floor) {
    std::vector<Flag> flags;
    if (s.levels.empty()) return flags;
    size_t below = 0;
    for (const LevelStats& l : s.levels) below += below_reference_noise(l, floor) ? 1 : 0;
    if (below > 0) {
        Flag f(FlagCode::ReferenceNoise);
        f.count = below;
        f.of = s.levels.size();
        f.threshold = floor;
        flags.push_back(f);
    }
    // Levels carried by a few (pixel, image) terms: the study's relative MSE is made by rare
    // events, which the other levels may simply not have seen.
    size_t concentrated = 0;
    size_t worst = 0;
    for (size_t i = 0; i < s.concentration.size() && i < s.levels.size(); ++i)
        if (few_error_terms(s.concentration[i])) {
            if (concentrated == 0 ||
                s.concentration[i].effective_terms < s.concentration[worst].effective_terms)
                worst = i;
            ++concentrated;
        }
    if (concentrated > 0) {
        Flag f(FlagCode::RareLargeErrors);
        // Bounded samples: each term has finite variance, and the concentration fades as the
        // images and pixels grow (heavy_tail's rule for bounded contributions).
        if (s.bound.bounded) f.severity = Severity::Info;
        f.count = concentrated;
        f.of = s.levels.size();
        f.n = s.levels[worst].n;
        f.value = s.concentration[worst].effective_terms;
        f.threshold = kFewErrorTerms;
        flags.push_back(f);
    }
    const LevelStats& deepest = s.levels.back();
    std::vector<Flag> tail = tail_flags(deepest, s.bound.bounded);
    // Infinite by construction (contribution_bound): heavy_tail at warning, whatever the tail
    // estimate reads (a contact is carried by rare pixels, beyond a few thousand samples' view).
    if (s.bound.infinite_variance && (tail.empty() || tail[0].code != FlagCode::HeavyTail)) {
        Flag f(FlagCode::HeavyTail);
        f.n = deepest.n;
        f.value = deepest.tail_index;
        f.count = deepest.tail_k > 0 ? uint64_t(deepest.tail_k) : 0;
        if (f.count > 0) f.se = f.value / std::sqrt(double(f.count));
        f.threshold = kHeavyTailAlpha;
        tail = {f};
    }
    for (const Flag& f : tail) flags.push_back(f);
    if (s.fit.valid && s.fit.order > -1.0 + 3.0 * s.fit.order_se && s.fit.order > -0.8) {
        Flag f(FlagCode::SlowConvergence);
        // Bounded samples have a finite variance: unbiased, their expected relative MSE falls
        // as 1/spp, and a slower fit is the levels' own noise (rare large errors), the
        // reference's, or a bias, which pixel_error_bars judges against the reference.
        if (s.bound.bounded) f.severity = Severity::Info;
        f.value = s.fit.order;
        f.se = s.fit.order_se;
        f.threshold = -1.0;
        flags.push_back(f);
    }
    if (deepest.coverage < 0.85 && deepest.n >= 16) {
        Flag f(FlagCode::PixelErrorBars);
        f.n = deepest.n;
        f.value = deepest.coverage;
        f.threshold = 0.85;
        flags.push_back(f);
    }
    return flags;
}

ImageSummary summarise_image(const RenderImage& image, const RenderImage& reference) {
    return ImageSummary{image_error(image, reference), image.diagnostics, image.seconds, image.spp};
}

namespace {

ErrorConcentration error_concentration(const std::vector<ImageSummary>& images) {
    ErrorConcentration c;
    c.images = int(images.size());
    double total = 0.0, squares = 0.0;
    bool overflow = false; // a pixel's term, or its square, beyond the doubles: one term rules
    std::vector<double> rel;
    for (size_t r = 0; r < images.size(); ++r) {
        const ImageError& e = images[r].error;
        if (std::isfinite(e.rel_mse)) rel.push_back(e.rel_mse);
        if (std::isnan(e.rel_mse_raw) || std::isnan(e.pixel_term_squares)) continue;
        if (!std::isfinite(e.rel_mse_raw) || !std::isfinite(e.pixel_term_squares)) {
            if (!overflow) {
                c.worst_image = int(r);
                c.worst_x = e.worst_x;
                c.worst_y = e.worst_y;
            }
            overflow = true;
            continue;
        }
        if (overflow) continue;
        total += e.rel_mse_raw;
        squares += e.pixel_term_squares;
        if (c.worst_image < 0 ||
            e.worst_pixel_term > images[size_t(c.worst_image)].error.worst_pixel_term) {
            c.worst_image = int(r);
            c.worst_x = e.worst_x;
            c.worst_y = e.worst_y;
        }
    }
    if (overflow) {
        c.effective_terms = 1.0;
    } else if (c.worst_image >= 0 && total > 0.0 && squares > 0.0) {
        // [Kish65]: (sum t)^2 / sum t^2, each factor divided first (no overflow).
        c.effective_terms = (total / std::sqrt(squares)) * (total / std::sqrt(squares));
        c.worst_share = images[size_t(c.worst_image)].error.worst_pixel_term / total;
    }
    if (!rel.empty()) c.median_rel_mse = median_interval(rel).median;
    return c;
}

} // namespace

ReferenceSummary summarise_reference(const RenderImage& reference) {
    ReferenceSummary r;
    r.mean_luminance = mean_luminance(reference, &r.mean_luminance_se);
    r.floor = relative_mse_floor(reference);
    return r;
}

LevelStats render_level_stats(const std::vector<ImageSummary>& images, const RenderImage& reference,
                              ErrorConcentration* concentration) {
    return render_level_stats(images, summarise_reference(reference), concentration);
}

LevelStats render_level_stats(const std::vector<ImageSummary>& images,
                              const ReferenceSummary& reference,
                              ErrorConcentration* concentration) {
    if (concentration) *concentration = error_concentration(images);
    LevelStats l;
    l.measure = LevelMeasure::RelativeMse;
    l.reps = int(images.size());
    if (images.empty()) return l;
    l.n = images[0].spp;
    const double ref_se = reference.mean_luminance_se, ref_mean = reference.mean_luminance;
    RunningMoments rel, lum, times;
    std::vector<double> seconds;
    double coverage = 0.0, run_se = 0.0;
    RenderDiagnostics pooled;
    for (const ImageSummary& im : images) {
        const ImageError& e = im.error;
        rel.add(e.rel_mse);
        lum.add(e.mean_luminance);
        coverage += e.coverage;
        run_se += e.mean_luminance_se;
        l.estimates.push_back(e.mean_luminance);
        l.run_std_errors.push_back(e.mean_luminance_se);
        l.time_total += im.seconds;
        times.add(im.seconds);
        seconds.push_back(im.seconds);
        pooled.merge(im.diagnostics);
    }
    double R = double(images.size());
    l.variance = rel.mean();
    double t = images.size() > 1 ? student_t_quantile(0.975, R - 1.0) : NAN;
    double rel_se = images.size() > 1 ? std::sqrt(rel.variance() / R) : NAN;
    l.variance_lo = l.variance - t * rel_se;
    l.variance_hi = l.variance + t * rel_se;
    l.mse = l.variance;
    l.rmse = std::sqrt(std::max(0.0, l.mse));
    l.error = l.rmse;
    l.has_exact = true;
    l.mean = lum.mean();
    // The comparison with the reference's mean carries the reference's own noise too.
    double se_mean = images.size() > 1 ? std::sqrt(lum.variance() / R) : NAN;
    l.std_error = std::sqrt(se_mean * se_mean + ref_se * ref_se);
    l.ci_lo = l.mean - t * se_mean;
    l.ci_hi = l.mean + t * se_mean;
    l.bias = l.mean - ref_mean;
    l.coverage = coverage / R;
    l.mean_run_se = run_se / R;
    l.time_mean = l.time_total / R;
    // The images' own timing noise, as for an integration level's replicates: the equal-time
    // comparison tests a difference against it (without it no winner can be named).
    l.time_std = std::sqrt(times.variance());
    const MedianInterval mi = median_interval(seconds);
    l.time_median = mi.median;
    l.time_median_lo = mi.lo;
    l.time_median_hi = mi.hi;
    // Below the reference's noise the relative MSE measures the reference, not the estimator:
    // no efficiency (it would be arbitrarily large).
    l.efficiency =
        l.variance > 0.0 && l.time_mean > 0.0 && !below_reference_noise(l, reference.floor)
            ? 1.0 / (l.variance * l.time_mean)
            : NAN;
    l.diagnostics.nonfinite = pooled.discarded_nonfinite;
    l.diagnostics.nonzero = pooled.samples;
    l.diagnostics.max_weight_share = pooled.max_sample_share;
    l.nonzero_per_run = double(pooled.samples) / R;
    l.ess_mean = NAN; // per pixel it is meaningless pooled over an image
    std::sort(pooled.top.begin(), pooled.top.end(), std::greater<double>());
    l.tail_k = hill_order(pooled.samples);
    l.tail_k = std::min<int>(l.tail_k, int(pooled.top.size()) - 1);
    l.tail_index = l.tail_k > 0 ? hill_tail_index(pooled.top, l.tail_k) : NAN;
    if (l.tail_k <= 0) l.tail_k = 0;
    return l;
}

ConvergenceFit fit_render_convergence(const std::vector<LevelStats>& levels, double floor) {
    // Each level's log relMSE has standard deviation se / relMSE by the delta method, with se
    // from the spread of its replicates (floored at 1e-3: a level is never trusted beyond that).
    std::vector<FitPoint> points;
    for (const LevelStats& l : levels) {
        const double rel = l.variance;
        const double t = l.reps > 1 ? student_t_quantile(0.975, double(l.reps - 1)) : NAN;
        const double se = (l.variance_hi - l.variance_lo) / 2.0 / t;
        if (!(rel > 0.0) || !std::isfinite(rel) || !(se > 0.0) || below_reference_noise(l, floor))
            continue;
        points.push_back({l.n, rel, std::max(se / rel, 1e-3)});
    }
    ConvergenceFit fit = fit_power_law(points, LevelMeasure::RelativeMse);
    if (points.size() < 3)
        fit.note = "fewer than 3 levels with a positive relative MSE above the reference's noise";
    else if (!fit.valid)
        fit.note = "all levels at one spp";
    else if (fit.levels_used < int(levels.size()))
        fit.note = "levels at or below the reference's noise are left out";
    return fit;
}

RenderStudyResult run_render_study(const RenderScene& rs, const std::vector<RenderEstimator>& given,
                                   const RenderStudySettings& settings,
                                   const RenderImage& reference,
                                   const RenderStudyProgress& progress) {
    auto start = std::chrono::steady_clock::now();
    RenderStudyResult result;
    result.settings = settings;
    result.threads_used = resolve_threads(settings.threads);
    // The "auto" counts: chosen once per study by a timed pilot (splitting.h).
    std::vector<RenderEstimator> estimators;
    for (const RenderEstimator& e : given) {
        RenderSettings image;
        image.width = settings.width;
        image.height = settings.height;
        image.stream = replicate_stream(settings.seed, e.name, 0, 0);
        image.threads = result.threads_used;
        // The pilot measures at the study's largest level, where most of its time goes.
        image.spp = std::max<uint64_t>(1, settings.spp_max);
        estimators.push_back(resolve_split(rs, e, image));
    }
    result.reference_mean_luminance = mean_luminance(reference, nullptr);
    result.relative_mse_floor = relative_mse_floor(reference);
    const LightContacts contacts =
        light_contacts(rs, double(settings.width) / double(settings.height));
    for (const RenderEstimator& e : estimators) {
        RenderEstimatorStudy s;
        s.estimator = e;
        s.bound = contribution_bound(e, contacts);
        result.estimators.push_back(s);
    }
    // The integration studies' loop (run_ladder), with an image as the estimate. Images run one
    // after another, each on all the study's threads (rows of pixels), so that a level's seconds
    // per image are the wall time of one image as a user renders it. An image is summarised as
    // soon as it is rendered: a level keeps one image (replicate 0, the preview), not reps.
    struct Rendered {
        bool rendered = false; ///< false: another part's replicate
        ImageSummary summary;
        RenderImage preview; ///< replicate 0 only
    };
    const int parts = std::max(1, settings.parts);
    const ReferenceSummary ref_summary = summarise_reference(reference);
    const std::vector<uint64_t> ladder = n_ladder(settings.spp_min, settings.spp_max);
    const size_t reps = static_cast<size_t>(settings.reps);
    auto run = [&](size_t e, uint64_t spp, int r, int) {
        if (r % parts != settings.part) return Rendered{};
        RenderSettings rset;
        rset.width = settings.width;
        rset.height = settings.height;
        rset.spp = spp;
        rset.stream = replicate_stream(settings.seed, estimators[e].name, spp, r);
        rset.threads = result.threads_used;
        rset.jitter_pixels = settings.jitter_pixels;
        Rendered out;
        out.rendered = true;
        RenderImage image = render_image(rs, estimators[e], rset);
        out.summary = summarise_image(image, reference);
        out.summary.replicate = r;
        if (r == 0) out.preview = std::move(image);
        return out;
    };
    auto end_level = [&](size_t level, std::vector<Rendered>& images) {
        for (size_t e = 0; e < estimators.size(); ++e) {
            RenderEstimatorStudy& s = result.estimators[e];
            std::vector<ImageSummary> summaries;
            for (size_t r = 0; r < reps; ++r)
                if (images[e * reps + r].rendered)
                    summaries.push_back(images[e * reps + r].summary);
            if (reps > 0 && images[e * reps].rendered)
                s.preview = std::move(images[e * reps].preview);
            ErrorConcentration c;
            s.levels.push_back(render_level_stats(summaries, ref_summary, &c));
            s.concentration.push_back(c);
            if (parts > 1) s.images.push_back(std::move(summaries));
            s.fit = fit_render_convergence(s.levels, result.relative_mse_floor);
        }
        return !progress || progress(result, level);
    };
    result.cancelled =
        !run_ladder<Rendered>(ladder, estimators.size(), settings.reps, 1, run, end_level);
    result.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace mcp
