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
        for (int k = 0; k < out_dim; ++k)
            std::fill(out + k * out_stride, out + k * out_stride + n, 0.0);
    };
    if (n == 0) return !control->stopped();
    if (control->stopped()) {
        zeros();
        return false;
    }
    // The block's columns are `capacity` apart: contiguous as the function wants them when the
    // block is full (a batch of kFunctionBatch) or has one column; else copied, per block, into
    // a buffer the thread reuses. The same for the values out.
    thread_local std::vector<double> columns_in, columns_out;
    const size_t d = static_cast<size_t>(x.dim), m = static_cast<size_t>(out_dim);
    const double* in = x.coord(0);
    if (x.capacity != n && d > 1) {
        if (columns_in.size() < n * d) columns_in.resize(n * d);
        for (size_t j = 0; j < d; ++j) {
            const double* xj = x.coord(static_cast<int>(j));
            std::copy(xj, xj + n, columns_in.begin() + static_cast<long>(j * n));
        }
        in = columns_in.data();
    }
    const bool direct_out = out_stride == n || m == 1;
    if (!direct_out && columns_out.size() < n * m) columns_out.resize(n * m);
    double* values = direct_out ? out : columns_out.data();
    std::fill(values, values + n * m, 0.0);
    if (fn(user, in, n, x.dim, values, out_dim) != 0) {
        control->fail(name);
        zeros();
        return false;
    }
    if (!direct_out)
        for (size_t k = 0; k < m; ++k)
            std::copy(columns_out.begin() + static_cast<long>(k * n),
                      columns_out.begin() + static_cast<long>((k + 1) * n), out + k * out_stride);
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
