#include "python/python_errors.h"

#include "api/mcplay.h"

namespace nb = nanobind;

namespace mcp::python {

namespace {
// The class object, owned by the module (which keeps it as an attribute for its lifetime).
PyObject* g_error_type = nullptr;
} // namespace

const char* status_name(int status) {
    switch (status) {
    case MCP_OK: return "OK";
    case MCP_ERROR_ARGUMENT: return "ARGUMENT";
    case MCP_ERROR_SCENE: return "SCENE";
    case MCP_ERROR_CANCELLED: return "CANCELLED";
    case MCP_ERROR_INTERNAL: return "INTERNAL";
    case MCP_ERROR_FUNCTION: return "FUNCTION";
    default: return "UNKNOWN";
    }
}

void register_error_type(nb::module_& m) {
    nb::dict defaults;
    // Class defaults, for an McplayError raised by the Python layer without a status.
    defaults["status"] = int(MCP_ERROR_ARGUMENT);
    defaults["status_name"] = status_name(MCP_ERROR_ARGUMENT);
    g_error_type = PyErr_NewExceptionWithDoc(
        "mcplay._core.McplayError",
        "An error of mcplay's core: its one-line message names what is wrong. .status is the C "
        "API's status code (int) and .status_name its name: 'ARGUMENT' (a malformed argument), "
        "'SCENE' (the scene is malformed or names something invalid), 'CANCELLED', 'INTERNAL' "
        "(a bug: please report it), 'FUNCTION' (a Python callable failed: the exception it "
        "raised is the __cause__).",
        PyExc_ValueError, defaults.ptr());
    if (!g_error_type) nb::raise_python_error();
    m.attr("McplayError") = nb::handle(g_error_type);
    nb::dict names;
    for (int status : {MCP_ERROR_ARGUMENT, MCP_ERROR_SCENE, MCP_ERROR_CANCELLED, MCP_ERROR_INTERNAL,
                       MCP_ERROR_FUNCTION}) {
        names[nb::int_(status)] = status_name(status);
    }
    m.attr("STATUS_NAMES") = names;
}

void raise_error(int status, const std::string& message, nb::handle cause) {
    // The message may quote user text that is not valid UTF-8: replaced, never an error.
    nb::object text =
        nb::steal(PyUnicode_DecodeUTF8(message.data(), Py_ssize_t(message.size()), "replace"));
    if (!text.is_valid()) nb::raise_python_error();
    nb::object error = nb::handle(g_error_type)(text);
    error.attr("status") = status;
    error.attr("status_name") = status_name(status);
    if (cause.is_valid() && !cause.is_none()) {
        PyException_SetCause(error.ptr(), cause.inc_ref().ptr()); // steals the reference
    }
    PyErr_SetObject(g_error_type, error.ptr());
    throw nb::python_error();
}

} // namespace mcp::python
