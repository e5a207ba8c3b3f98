// mcplay._core: the Python extension over the C APIs (src/api/mcplay.h,
// src/render_api/mcplay_render.h), nothing else. JSON strings go in and out; the Python layer
// (python/mcplay) builds the requests and reads the results.
//
// Python callables become mcp_functions (function_bridge.h). The calls that may run long (studies,
// warp tests, renders) run on a worker thread while the calling thread waits with the GIL
// released, waking every 5 ms to let Python handle signals: Ctrl-C cancels the call within a
// block and is raised as KeyboardInterrupt once the worker has stopped.

#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "api/mcplay.h"
#include "python/function_bridge.h"
#include "python/python_errors.h"
#include "render_api/mcplay_render.h"

namespace nb = nanobind;
using mcp::python::CallState;
using mcp::python::raise_error;

namespace {

// Parameter types in the signatures Python sees (help(), stubs).
#define FUNCTIONS_T "dict[str, collections.abc.Callable[[numpy.ndarray], numpy.typing.ArrayLike]]"
#define PROGRESS_T "collections.abc.Callable[[str], object]"

using OptionalText = std::optional<std::string>;

/// The text a C call returned, copied and released.
std::string take_result(char* out) {
    std::string text = out ? out : "";
    mcp_free(out);
    return text;
}

/// A JSON argument as the C API takes it; a NUL character would cut the text short silently.
const char* c_text(const std::string& text, const char* what) {
    if (text.find('\0') != std::string::npos) {
        raise_error(MCP_ERROR_ARGUMENT, std::string(what) + ": contains a NUL character");
    }
    return text.c_str();
}

const char* c_text(const OptionalText& text, const char* what) {
    return text ? c_text(*text, what) : nullptr;
}

// --- call(): the JSON-in, JSON-out calls that take no callback ------------------------------

using CallFn = int (*)(const char* request, const char* options, char** out);

/// Arguments of a call: none (catalog), the request alone, or the request and options.
enum class Arity { none, request, request_and_options };

struct CallEntry {
    const char* name;
    Arity arity;
    CallFn run;
};

const CallEntry kCalls[] = {
    {"catalog", Arity::none, [](const char*, const char*, char** out) { return mcp_catalog(out); }},
    {"scene_info", Arity::request,
     [](const char* scene, const char*, char** out) { return mcp_scene_info(scene, out); }},
    {"points", Arity::request,
     [](const char* request, const char*, char** out) { return mcp_points(request, out); }},
    {"points_analyze", Arity::request,
     [](const char* request, const char*, char** out) { return mcp_points_analyze(request, out); }},
    {"discrepancy_curve", Arity::request,
     [](const char* request, const char*, char** out) {
         return mcp_discrepancy_curve(request, out);
     }},
    {"points_integrate", Arity::request_and_options,
     [](const char* scene, const char* request, char** out) {
         return mcp_points_integrate(scene, request, out);
     }},
    {"result_format", Arity::request_and_options,
     [](const char* result, const char* format, char** out) {
         return mcp_result_format(result, format, out);
     }},
    {"study_merge", Arity::request,
     [](const char* parts, const char*, char** out) { return mcp_study_merge(parts, out); }},
    {"study_samples", Arity::request_and_options,
     [](const char* scene, const char* options, char** out) {
         return mcp_study_samples(scene, options, out);
     }},
    {"render_study_merge", Arity::request,
     [](const char* parts, const char*, char** out) { return mcp_render_study_merge(parts, out); }},
    {"render_image", Arity::request_and_options,
     [](const char* scene, const char* options, char** out) {
         return mcp_render_image(scene, options, out);
     }},
    {"render_scene_info", Arity::request_and_options,
     [](const char* scene, const char* options, char** out) {
         return mcp_render_scene_info(scene, options, out);
     }},
    {"render_pixel_points", Arity::request,
     [](const char* request, const char*, char** out) {
         return mcp_render_pixel_points(request, out);
     }},
    {"render_study_plan", Arity::request_and_options,
     [](const char* scene, const char* options, char** out) {
         return mcp_render_study_plan(scene, options, out);
     }},
};

std::string call(const std::string& fn, const std::string& request, const OptionalText& options) {
    const CallEntry* entry = nullptr;
    for (const CallEntry& e : kCalls) {
        if (fn == e.name) entry = &e;
    }
    if (!entry) {
        std::string names;
        for (const CallEntry& e : kCalls) names += std::string(names.empty() ? "" : ", ") + e.name;
        raise_error(MCP_ERROR_ARGUMENT,
                    "call: unknown function '" + fn + "' (one of " + names + ")");
    }
    if (entry->arity == Arity::none && !request.empty()) {
        raise_error(MCP_ERROR_ARGUMENT, "call('" + fn + "'): takes no request (pass \"\")");
    }
    if (entry->arity != Arity::request_and_options && options) {
        raise_error(MCP_ERROR_ARGUMENT, "call('" + fn + "'): takes no options");
    }
    const char* request_c = c_text(request, "request");
    const char* options_c = c_text(options, "options");
    char* out = nullptr;
    int status = MCP_OK;
    std::string error;
    {
        nb::gil_scoped_release release;
        status = entry->run(request_c, options_c, &out);
        if (status != MCP_OK) error = mcp_last_error();
    }
    std::string text = take_result(out);
    if (status != MCP_OK) raise_error(status, error);
    return text;
}

// --- Calls on a worker thread, watched for signals ------------------------------------------

/// Runs c_call(&out) on a new thread while this one waits with the GIL released, checking for
/// signals every 5 ms (a signal handler's exception cancels the call through `state`; at 50 ms a
/// fast callable ran a thousand more batches after Ctrl-C), and returns the call's result text
/// or raises: the pending exception (Ctrl-C, a failing progress callable), a function's failure,
/// or the C API's error.
template <class CCall> std::string run_watched(CallState& state, CCall&& c_call) {
    struct Outcome {
        std::mutex mutex;
        std::condition_variable finished;
        bool done = false;
        int status = MCP_OK;
        std::string text;
        std::string error;
    } outcome;

    std::thread worker;
    try {
        worker = std::thread([&outcome, &c_call] {
            char* out = nullptr;
            int status = c_call(&out);
            std::string text, error;
            try {
                text = out ? out : "";
                if (status != MCP_OK) error = mcp_last_error();
            } catch (...) {
                status = MCP_ERROR_INTERNAL;
                error = "out of memory while copying the result";
            }
            mcp_free(out);
            {
                std::lock_guard<std::mutex> lock(outcome.mutex);
                outcome.status = status;
                outcome.text = std::move(text);
                outcome.error = std::move(error);
                outcome.done = true;
            }
            outcome.finished.notify_all();
        });
    } catch (const std::exception& e) {
        raise_error(MCP_ERROR_INTERNAL, std::string("could not start a thread: ") + e.what());
    }

    for (;;) {
        bool done = false;
        {
            nb::gil_scoped_release release;
            std::unique_lock<std::mutex> lock(outcome.mutex);
            done = outcome.finished.wait_for(lock, std::chrono::milliseconds(5),
                                             [&outcome] { return outcome.done; });
        }
        if (done) break;
        if (!state.has_pending() && PyErr_CheckSignals() != 0) state.set_pending_from_python();
    }
    {
        nb::gil_scoped_release release;
        worker.join();
    }
    state.raise_failure(outcome.status, outcome.error);
    return std::move(outcome.text);
}

std::string study_run(const std::string& scene, const OptionalText& options,
                      const nb::object& functions, const nb::object& progress) {
    CallState state(functions, progress);
    const char* scene_c = c_text(scene, "scene");
    const char* options_c = c_text(options, "options");
    return run_watched(state, [&](char** out) {
        return mcp_study_run_with(scene_c, options_c, state.context(),
                                  CallState::progress_trampoline, &state, out);
    });
}

/// A call with the caller's functions and no progress (mcp_study_plan_with,
/// mcp_warp_test_with), run watched like the studies.
using FunctionsCall = int (*)(const char*, const char*, const mcp_context*, char**);
std::string run_with_functions(FunctionsCall call, const std::string& scene,
                               const OptionalText& options, const nb::object& functions) {
    CallState state(functions, nb::none());
    const char* scene_c = c_text(scene, "scene");
    const char* options_c = c_text(options, "options");
    return run_watched(state,
                       [&](char** out) { return call(scene_c, options_c, state.context(), out); });
}

std::string study_plan(const std::string& scene, const OptionalText& options,
                       const nb::object& functions) {
    return run_with_functions(mcp_study_plan_with, scene, options, functions);
}

std::string warp_test(const std::string& scene, const OptionalText& options,
                      const nb::object& functions) {
    return run_with_functions(mcp_warp_test_with, scene, options, functions);
}

/// A render call with progress (mcp_render_study_run, mcp_render_reference,
/// mcp_render_live_open), run watched like the studies.
using ProgressCall = int (*)(const char*, const char*, mcp_progress_fn, void*, char**);
std::string run_with_progress(ProgressCall call, const std::string& scene,
                              const OptionalText& options, const nb::object& progress) {
    CallState state(nb::none(), progress);
    const char* scene_c = c_text(scene, "scene");
    const char* options_c = c_text(options, "options");
    return run_watched(state, [&](char** out) {
        return call(scene_c, options_c, CallState::progress_trampoline, &state, out);
    });
}

std::string render_study_run(const std::string& scene, const OptionalText& options,
                             const nb::object& progress) {
    return run_with_progress(mcp_render_study_run, scene, options, progress);
}

std::string render_reference(const std::string& scene, const OptionalText& options,
                             const nb::object& progress) {
    return run_with_progress(mcp_render_reference, scene, options, progress);
}

std::string render_live_open(const std::string& scene, const OptionalText& options,
                             const nb::object& progress) {
    return run_with_progress(mcp_render_live_open, scene, options, progress);
}

std::string render_live_pass(int session, const std::string& pass, const nb::object& progress) {
    CallState state(nb::none(), progress);
    const char* pass_c = c_text(pass, "pass");
    return run_watched(state, [&](char** out) {
        return mcp_render_live_pass(session, pass_c, CallState::progress_trampoline, &state, out);
    });
}

std::string render_live_reference(int session, const std::string& reference) {
    const char* reference_c = c_text(reference, "reference");
    char* out = nullptr;
    int status = MCP_OK;
    std::string error;
    {
        nb::gil_scoped_release release;
        status = mcp_render_live_reference(session, reference_c, &out);
        if (status != MCP_OK) error = mcp_last_error();
    }
    std::string text = take_result(out);
    if (status != MCP_OK) raise_error(status, error);
    return text;
}

void render_live_close(int session) {
    const int status = mcp_render_live_close(session);
    if (status != MCP_OK) raise_error(status, mcp_last_error());
}

} // namespace

