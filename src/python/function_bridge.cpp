#include "python/function_bridge.h"

#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <charconv>
#include <cmath>
#include <cstring>

#include "api/boundary.h"
#include "python/python_errors.h"

namespace nb = nanobind;

namespace mcp::python {

namespace {

/// At most this many arrays per function are kept for reuse (one per thread in use is enough).
constexpr size_t kSpareInputs = 8;
/// Coordinates of a point quoted in a message, and characters of a quoted exception message.
constexpr int kQuotedCoordinates = 8;
constexpr size_t kQuotedMessage = 300;

std::string number_text(double value) {
    char buffer[32];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
    return ec == std::errc() ? std::string(buffer, end) : std::string("?");
}

/// "[0.1, 0.5]": the coordinates of point i of a column-major block x of n points (x[j * n + i]),
/// the first kQuotedCoordinates of them.
std::string point_text(const double* x, uint64_t n, uint64_t i, int dim) {
    std::string text = "[";
    for (int j = 0; j < dim && j < kQuotedCoordinates; ++j) {
        text += (j ? ", " : "") + number_text(x[static_cast<uint64_t>(j) * n + i]);
    }
    if (dim > kQuotedCoordinates) text += ", ... (" + std::to_string(dim) + " coordinates)";
    return text + "]";
}

/// "(256,)", "(256, 3)", "()".
std::string shape_text(const std::vector<size_t>& shape) {
    std::string text = "(";
    for (size_t i = 0; i < shape.size(); ++i) {
        text += (i ? ", " : "") + std::to_string(shape[i]);
    }
    return text + (shape.size() == 1 ? ",)" : ")");
}

/// str(object).
std::string text_of(nb::handle object) {
    nb::object text = nb::steal(PyObject_Str(object.ptr()));
    if (!text.is_valid()) nb::raise_python_error();
    return nb::cast<std::string>(text);
}

std::string python_type_name(nb::handle object) {
    return Py_TYPE(object.ptr())->tp_name;
}

/// "ZeroDivisionError: division by zero", kept short.
std::string exception_text(nb::handle exception) {
    std::string text = python_type_name(exception);
    std::string message;
    try {
        message = text_of(exception);
    } catch (const nb::python_error&) {
        message = "(its message could not be read)";
    }
    if (message.size() > kQuotedMessage) message = message.substr(0, kQuotedMessage) + "...";
    return message.empty() ? text : text + ": " + message;
}

/// Keeps a Python thread state for a core thread from its first callable call to its exit, so
/// that each block takes the GIL without creating and destroying a thread state (which costs
/// as much as a small numpy call).
struct ThreadStateKeeper {
    bool active = false;
    PyGILState_STATE outer{};
    PyThreadState* saved = nullptr;

