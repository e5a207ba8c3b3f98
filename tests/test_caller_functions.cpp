// Functions given by the library's caller (mcp_context, api/mcplay.h): a scene names them, the
// core calls them a block at a time, column-major, and stops within a block when one fails or the
// caller cancels.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "api/mcplay.h"

using nlohmann::json;

namespace {

struct Outcome {
    int status = -1;
    std::string error;
    json result;
};

Outcome run_with(const json& scene, const json& options, const mcp_context* ctx,
                 mcp_progress_fn progress = nullptr, void* user = nullptr) {
    char* out = nullptr;
    Outcome o;
    const std::string s = scene.dump(), opt = options.dump();
    o.status = mcp_study_run_with(s.c_str(), opt.c_str(), ctx, progress, user, &out);
    o.error = mcp_last_error();
    if (out) {
        o.result = json::parse(out);
        mcp_free(out);
    }
    return o;
}

/// What a test function records of its calls.
struct Calls {
    std::atomic<uint64_t> calls{0}, points{0}, smallest{UINT64_MAX}, largest{0};
    std::atomic<uint64_t> fail_at{0}; ///< fail on this call (1-based); 0: never
    std::atomic<int> bad_layout{0};   ///< a point outside the unit cube or a wrong dimension
    int expect_dim = 0;
};

/// f(x) = x1 * x2 + x1 (column-major x), the same doubles as the expression "x1 * x2 + x1".
int product_plus_first(void* user, const double* x, uint64_t n, int in_dim, double* out,
                       int out_dim) {
    Calls* c = static_cast<Calls*>(user);
    const uint64_t call = ++c->calls;
    c->points += n;
    for (uint64_t s = c->smallest; n < s && !c->smallest.compare_exchange_weak(s, n);) {
    }
    for (uint64_t l = c->largest; n > l && !c->largest.compare_exchange_weak(l, n);) {
    }
    if (in_dim != c->expect_dim || out_dim != 1 || n == 0 || n > 4096) ++c->bad_layout;
    if (c->fail_at != 0 && call >= c->fail_at) return 1;
    for (uint64_t i = 0; i < n; ++i) {
        for (int j = 0; j < in_dim; ++j)
            if (!(x[uint64_t(j) * n + i] >= 0.0 && x[uint64_t(j) * n + i] < 1.0)) ++c->bad_layout;
        out[i] = x[i] * x[n + i] + x[i];
    }
    return 0;
}

/// f(x) = x2 on the box [0, 1] x [10, 11] x [100, 101], checking that each of the block's
/// columns holds one axis's coordinates (column-major, as mcplay.h says).
int second_coordinate(void* user, const double* x, uint64_t n, int in_dim, double* out, int) {
    Calls* c = static_cast<Calls*>(user);
    c->calls++;
    const double lower[] = {0.0, 10.0, 100.0};
    for (uint64_t i = 0; i < n; ++i) {
        for (int j = 0; j < in_dim && j < 3; ++j) {
            const double v = x[uint64_t(j) * n + i];
            if (!(v >= lower[j] && v <= lower[j] + 1.0)) ++c->bad_layout;
        }
        out[i] = x[n + i];
    }
    return 0;
}

json box_scene(const json& integrand, int dim) {
    return json{{"name", "caller"},
                {"integrand", integrand},
                {"domain",
                 {{"type", "box"},
                  {"lower", std::vector<double>(size_t(dim), 0.0)},
                  {"upper", std::vector<double>(size_t(dim), 1.0)}}}};
}

mcp_context context_of(const mcp_function* fns, int count, mcp_cancel_fn cancel = nullptr,
                       void* cancel_user = nullptr) {
    mcp_context ctx;
    ctx.functions = fns;
    ctx.function_count = count;
    ctx.cancel = cancel;
    ctx.cancel_user = cancel_user;
    return ctx;
}

/// Every number of two study results but the timing fields.
void expect_same_numbers(const json& a, const json& b) {
    ASSERT_EQ(a["estimators"].size(), b["estimators"].size());
    for (size_t e = 0; e < a["estimators"].size(); ++e) {
        const json& la = a["estimators"][e]["levels"];
        const json& lb = b["estimators"][e]["levels"];
        ASSERT_EQ(la.size(), lb.size());
        for (size_t l = 0; l < la.size(); ++l)
            for (const char* key :
                 {"n", "mean", "variance", "std_error", "mean_run_std_error", "coverage95"}) {
                if (!la[l].contains(key)) continue;
                EXPECT_EQ(la[l][key], lb[l][key])
                    << "estimator " << e << " level " << l << " " << key;
            }
    }
}

} // namespace

