// Convergence studies of radiance estimators (run_render_study): every estimator renders the
// image at every spp of a ladder of powers of two, R replicates each, and is measured against a
// reference image by its relative mean squared error, the same way the integration studies
// measure estimators by their variance (study.h): relative MSE against spp, and against seconds
// per image. Declared here: the study's settings (RenderStudySettings, with the part of a study
// split over processes) and result; one image's error against the reference (image_error,
// mean_luminance, relative_mse_floor) and what a level keeps of it (ImageSummary,
// ReferenceSummary); a level's statistics, flags and error concentration (render_level_stats,
// render_level_flags, ErrorConcentration); the fitted order (fit_render_convergence) and the
// estimator's flags (render_flags).
//
// Relative MSE of an image I against the reference R [RousselleKnausZwicker11]:
//   relMSE = mean over pixels p and channels c of ((I_pc - R_pc)^2 - v_pc) / (R_pc^2 + eps),
// where v_pc, the variance of the reference pixel's own mean, removes the reference's noise
// from the expected squared difference (E (I - R)^2 = MSE(I) + Var(R) for independent I and
// R), and eps = 1e-2 times the squared mean of the reference keeps dark pixels from
// dominating. An unbiased estimator converges as relMSE ~ 1/spp. Every pixel is divided by
// the reference's mean luminance before squaring (no overflow or underflow at any radiance
// scale); a black reference makes relative MSE undefined (NaN, null in JSON), never 0.
//
// The reference's own noise, summed the same way, is the relative-MSE floor
//   floor = mean over p, c of v_pc / (R_pc^2 + eps):
// the raw relative MSE of a perfect estimator. v_pc is the reference pixel's sample variance
// over spp, which for the stratified and Sobol' pixel samplers overestimates the variance of
// its mean, so the subtraction can overshoot: a level whose corrected relative MSE is below the
// floor (or negative) measures the reference rather than the estimator. Such levels are
// flagged (below_reference_noise), have no efficiency, and are left out of the fitted order.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "estimators/diagnostics.h"
#include "estimators/study.h"
#include "render/contribution_bound.h"
#include "render/renderer.h"

