// VEGAS adaptive importance sampling [Lepage78, Lepage21]: a separable, piecewise-linear map
// y -> u of the unit cube, trained on the squared weights it sees, then frozen.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/points.h"
#include "core/samplers.h"

namespace mcp {

/// How a VEGAS run reports its estimate.
enum class VegasReport {
    Frozen,    ///< train, freeze the map, estimate from fresh points: an ordinary error bar
    Iterations ///< keep adapting over `iterations` iterations and report their weighted
               ///< average with chi^2 / dof, as vegas and GSL do [Lepage78, eq. 6-8]
};

/// When VEGAS training stops.
enum class VegasTrainStop {
    Default, ///< the estimator's own (vegas_resolved)
    Settled, ///< once the map has settled (TrainingStop, vegas_train.h), at most the budget
    Budget   ///< after the whole training budget, train_fraction N in train_iterations
};

/// The options of a VEGAS estimator (scene field "vegas"; docs/scene-format.md).
struct VegasOptions {
    int increments = 0; ///< per axis; 0 chooses vegas_increments()
    /// Damping exponent of the refinement [Lepage78, Lepage21, eq. 22]: Lepage78 gives 1 to 2
    /// (GSL 1.5), vegas 0.5. Negative: the estimator's default (vegas_resolved).
    double alpha = -1.0;
    double train_fraction = 0.25; ///< share of the N evaluations spent training the map
    /// The training share is split into this many iterations, at most: training stops when
    /// the map has settled (train_stop). More, smaller iterations converge on a sharp peak
    /// where 10 did not (the map needs steps more than points per step). 0: the default.
    int train_iterations = 0;
    VegasTrainStop train_stop =
        VegasTrainStop::Default; ///< Settled: the calls left go to the estimate
    /// Share of each axis's increments spread evenly; negative: the estimator's default
    /// (vegas_resolved: 1 - (1 - kVegasEvenShare)^(1/d) for the map alone, else kVegasEvenShare).
    double uniform_share = -1.0;
    VegasReport report = VegasReport::Frozen;
    int iterations = 5; ///< Iterations: the estimation share is split into this many
    /// VEGAS+ [Lepage21, sec. 3]: hypercubes of the y space, each sampled with n_h >= 2 points,
    /// n_h proportional to sigma_h^beta from the previous iteration. Read by the scene parser
    /// only: it makes the estimator of kind vegas_plus (estimators/vegas_plus.cpp).
    bool stratify = false;
    double beta = 0.75;
};

/// The even share of the map: of each axis, or (the map alone) of the whole map.
constexpr double kVegasEvenShare = 0.05;

/// The options a run uses: `options` with the fields left to the estimator (alpha < 0,
/// train_iterations 0, train_stop Default, uniform_share < 0) filled in for its sampler, its
/// report, whether it is VEGAS+ (`plus`: the estimator kind vegas_plus) and the dimension of
/// its unit cube (docs/scene-format.md, VEGAS).
VegasOptions vegas_resolved(const VegasOptions& options, SamplerKind sampler, bool plus, int dim);

/// VEGAS+'s hypercubes per axis for an iteration of `points` points in `dim` dimensions: the
/// largest m with m^dim hypercubes of about 4 points each (m^dim * 4 <= points) and at most
/// kVegasMaxHypercubes of them; at least 1.
uint64_t vegas_plus_per_axis(int dim, uint64_t points);
constexpr uint64_t kVegasMaxHypercubes = uint64_t(1) << 20;

/// The medians of a group of n values with one of them left out, for VEGAS+'s pilot (a
/// hypercube's siblings without it): the median of the n - 1 others of a value v of the group
/// is of(v) (the median of m values: the sorted value m / 2, rounded down). Leaves the median
/// of all n, the sorted value n / 2, at first + n / 2 (std::nth_element's order); n >= 2.
struct MedianWithoutOne {
    double below = 0.0, above = 0.0; ///< the sorted values (n - 1) / 2 and (n + 1) / 2
    double of(double v) const { return v > below ? below : above; }
};
MedianWithoutOne median_without_one(double* first, double* last);

/// Least hypercubes per axis of a training iteration for VEGAS+'s nested mode (GSL's stratified
/// mode): with the default increments, each increment then holds a whole number of hypercubes
/// per axis (K at most M) and the map trains on the hypercubes' errors. Fewer, and K = M
/// increments are too coarse a map. The mode also needs kVegasSizingIterations training
/// iterations (N >= 40,000 at the defaults): the estimate keeps the map the last one measured,
/// and with one or two that is the identity or close to it, whose sigma_h from 4-point
/// hypercubes understated the error bars on a corner peak at N = 4096-32768.
constexpr uint64_t kVegasPlusNestedAxis = 16;
/// The map's damping in VEGAS+'s nested mode unless `alpha` is given: GSL's [Lepage78 gives
/// 1 to 2]; trained on the errors, the map must shrink a singularity's increments far.
constexpr double kVegasNestedAlpha = 1.5;

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

/// Fewest training points per increment per iteration that a map can learn from. With fewer,
/// most increments see no point and the rest one or two: the map follows the noise, its
/// Jacobian is a product of d axes' noisy factors, and in high d that product collapses (64-D,
/// 65536 increments, 2,500 points per iteration: estimates of 1e-164 for an integral of 1).
constexpr uint64_t kVegasPointsPerIncrement = 10;

/// The training share's split that sizes the default increments: vegas_increments() sees
/// training_calls / kVegasSizingIterations points per iteration however many iterations the
/// training runs, so that more, smaller iterations do not coarsen the map (sized by the actual
/// iterations, 20 halved K against 10; on Genz's d = 2 families vegas with the map alone's
/// defaults gained 2.3x in RMSE^2 before this and 2.6x after, geometric means of 6, R = 10).
constexpr int kVegasSizingIterations = 10;

/// The increments a run uses: options.increments when given, else vegas_increments() of the
/// larger of points_per_iteration and training_calls / kVegasSizingIterations; at most
/// points_per_iteration / kVegasPointsPerIncrement (at least 2) when the map is trained.
int vegas_trainable_increments(const VegasOptions& options, int dim, uint64_t points_per_iteration,
                               uint64_t training_calls = 0);

/// Why options.increments cannot be trained even at the largest N of a study, n_max: fewer than
/// kVegasPointsPerIncrement points per increment per training iteration (or per averaged
/// iteration, without training). Empty when they can, or when increments are chosen (0).
std::string vegas_untrainable(const VegasOptions& options, uint64_t n_max);

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
    /// Adds one point's `square` in place of its w^2 (VEGAS+'s squared deviation from its
    /// hypercube's mean) to its increments bins[j * stride], counted with `importance`. A
    /// non-finite square is skipped.
    void add_square(const uint32_t* bins, size_t stride, double square, double importance);

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