TEST(CallerFunctions, SameNumbersAsTheSameExpression) {
    Calls calls;
    calls.expect_dim = 2;
    const mcp_function fns[] = {{"f", product_plus_first, &calls}};
    const mcp_context ctx = context_of(fns, 1);
    const json options = {{"estimators", {"uniform", "sobol", "vegas", "miser"}},
                          {"n_max", 4096},
                          {"reps", 4},
                          {"threads", 2}};
    const Outcome by_function =
        run_with(box_scene({{"type", "function"}, {"name", "f"}}, 2), options, &ctx);
    ASSERT_EQ(by_function.status, MCP_OK) << by_function.error;
    const Outcome by_expression = run_with(box_scene("x1 * x2 + x1", 2), options, nullptr);
    ASSERT_EQ(by_expression.status, MCP_OK) << by_expression.error;
    expect_same_numbers(by_function.result, by_expression.result);
    EXPECT_EQ(calls.bad_layout.load(), 0);
    EXPECT_GT(calls.calls.load(), 0u);
    // Blocks, never single points: far fewer calls than points.
    EXPECT_LT(calls.calls.load() * 16, calls.points.load());
    EXPECT_EQ(by_function.result["scene"]["exact"], nullptr); // a function has no closed form
}

TEST(CallerFunctions, FixedEstimatorsCallOncePerBatchOfBlocks) {
    // A Python callable costs microseconds per call: the fixed estimators (and the support
    // check's probes) hand it kFunctionBatch = 4096 points at a time, not one block of 256.
    Calls calls;
    calls.expect_dim = 2;
    const mcp_function fns[] = {{"f", product_plus_first, &calls}};
    const mcp_context ctx = context_of(fns, 1);
    const Outcome o = run_with(box_scene({{"type", "function"}, {"name", "f"}}, 2),
                               {{"estimators", {"uniform", "sobol", "stratified"}},
                                {"n_min", 4096},
                                {"n_max", 16384},
                                {"reps", 2}},
                               &ctx);
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(calls.smallest.load(), 4096u);
    EXPECT_EQ(calls.bad_layout.load(), 0);
}

TEST(CallerFunctions, VegasEstimatesFromItsFrozenMapInBatches) {
    // Training adapts the map block by block (256 points per call); the estimate from the frozen
    // map comes in batches of 4096, and the numbers are the expression's (test above).
    Calls calls;
    calls.expect_dim = 2;
    const mcp_function fns[] = {{"f", product_plus_first, &calls}};
    const mcp_context ctx = context_of(fns, 1);
    const Outcome o = run_with(
        box_scene({{"type", "function"}, {"name", "f"}}, 2),
        {{"estimators", {"vegas"}}, {"n_min", 65536}, {"n_max", 65536}, {"reps", 2}}, &ctx);
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(calls.largest.load(), 4096u);
    EXPECT_LT(calls.calls.load(), calls.points.load() / 512); // half the calls of 256 each
}

TEST(CallerFunctions, PointsArriveColumnMajor) {
    Calls calls;
    const mcp_function fns[] = {{"g", second_coordinate, &calls}};
    const mcp_context ctx = context_of(fns, 1);
    const json options = {{"estimators", {"uniform", "vegas"}}, {"n_max", 16384}, {"reps", 8}};
    json scene = {{"integrand", {{"type", "function"}, {"name", "g"}}},
                  {"domain", {{"type", "box"}, {"lower", {0, 10, 100}}, {"upper", {1, 11, 101}}}},
                  {"exact", 10.5}};
    const Outcome o = run_with(scene, options, &ctx);
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(calls.bad_layout.load(), 0);
    for (const json& e : o.result["estimators"]) {
        const json& top = e["levels"].back();
        const double mean = top["mean"], se = top["std_error"];
        EXPECT_LT(std::fabs(mean - 10.5), 5.0 * se) << e["name"] << ": " << mean << " +- " << se;
    }
}

