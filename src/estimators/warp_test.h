// Does a warp sample the density it claims? Pearson's chi-square goodness-of-fit test of a
// warp's samples against its pdf [Pearson1900], as Mitsuba's ChiSquareTest [Mitsuba3] and
// Nori's warptest [Nori] run it: N unit-cube points from PCG32 are warped, and binned in the
// domain's natural coordinates, where the domain is a unit square or cube of equal measure
// everywhere; the expected count of each bin is N times the integral of the pdf over it, by an
// adaptive quadrature. Bins with small expected counts are pooled, and the statistic's upper
// tail probability compared with a Sidak-corrected level [Sidak67]. The quadrature's error is
// carried into the verdict: a warp is rejected only when it would be with any expected counts
// within that error, passed only when it would pass with any, and otherwise "could not verify"
// (outcome Unverified) with the reason. A few samples of every bin probe the pdf where the
// quadrature's nodes did not look: a value far above every node near it (a peak the nodes
// missed) refines the quadrature around that sample, and only a sample where the pdf is 0
// itself says that the warp lands where its pdf says it cannot.
//
// Natural coordinates t in [0, 1)^k (each maps the domain's measure to a constant times
// Lebesgue measure, so a uniform warp fills the bins equally):
//   box (1 to 3 axes)  t_j = (x_j - lo_j) / (hi_j - lo_j)
//   disk               t1 = |x - c|^2 / R^2, t2 = phi / 2 pi about the centre c
//   triangle           t1 = (1 - b0)^2, t2 = b1 / (1 - b0) (barycentrics b0 of v0, b1 of v1:
//                      the inverse of the uniform warp b0 = 1 - sqrt(u1), b1 = u2 sqrt(u1))
//   sphere             t1 = (1 - z) / 2, t2 = phi / 2 pi
//   hemisphere         t1 = 1 - z, t2 = phi / 2 pi
// phi = atan2(y, x) taken in [0, 2 pi).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/made.h"
#include "estimators/named_warps.h"
#include "estimators/problem.h"

