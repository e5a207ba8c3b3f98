// The caller's functions of one library call (mcp_context in api/mcplay.h): each entry made into
// the core's CallerFunction (core/caller_function.h), all sharing the call's CallControl, found
// by the name a scene gives them. Internal to the C API.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "api/mcplay.h"
#include "core/caller_function.h"
#include "core/made.h"

namespace mcp {

/// Most functions one call may be given, and the longest name.
constexpr int kMaxCallerFunctions = 16;
constexpr size_t kMaxCallerFunctionName = 64;

struct CallerFunctions {
    std::vector<std::shared_ptr<const CallerFunction>> list;
    std::shared_ptr<CallControl> control; ///< the call's: its functions' failures, its cancel
    /// The function of that name, or null.
    std::shared_ptr<const CallerFunction> find(const std::string& name) const;
    /// "f, g" (or "none") for messages.
    std::string names() const;
};

/// The functions and cancel callback of a context (ctx may be null: none, and no cancel). An
/// error names the bad entry ("ctx.functions[1].name: ...").
Made<CallerFunctions> caller_functions(const mcp_context* ctx);

/// After a call that used them: MCP_ERROR_FUNCTION (a function failed; the message names it),
/// MCP_ERROR_CANCELLED (the caller cancelled), or MCP_OK. Sets the last error when not OK.
int caller_outcome(const CallerFunctions& functions);

} // namespace mcp
