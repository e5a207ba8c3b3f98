// Block-at-a-time sampling and the estimator interface built on it. Samples are made a block of
// kBlockSize at a time (structure of arrays): unit-cube points are generated, warped by the
// proposal into domain points and densities, and the integrand is evaluated on them; dispatch
// happens per block, never per sample. Declared here:
// - Workspace and SampleBlock: the reused buffers and one block of samples (u, x, pdf, f);
//   prepare_workspace, sample_block (generate -> warp -> evaluate for a sampler plan), block_of
//   (the workspace's buffers as a block, for estimators that fill them their own way: VEGAS
//   through its map, VEGAS+ and MISER in their hypercubes and regions), and for_each_block
//   (every block of a plan, handed to a consumer: the support check's probes);
// - EstimatorAlgorithm, the interface of an estimator's runs (begin, run_block, result), and what
//   the adaptive ones report: AdaptiveView, TrainingLog, view_of, clock_seconds. Its
//   implementations are made through their kinds (estimators/estimator_kind.h, registry.h).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/samplers.h"
#include "estimators/accumulator.h"
#include "estimators/estimator.h"
#include "estimators/problem.h"

namespace mcp {

/// Points per call of a caller's function (IntegrandKind::Function): a Python callable costs
/// microseconds per call whatever its size, so its blocks are made ahead in batches of this many
/// points and the function is called once per batch (FunctionBatch).
constexpr size_t kFunctionBatch = 16 * kBlockSize;

/// The batch of samples made ahead for a caller's function: the samples begin .. end - 1 of one
/// run's plan, generated and warped block by block as sample_block makes them, then evaluated in
/// one call.
struct FunctionBatch {
    PointBlock u, x;
    std::vector<double> pdf, f;
    uint64_t begin = 0, end = 0; ///< empty when begin == end
    void clear() { begin = end = 0; }
};

/// Buffers reused across runs so that a run allocates nothing per block.
struct Workspace {
    PointBlock u, x;
    std::vector<double> pdf, f;
    FunctionBatch batch; ///< used for caller's functions only
};

/// One block of samples: unit-cube points u, domain points x, densities pdf, values f.
struct SampleBlock {
    uint64_t first = 0; ///< index of the block's first sample in the run
    size_t count = 0;
    const PointBlock* u = nullptr;
    const PointBlock* x = nullptr;
    double* pdf = nullptr; ///< writable: a consumer may turn the densities into weights
    const double* f = nullptr;
};

/// Copies points [from, from + count) of src into dst from index `at` (same dimension).
void copy_points(const PointBlock& src, size_t from, PointBlock& dst, size_t at, size_t count);

/// Sizes the workspace's buffers for a domain (no allocation when they already fit).
void prepare_workspace(const Domain& domain, Workspace& ws);

/// Samples first .. first + count - 1 of the plan (count <= kBlockSize; the workspace prepared
/// for the domain): generate -> warp -> evaluate. The points depend on the plan and their
/// indices alone, so blocks may come in any order.
SampleBlock sample_block(const Problem& problem, const Proposal& proposal, const SamplerPlan& plan,
                         uint64_t first, size_t count, Workspace& ws);

/// The block of samples first .. first + count - 1 of a run of `total` whose points make(at, m)
/// writes into ws.u, ws.x and ws.pdf (the m samples from `at`, m <= kBlockSize; they may depend
/// only on their indices), evaluated: for a caller's function, from a batch of up to
/// kFunctionBatch samples made ahead from `first` (when the batch does not hold them yet) and
/// evaluated in one call; otherwise made and evaluated as one block. Blocks come in increasing
/// order within a run; ws.batch is cleared when a run begins.
template <class Make>
SampleBlock batched_block(const Problem& problem, uint64_t first, size_t count, uint64_t total,
                          Workspace& ws, Make&& make);

/// sample_block for a run whose integrand may be a caller's function: the same samples, in
/// batches for a function (batched_block).
SampleBlock sample_block_batched(const Problem& problem, const Proposal& proposal,
                                 const SamplerPlan& plan, uint64_t first, size_t count,
                                 Workspace& ws);

/// The workspace's current buffers as the block of samples first .. first + count - 1.
SampleBlock block_of(Workspace& ws, uint64_t first, size_t count);

/// Samples 0 .. plan.total - 1 of the plan, block by block (a caller's function evaluated in
/// batches), calling consume(const SampleBlock&) for each.
template <class Consume>
void for_each_block(const Problem& problem, const Proposal& proposal, const SamplerPlan& plan,
                    Workspace& ws, Consume&& consume) {
    prepare_workspace(problem.domain, ws);
    ws.batch.clear();
    const uint64_t n = plan.total;
    for (uint64_t first = 0; first < n; first += kBlockSize) {
        const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, n - first));
        consume(static_cast<const SampleBlock&>(
            sample_block_batched(problem, proposal, plan, first, count, ws)));
    }
}

