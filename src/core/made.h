// Made<T>: a value or an error message, for constructors that validate user input
// (the core is built without exceptions).
#pragma once

#include <string>

namespace mcp {

/// Result of a factory: either a value or an error naming the bad parameter and its value.
template <class T> struct Made {
    T value;
    std::string error; ///< empty on success
    bool ok() const { return error.empty(); }
};

template <class T> Made<T> made_error(std::string message) {
    return Made<T>{T{}, std::move(message)};
}

} // namespace mcp
