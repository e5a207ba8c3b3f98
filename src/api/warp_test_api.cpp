// mcp_warp_test: a scene's "warp" parsed (api/parse_warp.cpp) and put to the chi-square test of
// estimators/warp_test.h; the result as JSON.
#include <cmath>
#include <string>

#include "api/boundary.h"
#include "api/caller_functions.h"
#include "api/json_read.h"
#include "api/mcplay.h"
#include "api/report.h"
#include "api/scene_parsers.h"
#include "estimators/warp_test.h"

using mcp::boundary::copy_out;
using mcp::boundary::dump;
using mcp::boundary::fail;

namespace mcp {
namespace {

Json finite_or_null(double v) {
    return std::isfinite(v) ? Json(v) : Json(nullptr);
}

/// The options of a warp test: {"samples", "seed", "significance", "tests", "bins", "worst"}.
bool parse_warp_test_options(Ctx& c, const Json& j, WarpTestOptions* out) {
    if (j.is_null()) return true;
    if (!j.is_object()) return c.fail("options", "expected an object, got " + type_of(j));
    if (!check_keys(c, j, "options", {"samples", "seed", "significance", "tests", "bins", "worst"}))
        return false;
    uint64_t tests = 1, worst = static_cast<uint64_t>(out->worst);
    if (!get_count(c, j, "samples", "options", &out->samples) ||
        !get_count(c, j, "seed", "options", &out->seed) ||
        !get_number(c, j, "significance", "options", &out->significance) ||
        !get_count(c, j, "tests", "options", &tests) ||
        !get_count(c, j, "worst", "options", &worst))
        return false;
    if (out->samples < 1 || out->samples > kMaxWarpTestSamples)
        return c.fail("options.samples", "expected 1 to " + std::to_string(kMaxWarpTestSamples) +
                                             ", got " + std::to_string(out->samples));
    if (!(out->significance > 0.0 && out->significance < 1.0))
        return c.fail("options.significance", "expected a number in (0, 1)");
    if (tests < 1 || tests > 1000000)
        return c.fail("options.tests", "expected 1 to 1000000, got " + std::to_string(tests));
    if (worst > 1000) return c.fail("options.worst", "expected 0 to 1000");
    out->tests = static_cast<int>(tests);
    out->worst = static_cast<int>(worst);
    if (const Json* b = find(j, "bins")) {
        std::vector<double> bins;
        if (!to_numbers(c, *b, "options.bins", &bins)) return false;
        if (bins.empty() || bins.size() > 3)
            return c.fail("options.bins", "expected 1 to 3 counts, one per natural coordinate");
        for (size_t k = 0; k < bins.size(); ++k) {
            if (bins[k] != std::floor(bins[k]) || bins[k] < 1 || bins[k] > kMaxWarpTestBinsPerAxis)
                return c.fail("options.bins", "each count must be a whole number from 1 to " +
                                                  std::to_string(kMaxWarpTestBinsPerAxis));
            out->bins[k] = static_cast<int>(bins[k]);
        }
    }
    return true;
}

Json warp_test_to_json(const WarpTestResult& r, const Warp& warp, const Domain& domain,
                       const WarpTestOptions& options) {
    Json bins = Json::array(), worst = Json::array();
    for (int k = 0; k < r.axes; ++k) bins.push_back(r.bins[k]);
    for (const WarpTestBin& b : r.worst) {
        Json index = Json::array(), range = Json::array();
        for (int k = 0; k < r.axes; ++k) {
            index.push_back(b.index[k]);
            range.push_back({b.lo[k], b.hi[k]});
        }
        worst.push_back({{"index", index},
                         {"range", range},
                         {"observed", b.observed},
                         {"expected", b.expected},
                         {"residual", finite_or_null(b.residual)}});
    }
    return Json{
        {"version", kResultSchemaVersion},
        {"warp", warp.name},
        {"domain", domain.describe()},
        {"domain_type", domain_kind_name(domain.kind)},
        {"samples", r.samples},
        {"seed", options.seed},
        {"coordinates", r.axis_names},
        {"bins", bins},
        {"observed", r.observed},
        {"expected", r.expected},
        {"expected_error", r.expected_error},
        {"pdf_integral", finite_or_null(r.pdf_integral)},
        {"pdf_integral_error", finite_or_null(r.pdf_integral_error)},
        {"pdf_integral_ok", r.pdf_integral_ok},
        {"pdf_evaluations", r.pdf_evaluations},
        {"statistic", finite_or_null(r.chi_square)},
        {"dof", r.dof},
        {"cells", r.cells},
        {"pooled_bins", r.pooled_bins},
        {"zero_bins_hit", r.zero_bins_hit},
        {"zero_pdf_samples", r.zero_pdf_samples},
        {"probed_bins", r.probed_bins},
        {"unresolved_bins", r.unresolved_bins},
        {"quadrature_chi_square", finite_or_null(r.quadrature_chi_square)},
        {"p_value", r.p_value},
        {"p_value_range", {r.p_value_low, r.p_value_high}},
        {"significance", options.significance},
        {"tests", options.tests},
        {"level", r.level},
        {"outcome", warp_test_outcome_name(r.outcome)},
        {"passed", r.outcome == WarpTestOutcome::Unverified ? Json(nullptr) : Json(r.passed)},
        {"verdict", r.reason},
        {"where", r.where.empty() ? Json(nullptr) : Json(r.where)},
        {"off_by_constant", r.off_by_constant},
        {"worst_bins", worst}};
}

} // namespace
} // namespace mcp

