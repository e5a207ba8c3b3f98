#include "chi_square.h"

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

} // namespace mcp::test
