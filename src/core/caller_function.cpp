// Caller functions and the control of the call that uses them (core/caller_function.h).
#include "core/caller_function.h"

#include <algorithm>

namespace mcp {

bool CallControl::stopped() const {
    if (failed_.load(std::memory_order_acquire) || cancelled_.load(std::memory_order_acquire))
        return true;
    if (cancel_ && cancel_(user_) != 0) {
        cancelled_.store(true, std::memory_order_release);
        return true;
    }
    return false;
}

void CallControl::fail(const std::string& name) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failed_name_.empty()) failed_name_ = name;
    failed_.store(true, std::memory_order_release);
}

std::string CallControl::failed_function() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return failed_name_;
}

bool CallerFunction::evaluate(const PointBlock& x, int out_dim, double* out,
                              size_t out_stride) const {
    const size_t n = x.n;
    auto zeros = [&] {
        for (int k = 0; k < out_dim; ++k) std::fill(out + k * out_stride, out + k * out_stride + n, 0.0);
    };
    if (n == 0) return !control->stopped();
    if (control->stopped()) {
        zeros();
        return false;
    }
    // Row-major copies of the block in and out: per block, reused by the thread.
    thread_local std::vector<double> rows_in, rows_out;
    const size_t d = static_cast<size_t>(x.dim), m = static_cast<size_t>(out_dim);
    if (rows_in.size() < n * d) rows_in.resize(n * d);
    if (rows_out.size() < n * m) rows_out.resize(n * m);
    for (size_t j = 0; j < d; ++j) {
        const double* xj = x.coord(static_cast<int>(j));
        for (size_t i = 0; i < n; ++i) rows_in[i * d + j] = xj[i];
    }
    std::fill(rows_out.begin(), rows_out.begin() + static_cast<long>(n * m), 0.0);
    if (fn(user, rows_in.data(), n, x.dim, rows_out.data(), out_dim) != 0) {
        control->fail(name);
        zeros();
        return false;
    }
    for (size_t k = 0; k < m; ++k)
        for (size_t i = 0; i < n; ++i) out[k * out_stride + i] = rows_out[i * m + k];
    return true;
}

std::shared_ptr<const CallerFunction> make_caller_function(std::string name, CallerFunction::Fn fn,
                                                           void* user,
                                                           std::shared_ptr<CallControl> control) {
    auto f = std::make_shared<CallerFunction>();
    f->name = std::move(name);
    f->fn = fn;
    f->user = user;
    f->control = control ? std::move(control) : std::make_shared<CallControl>();
    return f;
}

} // namespace mcp
