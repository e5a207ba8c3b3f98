#include "core/walsh_bound.h"

#include <cmath>
#include <utility>

namespace mcp {

namespace {

// In-place fast Walsh-Hadamard transform normalized by 1/n: x_nu = (1/n) sum_i x_i (-1)^<nu,i>.
void walsh_transform(double* x, uint64_t n) {
    for (uint64_t half = 1; half < n; half *= 2)
        for (uint64_t block = 0; block < n; block += 2 * half)
            for (uint64_t i = block; i < block + half; ++i) {
                const double a = x[i], b = x[i + half];
                x[i] = 0.5 * (a + b);
                x[i + half] = 0.5 * (a - b);
            }
}

double fudge(int m) {
    return 5.0 * std::ldexp(1.0, -m);
}

} // namespace

void WalshBound::start(const double* y, uint64_t n) {
    m_ = 0;
    while ((uint64_t(1) << m_) < n) ++m_;
    coefficients_.assign(y, y + n);
    walsh_transform(coefficients_.data(), n);
    map_.resize(n);
    for (uint64_t k = 0; k < n; ++k) map_[k] = static_cast<uint32_t>(k);
    reorder_levels(m_ - 1, 0);
}

void WalshBound::extend(const double* y) {
    const uint64_t n = size();
    std::vector<double> next(y, y + n);
    walsh_transform(next.data(), n);
    // The 2n-point coefficients from the two halves' [HickernellJimenezRugama16]: nu < n sees
    // both halves with the same sign, nu + n with opposite signs (bit m of the index).
    coefficients_.resize(2 * n);
    for (uint64_t nu = 0; nu < n; ++nu) {
        const double a = coefficients_[nu], b = next[nu];
        coefficients_[nu] = 0.5 * (a + b);
        coefficients_[nu + n] = 0.5 * (a - b);
    }
    map_.resize(2 * n);
    for (uint64_t k = 0; k < n; ++k) map_[k + n] = static_cast<uint32_t>(map_[k] + n);
    ++m_;
    // Only the levels whose pairs the new coefficients change are reordered; the lower ones
    // keep their order (the band the bound reads is below them).
    reorder_levels(m_ - 1, m_ - kWalshLag - 1);
}

void WalshBound::reorder_levels(int from, int to) {
    // Level l pairs rank kappa with kappa + 2^l (kappa in [1, 2^l)): where the later one has
    // the larger coefficient it is taken as the lower wavenumber. The pairs of the first block
    // of 2^(l+1) ranks decide; every block is reordered the same way (their coefficients are
    // aliases of the same pairs one level down).
    const uint64_t n = size();
    for (int l = from; l > to && l >= 1; --l) {
        const uint64_t half = uint64_t(1) << l;
        for (uint64_t k = 1; k < half; ++k) {
            if (!(std::fabs(coefficients_[map_[half + k]]) > std::fabs(coefficients_[map_[k]])))
                continue;
            for (uint64_t block = 0; block < n; block += 2 * half)
                std::swap(map_[block + k], map_[block + half + k]);
        }
    }
}

double WalshBound::band_sum(int l) const {
    if (l < 1 || l > m_) return 0.0;
    double sum = 0.0;
    const uint64_t lo = uint64_t(1) << (l - 1), hi = uint64_t(1) << l;
    for (uint64_t k = lo; k < hi; ++k) sum += std::fabs(coefficients_[map_[k]]);
    return sum;
}

double WalshBound::bound() const {
    return fudge(m_) * band_sum(m_ - kWalshLag);
}

WalshBound walsh_bound_of(const std::vector<double>& values) {
    WalshBound w;
    uint64_t n = values.size() < (uint64_t(1) << kWalshMinLog2) ? values.size()
                                                                : uint64_t(1) << kWalshMinLog2;
    w.start(values.data(), n);
    for (; n < values.size(); n *= 2) w.extend(values.data() + n);
    return w;
}

} // namespace mcp
