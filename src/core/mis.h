// Multiple importance sampling weights [Veach97, 9.2]: how the samples of several techniques,
// technique k drawing n_k points from density p_k, share the integrand. At a point x every
// heuristic is a function of q_k = n_k p_k(x) (or c_k p_k(x) for one-sample MIS with choice
// probabilities c_k), and the weights of the techniques with q_k > 0 sum to 1, which keeps the
// combined estimator F = sum_k (1/n_k) sum_j w_k(x_kj) f(x_kj) / p_k(x_kj) unbiased. One
// module for the integration estimators (estimators/mis.cpp) and the renderer's light/BSDF MIS.
#pragma once

#include <cstddef>

namespace mcp {

enum class MisHeuristic {
    Balance, ///< w_i = q_i / sum_k q_k                                   [Veach97, 9.2.2]
    Power,   ///< w_i = q_i^beta / sum_k q_k^beta                          [Veach97, 9.2.4]
    Maximum, ///< w_i = 1 where q_i is the largest q (ties: the lowest index), else 0
    Cutoff,  ///< w_i = q_i / sum_{q_k >= a q_max} q_k where q_i >= a q_max, else 0
};

/// The most techniques one estimator combines.
constexpr int kMaxMisTechniques = 16;

const char* mis_heuristic_name(MisHeuristic h);

struct MisWeighting {
    MisHeuristic heuristic = MisHeuristic::Balance;
    double beta = 2.0;   ///< power heuristic exponent (beta = 1 is the balance heuristic)
    double cutoff = 0.1; ///< cutoff heuristic threshold a in [0, 1]
};

/// Weight of technique i at a point where q[k] = n_k p_k(x), k < techniques. 0 when q_i is not
/// positive. Ratios q_k / q_i are formed first, so huge densities (tiny lights, near-mirrors)
/// neither overflow nor underflow; infinite q (delta densities) share the weight among
/// themselves.
double mis_weight(const MisWeighting& w, const double* q, int techniques, int i);

/// Two techniques: the weight of the one with q_this against the other's q_other (inline for the
/// renderer's per-sample use: the balance and beta = 2 power heuristics as one division).
inline double mis_weight(const MisWeighting& w, double q_this, double q_other) {
    const bool simple = w.heuristic == MisHeuristic::Balance ||
                        (w.heuristic == MisHeuristic::Power && w.beta == 2.0);
    if (simple && q_this > 0.0 && q_this < 1e300) {
        if (!(q_other > 0.0)) return 1.0;
        const double r = q_other / q_this; // divided first: q^2 overflows for huge densities
        return 1.0 / (1.0 + (w.heuristic == MisHeuristic::Balance ? r : r * r));
    }
    const double q[2] = {q_this, q_other};
    return mis_weight(w, q, 2, 0);
}

/// The weights of technique i for a block: q[k][j] is q_k at point j (j < count),
/// techniques <= kMaxMisTechniques.
void mis_weight_block(const MisWeighting& w, const double* const* q, int techniques, int i,
                      size_t count, double* out);

} // namespace mcp
