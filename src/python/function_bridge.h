// Python callables as the C API's caller functions (mcp_function, mcp_context in mcplay.h), and
// the state one watched C call shares between the calling thread and the core's threads: the
// cancel flag (Ctrl-C, a failing progress callable), the first failure of a callable, the
// exception to raise when the call is over.
//
// Threads and the GIL: the core calls the trampolines from its worker threads without the GIL;
// each takes the GIL for the duration of one Python call (one block of points), so callables run
// one at a time while the core's own work (sampling, warping, accumulating) runs in parallel.
#pragma once

#include <nanobind/nanobind.h>

#include <atomic>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "api/mcplay.h"

namespace mcp::python {

class CallState {
  public:
    /// functions: None or a dict {name: callable}; progress: None or a callable taking the
    /// level's JSON. Raises McplayError (ARGUMENT) naming a bad entry. The GIL must be held.
    CallState(const nanobind::object& functions, const nanobind::object& progress);
    CallState(const CallState&) = delete;
    CallState& operator=(const CallState&) = delete;

    /// The context to pass to the C call (functions and the cancel callback).
    const mcp_context* context() const { return &context_; }

    /// mcp_progress_fn: calls the progress callable (if any) under the GIL; returns non-zero
    /// once the call is to be cancelled. user is the CallState.
    static int progress_trampoline(const char* level_json, void* user) noexcept;

    /// Whether an exception waits to be raised when the call is over (GIL held).
    bool has_pending() const { return pending_.has_value(); }

    /// Takes the current Python error (a signal handler's) as the one to raise, and cancels the
    /// call. The GIL must be held.
    void set_pending_from_python();

    /// After the C call (GIL held): raises the pending exception, then a callable's failure
    /// (McplayError FUNCTION from its exception), then the C error (McplayError with status);
    /// returns when the call succeeded.
    void raise_failure(int status, const std::string& c_error);

  private:
    /// A block of input points as a read-only (n, dim) float64 array in column-major order (as
    /// the core gives them), which the callable may keep.
    struct InputArray {
        nanobind::object array;
        double* data = nullptr;
        uint64_t n = 0;
        int dim = 0;
    };

    struct Slot {
        std::string name;
        nanobind::object callable;
        CallState* state = nullptr;
        std::atomic<uint64_t> blocks{0};
        std::atomic<uint64_t> points{0};
        std::vector<InputArray> spare_inputs; // arrays no one else holds, reused (GIL held)
    };

    static int function_trampoline(void* user, const double* x, uint64_t n, int in_dim, double* out,
                                   int out_dim) noexcept;
    static int cancel_trampoline(void* user) noexcept;

    bool stopping() const { return cancel_.load() || failed_.load(); }

    /// Calls the slot's callable on one block and writes its values; returns "" or what went
    /// wrong (cause: the Python exception behind it, if any).
    std::string evaluate(Slot& slot, const double* x, uint64_t n, int in_dim, double* out,
                         int out_dim, nanobind::object& cause);
    /// Checks what a callable returned (dtype, shape, finite values) and copies it to out.
    std::string store_values(nanobind::handle returned, const double* x, uint64_t n, int in_dim,
                             double* out, int out_dim);
    InputArray take_input(Slot& slot, uint64_t n, int dim);
    static void give_back(Slot& slot, InputArray&& input);
    void record_failure(const Slot& slot, uint64_t block, uint64_t first, uint64_t n,
                        const std::string& what, nanobind::handle cause);

    nanobind::object numpy_;
    std::deque<Slot> slots_; // stable addresses: each is an mcp_function's user pointer
    std::vector<mcp_function> functions_;
    mcp_context context_{};
    nanobind::object progress_;
    bool has_progress_ = false;

    std::atomic<bool> cancel_{false}; // a signal or the progress callable stops the call
    std::atomic<bool> failed_{false}; // a callable failed: no further calls
    // Written under the GIL:
    std::optional<nanobind::python_error> pending_;
    std::string failure_message_;
    nanobind::object failure_cause_;
};

} // namespace mcp::python