NB_MODULE(_core, m) {
    m.doc() = "mcplay's C++ core: the C API's JSON calls, Python callables as integrands and "
              "warps. Use the package mcplay rather than this module.";
    mcp::python::register_error_type(m);

    m.def(
        "version", [] { return std::string(mcp_version()); }, "The core's version, e.g. '0.1.0'.");

    m.def("call", &call, nb::arg("fn"), nb::arg("request") = "", nb::arg("options") = nb::none(),
          "Runs one JSON-in, JSON-out C call that takes no callback, by name: 'catalog' (no "
          "request), 'scene_info', 'points', 'points_analyze', 'discrepancy_curve', "
          "'points_integrate' (request: the scene, options: the points request), "
          "'result_format' (request: a result, options: 'table', 'csv' or 'json'), "
          "'study_merge', 'study_samples' (scene, options), 'render_study_merge', "
          "'render_image' (scene, options), 'render_scene_info' (scene, options), "
          "'render_pixel_points', 'render_study_plan' (scene, options). The GIL is released "
          "while it runs. Raises McplayError with the C API's message.");

    m.def("study_run", &study_run,
          nb::sig("def study_run(scene: str, options: str | None = None, "
                  "functions: " FUNCTIONS_T " | None = None, "
                  "progress: " PROGRESS_T " | None = None) -> str"),
          nb::arg("scene"), nb::arg("options") = nb::none(), nb::arg("functions") = nb::none(),
          nb::arg("progress") = nb::none(),
          "A convergence study (mcp_study_run_with). functions maps the names the scene gives "
          "({'type': 'function', 'name': ...}) to callables f(x) -> values, x a read-only "
          "(n, in_dim) float64 array of one block of points (the callable may keep it), the "
          "values (n,) float64 (or (n, out_dim)). progress(level_json) is called after each N; "
          "an exception in it cancels the study and is raised. Ctrl-C cancels within a block "
          "(KeyboardInterrupt). A failing callable raises McplayError (status 'FUNCTION') "
          "naming the block and the point, from the callable's exception.");

    m.def("study_plan", &study_plan,
          nb::sig("def study_plan(scene: str, options: str | None = None, "
                  "functions: " FUNCTIONS_T " | None = None) -> str"),
          nb::arg("scene"), nb::arg("options") = nb::none(), nb::arg("functions") = nb::none(),
          "A study's cost predicted from a short pilot (mcp_study_plan_with); functions as "
          "study_run's.");

    m.def("warp_test", &warp_test,
          nb::sig("def warp_test(scene: str, options: str | None = None, "
                  "functions: " FUNCTIONS_T " | None = None) -> str"),
          nb::arg("scene"), nb::arg("options") = nb::none(), nb::arg("functions") = nb::none(),
          "Tests a warp against its density (mcp_warp_test_with); the warp's map g and density "
          "p may name callables in functions (g returns (n, dim) points, p (n,) densities).");

    m.def("render_study_run", &render_study_run,
          nb::sig("def render_study_run(scene: str, options: str | None = None, "
                  "progress: " PROGRESS_T " | None = None) -> str"),
          nb::arg("scene"), nb::arg("options") = nb::none(), nb::arg("progress") = nb::none(),
          "A render convergence study (mcp_render_study_run); progress and Ctrl-C as "
          "study_run's.");

    m.def("render_reference", &render_reference,
          nb::sig("def render_reference(scene: str, options: str | None = None, "
                  "progress: " PROGRESS_T " | None = None) -> str"),
          nb::arg("scene"), nb::arg("options") = nb::none(), nb::arg("progress") = nb::none(),
          "A render study's reference image (mcp_render_reference).");

    m.def("render_live_open", &render_live_open,
          nb::sig("def render_live_open(scene: str, options: str | None = None, "
                  "progress: " PROGRESS_T " | None = None) -> str"),
          nb::arg("scene"), nb::arg("options") = nb::none(), nb::arg("progress") = nb::none(),
          "Opens a live-view session (mcp_render_live_open); the result's 'session' is the "
          "id the other render_live_* calls take. Close it with render_live_close.");

    m.def("render_live_pass", &render_live_pass,
          nb::sig("def render_live_pass(session: int, pass_json: str, "
                  "progress: " PROGRESS_T " | None = None) -> str"),
          nb::arg("session"), nb::arg("pass_json"), nb::arg("progress") = nb::none(),
          "Takes one estimator of a live session to more samples per pixel "
          "(mcp_render_live_pass).");

    m.def("render_live_reference", &render_live_reference, nb::arg("session"),
          nb::arg("reference_json"),
          "Gives a live session its reference (mcp_render_live_reference).");

    m.def("render_live_close", &render_live_close, nb::arg("session"),
          "Frees a live-view session.");
}
