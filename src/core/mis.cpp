#include "core/mis.h"

#include <cmath>

namespace mcp {

const char* mis_heuristic_name(MisHeuristic h) {
    switch (h) {
    case MisHeuristic::Balance: return "balance";
    case MisHeuristic::Power: return "power";
    case MisHeuristic::Maximum: return "maximum";
    case MisHeuristic::Cutoff: return "cutoff";
    }
    return "?";
}

namespace {

/// q_k / q_i for q_i > 0, with infinite densities compared among themselves: inf / inf = 1,
/// finite / inf = 0.
double ratio(double qk, double qi) {
    if (std::isinf(qi)) return std::isinf(qk) ? 1.0 : 0.0;
    return qk / qi;
}

double powered(const MisWeighting& w, double r) {
    if (w.heuristic == MisHeuristic::Balance) return r;
    if (w.beta == 2.0) return r * r;
    return std::pow(r, w.beta);
}

} // namespace

double mis_weight(const MisWeighting& w, const double* q, int techniques, int i) {
    const double qi = q[i];
    if (!(qi > 0.0)) return 0.0;
    switch (w.heuristic) {
    case MisHeuristic::Maximum:
        for (int k = 0; k < techniques; ++k)
            if (q[k] > qi || (k < i && q[k] == qi)) return 0.0;
        return 1.0;
    case MisHeuristic::Cutoff: {
        double q_max = qi;
        for (int k = 0; k < techniques; ++k)
            if (q[k] > q_max) q_max = q[k];
        // Compared as ratios to q_max, so that an infinite q_max cuts every finite q.
        if (ratio(qi, q_max) < w.cutoff) return 0.0;
        double sum = 0.0;
        for (int k = 0; k < techniques; ++k)
            if (q[k] > 0.0 && ratio(q[k], q_max) >= w.cutoff) sum += ratio(q[k], qi);
        return 1.0 / sum;
    }
    case MisHeuristic::Balance:
    case MisHeuristic::Power: {
        // 1 / sum_k (q_k / q_i)^beta: the technique's own term is exactly 1.
        double sum = 1.0;
        for (int k = 0; k < techniques; ++k)
            if (k != i && q[k] > 0.0) sum += powered(w, ratio(q[k], qi));
        return 1.0 / sum;
    }
    }
    return 0.0;
}

void mis_weight_block(const MisWeighting& w, const double* const* q, int techniques, int i,
                      size_t count, double* out) {
    double at[kMaxMisTechniques];
    const int t = techniques < kMaxMisTechniques ? techniques : kMaxMisTechniques;
    for (size_t j = 0; j < count; ++j) {
        for (int k = 0; k < t; ++k) at[k] = q[k][j];
        out[j] = mis_weight(w, at, t, i);
    }
}

} // namespace mcp
