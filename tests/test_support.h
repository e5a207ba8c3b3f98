// Helpers shared by the test suites: Pearson chi-square goodness of fit, Sidak levels,
// and composite Gauss-Legendre quadrature.
#pragma once

#include <functional>
#include <vector>

namespace mcp::test {

struct ChiSquareResult {
    double statistic = 0.0;
    int dof = 0;
    double p_value = 1.0;
    int cells = 0; ///< cells after pooling
};

/// Pearson chi-square of observed against expected counts. Cells with an expected count
/// below min_expected are pooled (in order) until the pool reaches it, as in pbrt's and
/// Mitsuba's warp tests; dof = pooled cells - 1.
ChiSquareResult chi_square(const std::vector<double>& observed, const std::vector<double>& expected,
                           double min_expected = 5.0);

/// Per-test significance level that keeps the family-wise level alpha over k tests
/// (Sidak correction).
double sidak_level(double alpha, int k);

/// Composite 5-point Gauss-Legendre rule on `panels` equal panels of [lo, hi] (exact for
/// polynomials of degree 9 on each panel).
double gauss_legendre(const std::function<double(double)>& f, double lo, double hi, int panels);

} // namespace mcp::test
