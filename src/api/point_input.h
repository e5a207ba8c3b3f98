// Points a user brings: a CSV text (one point per row, an optional header; a column named "set"
// splits the rows into K point sets) or a JSON array of rows. Every count is bounded before a
// number is read, and every error names the row (1-based, as an editor shows it) and the column.
#pragma once

#include <string>
#include <vector>

#include "api/json_read.h"
#include "core/made.h"
#include "core/point_analysis.h"

namespace mcp {

/// K point sets of the same size and dimension (K = 1 without a "set" column).
struct UserPointSets {
    std::vector<PointSet> sets;
    std::vector<std::string> set_names; ///< the "set" column's values, in order of appearance
    int dim() const { return sets.empty() ? 0 : sets[0].dim; }
    uint64_t total_points() const;
};

/// At most this many sets (randomizations) in one upload.
constexpr size_t kMaxUserSets = 1024;

/// Parses CSV text: fields separated by commas (or semicolons, tabs or spaces), one point per
/// line, blank lines and lines starting with '#' skipped, a leading UTF-8 byte-order mark
/// ignored. A first line none of whose fields is a number is a header (its column "set", any
/// case, names the point set of each row); a first line of numbers and text is an error naming
/// the field, not a header. Values must be
/// finite numbers in [0, 1); at most kMaxAnalysisPoints points in all and kMaxAnalysisDim
/// coordinates per point. Sets must have equal sizes.
Made<UserPointSets> parse_points_csv(const std::string& text);

/// The same from JSON: an array of rows (one set), or an array of such arrays (K sets).
Made<UserPointSets> parse_points_json(const Json& value, const std::string& path);

} // namespace mcp
