// A problem integrated with point sets given whole (a user's points, or one sampler's set): the
// equal-weight rule I_hat = (measure / N) sum_i f(x(u_i)), x the domain's uniform warp. One set is
// a deterministic rule: its error against the exact value is all it has, no error bar. K sets
// that are independent randomizations of one rule give the randomized quasi-Monte Carlo error
// bar: the t interval of their K estimates [Owen95, LEcuyerLemieux02].
#pragma once

#include <vector>

#include "core/point_analysis.h"
#include "estimators/problem.h"

namespace mcp {

struct PointRuleEstimate {
    std::vector<double> per_set; ///< the rule's estimate with each set
    double estimate = 0.0;       ///< their mean
    bool has_error_bar = false;  ///< K >= 2 distinct sets whose estimates differ
    /// Why there is no error bar: one set, two identical sets, or estimates that agree to
    /// round-off (a zero-width interval no finite number of sets can show).
    std::string no_error_bar;
    double standard_error = 0.0; ///< s / sqrt(K) of the K estimates (K >= 2)
    double half_width_95 = 0.0;  ///< t_{0.975, K-1} standard_error (K >= 2)
    double degrees_of_freedom = 0.0;
    uint64_t evaluations = 0;
};

/// "" when the sets can integrate the problem: same dimension as the domain's unit cube
/// (domain.sample_dim()), at least one point each.
std::string check_point_rule(const Problem& problem, const std::vector<PointSet>& sets);

/// The rule's estimates of the problem's quantity (integral or mean) with each set. The error
/// bar's spread is computed on the estimates scaled by the largest of them, so that estimates
/// near 1e-170 (whose squares underflow) keep their true standard error; an interval of width 0
/// is never claimed (no_error_bar says why).
PointRuleEstimate integrate_with_point_sets(const Problem& problem,
                                            const std::vector<PointSet>& sets);

} // namespace mcp
