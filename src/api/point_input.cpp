#include "api/point_input.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>

namespace mcp {

uint64_t UserPointSets::total_points() const {
    uint64_t total = 0;
    for (const PointSet& s : sets) total += s.n;
    return total;
}

namespace {

/// The fields of one line: split at commas, semicolons or tabs (each field trimmed of spaces),
/// or at runs of spaces when the line has none of those.
std::vector<std::string> split_fields(const std::string& line) {
    const bool hard = line.find_first_of(",;\t") != std::string::npos;
    std::vector<std::string> fields;
    std::string field;
    auto flush = [&](bool keep_empty) {
        const size_t a = field.find_first_not_of(" \r"), b = field.find_last_not_of(" \r");
        std::string trimmed = a == std::string::npos ? "" : field.substr(a, b - a + 1);
        if (keep_empty || !trimmed.empty()) fields.push_back(trimmed);
        field.clear();
    };
    for (char c : line) {
        if (hard ? (c == ',' || c == ';' || c == '\t') : c == ' ') {
            flush(hard);
        } else {
            field += c;
        }
    }
    flush(hard);
    return fields;
}

/// A finite double from the whole field, or false.
bool read_number(const std::string& field, double* out) {
    if (field.empty() || field.size() > 64) return false;
    char* end = nullptr;
    const double v = std::strtod(field.c_str(), &end);
    if (end != field.c_str() + field.size()) return false;
    *out = v;
    return true;
}

std::string quoted(const std::string& field) {
    return "'" + (field.size() > 24 ? field.substr(0, 24) + "..." : field) + "'";
}

/// Why a field that read_number refused is not a coordinate.
std::string not_a_number(const std::string& field) {
    return field.empty() ? "the field is empty" : quoted(field) + " is not a number";
}

/// "" when v may be a coordinate, else why not.
std::string check_coordinate(double v, const std::string& field) {
    if (std::isnan(v)) return "NaN is not a coordinate";
    if (!std::isfinite(v)) return quoted(field) + " is infinite";
    if (v < 0.0 || v >= 1.0) return quoted(field) + " is outside [0, 1)";
    return "";
}

/// Builds the sets from rows already read (set index per row), checking equal sizes.
Made<UserPointSets> assemble(const std::vector<double>& values, const std::vector<size_t>& set_of,
                             const std::vector<std::string>& names, int dim) {
    const size_t rows = set_of.size();
    std::vector<uint64_t> counts(names.size(), 0);
    for (size_t s : set_of) ++counts[s];
    for (size_t s = 1; s < counts.size(); ++s)
        if (counts[s] != counts[0])
            return made_error<UserPointSets>("set '" + names[s] + "' has " +
                                             std::to_string(counts[s]) + " points, set '" +
                                             names[0] + "' " + std::to_string(counts[0]) +
                                             ": the sets of one file are randomizations of one "
                                             "rule and must have the same size");
    UserPointSets out;
    out.set_names = names;
    out.sets.resize(names.size());
    for (size_t s = 0; s < names.size(); ++s) {
        out.sets[s].dim = dim;
        out.sets[s].n = counts[s];
        out.sets[s].coords.assign(static_cast<size_t>(counts[s]) * static_cast<size_t>(dim), 0.0);
    }
    std::vector<uint64_t> next(names.size(), 0);
    for (size_t r = 0; r < rows; ++r) {
        PointSet& set = out.sets[set_of[r]];
        const uint64_t i = next[set_of[r]]++;
        for (int k = 0; k < dim; ++k)
            set.coords[static_cast<size_t>(static_cast<uint64_t>(k) * set.n + i)] =
                values[r * static_cast<size_t>(dim) + static_cast<size_t>(k)];
    }
    return Made<UserPointSets>{std::move(out), ""};
}

} // namespace

Made<UserPointSets> parse_points_csv(const std::string& text) {
    // Bounds before any number is read: lines and the columns of the first data line.
    size_t lines = 1;
    for (char c : text) lines += c == '\n';
    if (lines > kMaxAnalysisPoints + 1024)
        return made_error<UserPointSets>("the file has " + std::to_string(lines) +
                                         " lines; at most " + std::to_string(kMaxAnalysisPoints) +
                                         " points are analysed");
    std::vector<double> values;
    std::vector<size_t> set_of;
    std::vector<std::string> names;
    std::map<std::string, size_t> set_index;
    int dim = -1;        // coordinates per point
    int set_column = -1; // the header's "set" column
    int columns = -1;    // fields per row
    bool header_seen = false, data_seen = false;
    // A UTF-8 byte-order mark (spreadsheets write one) is no part of the first field.
    size_t line_no = 0, pos = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    while (pos <= text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        std::string line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_no;
        const std::string row = "row " + std::to_string(line_no);
        size_t first = line.find_first_not_of(" \t\r");
        if (first == std::string::npos || line[first] == '#') {
            if (end == text.size()) break;
            continue;
        }
        std::vector<std::string> fields = split_fields(line);
        if (!header_seen && !data_seen) {
            // A header is a row none of whose fields is a number; a first row of numbers and
            // text is a data row with a bad field, never a header (it would lose a point).
            double v = 0.0;
            size_t numbers = 0, text_at = fields.size();
            for (size_t k = 0; k < fields.size(); ++k) {
                if (read_number(fields[k], &v))
                    ++numbers;
                else if (text_at == fields.size())
                    text_at = k;
            }
            if (numbers > 0 && text_at < fields.size())
                return made_error<UserPointSets>(
                    row + ", column " + std::to_string(text_at + 1) + ": " +
                    not_a_number(fields[text_at]) +
                    " (the row's other fields are numbers, so it is no header: a header "
                    "has no number in it)");
            if (numbers == 0) {
                header_seen = true;
                for (size_t k = 0; k < fields.size(); ++k) {
                    std::string lower = fields[k];
                    for (char& c : lower)
                        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
                    if (lower == "set") set_column = static_cast<int>(k);
                }
                columns = static_cast<int>(fields.size());
                dim = columns - (set_column >= 0 ? 1 : 0);
                if (dim < 1)
                    return made_error<UserPointSets>(row +
                                                     ": the header names no coordinate column");
                if (dim > kMaxAnalysisDim)
                    return made_error<UserPointSets>(row + ": " + std::to_string(dim) +
                                                     " coordinate columns; at most " +
                                                     std::to_string(kMaxAnalysisDim));
                if (end == text.size()) break;
                continue;
            }
        }
        if (columns < 0) {
            columns = static_cast<int>(fields.size());
            dim = columns;
            if (dim > kMaxAnalysisDim)
                return made_error<UserPointSets>(row + ": " + std::to_string(dim) +
                                                 " coordinates; at most " +
                                                 std::to_string(kMaxAnalysisDim) + " dimensions");
        }
        data_seen = true;
        if (static_cast<int>(fields.size()) != columns)
            return made_error<UserPointSets>(row + ": expected " + std::to_string(columns) +
                                             " columns, got " + std::to_string(fields.size()));
        if (set_of.size() >= kMaxAnalysisPoints)
            return made_error<UserPointSets>(row + ": more than " +
                                             std::to_string(kMaxAnalysisPoints) + " points");
        size_t set = 0;
        for (int k = 0; k < columns; ++k) {
            const std::string& f = fields[static_cast<size_t>(k)];
            if (k == set_column) {
                auto it = set_index.find(f);
                if (it == set_index.end()) {
                    if (names.size() >= kMaxUserSets)
                        return made_error<UserPointSets>(row + ": more than " +
                                                         std::to_string(kMaxUserSets) + " sets");
                    it = set_index.emplace(f, names.size()).first;
                    names.push_back(f);
                }
                set = it->second;
                continue;
            }
            double v = 0.0;
            const std::string col = ", column " + std::to_string(k + 1);
            if (!read_number(f, &v))
                return made_error<UserPointSets>(row + col + ": " + not_a_number(f));
            const std::string why = check_coordinate(v, f);
            if (!why.empty()) return made_error<UserPointSets>(row + col + ": " + why);
            values.push_back(v);
        }
        set_of.push_back(set);
        if (end == text.size()) break;
    }
    if (set_of.empty()) return made_error<UserPointSets>("the file holds no points");
    if (names.empty()) names.push_back("0");
    return assemble(values, set_of, names, dim);
}

Made<UserPointSets> parse_points_json(const Json& value, const std::string& path) {
    if (!value.is_array() || value.empty())
        return made_error<UserPointSets>(path + ": expected a non-empty array of points, got " +
                                         type_of(value));
    // An array of sets when its first element's first element is itself an array.
    const bool many = value[0].is_array() && !value[0].empty() && value[0][0].is_array();
    const size_t set_count = many ? value.size() : 1;
    if (set_count > kMaxUserSets)
        return made_error<UserPointSets>(path + ": " + std::to_string(set_count) +
                                         " sets; at most " + std::to_string(kMaxUserSets));
    uint64_t rows_total = 0;
    for (size_t s = 0; s < set_count; ++s) {
        const Json& rows = many ? value[s] : value;
        if (!rows.is_array())
            return made_error<UserPointSets>(path + "[" + std::to_string(s) +
                                             "]: expected an array of points, got " +
                                             type_of(rows));
        rows_total += rows.size();
    }
    if (rows_total > kMaxAnalysisPoints)
        return made_error<UserPointSets>(path + ": " + std::to_string(rows_total) +
                                         " points; at most " + std::to_string(kMaxAnalysisPoints));
    std::vector<double> values;
    std::vector<size_t> set_of;
    std::vector<std::string> names;
    int dim = -1;
    for (size_t s = 0; s < set_count; ++s) {
        const Json& rows = many ? value[s] : value;
        const std::string set_path = many ? path + "[" + std::to_string(s) + "]" : path;
        names.push_back(std::to_string(s));
        for (size_t r = 0; r < rows.size(); ++r) {
            const std::string p = set_path + "[" + std::to_string(r) + "]";
            const Json& row = rows[r];
            if (!row.is_array())
                return made_error<UserPointSets>(p + ": expected an array of coordinates, got " +
                                                 type_of(row));
            if (dim < 0) {
                dim = static_cast<int>(row.size());
                if (dim < 1 || dim > kMaxAnalysisDim)
                    return made_error<UserPointSets>(p + ": " + std::to_string(row.size()) +
                                                     " coordinates; expected 1 to " +
                                                     std::to_string(kMaxAnalysisDim));
            }
            if (static_cast<int>(row.size()) != dim)
                return made_error<UserPointSets>(p + ": expected " + std::to_string(dim) +
                                                 " coordinates, got " + std::to_string(row.size()));
            for (size_t k = 0; k < row.size(); ++k) {
                const std::string pk = p + "[" + std::to_string(k) + "]";
                if (!row[k].is_number())
                    return made_error<UserPointSets>(pk + ": expected a number, got " +
                                                     type_of(row[k]));
                const double v = row[k].get<double>();
                const std::string why = check_coordinate(v, row[k].dump());
                if (!why.empty()) return made_error<UserPointSets>(pk + ": " + why);
                values.push_back(v);
            }
            set_of.push_back(s);
        }
    }
    if (set_of.empty()) return made_error<UserPointSets>(path + ": no points");
    return assemble(values, set_of, names, dim);
}

} // namespace mcp
