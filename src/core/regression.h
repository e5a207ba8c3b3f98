// Regression on streamed samples, for control variates and optimally weighted MIS: running
// means and co-moments of a vector of values (Welford's update per block, merged by Chan's
// formula [Welford62, Chan79]), and the least-squares coefficients they give, solved by a
// Cholesky factorisation that drops columns which are linear combinations of earlier ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mcp {

/// Means and the matrix of co-moments C_ab = sum_i (z_ia - mean_a)(z_ib - mean_b) of
/// d-vectors z_i, added a block at a time.
class RunningCovariance {
  public:
    void reset(int dim);
    int dim() const { return dim_; }
    uint64_t count() const { return n_; }
    /// Adds `count` vectors: component a of vector i is columns[a][i].
    void add_block(const double* const* columns, size_t count);
    void merge(const RunningCovariance& o);
    double mean(int a) const { return mean_[static_cast<size_t>(a)]; }
    double comoment(int a, int b) const {
        return c_[static_cast<size_t>(a) * static_cast<size_t>(dim_) + static_cast<size_t>(b)];
    }
    /// v^T C v (>= 0 up to rounding, clamped at 0): the sum of squared deviations of v . z.
    double quadratic_form(const std::vector<double>& v) const;

  private:
    int dim_ = 0;
    uint64_t n_ = 0;
    std::vector<double> mean_, c_; // c_: dim x dim, row major
    std::vector<double> block_mean_, block_c_;
};

/// Solves the symmetric positive semi-definite system A x = b (A: n x n, row major) by
/// Cholesky factorisation. A pivot below 1e-12 of its column's diagonal entry means the
/// column is (numerically) a combination of the earlier ones: its coefficient is set to 0 and
/// the column dropped, so the solution is a least-squares one on the columns that remain.
/// Returns the number of columns kept.
int solve_psd(const std::vector<double>& a, const std::vector<double>& b, int n,
              std::vector<double>* x);

} // namespace mcp
