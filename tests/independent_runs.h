// R independent runs of one estimator at one N: the mean and variance of their estimates and
// how many of their own 95% intervals cover the exact value (the adaptive estimators' tests).
#pragma once

#include <cmath>
#include <cstdint>

#include "estimators/block_driver.h"

namespace mcp::test {

struct IndependentRuns {
    int runs = 0;
    double mean = 0.0, variance = 0.0; ///< of the R estimates (unbiased variance)
    int covered = 0;                   ///< runs whose interval estimate +- t se holds `exact`
    bool every_n_reported = true;      ///< every run reported n (training and probes included)
};

/// Run k draws from Pcg32(seed + k, stream).
inline IndependentRuns independent_runs(const Problem& problem, const EstimatorSpec& spec,
                                        uint64_t n, int runs, uint64_t seed, uint64_t stream,
                                        double exact) {
    IndependentRuns r;
    r.runs = runs;
    Workspace ws;
    double sum = 0.0, sum2 = 0.0;
    for (int k = 0; k < runs; ++k) {
        Pcg32 rng(seed + static_cast<uint64_t>(k), stream);
        const RunResult run = run_estimate(problem, spec, n, rng, ws);
        r.every_n_reported = r.every_n_reported && run.n == n;
        sum += run.estimate;
        sum2 += run.estimate * run.estimate;
        r.covered += std::fabs(run.estimate - exact) <= interval_quantile(run.dof) * run.std_error;
    }
    r.mean = sum / runs;
    r.variance = (sum2 - runs * r.mean * r.mean) / (runs - 1);
    return r;
}

} // namespace mcp::test
