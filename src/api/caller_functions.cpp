// The caller's functions of one library call (api/caller_functions.h).
#include "api/caller_functions.h"

#include <cstring>

#include "api/boundary.h"

namespace mcp {

std::shared_ptr<const CallerFunction> CallerFunctions::find(const std::string& name) const {
    for (const auto& f : list)
        if (f->name == name) return f;
    return nullptr;
}

std::string CallerFunctions::names() const {
    std::string out;
    for (const auto& f : list) out += (out.empty() ? "" : ", ") + f->name;
    return out.empty() ? "none" : out;
}

Made<CallerFunctions> caller_functions(const mcp_context* ctx) {
    CallerFunctions out;
    if (!ctx) return {out, {}};
    if (ctx->function_count < 0 || ctx->function_count > kMaxCallerFunctions)
        return made_error<CallerFunctions>("ctx.function_count: expected 0 to " +
                                           std::to_string(kMaxCallerFunctions) + ", got " +
                                           std::to_string(ctx->function_count));
    if (ctx->function_count > 0 && !ctx->functions)
        return made_error<CallerFunctions>("ctx.functions: NULL with function_count " +
                                           std::to_string(ctx->function_count));
    out.control = std::make_shared<CallControl>(ctx->cancel, ctx->cancel_user);
    for (int i = 0; i < ctx->function_count; ++i) {
        const mcp_function& f = ctx->functions[i];
        const std::string path = "ctx.functions[" + std::to_string(i) + "]";
        if (!f.name) return made_error<CallerFunctions>(path + ".name: NULL");
        const std::string name(f.name, strnlen(f.name, kMaxCallerFunctionName + 1));
        if (name.empty() || name.size() > kMaxCallerFunctionName)
            return made_error<CallerFunctions>(path + ".name: expected 1 to " +
                                               std::to_string(kMaxCallerFunctionName) +
                                               " characters");
        if (!f.fn) return made_error<CallerFunctions>(path + ".fn: NULL");
        if (out.find(name))
            return made_error<CallerFunctions>(path + ".name: '" + boundary::one_line(name) +
                                               "' is given twice");
        out.list.push_back(make_caller_function(name, f.fn, f.user, out.control));
    }
    return {out, {}};
}

int caller_outcome(const CallerFunctions& functions) {
    if (!functions.control) return MCP_OK;
    if (functions.control->failed())
        return boundary::fail(MCP_ERROR_FUNCTION,
                              "the function '" +
                                  boundary::one_line(functions.control->failed_function()) +
                                  "' failed (its caller holds the reason); the call stopped");
    if (functions.control->cancelled())
        return boundary::fail(MCP_ERROR_CANCELLED, "cancelled by the caller");
    return MCP_OK;
}

} // namespace mcp
