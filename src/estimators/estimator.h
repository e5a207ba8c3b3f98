// One Monte Carlo estimate: N points from a sampler, warped by a proposal density p,
// weighted f/p and averaged: I_N = (1/N) sum f(x_i) / p(x_i). Streaming, block by block.
#pragma once

#include <cstdint>
#include <vector>

#include "core/points.h"
#include "core/rng.h"
#include "estimators/problem.h"

namespace mcp {

/// Sample-level problems found during a run. A dropped sample contributes 0 to the sum
/// (the estimate is then biased, and the count says by how many samples).
struct RunDiagnostics {
    uint64_t nonfinite = 0;        ///< f/p was NaN or infinite (f itself NaN/Inf): dropped
    uint64_t zero_pdf = 0;         ///< f != 0 where p = 0: unreachable mass, dropped
    double max_weight_share = 0.0; ///< max |w_i| / sum |w_i|: near 1 means one sample rules
    void merge(const RunDiagnostics& o);
};

/// How the per-run standard error is estimated.
enum class ErrorMethod {
    Iid,             ///< s^2 / N from the sample variance (independent samples)
    CollapsedStrata, ///< pairs of neighbouring strata [Cochran77, 5A.12]: conservative
    IidConservative, ///< s^2 / N for Latin hypercube: >= its variance up to N/(N-1) [Owen97]
};
const char* error_method_name(ErrorMethod m);
ErrorMethod error_method_for(SamplerKind sampler);

struct RunResult {
    uint64_t n = 0;
    double estimate = 0.0;
    double std_error = 0.0; ///< NaN when it cannot be estimated (N = 1)
    double seconds = 0.0;
    RunDiagnostics diagnostics;
};

/// Buffers reused across runs so that a run allocates nothing per block.
struct Workspace {
    PointBlock u, x;
    std::vector<double> pdf, f;
};

/// Runs one estimate of the problem with n samples, all randomness drawn from rng.
RunResult run_estimate(const Problem& problem, const EstimatorSpec& spec, uint64_t n, Pcg32& rng,
                       Workspace& ws);

} // namespace mcp
