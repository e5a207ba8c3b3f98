// Reading user JSON without exceptions: every accessor checks the type first, and the
// first error is kept as "path: message" naming the offending field.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/made.h"

namespace mcp {

using Json = nlohmann::json;

/// Limits on every JSON text mcplay reads (scenes, options, results, glTF): objects and arrays
/// nested at most this deep, and texts of at most this many bytes.
constexpr int kMaxJsonDepth = 64;
constexpr uint64_t kMaxJsonBytes = 256ull << 20;

/// Checks JSON text before any tree is built from it: syntax, nesting at most kMaxJsonDepth,
/// no key twice in one object. The walk is iterative (nlohmann's SAX parser keeps its own
/// stack), so no input can exhaust the call stack. Returns "" when the text is fine, else a
/// reason with the line and column or the JSON path (from `root`), never quoting the text.
std::string check_json_text(const char* text, size_t size, const char* root = "$");

/// Parses JSON text (checked by check_json_text first) without exceptions; on failure the
/// message starts with `what`. Every JSON text mcplay reads goes through here (the CLI's files
/// and the C API's results included), so that no text can nest deep enough to exhaust a stack.
Made<Json> parse_json(const char* text, const char* what);
/// The same for `size` bytes (a file's contents, which may hold a NUL byte).
Made<Json> parse_json(const char* text, size_t size, const char* what);
inline Made<Json> parse_json(const std::string& text, const char* what) {
    return parse_json(text.data(), text.size(), what);
}

struct CallerFunctions; // api/caller_functions.h

// Records the first error as "path: message"; carries the caller's functions a scene may name.
struct Ctx {
    std::string error;
    const CallerFunctions* functions = nullptr; ///< null: the call was given none
    bool fail(const std::string& path, const std::string& msg) {
        if (error.empty()) error = path + ": " + msg;
        return false;
    }
};

/// "a number", "an object", ... for messages.
std::string type_of(const Json& j);
std::string join(const std::vector<std::string>& items);
/// Rejects keys outside `known`, so that a typo ("n_mx") is an error, not a silent default.
bool check_keys(Ctx& c, const Json& obj, const std::string& path,
                const std::vector<std::string>& known);
const Json* find(const Json& obj, const char* key);
std::string sub(const std::string& path, const char* key);
/// The first path at which two JSON values differ (objects by key, arrays of one size by index),
/// "" when they are equal: for messages that name the field two inputs disagree on.
std::string first_difference(const Json& a, const Json& b, const std::string& path);
// Optional fields: each leaves *out unchanged when the key is absent.
bool get_number(Ctx& c, const Json& obj, const char* key, const std::string& path, double* out);
bool get_count(Ctx& c, const Json& obj, const char* key, const std::string& path, uint64_t* out);
bool get_string(Ctx& c, const Json& obj, const char* key, const std::string& path,
                std::string* out);
bool to_numbers(Ctx& c, const Json& v, const std::string& path, std::vector<double>* out);
bool get_numbers(Ctx& c, const Json& obj, const char* key, const std::string& path,
                 std::vector<double>* out);

} // namespace mcp
