// What every mcplay command shares: exit codes, the one-line usage error, strict whole numbers,
// and writing a result to a file or to standard output.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "api/boundary.h"
#include "api/json_read.h"
#include "api/mcplay.h"

namespace mcp::cli {

// Exit codes.
constexpr int kExitOk = 0;
constexpr int kExitRuntime = 1; // I/O failure, cancelled study, internal error
constexpr int kExitUsage = 2;   // bad command line
constexpr int kExitScene = 3;   // bad scene file

/// The exit code for a failed C API call.
inline int exit_code(int status) {
    if (status == MCP_ERROR_SCENE) return kExitScene;
    if (status == MCP_ERROR_ARGUMENT) return kExitUsage;
    return kExitRuntime;
}

/// A JSON text of the C API's (a result, a plan, a progress line) read back as every JSON text
/// is, through the bounded reader (api/json_read.h); a discarded value when it is not JSON.
inline Json api_json(const char* text) {
    Made<Json> j = parse_json(text, "result");
    return j.ok() ? std::move(j.value) : Json(Json::value_t::discarded);
}

/// A C API error about `field` ("options.parts: must be ...") named as the command-line flag
/// that set it ("--part 0/9: must be ..."); other errors unchanged.
inline std::string flag_named(const std::string& error, const std::string& field,
                              const std::string& flag) {
    if (error.compare(0, field.size() + 1, field + ":") != 0) return error;
    return flag + error.substr(field.size());
}

inline int usage_error(const std::string& msg) {
    std::fprintf(stderr, "mcplay: %s (see mcplay --help)\n", boundary::one_line(msg).c_str());
    return kExitUsage;
}

/// Strict whole-number parsing: digits only, no sign, no trailing text, no overflow.
inline bool parse_count(const std::string& text, unsigned long long* out) {
    if (text.empty() || text.size() > 20) return false;
    for (char c : text)
        if (c < '0' || c > '9') return false;
    errno = 0;
    char* end = nullptr;
    unsigned long long v = std::strtoull(text.c_str(), &end, 10);
    if (errno == ERANGE || *end != '\0') return false;
    *out = v;
    return true;
}

/// Writes the bytes and closes the file, every step checked (a full disk fails at the close).
inline bool write_file(const std::string& path, const std::string& bytes) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const bool flushed = std::fflush(f) == 0;
    return std::fclose(f) == 0 && written && flushed;
}

/// Flushes and closes standard output; false (with a message on standard error) when what was
/// written to it is lost (a full disk, a closed pipe or descriptor). Every command ends here.
inline bool close_stdout() {
    const bool ok = std::fflush(stdout) == 0 && !std::ferror(stdout);
    const int err = errno;
    const bool closed = std::fclose(stdout) == 0;
    if (ok && closed) return true;
    std::fprintf(stderr, "mcplay: cannot write standard output: %s\n",
                 std::strerror(ok ? errno : err));
    return false;
}

/// Writes a formatted result to `out_path`, or to standard output when it is empty.
inline int write_output(const std::string& out_path, const std::string& formatted) {
    if (out_path.empty()) {
        // checked at the flush (close_stdout), where a full disk shows
        std::fputs(formatted.c_str(), stdout);
        return kExitOk;
    }
    errno = 0;
    if (write_file(out_path, formatted)) return kExitOk;
    std::fprintf(stderr, "mcplay: cannot write '%s'%s%s\n", boundary::one_line(out_path).c_str(),
                 errno ? ": " : "", errno ? std::strerror(errno) : "");
    return kExitRuntime;
}

} // namespace mcp::cli
