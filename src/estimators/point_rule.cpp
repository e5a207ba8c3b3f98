#include "estimators/point_rule.h"

#include <algorithm>
#include <cmath>

#include "core/special.h"
#include "core/stats.h"

namespace mcp {

std::string check_point_rule(const Problem& problem, const std::vector<PointSet>& sets) {
    if (sets.empty()) return "no point set";
    const int need = problem.domain.sample_dim();
    for (const PointSet& s : sets) {
        if (s.dim != need)
            return "the points have " + std::to_string(s.dim) + " coordinates, but the " +
                   problem.domain.describe() + " is sampled from the unit cube of dimension " +
                   std::to_string(need);
        if (s.n == 0) return "a point set is empty";
    }
    return "";
}

PointRuleEstimate integrate_with_point_sets(const Problem& problem,
                                            const std::vector<PointSet>& sets) {
    const Domain& domain = problem.domain;
    const Proposal proposal = uniform_proposal(domain);
    // f / p with p the uniform density 1/measure, times the quantity's scale.
    PointBlock u, x;
    u.reset(domain.sample_dim(), kBlockSize);
    x.reset(domain.point_dim(), kBlockSize);
    std::vector<double> pdf(kBlockSize), f(kBlockSize);
    PointRuleEstimate out;
    RunningMoments across;
    for (const PointSet& set : sets) {
        NeumaierSum sum;
        for (uint64_t first = 0; first < set.n; first += kBlockSize) {
            const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, set.n - first));
            for (int k = 0; k < set.dim; ++k) {
                const double* src = set.coords.data() + static_cast<uint64_t>(k) * set.n + first;
                std::copy(src, src + count, u.coord(k));
            }
            u.n = count;
            warp_block(proposal, domain, u, x, pdf.data());
            x.n = count;
            evaluate_block(problem.integrand, x, f.data());
            for (size_t i = 0; i < count; ++i) sum.add(f[i] / pdf[i]);
        }
        out.evaluations += set.n;
        const double estimate = sum.value() / static_cast<double>(set.n) * quantity_scale(problem);
        out.per_set.push_back(estimate);
        across.add(estimate);
    }
    out.estimate = across.mean();
    const uint64_t k = sets.size();
    if (k >= 2) {
        out.has_error_bar = true;
        out.degrees_of_freedom = static_cast<double>(k - 1);
        out.standard_error = std::sqrt(across.variance() / static_cast<double>(k));
        out.half_width_95 = student_t_quantile(0.975, out.degrees_of_freedom) * out.standard_error;
    }
    return out;
}

} // namespace mcp
