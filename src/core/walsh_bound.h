// The error bound of one digitally shifted digital net from its own Walsh coefficients
// [HickernellJimenezRugama16]: the cubature error of 2^m points of a base-2 digital sequence
// is a sum of the integrand's Walsh coefficients over the net's dual; for functions whose
// coefficients decay in a predictable way (a cone), the discrete coefficients of the data in
// one band bound it: |I - I_m| <= fudge(m) S_{m-r,m}, with
//   ytilde_nu = 2^-m sum_i y_i (-1)^<nu, i>  (the fast Walsh transform of the values in the
//               net's natural, radical-inverse order),
//   S_{l,m}  = sum over kappa in [2^(l-1), 2^l) of |ytilde_{nutilde(kappa)}|,
// nutilde the data-driven map that orders the coefficients by wavenumber (the larger of each
// pair (kappa, kappa + 2^l) taken as the lower wavenumber, level by level), r = 4 and
// fudge(m) = 5 2^-m, the paper's (and QMCPy's CubQMCNetG's) defaults.
// Doubling the net (points 2^m .. 2^(m+1) - 1, the next net of the sequence) updates the
// coefficients by one butterfly and the map for the new levels only, as the paper's algorithm
// does, so a bound at 2^M costs O(2^M M).
#pragma once

#include <cstdint>
#include <vector>

namespace mcp {

/// Smallest and largest sizes of a Walsh bound: the cone's conditions start at band
/// l* = m_min - r = 6 [HickernellJimenezRugama16], so the bound reads a band of the theory from
/// m_min = 10 on (smaller runs have no error bar); 2^24 values are 192 MiB of coefficients and
/// map. The map is built at 2^10 points, then doubled.
constexpr int kWalshLag = 4;
constexpr int kWalshMinLog2 = 10;
constexpr int kWalshMaxLog2 = 24;

class WalshBound {
  public:
    /// Starts from the first n = 2^m values of the sequence, in natural order
    /// (2^(kWalshLag + 1) <= n <= 2^kWalshMaxLog2; the bound is the paper's from 2^kWalshMinLog2).
    void start(const double* y, uint64_t n);
    /// Adds the next size() values (natural indices size() .. 2 size() - 1).
    void extend(const double* y);

    uint64_t size() const { return coefficients_.size(); }
    int log2_size() const { return m_; }
    /// The mean of the values (the coefficient at wavenumber 0).
    double mean() const { return coefficients_.empty() ? 0.0 : coefficients_[0]; }
    /// fudge(m) S_{m-r,m}: the bound on |I - mean()|.
    double bound() const;
    /// S_{l,m} for 1 <= l <= m (the band of the coefficients mapped to [2^(l-1), 2^l)).
    double band_sum(int l) const;

  private:
    void reorder_levels(int from, int to);

    std::vector<double> coefficients_; ///< ytilde, in Walsh (Hadamard) index order
    std::vector<uint32_t> map_;        ///< nutilde: wavenumber rank -> coefficient index
    int m_ = 0;
};

/// The whole bound of n = 2^m values in natural order, as a run that started at
/// 2^kWalshMinLog2 points and doubled (so a fixed run and a stopping run that ends at
/// the same n give the same bound).
WalshBound walsh_bound_of(const std::vector<double>& values);

/// The natural (radical-inverse) index of the point at position `position` of a Gray-code
/// ordered sequence: gray(position) = position XOR (position >> 1).
inline uint64_t gray_natural_index(uint64_t position) {
    return position ^ (position >> 1);
}

} // namespace mcp