TEST(CallerFunctions, AFailingFunctionStopsTheStudyWithinABlock) {
    Calls calls;
    calls.expect_dim = 2;
    calls.fail_at = 5;
    const mcp_function fns[] = {{"my_f", product_plus_first, &calls}};
    const mcp_context ctx = context_of(fns, 1);
    const Outcome o = run_with(
        box_scene({{"type", "function"}, {"name", "my_f"}}, 2),
        {{"estimators", {"uniform", "vegas"}}, {"n_max", 1 << 20}, {"reps", 16}, {"threads", 2}},
        &ctx);
    EXPECT_EQ(o.status, MCP_ERROR_FUNCTION);
    EXPECT_NE(o.error.find("'my_f'"), std::string::npos) << o.error;
    EXPECT_TRUE(o.result.is_null()); // a failed function's numbers are not given
    // No call starts after the failure: at most the calls already under way on other threads.
    EXPECT_LE(calls.calls.load(), 5u + 2u);
}

TEST(CallerFunctions, AFailingFunctionStopsAStoppingStudyAndAPlan) {
    Calls calls;
    calls.expect_dim = 2;
    calls.fail_at = 3;
    const mcp_function fns[] = {{"f", product_plus_first, &calls}};
    const mcp_context ctx = context_of(fns, 1);
    const Outcome o = run_with(box_scene({{"type", "function"}, {"name", "f"}}, 2),
                               {{"estimators", {"uniform", "sobol"}}, {"rel_tol", 1e-9}}, &ctx);
    EXPECT_EQ(o.status, MCP_ERROR_FUNCTION) << o.error;
    EXPECT_LE(calls.calls.load(), 3u);

    calls.calls = 0;
    char* plan = nullptr;
    const std::string scene = box_scene({{"type", "function"}, {"name", "f"}}, 2).dump();
    EXPECT_EQ(mcp_study_plan_with(scene.c_str(), nullptr, &ctx, &plan), MCP_ERROR_FUNCTION);
    EXPECT_EQ(plan, nullptr);
}

namespace {
int cancel_after(void* user) {
    auto* polls = static_cast<std::atomic<int>*>(user);
    return ++*polls > 40 ? 1 : 0;
}
} // namespace

TEST(CallerFunctions, CancelStopsWithinABlockAndKeepsTheCompletedLevels) {
    Calls calls;
    calls.expect_dim = 2;
    const mcp_function fns[] = {{"f", product_plus_first, &calls}};
    std::atomic<int> polls{0};
    const mcp_context ctx = context_of(fns, 1, cancel_after, &polls);
    const Outcome o = run_with(box_scene({{"type", "function"}, {"name", "f"}}, 2),
                               {{"estimators", {"uniform"}},
                                {"n_min", 16},
                                {"n_max", 1 << 22},
                                {"reps", 4},
                                {"threads", 1}},
                               &ctx);
    EXPECT_EQ(o.status, MCP_ERROR_CANCELLED) << o.error;
    ASSERT_TRUE(o.result.is_object());
    EXPECT_TRUE(o.result["cancelled"].get<bool>());
    // 4 x 2^22 points would be 65536 blocks; the cancel came after about 40 polls.
    EXPECT_LT(calls.calls.load(), 200u);
    for (const json& level : o.result["estimators"][0]["levels"])
        EXPECT_LT(level["n"].get<uint64_t>(), uint64_t(1) << 22);
}

TEST(CallerFunctions, ScenesNamingFunctionsTheCallWasNotGiven) {
    const std::string scene = box_scene({{"type", "function"}, {"name", "f"}}, 2).dump();
    char* out = nullptr;
    EXPECT_EQ(mcp_study_run(scene.c_str(), nullptr, nullptr, nullptr, &out), MCP_ERROR_SCENE);
    EXPECT_NE(std::string(mcp_last_error()).find("given no functions"), std::string::npos)
        << mcp_last_error();
    Calls calls;
    const mcp_function fns[] = {{"g", product_plus_first, &calls},
                                {"h", product_plus_first, &calls}};
    const mcp_context ctx = context_of(fns, 2);
    const Outcome o =
        run_with(box_scene({{"type", "function"}, {"name", "f"}}, 2), json::object(), &ctx);
    EXPECT_EQ(o.status, MCP_ERROR_SCENE);
    EXPECT_NE(o.error.find("no function named 'f' was given (given: g, h)"), std::string::npos)
        << o.error;
    const Outcome dim = run_with(box_scene({{"type", "function"}, {"name", "g"}, {"dim", 3}}, 2),
                                 json::object(), &ctx);
    EXPECT_EQ(dim.status, MCP_ERROR_SCENE);
    EXPECT_NE(dim.error.find("scene.integrand.dim"), std::string::npos) << dim.error;
    EXPECT_EQ(calls.calls.load(), 0u);
}

