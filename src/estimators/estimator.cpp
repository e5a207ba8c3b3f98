#include "estimators/estimator.h"

#include <chrono>
#include <cmath>
#include <limits>

#include "core/stats.h"

namespace mcp {

void RunDiagnostics::merge(const RunDiagnostics& o) {
    nonfinite += o.nonfinite;
    zero_pdf += o.zero_pdf;
    max_weight_share = std::fmax(max_weight_share, o.max_weight_share);
}

const char* error_method_name(ErrorMethod m) {
    switch (m) {
    case ErrorMethod::Iid:
        return "iid";
    case ErrorMethod::CollapsedStrata:
        return "collapsed_strata";
    case ErrorMethod::IidConservative:
        return "iid_conservative";
    }
    return "?";
}

ErrorMethod error_method_for(SamplerKind sampler) {
    switch (sampler) {
    case SamplerKind::Independent:
        return ErrorMethod::Iid;
    case SamplerKind::Stratified:
        return ErrorMethod::CollapsedStrata;
    case SamplerKind::LatinHypercube:
        return ErrorMethod::IidConservative;
    }
    return ErrorMethod::Iid;
}

RunResult run_estimate(const Problem& problem, const EstimatorSpec& spec, uint64_t n, Pcg32& rng,
                       Workspace& ws) {
    const auto start = std::chrono::steady_clock::now();
    const Domain& domain = problem.domain;
    const int sdim = domain.sample_dim(), pdim = domain.point_dim();
    if (ws.u.dim != sdim || ws.u.capacity != kBlockSize) ws.u.reset(sdim, kBlockSize);
    if (ws.x.dim != pdim || ws.x.capacity != kBlockSize) ws.x.reset(pdim, kBlockSize);
    ws.pdf.resize(kBlockSize);
    ws.f.resize(kBlockSize);

    const SamplerPlan plan = make_sampler_plan(spec.sampler, sdim, n, rng);
    RunResult result;
    result.n = n;
    RunningMoments moments;
    NeumaierSum abs_sum, pair_sq_sum; // sum |w|; sum over strata pairs (2m, 2m+1) of (w_a - w_b)^2
    double max_abs = 0.0;
    uint64_t pairs = 0;
    double* w = ws.pdf.data(); // the weights overwrite the densities

    for (uint64_t first = 0; first < n; first += kBlockSize) {
        const size_t count = static_cast<size_t>(n - first < kBlockSize ? n - first : kBlockSize);
        generate_block(plan, first, count, rng, ws.u);
        warp_block(spec.proposal, domain, ws.u, ws.x, ws.pdf.data());
        evaluate_block(problem.integrand, ws.x, ws.f.data());
        for (size_t i = 0; i < count; ++i) {
            const double f = ws.f[i], p = ws.pdf[i];
            double wi = f / p;
            if (!std::isfinite(wi) || !(p > 0.0)) {
                // Rare path: classify, count, and drop (contribute 0).
                if (p > 0.0 && std::isfinite(p))
                    ++result.diagnostics.nonfinite; // f/p overflowed or f NaN/Inf
                else if (f == 0.0) {
                } // 0/0: no mass on either side
                else if (std::isnan(f) || std::isnan(p))
                    ++result.diagnostics.nonfinite;
                else
                    ++result.diagnostics.zero_pdf; // f != 0 where p = 0
                wi = 0.0;
            }
            w[i] = wi;
        }
        moments.add_block(w, count);
        double block_abs = 0.0;
        for (size_t i = 0; i < count; ++i) {
            block_abs += std::fabs(w[i]);
            max_abs = std::fmax(max_abs, std::fabs(w[i]));
        }
        abs_sum.add(block_abs);
        // Blocks start at multiples of kBlockSize (even), so pairs never straddle two blocks.
        double block_pairs = 0.0;
        for (size_t i = 0; i + 1 < count; i += 2)
            block_pairs += (w[i] - w[i + 1]) * (w[i] - w[i + 1]);
        pair_sq_sum.add(block_pairs);
        pairs += count / 2;
    }

    const double scale = problem.quantity == Quantity::Mean ? 1.0 / domain.measure() : 1.0;
    result.estimate = moments.mean() * scale;
    const double nd = static_cast<double>(n);
    double variance_of_mean = std::numeric_limits<double>::quiet_NaN();
    if (error_method_for(spec.sampler) == ErrorMethod::CollapsedStrata) {
        // E[(w_a - w_b)^2] = s_a^2 + s_b^2 + (m_a - m_b)^2 >= s_a^2 + s_b^2, so
        // sum (w_a - w_b)^2 / (2 pairs) bounds the mean within-stratum variance from above.
        if (pairs > 0) variance_of_mean = pair_sq_sum.value() / (2.0 * pairs) / nd;
    } else if (n > 1) {
        variance_of_mean = moments.variance() / nd;
    }
    result.std_error = std::sqrt(variance_of_mean) * scale;
    const double total_abs = abs_sum.value();
    result.diagnostics.max_weight_share = total_abs > 0.0 ? max_abs / total_abs : 0.0;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace mcp
