// What every estimator's runs share (estimators/estimator.h): merging run diagnostics, the error
// methods (names, which are conservative, the sampler's), the interval quantile and Hill's tail
// index. The estimators themselves are kinds (estimators/estimator_kind.h, registry.h).
#include "estimators/estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/special.h"
#include "core/stats.h"

namespace mcp {

void RunDiagnostics::merge(const RunDiagnostics& o) {
    nonfinite += o.nonfinite;
    zero_pdf += o.zero_pdf;
    nonzero += o.nonzero;
    max_weight_share = std::fmax(max_weight_share, o.max_weight_share);
    weights.merge(o.weights);
    error_units.merge(o.error_units);
    batch_units = batch_units || o.batch_units;
}

const char* error_method_name(ErrorMethod m) {
    switch (m) {
    case ErrorMethod::Iid: return "iid";
    case ErrorMethod::CollapsedStrata: return "collapsed_strata";
    case ErrorMethod::PairedStrata: return "paired_strata";
    case ErrorMethod::IidConservative: return "iid_conservative";
    case ErrorMethod::Randomizations: return "randomizations";
    case ErrorMethod::None: return "none";
    case ErrorMethod::PartsSum: return "parts_sum";
    case ErrorMethod::Regression: return "regression";
    case ErrorMethod::WalshBound: return "walsh_bound";
    }
    return "?";
}

double interval_quantile(int dof) {
    return dof > 0 ? student_t_quantile(0.975, dof) : 1.959963984540054;
}

bool error_method_conservative(ErrorMethod m) {
    return m == ErrorMethod::CollapsedStrata || m == ErrorMethod::IidConservative;
}

ErrorMethod sampler_error_method(const EstimatorSpec& spec) {
    switch (spec.sampler) {
    case SamplerKind::Independent: return ErrorMethod::Iid;
    case SamplerKind::Stratified:
        return spec.per_stratum == 2 ? ErrorMethod::PairedStrata : ErrorMethod::CollapsedStrata;
    case SamplerKind::LatinHypercube: return ErrorMethod::IidConservative;
    case SamplerKind::Sobol:
        if (spec.walsh_bound) return ErrorMethod::WalshBound;
        [[fallthrough]];
    case SamplerKind::Halton:
    case SamplerKind::Lattice:
        return spec.randomization == QmcRandomization::None ? ErrorMethod::None
                                                            : ErrorMethod::Randomizations;
    }
    return ErrorMethod::Iid;
}

int hill_order(uint64_t samples) {
    // k grows with the sample (k / n -> 0, k -> infinity, as Hill's estimator needs) but stays
    // small enough for a fixed-size heap: k = min(64, n / 16); below 8 there is no estimate.
    const uint64_t k = std::min<uint64_t>(64, samples / 16);
    return k < 8 ? 0 : static_cast<int>(k);
}

int tail_order(uint64_t samples) {
    const uint64_t k = std::min<uint64_t>(kTailOrder, samples / 16);
    return k < 8 ? 0 : static_cast<int>(k);
}

double stable_tail_index(const std::vector<double>& top, int k_max, int* k) {
    *k = 0;
    if (k_max <= 0) return std::numeric_limits<double>::quiet_NaN();
    int kept = std::min(64, k_max);
    double alpha = hill_tail_index(top, kept);
    *k = kept;
    // No tail to follow: none measured (NaN), fewer than k + 1 non-zero weights (0), or equal
    // top values (infinite).
    if (!(alpha > 0.0) || !std::isfinite(alpha)) return alpha;
    while (kept < k_max) {
        const int next = std::min(2 * kept, k_max);
        const double a = hill_tail_index(top, next);
        if (!(a > 0.0) || !std::isfinite(a)) break;
        const double sd = (1.0 / a) * std::sqrt(1.0 / kept - 1.0 / next);
        if (1.0 / alpha - 1.0 / a > 3.0 * sd) break; // the body, not the tail
        kept = next;
        alpha = a;
    }
    *k = kept;
    return alpha;
}

double hill_tail_index(const std::vector<double>& top, int k) {
    if (k < 1 || static_cast<int>(top.size()) < k + 1)
        return std::numeric_limits<double>::quiet_NaN();
    const double xk = top[static_cast<size_t>(k)];
    if (!(xk > 0.0)) return 0.0;
    // Top values equal up to rounding (a constant weight computed along different paths)
    // have no tail: their log spacings are noise of a few ulps, not a power law.
    if (top[0] <= xk * (1.0 + 1e-12)) return std::numeric_limits<double>::infinity();
    double sum = 0.0;
    for (int i = 0; i < k; ++i) sum += std::log(top[static_cast<size_t>(i)] / xk);
    return sum > 0.0 ? k / sum : std::numeric_limits<double>::infinity();
}

} // namespace mcp
