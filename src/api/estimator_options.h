// The estimator kinds' own JSON fields (docs/scene-format.md, "estimators"), one entry per
// kind that has options: the fields that select the kind, the ones it reads besides, and the
// function that parses and validates them and sets the spec's kind. The core's kinds
// (estimators/registry.h) know no JSON; a kind without options (the fixed one, or a kind made
// by a preset alone) needs no entry. Part of the scene parsers (api/scene_parsers.h).
#pragma once

#include <string>
#include <vector>

#include "api/json_read.h"
#include "estimators/problem.h"

namespace mcp {

struct KindFields {
    /// The kinds these fields make (the parse picks one): {"vegas", "vegas_plus"}, {"miser"}, ...
    std::vector<const char*> kinds;
    /// Fields that select the kind: any of them present makes the estimator of this kind; the
    /// first names it in messages.
    std::vector<const char*> selecting;
    /// Fields it reads besides (an error without a selecting one).
    std::vector<const char*> extra;
    /// Whether it reads the estimator's "pdf" itself (MIS: the first technique).
    bool takes_pdf;
    /// Parses the fields of the estimator object `j` into *out and sets out->kind. The name,
    /// the sampler and the preset's kind (if any) are set; `pdf` is the object's "pdf" or null.
    bool (*parse)(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                  const Json* pdf, EstimatorSpec* out);
};

/// Every kind's fields, in the order messages list them.
const std::vector<KindFields>& kind_fields();

} // namespace mcp
