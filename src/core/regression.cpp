#include "core/regression.h"

#include <algorithm>
#include <cmath>

namespace mcp {

void RunningCovariance::reset(int dim) {
    dim_ = dim;
    n_ = 0;
    const size_t d = static_cast<size_t>(dim);
    mean_.assign(d, 0.0);
    c_.assign(d * d, 0.0);
    block_mean_.assign(d, 0.0);
    block_c_.assign(d * d, 0.0);
}

void RunningCovariance::add_block(const double* const* z, size_t count) {
    if (count == 0) return;
    const size_t d = static_cast<size_t>(dim_);
    // Two passes over the block (its mean, then co-moments about it), merged as one more set.
    for (size_t a = 0; a < d; ++a) {
        double s = 0.0;
        for (size_t i = 0; i < count; ++i) s += z[a][i];
        block_mean_[a] = s / static_cast<double>(count);
    }
    for (size_t a = 0; a < d; ++a)
        for (size_t b = a; b < d; ++b) {
            const double ma = block_mean_[a], mb = block_mean_[b];
            double s = 0.0;
            for (size_t i = 0; i < count; ++i) s += (z[a][i] - ma) * (z[b][i] - mb);
            block_c_[a * d + b] = block_c_[b * d + a] = s;
        }
    RunningCovariance block;
    block.dim_ = dim_;
    block.n_ = count;
    block.mean_.swap(block_mean_);
    block.c_.swap(block_c_);
    merge(block);
    block_mean_.swap(block.mean_);
    block_c_.swap(block.c_);
}

void RunningCovariance::merge(const RunningCovariance& o) {
    if (o.n_ == 0) return;
    if (n_ == 0) {
        n_ = o.n_;
        mean_ = o.mean_;
        c_ = o.c_;
        return;
    }
    // [Chan79]: C = C_a + C_b + delta delta^T n_a n_b / n, mean = mean_a + delta n_b / n.
    const size_t d = static_cast<size_t>(dim_);
    const double na = static_cast<double>(n_), nb = static_cast<double>(o.n_), n = na + nb;
    for (size_t a = 0; a < d; ++a)
        for (size_t b = 0; b < d; ++b)
            c_[a * d + b] +=
                o.c_[a * d + b] + (o.mean_[a] - mean_[a]) * (o.mean_[b] - mean_[b]) * na * nb / n;
    for (size_t a = 0; a < d; ++a) mean_[a] += (o.mean_[a] - mean_[a]) * nb / n;
    n_ += o.n_;
}

double RunningCovariance::quadratic_form(const std::vector<double>& v) const {
    const size_t d = static_cast<size_t>(dim_);
    double s = 0.0;
    for (size_t a = 0; a < d; ++a)
        for (size_t b = 0; b < d; ++b) s += v[a] * c_[a * d + b] * v[b];
    return std::max(0.0, s);
}

int solve_psd(const std::vector<double>& a, const std::vector<double>& b, int n,
              std::vector<double>* x) {
    const size_t m = static_cast<size_t>(n);
    std::vector<double> l(m * m, 0.0);
    std::vector<bool> kept(m, false);
    int rank = 0;
    for (size_t j = 0; j < m; ++j) {
        double d = a[j * m + j];
        for (size_t k = 0; k < j; ++k)
            if (kept[k]) d -= l[j * m + k] * l[j * m + k];
        if (!(d > 1e-12 * a[j * m + j]) || !(a[j * m + j] > 0.0) || !std::isfinite(d))
            continue; // dependent on the columns before it (or zero): dropped
        kept[j] = true;
        ++rank;
        const double root = std::sqrt(d);
        l[j * m + j] = root;
        for (size_t i = j + 1; i < m; ++i) {
            double s = a[i * m + j];
            for (size_t k = 0; k < j; ++k)
                if (kept[k]) s -= l[i * m + k] * l[j * m + k];
            l[i * m + j] = s / root;
        }
    }
    // L y = b, then L^T x = y, over the kept columns.
    std::vector<double> y(m, 0.0);
    x->assign(m, 0.0);
    for (size_t i = 0; i < m; ++i) {
        if (!kept[i]) continue;
        double s = b[i];
        for (size_t k = 0; k < i; ++k)
            if (kept[k]) s -= l[i * m + k] * y[k];
        y[i] = s / l[i * m + i];
    }
    for (size_t i = m; i-- > 0;) {
        if (!kept[i]) continue;
        double s = y[i];
        for (size_t k = i + 1; k < m; ++k)
            if (kept[k]) s -= l[k * m + i] * (*x)[k];
        (*x)[i] = s / l[i * m + i];
    }
    return rank;
}

} // namespace mcp