extern "C" int mcp_warp_test(const char* scene_json, const char* options_json, char** result_json) {
    return mcp_warp_test_with(scene_json, options_json, nullptr, result_json);
}

extern "C" int mcp_warp_test_with(const char* scene_json, const char* options_json,
                                  const mcp_context* ctx, char** result_json) {
    if (!result_json) return fail(MCP_ERROR_ARGUMENT, "mcp_warp_test: result_json is NULL");
    *result_json = nullptr;
    mcp::Made<mcp::CallerFunctions> functions = mcp::caller_functions(ctx);
    if (!functions.ok()) return fail(MCP_ERROR_ARGUMENT, functions.error);
    mcp::Made<mcp::Json> scene = mcp::parse_json(scene_json, "scene");
    if (!scene.ok()) return fail(MCP_ERROR_SCENE, scene.error);
    mcp::Ctx c;
    mcp::WarpTestOptions options;
    if (options_json && *options_json) {
        mcp::Made<mcp::Json> o = mcp::parse_json(options_json, "options");
        if (!o.ok()) return fail(MCP_ERROR_ARGUMENT, o.error);
        if (!mcp::parse_warp_test_options(c, o.value, &options))
            return fail(MCP_ERROR_ARGUMENT, c.error);
    }
    if (!scene.value.is_object()) return fail(MCP_ERROR_SCENE, "scene: expected an object");
    const mcp::Json* warp = mcp::find(scene.value, "warp");
    if (!warp)
        return fail(MCP_ERROR_SCENE, "scene: no \"warp\" to test (docs/scene-format.md, Warps)");
    mcp::NamedWarp w;
    c.functions = &functions.value;
    if (!mcp::parse_warp(c, *warp, "scene.warp", &w)) return fail(MCP_ERROR_SCENE, c.error);
    mcp::Made<mcp::WarpTestResult> r = mcp::run_warp_test(w.domain, w.warp, options);
    // A function that failed (or a cancel) stopped the test: its numbers are not the warp's.
    if (int st = mcp::caller_outcome(functions.value)) return st;
    if (!r.ok()) return fail(MCP_ERROR_SCENE, "scene.warp: " + r.error);
    *result_json = copy_out(dump(mcp::warp_test_to_json(r.value, w.warp, w.domain, options)));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    return mcp::boundary::succeed();
}
