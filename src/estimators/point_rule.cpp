#include "estimators/point_rule.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

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

namespace {

/// "sets 1 and 3 (counting from 1) are identical" for the first two sets with the same
/// coordinates, else "". Sets are compared by a hash of their coordinates' bytes first (linear
/// in the points).
std::string identical_sets(const std::vector<PointSet>& sets) {
    std::vector<std::pair<uint64_t, size_t>> hashes;
    for (size_t s = 0; s < sets.size(); ++s) {
        uint64_t h = 1469598103934665603ull; // FNV-1a over the coordinates' bytes
        const auto* bytes = reinterpret_cast<const unsigned char*>(sets[s].coords.data());
        for (size_t b = 0; b < sets[s].coords.size() * sizeof(double); ++b)
            h = (h ^ bytes[b]) * 1099511628211ull;
        hashes.emplace_back(h, s);
    }
    std::sort(hashes.begin(), hashes.end());
    for (size_t i = 1; i < hashes.size(); ++i) {
        const size_t a = hashes[i - 1].second, b = hashes[i].second;
        if (hashes[i].first == hashes[i - 1].first && sets[a].n == sets[b].n &&
            sets[a].coords == sets[b].coords)
            return "sets " + std::to_string(std::min(a, b) + 1) + " and " +
                   std::to_string(std::max(a, b) + 1) + " (counting from 1) are identical";
    }
    return "";
}

} // namespace

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
    const size_t k = sets.size();
    if (k < 2) {
        out.no_error_bar = "one point set is a deterministic rule: its error is measured against "
                           "the exact value, and no error bar is claimed";
        return out;
    }
    const std::string twins = identical_sets(sets);
    if (!twins.empty()) {
        out.no_error_bar = twins + ": the sets are not independent randomizations of one rule, "
                                   "so their spread says nothing of the error; no error bar is "
                                   "claimed";
        return out;
    }
    // The spread of the estimates over their largest magnitude, rescaled: their squares would
    // underflow below 1e-154 and give a standard error of 0 for estimates that differ.
    double largest = 0.0;
    for (double e : out.per_set) largest = std::max(largest, std::fabs(e));
    RunningMoments scaled;
    if (std::isfinite(largest) && largest > 0.0)
        for (double e : out.per_set) scaled.add(e / largest);
    const double se = largest * std::sqrt(scaled.variance() / static_cast<double>(k));
    if (!(se > 64.0 * 2.220446049250313e-16 * largest)) {
        out.no_error_bar =
            !std::isfinite(largest) || !std::isfinite(se)
                ? "the estimates are not finite: no error bar"
                : "the " + std::to_string(k) +
                      " estimates agree to round-off: a t interval of width 0 is a certainty no "
                      "finite number of sets can show; no error bar is claimed";
        return out;
    }
    out.has_error_bar = true;
    out.degrees_of_freedom = static_cast<double>(k - 1);
    out.standard_error = se;
    out.half_width_95 = student_t_quantile(0.975, out.degrees_of_freedom) * out.standard_error;
    return out;
}

} // namespace mcp