namespace mcp {

/// PCG32's stream for the samples ("warptest"); sample i takes draws sample_dim i ..
/// sample_dim (i + 1) - 1 of Pcg32(seed, kWarpTestStream), one per coordinate.
constexpr uint64_t kWarpTestStream = 0x7761727074657374ULL;
constexpr uint64_t kMaxWarpTestSamples = uint64_t(1) << 26;
/// Most bins per natural axis, and in all.
constexpr int kMaxWarpTestBinsPerAxis = 4096;
constexpr int kMaxWarpTestBins = 1 << 17;
/// Most pdf evaluations of the quadrature (its refinement stops there; the first pass over
/// the bins always runs and fits, at most kMaxWarpTestBins times 91 nodes).
constexpr uint64_t kMaxWarpTestPdfEvaluations = uint64_t(1) << 24;
/// How far outside its domain a warp's point may land by round-off: 1e-9 of the box's widths,
/// of the disk's radius, of the barycentrics, of a direction's unit length (or z below 0).
constexpr double kWarpDomainTolerance = 1e-9;

struct WarpTestOptions {
    uint64_t samples = 1000000; ///< N, 1 .. kMaxWarpTestSamples
    uint64_t seed = 1;          ///< PCG32's seed (its stream is fixed)
    /// Bins per natural axis (unused axes ignored); 0: the default for N, chosen for power
    /// (default_warp_test_bins): round(N^(2 / (k + 4)) / 4) per axis, at least 2.
    int bins[3] = {0, 0, 0};
    double significance = 0.01; ///< alpha, in (0, 1)
    /// The number of tests run together (1 .. 1e6): the level is Sidak's 1 - (1 - alpha)^(1 /
    /// tests), so that all of them pass with probability 1 - alpha when every warp is right.
    int tests = 1;
    int worst = 8; ///< how many of the most deviant bins to report, 0 .. 1000
    /// How far the pdf's integral over the domain may be from 1 (|integral - 1|), in (0, 1).
    double pdf_tolerance = 1e-3;
};

/// A bin: its index per natural axis and its range in each.
struct WarpTestBin {
    int index[3] = {0, 0, 0};
    double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {0.0, 0.0, 0.0};
    uint64_t observed = 0;
    double expected = 0.0;
    /// (observed - expected) / sqrt(expected); +-inf when expected is 0 and observed is not.
    double residual = 0.0;
};

/// The three outcomes: the samples follow the pdf, they do not, or the quadrature could not
/// settle which (the reason says why).
enum class WarpTestOutcome { Passed, Failed, Unverified };
const char* warp_test_outcome_name(WarpTestOutcome o); ///< "passed", "failed", "unverified"

struct WarpTestResult {
    int axes = 0;                        ///< natural coordinates: 1 to 3
    std::vector<std::string> axis_names; ///< e.g. "(1 - z) / 2", "phi / 2 pi"
    int bins[3] = {1, 1, 1};             ///< per axis (1 for unused axes)
    /// Per bin, flat index i0 + bins[0] (i1 + bins[1] i2) (axis 0 fastest).
    std::vector<uint64_t> observed;
    std::vector<double> expected; ///< N times the pdf's integral over the bin
    /// Per bin, the quadrature's error estimate of `expected` (N times the summed differences
    /// of its two rules over the bin's cells); N where a probe found a peak it never resolved.
    std::vector<double> expected_error;
    uint64_t samples = 0;
    /// The integral of the pdf over the domain (should be 1), and an estimate of its
    /// quadrature error (the sum over the quadrature's cells of the difference of its two
    /// rules: a bound in practice, far above the true error for smooth pdfs).
    double pdf_integral = 0.0, pdf_integral_error = 0.0;
    uint64_t pdf_evaluations = 0;
    double chi_square = 0.0;
    int dof = 0;                ///< pooled cells - 1
    int cells = 0;              ///< cells in the statistic after pooling
    int pooled_bins = 0;        ///< bins with expected count < 5 merged into pooled cells
    uint64_t zero_bins_hit = 0; ///< bins with expected count exactly 0 but samples in them
    /// Samples where the pdf, evaluated at the sample itself, is 0 (among the probes).
    uint64_t zero_pdf_samples = 0;
    /// Bins refined around a probe sample where the pdf was far above the quadrature's nodes,
    /// and those of them whose peak stayed unresolved.
    int probed_bins = 0, unresolved_bins = 0;
    double p_value = 0.0; ///< P(chi-square_dof >= statistic)
    /// The p-values of the largest and smallest statistic that expected counts within the
    /// quadrature's error allow (Cauchy-Schwarz, see warp_test.cpp); both p_value when exact.
    double p_value_low = 0.0, p_value_high = 0.0;
    /// sum over the cells of error^2 / expected: the quadrature's share of the statistic.
    double quadrature_chi_square = 0.0;
    double level = 0.0; ///< Sidak-corrected significance level
    bool pdf_integral_ok = false;
    WarpTestOutcome outcome = WarpTestOutcome::Failed;
    bool passed = false; ///< outcome == Passed
    std::string reason;  ///< the verdict in plain words
    /// Where the samples' mass departs from p's, in words, when the samples do not follow p
    /// (empty otherwise): per natural axis, the samples against p's expected counts (rescaled
    /// to the samples' total) in the quarters of its range summed over the other axes, the
    /// middle quarters together (quarter turns of an azimuth); a range is named when its count
    /// departs beyond its binomial noise and the quadrature's error at the level split over all
    /// ranges (Bonferroni): "too many samples near the centre (50% where p expects 25%), too
    /// few near the rim (13% where p expects 25%), in every direction". No such range: the
    /// departure is local, and the most deviant bin is named.
    std::string where;
    /// p integrates to c beyond its quadrature error, and the samples follow p / c.
    bool off_by_constant = false;
    /// The bins with the largest |residual|, largest first.
    std::vector<WarpTestBin> worst;
};

/// The expected counts of a test's bins: N times the pdf's integral over each, which depend on
/// the domain, the pdf, the bins and N but not on the seed. Computed once, they serve tests of
/// many seeds (run_warp_test with an expectation).
struct WarpTestExpectation {
    int bins[3] = {1, 1, 1};
    uint64_t samples = 0;
    std::vector<double> expected, expected_error;
    std::vector<double> max_pdf; ///< per bin, the largest pdf value at its quadrature nodes
    double pdf_integral = 0.0, pdf_integral_error = 0.0;
    uint64_t pdf_evaluations = 0;
};

/// The default bins per axis for N samples on k natural axes: round(N^(2 / (k + 4)) / 4), at
/// least 2. A smooth departure of relative size eps is seen through the noncentrality
/// N eps^2 against the statistic's spread sqrt(2 m), m = h^-k bins of width h: the smallest
/// departure seen has eps^2 ~ h^(-k/2) / N. Binning loses the part of it finer than a bin,
/// about (w h)^2 for a slope w. Balancing the two, h^(2 + k/2) ~ 1 / N, gives
/// h ~ N^(-2 / (k + 4)): Mann and Wald's
/// N^(2/5) in 1-D [MannWald42]. The constant 1/4 makes the test see g = u^1.01 claimed uniform
/// at N = 10^6 (63 bins: power ~1; 1024 bins: 0.43).
int default_warp_test_bins(uint64_t samples, int axes);

/// The quadrature of run_warp_test alone (the seed is not read). Errors: those of
/// run_warp_test but the samples'.
Made<WarpTestExpectation> expect_warp_counts(const Domain& domain, const Warp& warp,
                                             const WarpTestOptions& options = {});

/// Chi-square test of `warp` on `domain` (see the top of this file). Errors (one line): bad
/// options, a domain of more than 3 coordinates, a warp without map or pdf or of another
/// sample_dim than the domain's, a warp point outside the domain beyond round-off ("sample
/// 17 (u = (0.1, 0.7)) maps to x = (1.2, 0.3), outside the domain [0, 1] x [0, 1]"), a pdf
/// value negative, NaN or infinite ("the pdf is -0.5 at x = (0.2, 0.3)").
Made<WarpTestResult> run_warp_test(const Domain& domain, const Warp& warp,
                                   const WarpTestOptions& options = {});
/// The same with the expected counts computed beforehand by expect_warp_counts for the same
/// domain, warp and options (but the seed); an error when its samples or bins differ.
Made<WarpTestResult> run_warp_test(const Domain& domain, const Warp& warp,
                                   const WarpTestOptions& options,
                                   const WarpTestExpectation& expectation);

/// Pearson's statistic of observed against expected counts with Mitsuba's pooling: bins sorted
/// by expected count (ascending; ties by index) are merged in that order into a pool until the
/// pool's expectation reaches 5, which then counts as one cell; a last pool under 5 joins the
/// last cell emitted (or stands alone when there is none). Bins of expected count exactly 0
/// are left out. Sets chi_square, cells, dof = cells - 1 and pooled_bins.
void pooled_chi_square(const std::vector<uint64_t>& observed, const std::vector<double>& expected,
                       double* chi_square, int* cells, int* pooled_bins);
/// The same, and the quadrature's share: sum over the pooled cells of error^2 / expected and
/// the largest error / expected of a cell (errors of a pool summed).
void pooled_chi_square(const std::vector<uint64_t>& observed, const std::vector<double>& expected,
                       const std::vector<double>& expected_error, double* chi_square, int* cells,
                       int* pooled_bins, double* error_chi_square, double* max_relative_error);

/// Sidak's level 1 - (1 - alpha)^(1 / tests) [Sidak67], computed without cancellation.
double sidak_level(double alpha, int tests);

} // namespace mcp
