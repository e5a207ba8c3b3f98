// Reading user JSON without exceptions: every accessor checks the type first, and the
// first error is kept as "path: message" naming the offending field.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mcp {

using Json = nlohmann::json;

// Records the first error as "path: message".
struct Ctx {
    std::string error;
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
// Optional fields: each leaves *out unchanged when the key is absent.
bool get_number(Ctx& c, const Json& obj, const char* key, const std::string& path, double* out);
bool get_count(Ctx& c, const Json& obj, const char* key, const std::string& path, uint64_t* out);
bool get_string(Ctx& c, const Json& obj, const char* key, const std::string& path,
                std::string* out);
bool to_numbers(Ctx& c, const Json& v, const std::string& path, std::vector<double>* out);
bool get_numbers(Ctx& c, const Json& obj, const char* key, const std::string& path,
                 std::vector<double>* out);

} // namespace mcp
