#include "test_support.h"

#include <cmath>

#include "core/special.h"

namespace mcp::test {

ChiSquareResult chi_square(const std::vector<double>& observed, const std::vector<double>& expected,
                           double min_expected) {
    ChiSquareResult r;
    double pool_obs = 0.0, pool_exp = 0.0;
    for (size_t i = 0; i < expected.size(); ++i) {
        pool_obs += observed[i];
        pool_exp += expected[i];
        if (pool_exp >= min_expected) {
            r.statistic += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
            ++r.cells;
            pool_obs = pool_exp = 0.0;
        }
    }
    if (pool_exp > 0.0 || pool_obs > 0.0) {
        // A leftover pool too small to stand alone; an observation where nothing is expected
        // makes the statistic infinite, which is what a sampler outside its support deserves.
        if (pool_exp > 0.0) {
            r.statistic += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
            ++r.cells;
        } else if (pool_obs > 0.0) {
            r.statistic = INFINITY;
        }
    }
    r.dof = r.cells - 1;
    r.p_value = r.dof > 0 ? chi_square_sf(r.statistic, r.dof) : 1.0;
    if (std::isinf(r.statistic)) r.p_value = 0.0;
    return r;
}

double sidak_level(double alpha, int k) {
    return 1.0 - std::pow(1.0 - alpha, 1.0 / k);
}

double gauss_legendre(const std::function<double(double)>& f, double lo, double hi, int panels) {
    const double x1 = std::sqrt(5.0 - 2.0 * std::sqrt(10.0 / 7.0)) / 3.0;
    const double x2 = std::sqrt(5.0 + 2.0 * std::sqrt(10.0 / 7.0)) / 3.0;
    const double w0 = 128.0 / 225.0;
    const double w1 = (322.0 + 13.0 * std::sqrt(70.0)) / 900.0;
    const double w2 = (322.0 - 13.0 * std::sqrt(70.0)) / 900.0;
    const double h = (hi - lo) / panels;
    double sum = 0.0;
    for (int p = 0; p < panels; ++p) {
        double c = lo + (p + 0.5) * h, r = 0.5 * h;
        sum += r * (w0 * f(c) + w1 * (f(c - x1 * r) + f(c + x1 * r)) +
                    w2 * (f(c - x2 * r) + f(c + x2 * r)));
    }
    return sum;
}

} // namespace mcp::test
