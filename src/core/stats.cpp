#include "core/stats.h"

namespace mcp {

void RunningMoments::merge(const RunningMoments& o) {
    if (o.n_ == 0) return;
    if (n_ == 0) {
        *this = o;
        return;
    }
    double na = static_cast<double>(n_), nb = static_cast<double>(o.n_);
    double delta = o.mean_ - mean_;
    double n = na + nb;
    m2_ += o.m2_ + delta * delta * na * nb / n;
    mean_ += delta * nb / n;
    n_ += o.n_;
    sum_.add(o.sum_.value());
}

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
    LineFit fit;
    size_t n = x.size();
    fit.points = static_cast<int>(n);
    if (n < 2 || y.size() != n) return fit;
    double mx = 0.0, my = 0.0;
    for (size_t i = 0; i < n; ++i) {
        mx += x[i];
        my += y[i];
    }
    mx /= static_cast<double>(n);
    my /= static_cast<double>(n);
    double sxx = 0.0, sxy = 0.0;
    for (size_t i = 0; i < n; ++i) {
        sxx += (x[i] - mx) * (x[i] - mx);
        sxy += (x[i] - mx) * (y[i] - my);
    }
    if (!(sxx > 0.0)) return fit;
    fit.sxx = sxx;
    fit.slope = sxy / sxx;
    fit.intercept = my - fit.slope * mx;
    if (n > 2) {
        double ss = 0.0;
        for (size_t i = 0; i < n; ++i) {
            double r = y[i] - (fit.intercept + fit.slope * x[i]);
            ss += r * r;
        }
        fit.residual_variance = ss / static_cast<double>(n - 2);
        fit.slope_se = std::sqrt(fit.residual_variance / sxx);
    }
    return fit;
}

}  // namespace mcp