TEST(CallerFunctions, BadContextsAreArgumentErrors) {
    Calls calls;
    const json scene = box_scene({{"type", "function"}, {"name", "f"}}, 2);
    const mcp_function twice[] = {{"f", product_plus_first, &calls},
                                  {"f", product_plus_first, &calls}};
    mcp_context ctx = context_of(twice, 2);
    Outcome o = run_with(scene, json::object(), &ctx);
    EXPECT_EQ(o.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(o.error.find("given twice"), std::string::npos) << o.error;
    const mcp_function null_fn[] = {{"f", nullptr, &calls}};
    ctx = context_of(null_fn, 1);
    EXPECT_EQ(run_with(scene, json::object(), &ctx).status, MCP_ERROR_ARGUMENT);
    const mcp_function null_name[] = {{nullptr, product_plus_first, &calls}};
    ctx = context_of(null_name, 1);
    EXPECT_EQ(run_with(scene, json::object(), &ctx).status, MCP_ERROR_ARGUMENT);
    ctx = context_of(nullptr, 17);
    o = run_with(scene, json::object(), &ctx);
    EXPECT_EQ(o.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(o.error.find("function_count"), std::string::npos) << o.error;
    EXPECT_EQ(calls.calls.load(), 0u);
}

namespace {
// The course notes' polar map of the unit disk: r = sqrt(u1) is uniform, r = u1 is not.
template <bool Right>
int polar_disk(void*, const double* u, uint64_t n, int in_dim, double* x, int out_dim) {
    if (in_dim != 2 || out_dim != 2) return 1;
    for (uint64_t i = 0; i < n; ++i) {
        const double r = Right ? std::sqrt(u[i]) : u[i];
        const double phi = 2.0 * M_PI * u[n + i];
        x[i] = r * std::cos(phi);
        x[n + i] = r * std::sin(phi);
    }
    return 0;
}
int uniform_disk_density(void*, const double*, uint64_t n, int, double* out, int) {
    for (uint64_t i = 0; i < n; ++i) out[i] = 1.0 / M_PI;
    return 0;
}
json warp_test(const mcp_context& ctx, const std::string& p) {
    const json scene = {{"warp",
                         {{"domain", {{"type", "disk"}, {"center", {0, 0}}, {"radius", 1}}},
                          {"g", {{"function", "g"}, {"sample_dim", 2}}},
                          {"p", p == "function" ? json{{"function", "p"}} : json(p)}}}};
    const std::string s = scene.dump();
    char* out = nullptr;
    const int st = mcp_warp_test_with(s.c_str(), R"({"samples": 200000, "seed": 7})", &ctx, &out);
    EXPECT_EQ(st, MCP_OK) << mcp_last_error();
    json r = out ? json::parse(out) : json();
    mcp_free(out);
    return r;
}
} // namespace

TEST(CallerFunctions, WarpTestOfFunctionsRejectsTheWrongMapAndPassesTheRightOne) {
    const mcp_function right[] = {{"g", polar_disk<true>, nullptr},
                                  {"p", uniform_disk_density, nullptr}};
    const mcp_function wrong[] = {{"g", polar_disk<false>, nullptr},
                                  {"p", uniform_disk_density, nullptr}};
    const mcp_context right_ctx = context_of(right, 2), wrong_ctx = context_of(wrong, 2);
    // At a fixed seed; the right map passes at the test's 1% level, the wrong one fails with a
    // p-value far below it (its r density is 2 r against 1).
    const json pass = warp_test(right_ctx, "function");
    EXPECT_TRUE(pass["passed"].get<bool>()) << pass.dump();
    const json also_pass = warp_test(right_ctx, "1 / pi");
    EXPECT_TRUE(also_pass["passed"].get<bool>()) << also_pass.dump();
    const json fail = warp_test(wrong_ctx, "function");
    EXPECT_FALSE(fail["passed"].get<bool>());
    EXPECT_LT(fail["p_value"].get<double>(), 1e-6);
    // A sample_dim the domain does not read.
    const json bad = {{"warp",
                       {{"domain", {{"type", "disk"}}},
                        {"g", {{"function", "g"}, {"sample_dim", 3}}},
                        {"p", "1 / pi"}}}};
    char* out = nullptr;
    EXPECT_EQ(mcp_warp_test_with(bad.dump().c_str(), nullptr, &right_ctx, &out), MCP_ERROR_SCENE);
    EXPECT_NE(std::string(mcp_last_error()).find("sample_dim"), std::string::npos);
}
