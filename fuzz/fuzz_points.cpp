// libFuzzer target: bytes -> point files (mcp_points_analyze with {"csv": text}, a small
// spectrum) and, when they parse as a JSON array, {"points": value}; then the rule's estimate
// with them (mcp_points_integrate) on a 2-D problem.
// Contract checked (src/api/mcplay.h): every call returns a known status; on failure
// mcp_last_error() is a non-empty one-line message; on success the output is a JSON object.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

#include "api/mcplay.h"

namespace {

[[noreturn]] void violation(const char* what, const char* detail) {
    std::fprintf(stderr, "fuzz_points: contract violated: %s (%s)\n", what, detail ? detail : "");
    std::abort();
}

void check(const char* call, int status, char* out) {
    if (status < MCP_OK || status > MCP_ERROR_INTERNAL) violation("unknown status", call);
    if (status == MCP_ERROR_INTERNAL) violation("MCP_ERROR_INTERNAL", mcp_last_error());
    if (status == MCP_OK) {
        if (!out || out[0] != '{') violation("MCP_OK without a JSON object", call);
    } else {
        const char* e = mcp_last_error();
        if (!e || !*e) violation("failure without a message", call);
        if (std::strchr(e, '\n')) violation("error message spans lines", e);
    }
    mcp_free(out);
}

std::string dump(const nlohmann::json& j) {
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const nlohmann::json spectrum{{"size", 16}};
    char* out = nullptr;
    std::string request = dump({{"csv", text}, {"spectrum", spectrum}});
    check("mcp_points_analyze(csv)", mcp_points_analyze(request.c_str(), &out), out);

    const nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
    if (!value.is_discarded() && value.is_array()) {
        out = nullptr;
        request = dump({{"points", value}, {"spectrum", spectrum}});
        check("mcp_points_analyze(points)", mcp_points_analyze(request.c_str(), &out), out);
        out = nullptr;
        const char* scene = R"({"f": "x*y", "domain": {"type": "box", "dim": 2}})";
        request = dump({{"points", value}});
        check("mcp_points_integrate", mcp_points_integrate(scene, request.c_str(), &out), out);
    }
    return 0;
}
