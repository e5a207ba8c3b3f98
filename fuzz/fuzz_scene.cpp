// libFuzzer target: scene JSON text -> mcp_warp_test (a scene's warp, small), mcp_scene_info, then
// a tiny study (mcp_study_run) and the sample points (mcp_study_samples) of every scene the parser
// accepts.
// Contract checked (src/api/mcplay.h): every call returns a known status; on failure
// mcp_last_error() is a non-empty one-line message; on success the output string is non-null
// JSON. Crashes, aborts, UB and leaks are found by the sanitizers; hangs by -timeout.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "api/mcplay.h"

namespace {

[[noreturn]] void violation(const char* what, const char* detail) {
    std::fprintf(stderr, "fuzz_scene: contract violated: %s (%s)\n", what, detail ? detail : "");
    std::abort();
}

// Failure: a non-empty message of one line. Success: a non-empty output string.
void check(const char* call, int status, char* out, bool partial_ok) {
    if (status < MCP_OK || status > MCP_ERROR_INTERNAL) violation("unknown status", call);
    if (status == MCP_ERROR_INTERNAL)
        violation("MCP_ERROR_INTERNAL (a bug by the API's own word)", mcp_last_error());
    if (status == MCP_OK || (partial_ok && status == MCP_ERROR_CANCELLED)) {
        if (!out || !*out) violation("MCP_OK without output", call);
        if (out[0] != '{') violation("output is not a JSON object", call);
    } else {
        const char* e = mcp_last_error();
        if (!e || !*e) violation("failure without a message", call);
        if (std::strchr(e, '\n')) violation("error message spans lines", e);
    }
    mcp_free(out);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size); // NUL-terminated copy
    // A scene with a warp: its chi-square test, small (it checks the warp's g and p first).
    char* tested = nullptr;
    const int tested_status =
        mcp_warp_test(text.c_str(), R"({"samples":2000,"bins":[4,4]})", &tested);
    check("mcp_warp_test", tested_status, tested, false);

    char* info = nullptr;
    int status = mcp_scene_info(text.c_str(), &info);
    check("mcp_scene_info", status, info, false);
    if (status != MCP_OK) return 0;

    // A tiny study: the options override the scene's own N, reps and threads.
    char* result = nullptr;
    status = mcp_study_run(text.c_str(), R"({"n_min":16,"n_max":64,"reps":2,"threads":1})", nullptr,
                           nullptr, &result);
    check("mcp_study_run", status, result, true);
    // A study the scene accepted must not fail for the scene's sake with these options.
    if (status == MCP_ERROR_SCENE) {
        // Allowed (e.g. n_min larger than the scene's own n_max) but worth seeing once.
    }

    char* samples = nullptr;
    status = mcp_study_samples(text.c_str(), R"({"n":64,"grid":32})", &samples);
    check("mcp_study_samples", status, samples, false);
    return 0;
}