    void keep() {
        if (active) return;
        outer = PyGILState_Ensure();
        saved = PyEval_SaveThread();
        active = true;
    }
    ~ThreadStateKeeper() {
        if (!active) return;
        PyEval_RestoreThread(saved);
        PyGILState_Release(outer);
    }
};
thread_local ThreadStateKeeper t_thread_state;

} // namespace

CallState::CallState(const nb::object& functions, const nb::object& progress) {
    if (!progress.is_none()) {
        if (!PyCallable_Check(progress.ptr())) {
            raise_error(MCP_ERROR_ARGUMENT,
                        "progress: expected a callable or None, got " + python_type_name(progress));
        }
        progress_ = progress;
        has_progress_ = true;
    }
    if (!functions.is_none()) {
        if (!nb::isinstance<nb::dict>(functions)) {
            raise_error(MCP_ERROR_ARGUMENT, "functions: expected a dict {name: callable}, got " +
                                                python_type_name(functions));
        }
        for (auto [key, value] : nb::borrow<nb::dict>(functions)) {
            if (!nb::isinstance<nb::str>(key)) {
                raise_error(MCP_ERROR_ARGUMENT,
                            "functions: a name must be a str, got " + python_type_name(key));
            }
            std::string name = nb::cast<std::string>(key);
            if (name.find('\0') != std::string::npos) {
                raise_error(MCP_ERROR_ARGUMENT, "functions: a name contains a NUL character");
            }
            if (!PyCallable_Check(value.ptr())) {
                raise_error(MCP_ERROR_ARGUMENT, "functions['" + name +
                                                    "']: expected a callable, got " +
                                                    python_type_name(value));
            }
            Slot& slot = slots_.emplace_back();
            slot.name = std::move(name);
            slot.callable = nb::borrow(value);
            slot.state = this;
        }
        if (!slots_.empty()) numpy_ = nb::module_::import_("numpy");
    }
    for (Slot& slot : slots_) {
        functions_.push_back(mcp_function{slot.name.c_str(), &function_trampoline, &slot});
    }
    context_.functions = functions_.empty() ? nullptr : functions_.data();
    context_.function_count = static_cast<int>(functions_.size());
    context_.cancel = &cancel_trampoline;
    context_.cancel_user = this;
}

int CallState::cancel_trampoline(void* user) noexcept {
    return static_cast<CallState*>(user)->cancel_.load() ? 1 : 0;
}

int CallState::progress_trampoline(const char* level_json, void* user) noexcept {
    CallState& state = *static_cast<CallState*>(user);
    if (state.cancel_.load()) return 1;
    if (!state.has_progress_) return 0;
    t_thread_state.keep();
    nb::gil_scoped_acquire gil;
    if (state.cancel_.load()) return 1;
    try {
        state.progress_(nb::str(level_json));
    } catch (nb::python_error& e) {
        if (!state.pending_) state.pending_.emplace(std::move(e));
        state.cancel_ = true;
    } catch (...) {
        // A C++ exception out of nanobind's call machinery: stop, and say so.
        PyErr_SetString(PyExc_RuntimeError, "mcplay: the progress callable could not be called");
        if (!state.pending_) state.pending_.emplace();
        state.cancel_ = true;
    }
    return state.cancel_.load() ? 1 : 0;
}

void CallState::set_pending_from_python() {
    if (!pending_) pending_.emplace();
    cancel_ = true;
}

void CallState::raise_failure(int status, const std::string& c_error) {
    if (pending_) {
        nb::python_error pending = std::move(*pending_);
        pending_.reset();
        throw pending;
    }
    if (failed_.load()) {
        raise_error(MCP_ERROR_FUNCTION, failure_message_.empty() ? c_error : failure_message_,
                    failure_cause_);
    }
    if (status != MCP_OK) raise_error(status, c_error);
}

int CallState::function_trampoline(void* user, const double* x, uint64_t n, int in_dim, double* out,
                                   int out_dim) noexcept {
    Slot& slot = *static_cast<Slot*>(user);
    CallState& state = *slot.state;
    if (state.stopping()) return 1;
    t_thread_state.keep();
    nb::gil_scoped_acquire gil;
    if (state.stopping()) return 1;
    const uint64_t block = slot.blocks.fetch_add(1) + 1;
    const uint64_t first = slot.points.fetch_add(n);
    std::string failure;
    nb::object cause;
    try {
        failure = state.evaluate(slot, x, n, in_dim, out, out_dim, cause);
    } catch (nb::python_error& e) {
        // Our own calls into numpy, not the callable's.
        failure = "could not be called: " + exception_text(e.value());
        cause = nb::borrow(e.value());
    } catch (const std::exception& e) {
        failure = std::string("could not be called: ") + e.what();
    } catch (...) {
        failure = "could not be called: an unknown C++ exception";
    }
    if (failure.empty()) return 0;
    try {
        state.record_failure(slot, block, first, n, failure, cause);
    } catch (...) {
        state.failed_ = true; // out of memory for the message: the C error stands in
    }
    return 1;
}

void CallState::record_failure(const Slot& slot, uint64_t block, uint64_t first, uint64_t n,
                               const std::string& what, nb::handle cause) {
    if (failed_.exchange(true)) return; // the first failure is the one reported
    std::string points =
        n == 0 ? "no points"
               : "points " + std::to_string(first) + ".." + std::to_string(first + n - 1);
    failure_message_ =
        mcp::boundary::one_line("function '" + slot.name + "' on block " + std::to_string(block) +
                                " (" + points + "): " + what);
    failure_cause_ = nb::borrow(cause);
}

CallState::InputArray CallState::take_input(Slot& slot, uint64_t n, int dim) {
    for (size_t i = slot.spare_inputs.size(); i-- > 0;) {
        if (slot.spare_inputs[i].n == n && slot.spare_inputs[i].dim == dim) {
            InputArray input = std::move(slot.spare_inputs[i]);
            slot.spare_inputs.erase(slot.spare_inputs.begin() + static_cast<long>(i));
            return input;
        }
    }
    InputArray input;
    // Column-major, as the core gives the points: one contiguous array per coordinate.
    input.array = numpy_.attr("empty")(nb::make_tuple(n, dim), nb::arg("order") = "F");
    input.data = nb::cast<nb::ndarray<double, nb::f_contig, nb::device::cpu>>(input.array).data();
    input.array.attr("flags").attr("writeable") = false;
    input.n = n;
    input.dim = dim;
    return input;
}

void CallState::give_back(Slot& slot, InputArray&& input) {
    // Reused only when nothing else holds it (no view, no saved reference, no traceback):
    // an array the callable kept keeps its block's points.
    if (Py_REFCNT(input.array.ptr()) == 1 && slot.spare_inputs.size() < kSpareInputs) {
        slot.spare_inputs.push_back(std::move(input));
    }
}

std::string CallState::evaluate(Slot& slot, const double* x, uint64_t n, int in_dim, double* out,
                                int out_dim, nb::object& cause) {
    // The points are copied into an array numpy owns (a few microseconds per block at most):
    // a view of the core's buffer would dangle if the callable kept it.
    InputArray input = take_input(slot, n, in_dim);
    if (n > 0) std::memcpy(input.data, x, n * static_cast<size_t>(in_dim) * sizeof(double));
    nb::object returned;
    try {
        returned = slot.callable(input.array);
    } catch (nb::python_error& e) {
        if (!e.matches(PyExc_Exception)) {
            // KeyboardInterrupt, SystemExit: not the function's failure; raised as they are.
            if (!pending_) pending_.emplace(std::move(e));
            cancel_ = true;
            return "was interrupted";
        }
        cause = nb::borrow(e.value());
        std::string where = n == 0 ? "on an empty block"
                                   : "at the block's first point " + point_text(x, n, 0, in_dim);
        return "raised " + exception_text(e.value()) + " " + where;
    }
    give_back(slot, std::move(input));
    return store_values(returned, x, n, in_dim, out, out_dim);
}

std::string CallState::store_values(nb::handle returned, const double* x, uint64_t n, int in_dim,
                                    double* out, int out_dim) {
    // Column-major like the points: out[k * n + i] is value k of point i.
    using Values = nb::ndarray<const double, nb::f_contig, nb::device::cpu>;
    const std::vector<size_t> expected =
        out_dim == 1 ? std::vector<size_t>{n} : std::vector<size_t>{n, size_t(out_dim)};
    const std::string expected_text =
        out_dim == 1 ? shape_text(expected) + " (or " + shape_text({n, 1}) + ")"
                     : shape_text(expected);

    Values values;
    if (!nb::try_cast(returned, values, false)) {
        // Not a column-major float64 array: what numpy makes of it.
        nb::object array;
        try {
            array = numpy_.attr("asarray")(returned);
        } catch (nb::python_error& e) {
            return "returned a " + python_type_name(returned) +
                   " that numpy cannot make an array of (" + exception_text(e.value()) + ")";
        }
        const std::string kind = nb::cast<std::string>(array.attr("dtype").attr("kind"));
        if (kind != "b" && kind != "i" && kind != "u" && kind != "f") {
            const nb::object dtype_object = array.attr("dtype");
            const std::string dtype = text_of(dtype_object);
            const std::string what =
                returned.is_none() ? std::string("None")
                : PyObject_IsInstance(returned.ptr(), numpy_.attr("ndarray").ptr()) == 1
                    ? std::string("an array")
                    : "a " + python_type_name(returned);
            return "returned " + what + (returned.is_none() ? "" : " of dtype " + dtype) +
                   ", expected real (float64) values of shape " + expected_text;
        }
        array = numpy_.attr("asarray")(array, nb::arg("dtype") = "float64", nb::arg("order") = "F");
        if (!nb::try_cast(array, values, false)) {
            return "returned values that could not be read as float64";
        }
    }

    std::vector<size_t> shape(values.ndim());
    for (size_t i = 0; i < values.ndim(); ++i) shape[i] = values.shape(i);
    const bool fits = shape == expected || (out_dim == 1 && shape == std::vector<size_t>{n, 1});
    if (!fits) {
        const std::string what =
            shape.empty() ? "a scalar (shape ())" : "shape " + shape_text(shape);
        return "returned " + what + ", expected " + expected_text;
    }

    const double* v = values.data();
    const size_t count = static_cast<size_t>(n) * static_cast<size_t>(out_dim);
    bool finite = true;
    for (size_t i = 0; i < count; ++i) finite &= std::isfinite(v[i]);
    if (!finite) {
        // The first point (not the first column) with a value that is not finite.
        for (uint64_t point = 0; point < n; ++point) {
            for (int k = 0; k < out_dim; ++k) {
                const double value = v[static_cast<uint64_t>(k) * n + point];
                if (std::isfinite(value)) continue;
                return "returned " + number_text(value) + " at point " + std::to_string(point) +
                       " of the block, x = " + point_text(x, n, point, in_dim);
            }
        }
    }
    if (count > 0) std::memcpy(out, v, count * sizeof(double));
    return "";
}

} // namespace mcp::python