namespace detail {
/// Fills ws.batch with the samples [first, min(total, first + kFunctionBatch)) made by `make`
/// block by block through ws's buffers, then evaluates f on the whole batch.
template <class Make>
void fill_batch(const Problem& problem, uint64_t first, uint64_t total, Workspace& ws,
                Make&& make) {
    FunctionBatch& b = ws.batch;
    b.begin = first;
    b.end = std::min<uint64_t>(total, first + kFunctionBatch);
    const size_t n = static_cast<size_t>(b.end - b.begin);
    if (b.u.dim != ws.u.dim || b.u.capacity != kFunctionBatch) b.u.reset(ws.u.dim, kFunctionBatch);
    if (b.x.dim != ws.x.dim || b.x.capacity != kFunctionBatch) b.x.reset(ws.x.dim, kFunctionBatch);
    b.pdf.resize(kFunctionBatch);
    b.f.resize(kFunctionBatch);
    for (size_t at = 0; at < n; at += kBlockSize) {
        const size_t m = std::min(kBlockSize, n - at);
        make(b.begin + at, m);
        copy_points(ws.u, 0, b.u, at, m);
        copy_points(ws.x, 0, b.x, at, m);
        std::copy(ws.pdf.begin(), ws.pdf.begin() + static_cast<long>(m),
                  b.pdf.begin() + static_cast<long>(at));
    }
    b.u.n = b.x.n = n;
    evaluate_block(problem.integrand, b.x, b.f.data());
}
/// Hands out the block [first, first + count) of ws.batch through ws's buffers.
SampleBlock block_from_batch(uint64_t first, size_t count, Workspace& ws);
} // namespace detail

template <class Make>
SampleBlock batched_block(const Problem& problem, uint64_t first, size_t count, uint64_t total,
                          Workspace& ws, Make&& make) {
    if (problem.integrand.kind != IntegrandKind::Function) {
        make(first, count);
        evaluate_block(problem.integrand, ws.x, ws.f.data());
        return block_of(ws, first, count);
    }
    if (first < ws.batch.begin || first + count > ws.batch.end)
        detail::fill_batch(problem, first, total, ws, make);
    return detail::block_from_batch(first, count, ws);
}

/// What an adaptive estimator learnt in its last run, for looking at it (the sample view).
struct AdaptiveView {
    std::vector<std::vector<double>> edges; ///< VEGAS: per axis, the frozen map's increment edges
    /// VEGAS: the map before training and after each training iteration (at most
    /// kViewIterations snapshots, evenly picked), each the first two axes' edges thinned to at
    /// most kViewEdges + 1 (every k-th, both ends kept): for watching the map learn.
    std::vector<std::vector<std::vector<double>>> history;
    std::vector<std::vector<double>> box_lo, box_hi; ///< MISER: the leaf boxes (the first 4096)
};

/// Seconds since an arbitrary start (steady clock): for timing an estimator's phases, once per
/// phase or region, never per sample.
double clock_seconds();

/// A VEGAS map's edges, per axis, as a view.
AdaptiveView view_of(const VegasMap& map);

constexpr int kViewIterations = 100;
constexpr int kViewEdges = 64;

/// What a VEGAS run (plain or VEGAS+) spends on training and learns there: the calls and seconds
/// (RunResult::training_n, training_seconds) and, when recording, the map before training and
/// after each iteration (AdaptiveView::history: the first two axes, thinned). Per iteration,
/// never per sample.
class TrainingLog {
  public:
    void begin(const VegasMap& map, int iterations, bool record);
    void trained(uint64_t calls) { calls_ += calls; }
    /// After training iteration `iteration` (1-based) adapted the map.
    void adapted(const VegasMap& map, int iteration);
    /// Training is over (the first call counts).
    void end_training();
    void report(RunResult* r) const;
    void add_history(AdaptiveView* view) const { view->history = history_; }

  private:
    void record(const VegasMap& map, int iteration);
    bool record_ = false, ended_ = false;
    int iterations_ = 0;
    uint64_t calls_ = 0;
    double start_ = 0.0, seconds_ = 0.0;
    std::vector<std::vector<std::vector<double>>> history_;
};

/// How a run laid out its points, for the sample view: the grid's cells per axis (empty: no
/// grid), the points per cell, and the independent randomizations it is made of (0: none).
struct PointDesign {
    std::vector<uint64_t> strata;
    uint64_t per_stratum = 1;
    size_t randomizations = 0;
};

/// An estimator as an algorithm: it plans a run, consumes it block by block, and gives the
/// run's result. Fixed estimators (a sampler and one proposal; estimators/fixed.cpp) are one
/// implementation; VEGAS (vegas_estimator.cpp), VEGAS+ and MISER (which adapt their sampling
/// between iterations or regions), MIS (several proposals) and control variates are the others.
/// Stopping at a tolerance (stopping.h) runs whole estimates of any of them. Calls are per
/// block, never per sample.
class EstimatorAlgorithm {
  public:
    virtual ~EstimatorAlgorithm() = default;
    /// Called with every block the estimate is made from (not training or probing blocks),
    /// before the weights overwrite the densities: for looking at the points. Per block.
    using BlockObserver = std::function<void(const SampleBlock&)>;
    void observe(BlockObserver observer) { observer_ = std::move(observer); }
    /// The state an adaptive estimator ended its last run with (empty for fixed ones).
    virtual AdaptiveView adaptive_view() const { return {}; }
    /// How the run begun last laid out its points (none: independent points, or adaptive ones).
    virtual PointDesign design() const { return {}; }
    /// Starts a run of n samples; the run's randomization is drawn from rng.
    virtual void begin(uint64_t n, Pcg32& rng) = 0;
    /// Samples and weighs the next block; false when the run is complete (nothing was done).
    virtual bool run_block(Pcg32& rng, Workspace& ws) = 0;
    /// The completed run (estimate, error bar, diagnostics; not its time).
    virtual RunResult result() const = 0;

  protected:
    void notify(const SampleBlock& block) const {
        if (observer_) observer_(block);
    }
    BlockObserver observer_;
};

} // namespace mcp
