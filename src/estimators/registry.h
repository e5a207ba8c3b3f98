// The registry of estimators: every estimator kind (estimators/estimator_kind.h) and the named
// presets built on them, in one list (estimators/registry.cpp), and what is looked up through
// it: a spec's kind, method, error method and algorithm, and one whole estimate (run_estimate,
// declared in estimators/estimator.h). Dependencies point one way: the kinds' files know the
// block driver, this registry knows the kinds, and the studies and the C API know the registry.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/samplers.h"
#include "estimators/estimator_kind.h"

namespace mcp {

/// Every estimator kind, in the order the catalog lists them.
const std::vector<const EstimatorKind*>& estimator_kinds();
/// The kind of that name, or null.
const EstimatorKind* find_estimator_kind(const std::string& name);
/// The kind of a spec: spec.kind, or the fixed kind when it has none.
const EstimatorKind& kind_of(const EstimatorSpec& spec);

/// A named estimator with its defaults: scene and options "estimators": ["vegas", ...]
/// (docs/scene-format.md).
struct EstimatorPreset {
    const char* name;
    const char* kind; ///< the name of its EstimatorKind
    SamplerKind sampler;
    bool needs_pdf; ///< samples the scene's pdf (an estimator object must give one)
    const char* summary;
    /// Sobol' with one linear scramble (lms_shift) and the Walsh error bound (walsh_bound).
    bool walsh_bound = false;
    int ris_candidates = 0; ///< resampled importance sampling: M candidates per point
};
/// Every preset, in the order messages and the catalog list them.
const std::vector<EstimatorPreset>& estimator_presets();
/// The preset of that name, or null.
const EstimatorPreset* find_preset(const std::string& name);

/// The method a spec is an instance of, for explaining it (its kind's method; the catalog lists
/// every kind's).
const char* estimator_method(const EstimatorSpec& spec);

/// The words of a spec's points (its kind's, or sampler_point_words).
PointWords point_words(const EstimatorSpec& spec);
/// The words of the spec's sampler: its name, and for quasi-Monte Carlo its randomization and K.
PointWords sampler_point_words(const EstimatorSpec& spec);
/// The spec's kind's own checks on a study of it: "" or a one-line error.
std::string check_estimator(const EstimatorSpec& spec, const StudyShape& study);

/// How a spec's per-run standard error is estimated (its kind's error method).
ErrorMethod error_method_for(const EstimatorSpec& spec);

/// The algorithm of a spec (its kind's factory).
std::unique_ptr<EstimatorAlgorithm>
make_estimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator);

} // namespace mcp
