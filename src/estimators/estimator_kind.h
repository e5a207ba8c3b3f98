// An estimator kind: the one place that says what an estimator is, as pbrt-v4 makes its
// integrators by name in one place (Integrator::Create, src/pbrt/cpu/integrators.cpp). A kind
// owns its method name (what the page explains), its error method, its factory (whose algorithm
// draws and randomizes its own points), its checks on a study of it, the words reports show of
// its points, and the facts the page and the reports read instead of knowing estimators (whether
// the running mean of its first points is its estimate, whether it adapts). Each kind defines
// its entry in its own file under estimators/; estimators/registry.cpp lists them with the
// presets (docs/adding-an-estimator.md).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "estimators/block_driver.h"
#include "estimators/estimator.h"
#include "estimators/problem.h"

namespace mcp {

/// What reports and the sample view say of an estimator's points.
struct PointWords {
    const char* sampler;       ///< how they are placed: "independent", "sobol", "systematic", ...
    const char* randomization; ///< how a randomization is drawn ("owen", ...); null: none
    int randomizations;        ///< K independent randomizations per run; 0: none
};

/// What a kind's own check sees of a study: the sample dimension and the N of its runs, which
/// double from n_first up to n_max (the study's powers of two, or a stopping rule's n_min).
struct StudyShape {
    int dim;
    uint64_t n_first, n_max;
};

struct EstimatorKind {
    const char* name;    ///< "fixed", "vegas", "vegas_plus", "miser", "mis", ... (spec.kind)
    const char* summary; ///< one line: what an estimator of this kind does
    /// The method an estimator of this kind is an instance of, for explaining it (the page's
    /// panels are keyed by it): "uniform", "stratified", "rqmc", "vegas", "miser", ...
    const char* (*method)(const EstimatorSpec& spec);
    /// How its per-run standard error is estimated.
    ErrorMethod (*error_method)(const EstimatorSpec& spec);
    /// Its algorithm, for one problem; called once per run, never per sample.
    std::unique_ptr<EstimatorAlgorithm> (*make)(const Problem& problem, const EstimatorSpec& spec,
                                                Accumulator accumulator);
    /// Whether the mean of the first k of its points' weights f/p (in the order the sample view
    /// shows them) is its estimate at N = k, with the independent points' error bar: its points
    /// are independent and not a design of the whole N (strata, nets, pairs, a learnt map).
    bool (*replay_is_estimate)(const EstimatorSpec& spec);
    /// Whether it learns from its own run (VEGAS's map, MISER's cuts): the sample view runs it
    /// at a larger N (options.adaptive_n) and shows its first points; its points follow no
    /// sampler plan of their own.
    bool adaptive;
    /// The words reports and the sample view show of its points; null: its spec's sampler's
    /// (sampler_point_words, estimators/registry.h).
    PointWords (*points)(const EstimatorSpec& spec) = nullptr;
    /// Its own checks on a study of it (N, dimension, options), run before any work: "" or one
    /// line naming what is wrong, the value given and the way out; null: none.
    std::string (*check)(const EstimatorSpec& spec, const StudyShape& study) = nullptr;
};

} // namespace mcp
