#include "estimators/estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>

#include "core/stats.h"

namespace mcp {

void RunDiagnostics::merge(const RunDiagnostics& o) {
    nonfinite += o.nonfinite;
    zero_pdf += o.zero_pdf;
    nonzero += o.nonzero;
    max_weight_share = std::fmax(max_weight_share, o.max_weight_share);
}

const char* error_method_name(ErrorMethod m) {
    switch (m) {
    case ErrorMethod::Iid: return "iid";
    case ErrorMethod::CollapsedStrata: return "collapsed_strata";
    case ErrorMethod::PairedStrata: return "paired_strata";
    case ErrorMethod::IidConservative: return "iid_conservative";
    }
    return "?";
}

ErrorMethod error_method_for(const EstimatorSpec& spec) {
    switch (spec.sampler) {
    case SamplerKind::Independent: return ErrorMethod::Iid;
    case SamplerKind::Stratified:
        return spec.per_stratum == 2 ? ErrorMethod::PairedStrata : ErrorMethod::CollapsedStrata;
    case SamplerKind::LatinHypercube: return ErrorMethod::IidConservative;
    }
    return ErrorMethod::Iid;
}

int hill_order(uint64_t samples) {
    // k grows with the sample (k / n -> 0, k -> infinity, as Hill's estimator needs) but stays
    // small enough for a fixed-size heap: k = min(64, n / 16); below 8 there is no estimate.
    const uint64_t k = std::min<uint64_t>(64, samples / 16);
    return k < 8 ? 0 : static_cast<int>(k);
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

RunResult run_estimate(const Problem& problem, const EstimatorSpec& spec, uint64_t n, Pcg32& rng,
                       Workspace& ws, Accumulator accumulator) {
    const auto start = std::chrono::steady_clock::now();
    const Domain& domain = problem.domain;
    const int sdim = domain.sample_dim(), pdim = domain.point_dim();
    if (ws.u.dim != sdim || ws.u.capacity != kBlockSize) ws.u.reset(sdim, kBlockSize);
    if (ws.x.dim != pdim || ws.x.capacity != kBlockSize) ws.x.reset(pdim, kBlockSize);
    ws.pdf.resize(kBlockSize);
    ws.f.resize(kBlockSize);

    const SamplerPlan plan = make_sampler_plan(spec.sampler, sdim, n, rng, spec.per_stratum);
    RunResult result;
    result.n = n;
    RunningMoments moments;
    NeumaierSum abs_sum, diff_sq_sum; // sum |w|; sum of squared differences (see below)
    float float_sum = 0.0f;           // Accumulator::Float32 only
    double max_abs = 0.0;
    uint64_t diffs = 0, nonzero = 0;
    double previous = 0.0;
    const bool paired = error_method_for(spec) == ErrorMethod::PairedStrata;
    // Candidates for the kTopWeights largest |w|: everything above the current threshold.
    const size_t keep = kTopWeights;
    double top_threshold = -1.0;
    ws.top.clear();
    ws.top.reserve(keep + kBlockSize);
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
                    ++result.diagnostics.nonfinite; // f/p overflow, f NaN/Inf
                else if (f == 0.0) {
                } // 0/0: no mass either side
                else if (std::isnan(f) || std::isnan(p))
                    ++result.diagnostics.nonfinite;
                else
                    ++result.diagnostics.zero_pdf; // f != 0 where p = 0
                wi = 0.0;
            }
            w[i] = wi;
        }
        moments.add_block(w, count);
        if (accumulator == Accumulator::Float32)
            for (size_t i = 0; i < count; ++i) float_sum += static_cast<float>(w[i]);
        double block_abs = 0.0;
        for (size_t i = 0; i < count; ++i) {
            const double a = std::fabs(w[i]);
            block_abs += a;
            max_abs = std::fmax(max_abs, a);
            nonzero += a != 0.0;
            if (a > top_threshold) ws.top.push_back(a);
        }
        // Keep the kTopWeights largest: an O(n) selection per block instead of a heap update
        // per sample (an increasing integrand would otherwise replace the heap's root every time).
        if (ws.top.size() > keep) {
            std::nth_element(ws.top.begin(), ws.top.begin() + static_cast<long>(keep) - 1,
                             ws.top.end(), std::greater<double>());
            ws.top.resize(keep);
            top_threshold = ws.top[keep - 1];
        }
        abs_sum.add(block_abs);
        if (paired) {
            // Two points per cell: pairs (2m, 2m+1) share a cell. Blocks start at multiples of
            // kBlockSize (even), so a pair never straddles two blocks.
            double block_pairs = 0.0;
            for (size_t i = 0; i + 1 < count; i += 2)
                block_pairs += (w[i] - w[i + 1]) * (w[i] - w[i + 1]);
            diff_sq_sum.add(block_pairs);
            diffs += count / 2;
        } else {
            // Successive differences of neighbouring cells, across block boundaries too.
            double block_diffs = 0.0;
            if (first > 0) block_diffs = (w[0] - previous) * (w[0] - previous);
            for (size_t i = 1; i < count; ++i) block_diffs += (w[i] - w[i - 1]) * (w[i] - w[i - 1]);
            previous = w[count - 1];
            diff_sq_sum.add(block_diffs);
            diffs += first == 0 ? count - 1 : count;
        }
    }

    const double scale = problem.quantity == Quantity::Mean ? 1.0 / domain.measure() : 1.0;
    const double nd = static_cast<double>(n);
    const double mean =
        accumulator == Accumulator::Float32 ? static_cast<double>(float_sum) / nd : moments.mean();
    result.estimate = mean * scale;
    double variance_of_mean = std::numeric_limits<double>::quiet_NaN();
    switch (error_method_for(spec)) {
    case ErrorMethod::CollapsedStrata:
    case ErrorMethod::PairedStrata:
        // E[(w_a - w_b)^2] = s_a^2 + s_b^2 + (m_a - m_b)^2: exactly s_a^2 + s_b^2 when a and b
        // share a cell (paired strata, unbiased), an upper bound for neighbouring cells
        // (collapsed strata, conservative; all N-1 successive differences are used, so one
        // unlucky pair cannot make the error bar 0 [Cochran77, 5A.12; vonNeumann41]).
        // Either way Var[I_N] ~ sum d^2 / (2 count N).
        if (diffs > 0)
            variance_of_mean = diff_sq_sum.value() / (2.0 * static_cast<double>(diffs)) / nd;
        break;
    case ErrorMethod::Iid:
    case ErrorMethod::IidConservative:
        if (n > 1) variance_of_mean = moments.variance() / nd;
        break;
    }
    result.std_error = std::sqrt(variance_of_mean) * scale;
    if (n > 0 && result.diagnostics.nonfinite == n) {
        // Every sample was NaN or infinite: the sum of the (all dropped) weights is not an
        // estimate of anything, so there is none (not 0 +/- 0).
        result.estimate = result.std_error = std::numeric_limits<double>::quiet_NaN();
    }
    const double total_abs = abs_sum.value();
    result.diagnostics.max_weight_share = total_abs > 0.0 ? max_abs / total_abs : 0.0;
    result.diagnostics.nonzero = nonzero;
    // Effective sample size [Kish65]: how many equal weights would carry the same information.
    const double sum_sq = moments.sum_squared_deviations() + nd * moments.mean() * moments.mean();
    result.diagnostics.ess = sum_sq > 0.0 ? total_abs * total_abs / sum_sq : 0.0;
    std::sort(ws.top.begin(), ws.top.end(), std::greater<double>());
    result.top = ws.top;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace mcp