namespace mcp {

struct RenderStudySettings {
    int width = 64, height = 64;
    uint64_t spp_min = 1, spp_max = 64;
    int reps = 4;
    uint64_t seed = 1;
    int threads = 0; ///< 0: all hardware threads
    bool jitter_pixels = true;
    /// Part `part` of `parts` of a study split over processes (the page's workers): only the
    /// replicates r with r % parts == part are rendered. Each image is the one the whole study
    /// renders (its stream depends on r alone), so the parts' images, merged by replicate
    /// (render_level_stats), give the whole study's levels.
    int part = 0, parts = 1;
};

/// Error of one image against the reference.
struct ImageError {
    double rel_mse = 0.0;     ///< reference-noise corrected (see the header comment)
    double rel_mse_raw = 0.0; ///< without the correction
    /// Share of pixel channels with |I - R| <= 1.96 sqrt(v_I + v_R): the image's own 95%
    /// interval, widened by the reference's variance, covers the reference.
    double coverage = 0.0;
    double mean_luminance = 0.0;
    double mean_luminance_se = 0.0;
    /// The pixel with the largest raw term of the relative MSE (its three channels), and that
    /// term in the units of rel_mse_raw (the image's rel_mse_raw sums every pixel's term);
    /// the sum of the pixels' squared terms, in the same units squared.
    double worst_pixel_term = 0.0;
    double pixel_term_squares = 0.0;
    int worst_x = -1, worst_y = -1;
};
ImageError image_error(const RenderImage& image, const RenderImage& reference);

/// The relative MSE's sums over the rows of one band of an image (band: width x rows pixels,
/// its row 0 the reference's row `row_begin`), with the whole reference's mean luminance as the
/// scale: bands' sums add up, and the image's relMSE is (sum of sum) / (sum of terms), its raw
/// one (sum of sum_raw) / (sum of terms); a black reference gives NaN sums. For the whole image
/// (row_begin 0) sum / terms is image_error's rel_mse.
struct ErrorSums {
    double sum = 0.0, sum_raw = 0.0;
    uint64_t terms = 0; ///< pixel channels: 3 per pixel
};
ErrorSums band_error_sums(const RenderImage& band, const RenderImage& reference, int row_begin);

/// What a level keeps of one image.
struct ImageSummary {
    ImageError error;
    RenderDiagnostics diagnostics;
    double seconds = 0.0;
    uint64_t spp = 0;
    int replicate = 0;
};

/// The image's mean luminance, and when `se` is given its standard error from the pixels'
/// variances.
double mean_luminance(const RenderImage& image, double* se = nullptr);

/// The relative-MSE floor of a reference (see the header comment): 0 for a noiseless
/// reference (an HDR file), NaN for a black one.
double relative_mse_floor(const RenderImage& reference);

/// Is the level's relative MSE negative or below the reference's floor?
bool below_reference_noise(const LevelStats& level, double floor);

/// How concentrated a level's relative MSE is. The level's raw relative MSE is a sum of
/// (pixel, image) terms t; Kish's effective number of them, (sum t)^2 / sum t^2 [Kish65], is in
/// the hundreds or more when the error is spread over an image, and a handful when a few rare
/// events make it: a camera ray that hit a light from a dark pixel, a firefly. The level's
/// number (and the interval from its images' spread) then rests on those few events, levels
/// that saw none understate the error, and relative MSE can rise from one spp to the next.
struct ErrorConcentration {
    int images = 0;
    double effective_terms = NAN; ///< Kish's effective number of (pixel, image) terms
    int worst_image = -1, worst_x = -1, worst_y = -1; ///< the largest term
    double worst_share = NAN;                         ///< its share of the level's raw sum
    double median_rel_mse = NAN; ///< the median image's relative MSE: the typical image
};

/// A level whose relative MSE rests on fewer than kFewErrorTerms effective (pixel, image)
/// terms (the integration studies' threshold for Kish's effective sample size, kLowEss).
constexpr double kFewErrorTerms = kLowEss;
bool few_error_terms(const ErrorConcentration& c);

struct RenderEstimatorStudy {
    RenderEstimator estimator;
    std::vector<LevelStats> levels; ///< n = spp; see render_level_stats for the fields' meaning
    std::vector<ErrorConcentration> concentration; ///< one per level
    ConvergenceFit fit;                            ///< of relative MSE against spp
    /// Whether its per-sample contributions are bounded by construction (contribution_bound):
    /// then heavy_tail is info, a pre-asymptotic tail.
    ContributionBound bound;
    RenderImage preview; ///< replicate 0 at the largest spp rendered
    /// Each level's images, kept by a part of a study split over processes (for the merge).
    std::vector<std::vector<ImageSummary>> images;
};

struct RenderStudyResult {
    RenderStudySettings settings;
    int threads_used = 1;
    double wall_seconds = 0.0;
    bool cancelled = false;
    double reference_mean_luminance = 0.0;
    double relative_mse_floor = 0.0; ///< of the reference; NaN when it is black
    std::vector<RenderEstimatorStudy> estimators;
};

/// The flags of a render estimator over its study (diagnostics as data, worded by the API):
/// reference_noise (levels below the reference's floor: count, of), the tail flags of the
/// deepest level (heavy_tail as info when s.bound says the contributions are bounded),
/// slow_convergence (fitted order above -1 by more than 3 standard errors and above -0.8),
/// pixel_error_bars (under 85% of the pixels' own 95% intervals cover the
/// reference at the deepest spp, spp >= 16), rare_large_errors (levels whose relative MSE rests
/// on a few (pixel, image) terms: count, of; the most concentrated level's n and terms).
std::vector<Flag> render_flags(const RenderEstimatorStudy& s, double floor);
/// below_reference_noise and few_pixel_errors for one level, or nothing.
std::vector<Flag> render_level_flags(const LevelStats& level, const ErrorConcentration& c,
                                     double floor);

/// What a level needs of the reference: its mean luminance, that mean's standard error, and
/// the relative-MSE floor (so that parts of a study can be merged without the image).
struct ReferenceSummary {
    double mean_luminance = 0.0, mean_luminance_se = 0.0, floor = 0.0;
};
ReferenceSummary summarise_reference(const RenderImage& reference);
ImageSummary summarise_image(const RenderImage& image, const RenderImage& reference);

/// Summarises R replicate images of one level in the integration studies' terms:
///   variance, mse  relative MSE against the reference (mean over replicates), with a 95%
///                  t interval from the replicates' spread in variance_lo / variance_hi
///   rmse, error    its square root (0 when the relative MSE is negative)
///   mean, estimates, ci  the image's mean luminance per replicate and over them, with bias
///                  against the reference's mean luminance; std_error also counts the
///                  reference mean's own standard error, ci does not
///   coverage       share of (pixel channel, replicate) pairs whose 95% interval covers the
///                  reference (ImageError::coverage): honest per-pixel error bars give 0.95
///   time_mean      seconds per image; efficiency = 1 / (relMSE * seconds), none (NaN) below
///                  the reference's noise
///   diagnostics    discarded samples (nonfinite), samples (nonzero), largest single-sample
///                  share of a pixel (max_weight_share)
///   tail_index     Hill's estimate on the luminance of the samples' reflected radiance, pooled
///                  over the image and the replicates
/// With `concentration`, also where the level's relative MSE comes from.
LevelStats render_level_stats(const std::vector<ImageSummary>& images,
                              const ReferenceSummary& reference,
                              ErrorConcentration* concentration = nullptr);
LevelStats render_level_stats(const std::vector<ImageSummary>& images, const RenderImage& reference,
                              ErrorConcentration* concentration = nullptr);

/// Fitted order of relative MSE against spp (fit_power_law, measure RelativeMse): weights from
/// each level's replicate spread, the standard error inflated by the residuals. Levels below
/// the reference's noise (below_reference_noise with `floor`) are left out.
ConvergenceFit fit_render_convergence(const std::vector<LevelStats>& levels, double floor = 0.0);

/// Called after each completed level; returning false cancels the study.
using RenderStudyProgress = std::function<bool(const RenderStudyResult& partial, size_t level)>;

RenderStudyResult run_render_study(const RenderScene& rs,
                                   const std::vector<RenderEstimator>& estimators,
                                   const RenderStudySettings& settings,
                                   const RenderImage& reference,
                                   const RenderStudyProgress& progress = {});

} // namespace mcp
