// VEGAS adaptive importance sampling [Lepage78, Lepage21]: a separable, piecewise-linear map
// y -> u of the unit cube, trained on the squared weights it sees, then frozen.
#pragma once

#include <cstdint>
#include <vector>

#include "core/points.h"

namespace mcp {

/// How a VEGAS run reports its estimate.
enum class VegasReport {
    Frozen,    ///< train, freeze the map, estimate from fresh points: an ordinary error bar
    Iterations ///< keep adapting over `iterations` iterations and report their weighted
               ///< average with chi^2 / dof, as vegas and GSL do [Lepage78, eq. 6-8]
};

/// The options of a VEGAS estimator (scene field "vegas"; docs/scene-format.md).
struct VegasOptions {
    int increments = 0;           ///< per axis; 0 chooses vegas_increments()
    double alpha = 0.5;           ///< damping exponent of the refinement [Lepage21, eq. 22]
    double train_fraction = 0.25; ///< share of the N evaluations spent training the map
    int train_iterations = 10;    ///< the training share is split into this many iterations
    double uniform_share = 0.05;  ///< share of each axis's increments spread evenly
    VegasReport report = VegasReport::Frozen;
    int iterations = 5; ///< Iterations: the estimation share is split into this many
    /// VEGAS+ [Lepage21, sec. 3]: hypercubes of the y space, each sampled with n_h >= 2 points,
    /// n_h proportional to sigma_h^beta from the previous iteration. Read by the scene parser
    /// only: it makes the estimator of kind vegas_plus (estimators/vegas_plus.cpp).
    bool stratify = false;
    double beta = 0.75;
};

/// Least points per training iteration where the training share allows: fewer, and the map
/// learns from noise (vegas's own examples train on 1000 points per iteration).
constexpr uint64_t kVegasIterationPoints = 1000;

/// Training iterations for `calls` training calls: options.train_iterations, fewer when an
/// iteration would hold fewer than kVegasIterationPoints calls, at least 1.
int vegas_training_iterations(const VegasOptions& options, uint64_t calls);

/// The calls of part i of `calls` split into `parts` (sizes differ by at most one).
inline uint64_t part_of(uint64_t calls, int parts, int i) {
    return calls * static_cast<uint64_t>(i + 1) / static_cast<uint64_t>(parts) -
           calls * static_cast<uint64_t>(i) / static_cast<uint64_t>(parts);
}

/// Increments per axis: about 100 training points per increment per iteration (fewer make the
/// mean w^2 of an increment, and so the map, noisy: on a 2-D Gaussian of width 0.02 at
/// N = 2^20, 1000 increments gave 1.7x the variance of 250), and at most 1000 up to d = 4,
/// 500 up to d = 8, 200 above.
int vegas_increments(int dim, uint64_t points_per_iteration);

/// The map of [Lepage21, sec. 2]: per axis j, K increments with edges 0 = e_0 < ... < e_K = 1;
/// y in increment i = floor(K y) goes to u = e_i + (K y - i)(e_{i+1} - e_i), and the map's
/// Jacobian is prod_j K (e_{j,i+1} - e_{j,i}). Points u then have density 1 / J(y).
class VegasMap {
  public:
    VegasMap() = default;
    VegasMap(int dim, int increments); ///< the identity: equal increments

    int dim() const { return dim_; }
    int increments() const { return k_; }
    /// Edges of axis j: increments() + 1 values from 0 to 1.
    const double* edges(int j) const { return edges_.data() + static_cast<size_t>(j) * (k_ + 1); }

    /// Maps the block's points in place (y -> u, kept below 1) and writes each point's
    /// Jacobian; `bins` (dim x kBlockSize, may be null) receives each point's increments.
    void apply_block(PointBlock& points, double* jacobian, uint32_t* bins) const;

    /// Adds training data: the squared weights w^2 of a block's points, to the increments
    /// apply_block wrote in `bins`. Non-finite weights are skipped.
    void add_training(const uint32_t* bins, const double* weights, size_t count);
    /// The same for points drawn with density q(y) other than uniform (VEGAS+'s stratified
    /// points): each point counts with `importance` = 1 / q(y) (up to a constant), so that an
    /// increment's mean w^2 stays the mean over y uniform in it.
    void add_training(const uint32_t* bins, const double* weights, const double* importance,
                      size_t count);

    /// Refines the map from the training data and clears it [Lepage21, sec. 2.2]: per axis the
    /// mean w^2 of each increment d_i is smoothed with its neighbours (weights 1, 6, 1 over 8;
    /// 7, 1 at the ends), normalised to sum 1, damped to ((1 - d_i) / ln(1 / d_i))^alpha, and
    /// the new edges give every increment an equal share of the damped d. An axis with no
    /// non-zero data keeps its edges.
    void adapt(double alpha, double uniform_share);

  private:
    int dim_ = 0, k_ = 0;
    std::vector<double> edges_;  ///< dim x (K + 1)
    std::vector<double> sum_w2_; ///< dim x K: sum of w^2 per increment
    std::vector<double> counts_; ///< dim x K: points per increment (weighted by importance)
};

} // namespace mcp
