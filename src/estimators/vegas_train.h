// VEGAS training, shared by VEGAS (estimators/vegas_estimator.cpp) and VEGAS+ (vegas_plus.cpp):
// the map as a warp stage before a proposal's warp (MapStage), and train_map, the training
// iterations that adapt it [Lepage21, sec. 2.2], fed by each estimator's own training points
// (TrainingPoints: VEGAS's independent points, VEGAS+'s points in its hypercubes).
#pragma once

#include <cstdint>
#include <vector>

#include "estimators/block_driver.h"
#include "estimators/vegas.h"

namespace mcp {

/// The VEGAS map as a warp stage: unit-cube points y -> the map's u -> the proposal's domain
/// points x, with the density of x, p(x) / J(y) [Lepage21, sec. 2]. Holds the map and its
/// per-block buffers (sized once per run, never per block).
class MapStage {
  public:
    /// The identity map of `increments` per axis on the unit cube of dimension dim.
    void reset(int dim, int increments);
    VegasMap& map() { return map_; }
    const VegasMap& map() const { return map_; }
    /// Maps ws.u in place (y -> u), warps it by the proposal into ws.x and writes
    /// ws.pdf = p(x) / J(y); with record_bins, each point's increments go to bins().
    void warp(const Problem& problem, const Proposal& proposal, Workspace& ws, bool record_bins);
    /// The increments of the last warp's points (dim x kBlockSize), when recorded.
    const uint32_t* bins() const { return bins_.data(); }
    /// kBlockSize doubles free for the caller between warps (the last warp's Jacobians).
    double* scratch() { return jacobian_.data(); }

  private:
    VegasMap map_;
    std::vector<double> jacobian_;
    std::vector<uint32_t> bins_;
};

/// Where train_map's points come from, iteration by iteration. Calls are per iteration or per
/// block, never per sample.
class TrainingPoints {
  public:
    virtual ~TrainingPoints() = default;
    /// Starts an iteration of (about) `calls` points; its randomness is drawn from rng.
    virtual void start(uint64_t calls, Pcg32& rng) = 0;
    /// Writes the iteration's next points into u (at most kBlockSize; u.n set); 0 when the
    /// iteration is done.
    virtual size_t next(PointBlock& u) = 0;
    /// The block's weights w = f / p (p = ws.pdf, the mapped density) into `weights`; returns
    /// the points' importance 1 / q(y) relative to uniform y (VegasMap::add_training), or null
    /// for uniform y.
    virtual const double* weigh(const Workspace& ws, size_t count, double* weights) = 0;
    /// Gives the block's points (their increments `bins`, weights and importance) to the map:
    /// their w^2 (VegasMap::add_training) unless the points hold them back.
    virtual void train(VegasMap& map, const uint32_t* bins, const double* weights,
                       const double* importance, size_t count) {
        map.add_training(bins, weights, importance, count);
    }
    /// The iteration is over (before the map adapts to it): what `train` held back goes to map.
    virtual void finish(VegasMap& /*map*/) {}
};

/// Least relative fall of the map's movement, or of the per-point variance, that counts as
/// the map still improving.
constexpr double kVegasSettleGain = 0.1;
/// A per-point variance above this many times its least before counts as the map still
/// changing: the iteration's points found what the map had under-sampled (a peak's true
/// centre on some axis, a sliver), whose few large weights also widen the 3-standard-error
/// agreement test enough to pass it.
constexpr double kVegasSettleRise = 2.0;

/// When training may stop (options.train_stop = Settled). Two signs are followed per iteration:
/// the map's movement M, the mean over axes and edges of |new edge - old edge| in units of the
/// mean increment 1 / K, which falls while the map converges and stays at its noise level once
/// it has; and the per-point variance of the mapped weights, V = mean(c w^2) - mean(c w)^2 over
/// the iteration's points (c their importance, 1 for uniform y), which the map minimises
/// [Lepage21, sec. 2.2]. The map has settled when, for two successive iterations, neither M nor
/// V fell below (1 - kVegasSettleGain) times its least value before, nor V rose above
/// kVegasSettleRise times it, and the last two
/// iterations' estimates mean(c w) agree within 3 standard errors:
/// (I_i - I_{i-1})^2 <= 9 (V_i / n_i + V_{i-1} / n_{i-1}). A map whose first iterations miss a
/// sharp peak sees V too small, but still moves as it finds the peak; a non-finite V or M never
/// settles: training then runs its whole budget.
class TrainingStop {
  public:
    /// Records a training iteration; true when the map has settled.
    bool settled(double estimate, double variance, uint64_t points, double movement);

  private:
    double least_variance_ = -1.0, least_movement_ = -1.0; // < 0 before the first iteration
    int stalled_ = 0; // successive iterations in which neither fell
    double last_estimate_ = 0.0, last_se2_ = 0.0;
    bool has_last_ = false;
};

/// The map's movement between two sets of edges (dim x (K + 1)): the mean |difference| times K.
double vegas_movement(const VegasMap& before, const VegasMap& after);

/// What train_map spent.
struct TrainingSpent {
    uint64_t calls = 0;
    int iterations = 0;
};

/// Trains the stage's map [Lepage21, sec. 2.2]: up to `iterations` iterations of
/// part_of(calls, iterations, i) points from `points`, each block mapped and warped
/// (MapStage::warp), evaluated and weighed, its w^2 added to its increments; after each
/// iteration the map adapts (options.alpha, options.uniform_share). With options.train_stop =
/// Settled it stops early once TrainingStop says the map has settled; the calls left are the
/// caller's (for the estimate). The log counts the calls and records the map after each
/// iteration.
TrainingSpent train_map(MapStage& stage, const VegasOptions& options, const Problem& problem,
                        const Proposal& proposal, int iterations, uint64_t calls,
                        TrainingPoints& points, Pcg32& rng, Workspace& ws, TrainingLog& log);

} // namespace mcp
