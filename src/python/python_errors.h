// McplayError, the module's one exception class (a ValueError), and raising it from C++.
#pragma once

#include <nanobind/nanobind.h>

#include <string>

namespace mcp::python {

/// "ARGUMENT", "SCENE", "CANCELLED", "INTERNAL", "FUNCTION" for the C API's status codes.
const char* status_name(int status);

/// Creates McplayError and adds it to the module (call once, from the module's init).
void register_error_type(nanobind::module_& m);

/// Raises McplayError(message) with .status and .status_name, and `cause` as its __cause__
/// when given. The GIL must be held.
[[noreturn]] void raise_error(int status, const std::string& message,
                              nanobind::handle cause = nanobind::handle());

} // namespace mcp::python
