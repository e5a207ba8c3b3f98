// Functions given by the library's caller (a Python callable, a JavaScript function), and the
// control of the call that uses them: the core calls such a function on a whole block of points
// at a time, row-major, from any of its threads; a failure, or the caller's cancel request,
// stops every later call within a block (the loops poll CallControl::stopped between blocks).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/points.h"

namespace mcp {

/// The state of one library call that may be stopped from outside: a caller's function failed,
/// or the caller asked to cancel (polled). Shared by the call's functions and loops.
class CallControl {
  public:
    using CancelFn = int (*)(void* user);
    CallControl(CancelFn cancel = nullptr, void* user = nullptr) : cancel_(cancel), user_(user) {}

    /// Whether the call must stop: a function failed, or the cancel callback says so (polled
    /// here, once per block; the answer sticks).
    bool stopped() const;
    /// A caller's function named `name` failed: every later stopped() is true.
    void fail(const std::string& name);
    bool failed() const { return failed_.load(std::memory_order_acquire); }
    bool cancelled() const { return cancelled_.load(std::memory_order_acquire); }
    /// The name of the first function that failed ("" if none).
    std::string failed_function() const;

  private:
    CancelFn cancel_;
    void* user_;
    mutable std::atomic<bool> failed_{false}, cancelled_{false};
    mutable std::mutex mutex_; // guards failed_name_ (written once, on the first failure)
    std::string failed_name_;
};

/// A caller's function: out[i * out_dim + k] for the n points x[i * in_dim + j] (row-major).
/// Returns 0, or non-zero when it failed (its owner keeps the reason).
struct CallerFunction {
    using Fn = int (*)(void* user, const double* x, uint64_t n, int in_dim, double* out,
                       int out_dim);
    std::string name;
    Fn fn = nullptr;
    void* user = nullptr;
    std::shared_ptr<CallControl> control; ///< never null once made by make_caller_function

    /// Evaluates the function on the block x (structure of arrays), writing out_dim values per
    /// point into `out` as structure of arrays too (out + k * out_stride + i); out_stride >= x.n.
    /// Once the call is stopped (this or another function failed, or it was cancelled) the
    /// function is not called and `out` is filled with zeros. Returns false when stopped.
    bool evaluate(const PointBlock& x, int out_dim, double* out, size_t out_stride) const;
};

std::shared_ptr<const CallerFunction> make_caller_function(std::string name, CallerFunction::Fn fn,
                                                           void* user,
                                                           std::shared_ptr<CallControl> control);

/// Whether a call's control says stop (false without a control).
inline bool call_stopped(const std::shared_ptr<CallControl>& control) {
    return control && control->stopped();
}

} // namespace mcp
