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
    /// The iteration is over (before the map adapts to it).
    virtual void finish() {}
};

/// Trains the stage's map [Lepage21, sec. 2.2]: `iterations` iterations of
/// part_of(calls, iterations, i) points from `points`, each block mapped and warped
/// (MapStage::warp), evaluated and weighed, its w^2 added to its increments; after each
/// iteration the map adapts (options.alpha, options.uniform_share). The log counts the calls
/// and records the map after each iteration.
void train_map(MapStage& stage, const VegasOptions& options, const Problem& problem,
               const Proposal& proposal, int iterations, uint64_t calls, TrainingPoints& points,
               Pcg32& rng, Workspace& ws, TrainingLog& log);

} // namespace mcp
