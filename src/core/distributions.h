// One- and two-dimensional sampling distributions for importance sampling: analytic
// densities sampled by their inverse CDF, and piecewise-constant densities tabulated from a
// user-given shape. Each distribution is normalised on its interval, has an exact pdf and
// an inverse (the CDF), and samples whole blocks at once (one dispatch per block).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/made.h"

namespace mcp {

enum class Dist1DKind {
    Uniform,           ///< p = 1/(b-a)
    Power,             ///< p proportional to (x - a)^k, k > -1 (k = 1: linear ramp)
    Exponential,       ///< p proportional to exp(-rate x); rate may be negative, not 0
    TruncatedGaussian, ///< p proportional to exp(-(x-mu)^2 / (2 sigma^2)) on [a, b]
    Cosine,            ///< p proportional to cos(omega (x - x0)), |omega (x - x0)| <= pi/2
    Tabulated,         ///< piecewise constant on equal bins of [a, b]
};

/// A normalised density on [a, b]. Construct with the make_* functions below, which
/// validate their parameters and return an error message instead of an object on bad input.
class Distribution1D {
  public:
    Distribution1D() = default;

    Dist1DKind kind() const { return kind_; }
    /// The number of equal bins of a tabulated density (0 for the analytic kinds).
    size_t bins() const { return func_.size(); }
    double lower() const { return a_; }
    double upper() const { return b_; }

    /// Inverse-CDF sample for u in (0,1); the result lies in [a, b].
    double sample(double u) const;
    /// Density at x (0 outside [a, b]).
    double pdf(double x) const;
    /// CDF at x, so that cdf(sample(u)) == u up to rounding: the inverse of sample.
    double cdf(double x) const;

    /// x[i] = sample(u[i]), pdf[i] = pdf(x[i]) for i < n: the batch form used in hot loops.
    void sample_block(const double* u, double* x, double* pdf, size_t n) const;
    /// pdf[i] *= pdf(x[i]): multiplies the densities of a product of 1D distributions.
    void multiply_pdf_block(const double* x, double* pdf, size_t n) const;

    /// A short description, e.g. "power(k=1) on [0, 1]".
    std::string describe() const;
    /// The same in words for people, with `x` the variable's name, e.g. "power-law density
    /// proportional to x on [0, 1]" or "exponential density proportional to e^(0.8 x) on
    /// [0, 1]" (rate -0.8): no parameter names, no "=" and no "_".
    std::string describe_text(const std::string& x = "x") const;

  private:
    friend struct Distribution1DFactory;
    Dist1DKind kind_ = Dist1DKind::Uniform;
    double a_ = 0.0, b_ = 1.0;
    double p0_ = 0.0, p1_ = 0.0;  // kind-specific parameters and precomputed terms
    double c0_ = 0.0, c1_ = 0.0;  // (see the kernels in distributions.cpp)
    std::vector<double> func_;    // tabulated: the normalised density of each bin
    std::vector<double> cdf_;     // tabulated: cdf at bin edges, cdf_[0] = 0, back() = 1
    std::vector<uint32_t> guide_; // tabulated: the bin of u = g / bins, g < bins
};

/// The shortest "%g" text that reads back as the same double ("0.5", "1e-08").
std::string shortest_number_text(double v);

Made<Distribution1D> make_uniform(double a, double b);
Made<Distribution1D> make_power(double a, double b, double k);
Made<Distribution1D> make_exponential(double a, double b, double rate);
Made<Distribution1D> make_truncated_gaussian(double a, double b, double mu, double sigma);
Made<Distribution1D> make_cosine(double a, double b, double omega, double x0);
/// Piecewise-constant density on equal bins of [a, b] proportional to values[i] >= 0.
/// Errors when values is empty, has a negative, NaN or infinite entry, or sums to zero.
Made<Distribution1D> make_tabulated(double a, double b, const std::vector<double>& values);

/// Piecewise-constant density on an nx-by-ny grid over [x0,x1] x [y0,y1], proportional to
/// values[iy * nx + ix] >= 0, sampled as marginal in y (from u2) then conditional in x (from
/// u1) [PBR4, A.5.6].
class TabulatedDistribution2D {
  public:
    /// Samples (x, y) from (u1, u2) and returns the density per unit area.
    void sample(double u1, double u2, double* x, double* y, double* pdf) const;
    double pdf(double x, double y) const;
    /// The inverse of sample: (u1, u2) from a point.
    void invert(double x, double y, double* u1, double* u2) const;
    void sample_block(const double* u1, const double* u2, double* x, double* y, double* pdf,
                      size_t n) const;

    /// In words: "piecewise-constant density on a 16 x 16 grid of cells over [0, 1] x [0, 1]".
    std::string describe_text() const;

    int nx() const { return nx_; }
    int ny() const { return ny_; }
    double x0() const { return x0_; }
    double x1() const { return x1_; }
    double y0() const { return y0_; }
    double y1() const { return y1_; }

  private:
    friend Made<TabulatedDistribution2D> make_tabulated_2d(double, double, double, double, int, int,
                                                           const std::vector<double>&);
    int nx_ = 0, ny_ = 0;
    double x0_ = 0, x1_ = 1, y0_ = 0, y1_ = 1;
    std::vector<Distribution1D> conditional_; // one per row y, over x
    Distribution1D marginal_;                 // over y
    double total_ = 0.0;                      // integral of the unnormalised table
    std::vector<double> values_;              // |values|, row-major
};

Made<TabulatedDistribution2D> make_tabulated_2d(double x0, double x1, double y0, double y1, int nx,
                                                int ny, const std::vector<double>& values);

} // namespace mcp
