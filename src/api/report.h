// Study results -> JSON (docs/result-schema.md), table and CSV: the report API of the C API
// (api/report.cpp), shared by the integration studies, the stopping studies and the render
// API's levels. Internal to the C API.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "estimators/diagnostics.h"
#include "estimators/study.h"

namespace mcp {

using Json = nlohmann::json;

constexpr int kResultSchemaVersion = 1;

Json study_to_json(const StudyResult& result);
struct StoppingStudy;
/// A stopping study (estimators/stopping.h) as JSON: "kind": "stopping", per estimator its runs
/// (answer, half-width, target, met, reason, evaluations, seconds, the doublings) and summary.
Json stopping_to_json(const StoppingStudy& study);
Json level_to_json(const LevelStats& level);
Json fit_to_json(const ConvergenceFit& fit);
Json progress_to_json(const StudyResult& partial, size_t level_index);

/// A JSON number, or null when x is not finite (JSON has no NaN).
Json num(double x);
/// A warning object: a stable code, how much it matters and a sentence,
/// {"code", "severity", "message"} (severity "error", "warning" or "info", diagnostics.h).
Json warning(const char* code, Severity severity, const std::string& message);
/// The warning of a raised flag: its code and severity, and the sentence that words it.
Json flag_warning(const Flag& flag, const std::string& message);
/// Orders an array of warnings by severity, errors first, keeping the order within one.
void sort_by_severity(Json& warnings);
/// One number formatted printf-style ("-" when it is not finite).
std::string fmt(const char* f, double x);

/// Words for the tail-index warnings: "<what> are heavy-tailed ... (from the k largest of M
/// <unit> at <n_name> = n), and below 2 <variance> is infinite".
struct TailWording {
    const char* what;
    const char* unit;
    const char* n_name;
    const char* variance;
    /// Why the values are bounded, for heavy_tail as info (nullptr: the integration studies'
    /// reason, f bounded and the density bounded below).
    const char* bounded_why = nullptr;
};
/// Appends the `heavy_tail` / `heavy_tail_4` warnings for the tail index of a study's deepest
/// level, estimated from `pooled` values (`bounded` weights: heavy_tail is info).
void add_tail_warnings(Json& warnings, const LevelStats& deepest, uint64_t pooled,
                       const TailWording& words, bool bounded,
                       const IntegrandTail* integrand = nullptr);
/// The sentence of one heavy_tail / heavy_tail_4 flag (estimators/diagnostics.h).
Json tail_warning(const Flag& flag, uint64_t pooled, const TailWording& words);

std::string format_table(const Json& result);
std::string format_csv(const Json& result);

} // namespace mcp
