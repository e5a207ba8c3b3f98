// The list of estimator kinds and presets: a new estimator adds its kind's line and its presets
// here, and nothing else outside its own file (docs/adding-an-estimator.md).
#include "estimators/registry.h"

#include <chrono>

namespace mcp {

// Each defined in its estimator's own file.
const EstimatorKind& fixed_estimator_kind();           // estimators/fixed.cpp
const EstimatorKind& vegas_estimator_kind();           // estimators/vegas_estimator.cpp
const EstimatorKind& vegas_plus_estimator_kind();      // estimators/vegas_plus.cpp
const EstimatorKind& miser_estimator_kind();           // estimators/miser.cpp
const EstimatorKind& mis_estimator_kind();             // estimators/mis.cpp
const EstimatorKind& control_variate_estimator_kind(); // estimators/control_variates.cpp
const EstimatorKind& antithetic_estimator_kind();      // estimators/antithetic.cpp
const EstimatorKind& systematic_estimator_kind();      // estimators/systematic.cpp
const EstimatorKind& ris_estimator_kind();             // estimators/ris.cpp

const std::vector<const EstimatorKind*>& estimator_kinds() {
    static const std::vector<const EstimatorKind*> kinds = {
        &fixed_estimator_kind(),      &vegas_estimator_kind(),
        &vegas_plus_estimator_kind(), &miser_estimator_kind(),
        &mis_estimator_kind(),        &control_variate_estimator_kind(),
        &antithetic_estimator_kind(), &systematic_estimator_kind(),
        &ris_estimator_kind(),
    };
    return kinds;
}

const std::vector<EstimatorPreset>& estimator_presets() {
    static const std::vector<EstimatorPreset> presets = {
        {"uniform", "fixed", SamplerKind::Independent, false,
         "independent uniform points, f / p with p uniform"},
        {"stratified", "fixed", SamplerKind::Stratified, false,
         "one jittered point per cell of an N-cell grid"},
        {"latin_hypercube", "fixed", SamplerKind::LatinHypercube, false,
         "N-rooks: one point per slab of every axis"},
        {"importance", "fixed", SamplerKind::Independent, true,
         "independent points drawn from the given pdf"},
        {"stratified_importance", "fixed", SamplerKind::Stratified, true,
         "jittered unit-cube points warped by the pdf's inverse CDF"},
        {"sobol", "fixed", SamplerKind::Sobol, false,
         "Owen-scrambled Sobol' points: 16 randomizations of N/16 points"},
        {"halton", "fixed", SamplerKind::Halton, false,
         "Owen-scrambled Halton points: 16 randomizations of N/16 points"},
        {"lattice", "fixed", SamplerKind::Lattice, false,
         "randomly shifted rank-1 lattice: 16 shifts of N/16 points"},
        {"sobol_walsh", "fixed", SamplerKind::Sobol, false,
         "one linearly scrambled Sobol' sequence of N = 2^m points, its error bound from its own "
         "Walsh coefficients",
         true},
        {"vegas", "vegas", SamplerKind::Independent, false,
         "VEGAS: a map trained on up to a quarter of N until settled, then frozen"},
        {"vegas_sobol", "vegas", SamplerKind::Sobol, false,
         "VEGAS map trained, then frozen for 16 Owen-scrambled Sobol' nets"},
        {"miser", "miser", SamplerKind::Independent, false,
         "MISER: recursive bisection, calls to the halves by their spread (GSL's defaults)"},
        {"vegas_plus", "vegas_plus", SamplerKind::Independent, false,
         "VEGAS+: the map and hypercubes with points allocated by sigma^0.75, trained then "
         "frozen"},
        {"antithetic", "antithetic", SamplerKind::Independent, false,
         "antithetic pairs u and 1 - u: N/2 independent pairs, the error bar from their means"},
        {"systematic", "systematic", SamplerKind::Independent, false,
         "systematic sampling: 16 randomly shifted grids of N/16 points"},
        {"ris_m1", "ris", SamplerKind::Independent, false,
         "resampled importance sampling with M = 1 candidate: uniform sampling", false, 1},
        {"ris_m2", "ris", SamplerKind::Independent, false,
         "resampled importance sampling: 2 uniform candidates per point, one kept by |f|", false,
         2},
        {"ris_m4", "ris", SamplerKind::Independent, false,
         "resampled importance sampling: 4 uniform candidates per point, one kept by |f|", false,
         4},
        {"ris_m8", "ris", SamplerKind::Independent, false,
         "resampled importance sampling: 8 uniform candidates per point, one kept by |f|", false,
         8},
        {"ris_m16", "ris", SamplerKind::Independent, false,
         "resampled importance sampling: 16 uniform candidates per point, one kept by |f|", false,
         16},
    };
    return presets;
}

const EstimatorKind* find_estimator_kind(const std::string& name) {
    for (const EstimatorKind* k : estimator_kinds())
        if (name == k->name) return k;
    return nullptr;
}

const EstimatorKind& kind_of(const EstimatorSpec& spec) {
    return spec.kind ? *spec.kind : fixed_estimator_kind();
}

const EstimatorPreset* find_preset(const std::string& name) {
    for (const EstimatorPreset& p : estimator_presets())
        if (name == p.name) return &p;
    return nullptr;
}

const char* estimator_method(const EstimatorSpec& spec) {
    return kind_of(spec).method(spec);
}

PointWords sampler_point_words(const EstimatorSpec& spec) {
    if (!is_qmc(spec.sampler)) return {sampler_name(spec.sampler), nullptr, 0};
    return {sampler_name(spec.sampler), randomization_name(spec.randomization),
            spec.randomizations};
}

PointWords point_words(const EstimatorSpec& spec) {
    const EstimatorKind& kind = kind_of(spec);
    return kind.points ? kind.points(spec) : sampler_point_words(spec);
}

std::string check_estimator(const EstimatorSpec& spec, const StudyShape& study) {
    const EstimatorKind& kind = kind_of(spec);
    return kind.check ? kind.check(spec, study) : std::string();
}

ErrorMethod error_method_for(const EstimatorSpec& spec) {
    return kind_of(spec).error_method(spec);
}

std::unique_ptr<EstimatorAlgorithm>
make_estimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator) {
    return kind_of(spec).make(problem, spec, accumulator);
}

RunResult run_estimate(const Problem& problem, const EstimatorSpec& spec, uint64_t n, Pcg32& rng,
                       Workspace& ws, Accumulator accumulator) {
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<EstimatorAlgorithm> estimator = make_estimator(problem, spec, accumulator);
    estimator->begin(n, rng);
    while (!problem_stopped(problem) && estimator->run_block(rng, ws)) {
    }
    RunResult result = estimator->result();
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace mcp
