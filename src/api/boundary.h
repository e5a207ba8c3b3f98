// Helpers of the extern "C" boundary shared by the integration API (api.cpp) and the render
// API (src/render_api): the thread's last error message, malloc'd result strings, and JSON
// text that never throws on odd bytes in user strings.
#pragma once

#include <cstdlib>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

namespace mcp::boundary {

inline thread_local std::string g_last_error;

/// A message kept to one line: control characters (from user text quoted in it, such as a
/// key "a\nb") are written as escapes.
inline std::string one_line(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (unsigned char ch : text) {
        if (ch >= 0x20 && ch != 0x7f) {
            out += static_cast<char>(ch);
        } else if (ch == '\n') {
            out += "\\n";
        } else if (ch == '\t') {
            out += "\\t";
        } else {
            const char* hex = "0123456789abcdef";
            out += "\\x";
            out += hex[ch >> 4];
            out += hex[ch & 15];
        }
    }
    return out;
}

inline int fail(int status, const std::string& message) {
    g_last_error = one_line(message);
    return status;
}

/// The status of a request that could not be built: a bad value in the caller's options is a
/// bad argument (messages "options..."), anything else a bad scene.
inline int request_error(const std::string& message) {
    return fail(message.compare(0, 7, "options") == 0 ? 1 /* MCP_ERROR_ARGUMENT */
                                                      : 2 /* MCP_ERROR_SCENE */,
                message);
}

inline int succeed() {
    g_last_error.clear();
    return 0;
}

/// A malloc'd copy for the caller to release with mcp_free (nullptr when out of memory).
inline char* copy_out(const std::string& s) {
    char* p = static_cast<char*>(std::malloc(s.size() + 1));
    if (p) std::memcpy(p, s.c_str(), s.size() + 1);
    return p;
}

inline std::string dump(const nlohmann::json& j, int indent = -1) {
    return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

} // namespace mcp::boundary
