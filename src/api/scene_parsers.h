// The scene parsers behind build_request (api/scene.cpp), one file per part of a scene: the
// domain and the integrand (api/parse_problem.cpp), pdfs (api/parse_pdf.cpp), estimators
// (api/parse_estimator.cpp, with each kind's own fields in api/estimator_options.cpp). Every
// value is type-checked before use (the API is built without exceptions) and every error names
// the JSON path of the offending field and what was expected. Internal to the C API.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "api/json_read.h"
#include "estimators/estimator.h"
#include "estimators/named_warps.h"
#include "estimators/problem.h"

namespace mcp {

/// A number for messages ("1e+200", "0.25", "NaN", "-inf": the same on every platform).
std::string number_text(double x);

/// A "domain" object; `default_dim` for boxes without bounds.
bool parse_domain(Ctx& c, const Json& j, const std::string& path, int default_dim, Domain* out);
/// The caller's function that j[key] names (an error when the call was given none of that
/// name).
bool find_caller_function(Ctx& c, const Json& j, const char* key, const std::string& path,
                          std::shared_ptr<const CallerFunction>* out);
/// An integrand object or expression string over points of dimension `dim`.
bool parse_integrand(Ctx& c, const Json& j, const std::string& path, int dim, Integrand* out);
/// The dimension an integrand asks for when the scene gives no domain: the length of its
/// parameter arrays, a Genz "dim", or the highest variable an expression uses.
bool integrand_dimension(Ctx& c, const Json& j, const std::string& path, int* out);

/// A "pdf" object: a proposal density over the problem's domain.
bool parse_pdf(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
               Proposal* out);

/// A scene's "warp": a named warp's name, {"name", its parameters}, or {"domain", "g", "p"}
/// (api/parse_warp.cpp); the warp and the domain it maps onto.
bool parse_warp(Ctx& c, const Json& j, const std::string& path, NamedWarp* out);

/// One entry of "estimators": a preset name, or an object naming its sampler, pdf and its
/// kind's fields.
bool parse_estimator(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                     EstimatorSpec* out);
/// The "accumulator" field of an object ("compensated" or "float32"), if present.
bool parse_accumulator(Ctx& c, const Json& obj, const std::string& path, Accumulator* out);

/// The presets' names, in their order.
std::vector<std::string> preset_names();
/// Levenshtein distance (insertions, deletions, substitutions), for "did you mean".
size_t edit_distance(const std::string& a, const std::string& b);
/// " (did you mean 'stratified'? " or " (": the closest preset within a third of its length.
std::string did_you_mean(const std::string& name);
/// The text of an estimator name for messages: at most 64 characters.
std::string name_text(const std::string& name);

} // namespace mcp
