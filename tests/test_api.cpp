// The C API: documented result JSON, error codes and messages for bad input, progress and
// cancellation, formatting.
#include <dirent.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "api/mcplay.h"

using nlohmann::json;

namespace {

struct Outcome {
    int status;
    std::string error;
    json result;
};

Outcome run(const std::string& scene, const char* options = nullptr, mcp_progress_fn cb = nullptr,
            void* user = nullptr) {
    char* out = nullptr;
    Outcome o;
    o.status = mcp_study_run(scene.c_str(), options, cb, user, &out);
    o.error = mcp_last_error();
    if (out) {
        o.result = json::parse(out);
        mcp_free(out);
    }
    return o;
}

const char* kSmall = R"({"name": "small", "integrand": {"type": "monomial", "powers": [2]},
  "estimators": ["uniform", "stratified"], "n_min": 16, "n_max": 64, "reps": 4})";

} // namespace

TEST(Api, ResultFollowsTheDocumentedSchema) {
    Outcome o = run(kSmall);
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    const json& r = o.result;
    EXPECT_EQ(r["version"], 1);
    EXPECT_EQ(r["mcplay"], mcp_version());
    EXPECT_EQ(r["scene"]["name"], "small");
    EXPECT_NEAR(r["scene"]["exact"].get<double>(), 1.0 / 3.0, 1e-15); // closed form
    EXPECT_EQ(r["settings"]["reps"], 4);
    ASSERT_EQ(r["estimators"].size(), 2u);
    for (const json& e : r["estimators"]) {
        for (const char* k : {"name", "sampler", "pdf", "error_method", "levels", "fit"})
            EXPECT_TRUE(e.contains(k)) << k;
        ASSERT_EQ(e["levels"].size(), 3u); // 16, 32, 64
        for (const json& l : e["levels"])
            for (const char* k :
                 {"n", "reps", "mean", "variance", "variance_ci95", "std_error", "ci95", "bias",
                  "mse", "rmse", "coverage95", "mean_run_std_error", "time_mean_s", "efficiency",
                  "error", "diagnostics", "warnings", "replicates"})
                EXPECT_TRUE(l.contains(k)) << k;
        EXPECT_EQ(e["levels"][2]["n"], 64);
        EXPECT_EQ(e["levels"][0]["replicates"]["estimate"].size(), 4u);
        EXPECT_TRUE(e["fit"]["valid"].get<bool>());
    }
}

TEST(Api, BadScenesGiveScenesErrorsNamingTheField) {
    struct Case {
        const char* scene;
        const char* expected; // substring of the message
    };
    const Case cases[] = {
        {"{", "invalid JSON"},
        {"[1, 2]", "expected an object"},
        {"{}", "missing \"integrand\""},
        {R"({"integrand": {"type": "monomial", "powers": [1]}, "n_mx": 5})",
         "unknown field 'n_mx'"},
        {R"({"integrand": {"type": "wobble"}})", "unknown integrand 'wobble'"},
        {R"({"integrand": {"type": "monomial", "powers": [-1]}})", "powers[0] must be > -1"},
        {R"({"integrand": {"type": "monomial", "powers": "x"}})", "scene.integrand.powers"},
        {R"({"integrand": {"type": "gaussian", "sigma": 0}})", "sigma must be"},
        {R"({"domain": {"type": "disk", "radius": -1}, "integrand": {"type": "constant"}})",
         "radius"},
        {R"({"domain": {"type": "box", "lower": [0, 1], "upper": [1, 1]}, "integrand": {"type": "constant"}})",
         "axis 1"},
        {R"({"domain": {"type": "torus"}, "integrand": {"type": "constant"}})",
         "unknown domain 'torus'"},
        {R"({"domain": {"type": "triangle", "vertices": [[0,0],[1,1],[2,2]]}, "integrand": {"type": "constant"}})",
         "collinear"},
        {R"({"integrand": {"type": "constant"}, "estimators": ["importance"]})", "needs a pdf"},
        {R"({"integrand": {"type": "constant"}, "estimators": [{"name": "a", "sampler": "faure"}]})",
         "unknown sampler 'faure'"},
        {R"({"integrand": {"type": "constant"}, "estimators": ["uniform", "uniform"]})",
         "duplicate estimator"},
        {R"({"integrand": {"type": "constant"}, "estimators": [{"name": "i", "pdf": {"type": "power", "k": -2}}]})",
         "k"},
        {R"({"integrand": {"type": "constant"}, "estimators": [{"name": "i", "pdf": {"type": "exponential", "rate": 0}}]})",
         "rate"},
        {R"({"integrand": {"type": "constant"}, "estimators": [{"name": "i", "pdf": {"type": "tabulated", "values": [1, -1]}}]})",
         "values"},
        {R"({"integrand": {"type": "constant"}, "estimators": [{"name": "i", "pdf": {"type": "cosine_hemisphere"}}]})",
         "hemisphere"},
        {R"({"domain": {"type": "hemisphere"}, "integrand": {"type": "constant"}, "estimators": [{"name": "i", "pdf": {"type": "power"}}]})",
         "cosine_hemisphere"},
        {R"({"integrand": {"type": "constant"}, "estimators": [{"name": "w", "warp": "polar"}]})",
         "only disk"},
        {R"({"integrand": {"type": "constant"}, "n_min": 100, "n_max": 10})",
         "n_max (10) must be >= n_min (100)"},
        {R"({"integrand": {"type": "constant"}, "reps": 1})", "reps must be in 2.."},
        {R"({"integrand": {"type": "constant"}, "n_max": -5})",
         "scene.n_max: expected a non-negative whole number"},
        {R"({"integrand": {"type": "constant"}, "n_min": 17, "n_max": 31})", "no power of two"},
        {R"({"integrand": {"type": "constant"}, "quantity": "median"})", "scene.quantity"},
        {R"J({"f": "x*y + sinn(pi*x)"})J", "scene.f: at position 7: unknown function 'sinn'"},
        {R"J({"f": "exp(-(x-0.5)^2/0.01"})J",
         "scene.f: at position 20: expected ')' to close the '(' at position 4"},
        {R"J({"f": "1 +", "integrand": {"type": "constant"}})J", "not both"},
        {R"J({"domain": {"type": "box", "dim": 2}, "f": "x3"})J", "beyond the domain's dimension"},
        {R"({"integrand": {"type": "expression"}})", "needs \"f\""},
        {R"J({"f": "x", "estimators": [{"name": "i", "pdf": "x^"}]})J", "pdf.shape: at position 3"},
        {R"J({"f": "x", "domain": {"type": "box", "dim": 3}, "estimators": [{"name": "i", "pdf": "x"}]})J",
         "1- or 2-dimensional"},
        {R"J({"integrand": {"type": "genz_gaussian", "a": [1, -1], "u": [0.5, 0.5]}})J", "a[1]"},
        {R"J({"integrand": {"type": "genz_wobbly", "dim": 2}})J",
         "unknown integrand 'genz_wobbly'"},
        {R"J({"integrand": {"type": "genz_product_peak", "dim": 64, "seed": 1}})J",
         "outside double precision"},
        {R"J({"integrand": {"type": "genz_gaussian", "dim": 2, "difficulty": -1}})J", "difficulty"},
        {R"J({"integrand": {"type": "constant"}, "estimators": [{"name": "s", "sampler": "stratified", "samples_per_stratum": 3}]})J",
         "samples_per_stratum"},
        {R"J({"integrand": {"type": "constant"}, "accumulator": "float16"})J", "scene.accumulator"},
    };
    for (const Case& c : cases) {
        Outcome o = run(c.scene);
        EXPECT_EQ(o.status, MCP_ERROR_SCENE) << c.scene;
        EXPECT_NE(o.error.find(c.expected), std::string::npos) << c.scene << "\n  got: " << o.error;
        EXPECT_TRUE(o.result.is_null());
    }
}

// Stopping at a requested accuracy through the API: "kind": "stopping", one answer per
// replicate with its half-width, target, reason and cost; every run of x^2 under stratified
// sampling meets 1e-3 relative and lies within it; bad tolerances are named.
TEST(Api, StoppingAtARequestedAccuracy) {
    // The scene's n_max (64) is the stopping budget: the options give a larger one.
    Outcome o = run(kSmall, R"({"rel_tol": 1e-3, "reps": 8, "estimators": ["stratified"],
                                "n_max": 16777216})");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(o.result["kind"], "stopping");
    EXPECT_EQ(o.result["stopping"]["rel_tol"], 1e-3);
    const json& e = o.result["estimators"][0];
    EXPECT_EQ(e["name"], "stratified");
    ASSERT_EQ(e["runs"].size(), 8u);
    EXPECT_EQ(e["met"], 8);
    EXPECT_EQ(e["within_tolerance"], 8);
    for (const json& r : e["runs"]) {
        EXPECT_TRUE(r["met"].get<bool>());
        EXPECT_EQ(r["reason"], "tolerance_met");
        EXPECT_LE(r["half_width"].get<double>(), r["target"].get<double>());
        EXPECT_GE(r["steps"].size(), 2u);
        EXPECT_GT(r["evaluations"].get<uint64_t>(), r["n"].get<uint64_t>());
    }
    // A budget that ends first: reported unmet, with a warning naming it.
    o = run(kSmall, R"({"rel_tol": 1e-9, "n_max": 256, "reps": 2})");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(o.result["estimators"][0]["met"], 0);
    EXPECT_EQ(o.result["estimators"][0]["warnings"][0]["code"], "tolerance_not_met");
    EXPECT_NE(
        o.result["estimators"][0]["warnings"][0]["message"].get<std::string>().find("n_max = 256"),
        std::string::npos);
    for (const char* bad : {R"({"rel_tol": -1})", R"({"abs_tol": "small"})",
                            R"({"max_seconds": 5})", R"({"rel_tol": 0.1, "max_seconds": -1})"}) {
        o = run(kSmall, bad);
        EXPECT_NE(o.status, MCP_OK) << bad;
        EXPECT_TRUE(o.error.find("tol") != std::string::npos ||
                    o.error.find("max_seconds") != std::string::npos)
            << bad << ": " << o.error;
    }
}

TEST(Api, BadOptions) {
    // A bad value in the options is a bad argument, not a bad scene.
    Outcome o = run(kSmall, R"({"estimators": ["nope"]})");
    EXPECT_EQ(o.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(o.error.find("unknown estimator 'nope'"), std::string::npos) << o.error;
    o = run(kSmall, R"({"reps": "many"})");
    EXPECT_NE(o.error.find("options.reps"), std::string::npos) << o.error;
    o = run(kSmall, "{oops");
    EXPECT_EQ(o.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(o.error.find("options: invalid JSON"), std::string::npos) << o.error;
    // A preset that needs no pdf can be added from the options.
    o = run(kSmall, R"({"estimators": ["latin_hypercube"]})");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(o.result["estimators"][0]["sampler"], "latin_hypercube");
}

TEST(Api, NullPointersAreArgumentErrors) {
    EXPECT_EQ(mcp_study_run(kSmall, nullptr, nullptr, nullptr, nullptr), MCP_ERROR_ARGUMENT);
    char* out = nullptr;
    EXPECT_EQ(mcp_study_run(nullptr, nullptr, nullptr, nullptr, &out), MCP_ERROR_SCENE);
    EXPECT_EQ(mcp_result_format(nullptr, "table", &out), MCP_ERROR_ARGUMENT);
    EXPECT_EQ(mcp_result_format("{}", nullptr, &out), MCP_ERROR_ARGUMENT);
    EXPECT_EQ(mcp_scene_info(nullptr, &out), MCP_ERROR_SCENE);
    EXPECT_EQ(out, nullptr);
}

namespace {
struct ProgressLog {
    std::vector<uint64_t> ns;
    size_t cancel_after = 100;
};
int on_progress(const char* level_json, void* user) {
    auto* log = static_cast<ProgressLog*>(user);
    json j = json::parse(level_json);
    log->ns.push_back(j["n"].get<uint64_t>());
    EXPECT_EQ(j["estimators"].size(), 2u);
    EXPECT_TRUE(j["estimators"][0]["level"].contains("variance"));
    return log->ns.size() >= log->cancel_after ? 1 : 0;
}
} // namespace

TEST(Api, ProgressAfterEveryLevelAndCancel) {
    ProgressLog log;
    Outcome o = run(kSmall, nullptr, on_progress, &log);
    ASSERT_EQ(o.status, MCP_OK);
    EXPECT_EQ(log.ns, (std::vector<uint64_t>{16, 32, 64}));

    ProgressLog cancel;
    cancel.cancel_after = 2;
    o = run(kSmall, nullptr, on_progress, &cancel);
    EXPECT_EQ(o.status, MCP_ERROR_CANCELLED);
    EXPECT_TRUE(o.result["cancelled"].get<bool>());
    EXPECT_EQ(o.result["estimators"][0]["levels"].size(), 2u);
}

TEST(Api, FormatsTableCsvJson) {
    char* out = nullptr;
    ASSERT_EQ(mcp_study_run(kSmall, nullptr, nullptr, nullptr, &out), MCP_OK);
    std::string result = out;
    mcp_free(out);

    char* text = nullptr;
    ASSERT_EQ(mcp_result_format(result.c_str(), "table", &text), MCP_OK);
    std::string table = text;
    mcp_free(text);
    EXPECT_NE(table.find("fitted order: variance ~ N^("), std::string::npos) << table;
    EXPECT_NE(table.find("stratified"), std::string::npos);

    ASSERT_EQ(mcp_result_format(result.c_str(), "csv", &text), MCP_OK);
    std::string csv = text;
    mcp_free(text);
    size_t lines = 0;
    for (char c : csv) lines += c == '\n';
    EXPECT_EQ(lines, 1u + 2u * 3u); // header + estimators x levels
    EXPECT_EQ(csv.rfind("scene,estimator,sampler,pdf,n,", 0), 0u);

    ASSERT_EQ(mcp_result_format(result.c_str(), "json", &text), MCP_OK);
    EXPECT_EQ(json::parse(text), json::parse(result));
    mcp_free(text);

    EXPECT_EQ(mcp_result_format(result.c_str(), "xml", &text), MCP_ERROR_ARGUMENT);
    EXPECT_NE(std::string(mcp_last_error()).find("unknown format 'xml'"), std::string::npos);
    // Odd but valid JSON shapes are rejected (estimators and levels not lists of objects: see
    // FormatRefusesResultsOfTheWrongShape) or formatted with "-" for odd fields, never a crash.
    EXPECT_EQ(mcp_result_format("[1,2]", "table", &text), MCP_ERROR_ARGUMENT);
    EXPECT_EQ(
        mcp_result_format(R"({"estimators": 5, "scene": [], "settings": "x"})", "table", &text),
        MCP_ERROR_ARGUMENT);
    ASSERT_EQ(mcp_result_format(R"({"estimators": [{"levels": [{"n": "x"}]}], "scene": []})",
                                "table", &text),
              MCP_OK);
    mcp_free(text);
    ASSERT_EQ(mcp_result_format(R"({"estimators": [{"levels": [{"n": "x"}]}]})", "csv", &text),
              MCP_OK);
    mcp_free(text);
}

TEST(Api, ExpressionAndGenzScenesRun) {
    // Expression integrand and pdf: the integral of 3x^2 is 1; sampling p = 3x^2 is exact.
    Outcome o =
        run(R"J({"f": "3*x^2", "exact": 1, "estimators": ["uniform", {"name": "is", "pdf": "x^2"}],
                        "n_min": 1024, "n_max": 1024, "reps": 8})J");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(o.result["scene"]["dimension"], 1);
    for (const json& e : o.result["estimators"]) {
        const json& l = e["levels"][0];
        EXPECT_LT(std::fabs(l["mean"].get<double>() - 1.0), 5 * l["std_error"].get<double>() + 1e-3)
            << e["name"];
    }
    // Without a domain the highest variable sets the dimension.
    o = run(R"J({"f": "x1 * x3", "n_max": 64, "reps": 2})J");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    EXPECT_EQ(o.result["scene"]["dimension"], 3);
    // Genz: the exact value comes from the closed form.
    o = run(
        R"J({"integrand": {"type": "genz_continuous", "a": [2, 3], "u": [0.25, 0.5]}, "n_max": 64, "reps": 2})J");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    const double i1 = (-std::expm1(-2 * 0.25) - std::expm1(-2 * 0.75)) / 2;
    const double i2 = (-std::expm1(-3 * 0.5) - std::expm1(-3 * 0.5)) / 3;
    EXPECT_NEAR(o.result["scene"]["exact"].get<double>(), i1 * i2, 1e-14);
}

TEST(Api, SamplesAreTheStudysFirstReplicate) {
    // The dumped points are replicate 0 at N = n: their mean weight is that replicate's estimate.
    const char* scene = R"J({"f": "exp(x)", "estimators": ["uniform", "stratified",
        {"name": "is", "pdf": {"type": "exponential", "rate": -1}}], "n_min": 64, "n_max": 64, "reps": 2, "seed": 5})J";
    Outcome o = run(scene);
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    char* out = nullptr;
    ASSERT_EQ(mcp_study_samples(scene, R"({"n": 64, "grid": 32})", &out), MCP_OK)
        << mcp_last_error();
    json dump = json::parse(out);
    mcp_free(out);
    ASSERT_EQ(dump["estimators"].size(), 3u);
    for (size_t e = 0; e < 3; ++e) {
        const json& d = dump["estimators"][e];
        ASSERT_EQ(d["weight"].size(), 64u);
        double sum = 0.0;
        for (const json& w : d["weight"]) sum += w.get<double>();
        const double estimate = o.result["estimators"][e]["levels"][0]["replicates"]["estimate"][0];
        EXPECT_NEAR(sum / 64, estimate, 1e-13) << d["name"];
    }
    // Stratified: one point per cell of the reported grid.
    const json& st = dump["estimators"][1];
    EXPECT_EQ(st["strata"], json({64}));
    std::vector<int> cells(64, 0);
    for (const json& u : st["u"][0]) ++cells[static_cast<size_t>(u.get<double>() * 64)];
    for (int c : cells) EXPECT_EQ(c, 1);
    // 1D: the curve carries f and each density on the grid; the densities integrate to ~1.
    ASSERT_EQ(dump["curve"]["x"].size(), 32u);
    double mass = 0.0;
    for (const json& p : dump["curve"]["pdf"]["is"]) mass += p.get<double>() / 32;
    EXPECT_NEAR(mass, 1.0, 1e-3);
    EXPECT_EQ(mcp_study_samples(scene, R"({"n": 0})", &out), MCP_ERROR_ARGUMENT);
    EXPECT_NE(std::string(mcp_last_error()).find("options.n"), std::string::npos);
}

TEST(Api, SceneInfoAndCatalog) {
    char* out = nullptr;
    ASSERT_EQ(mcp_scene_info(kSmall, &out), MCP_OK);
    json info = json::parse(out);
    mcp_free(out);
    EXPECT_EQ(info["name"], "small");
    EXPECT_EQ(info["estimators"], json({"uniform", "stratified"}));
    // Each estimator's method (what the page explains), the scene's own and the presets it
    // does not list alike.
    std::map<std::string, std::string> method;
    for (const json& d : info["estimator_details"]) method[d["name"]] = d["method"];
    EXPECT_EQ(method["uniform"], "uniform");
    EXPECT_EQ(method["stratified"], "stratified");
    EXPECT_EQ(method["sobol"], "rqmc");
    EXPECT_EQ(method["vegas_plus"], "vegas_plus");
    EXPECT_EQ(method["miser"], "miser");
    const char* importance = R"J({"f": "exp(x)", "estimators": [{"name": "is", "pdf": "1 + x"},
        {"name": "mis", "proposals": ["uniform", "1 + x"]}]})J";
    ASSERT_EQ(mcp_scene_info(importance, &out), MCP_OK) << mcp_last_error();
    info = json::parse(out);
    mcp_free(out);
    EXPECT_EQ(info["estimator_details"][0]["method"], "importance");
    EXPECT_EQ(info["estimator_details"][1]["method"], "mis");
    EXPECT_EQ(info["estimator_details"][1]["kind"], "mis");
    EXPECT_FALSE(info["estimator_details"][1]["summary"].get<std::string>().empty());
    ASSERT_EQ(mcp_catalog(&out), MCP_OK);
    json cat = json::parse(out);
    mcp_free(out);
    EXPECT_GE(cat["estimators"].size(), 5u);
    // The kinds, the presets' kinds and the samplers come from the core's tables.
    std::set<std::string> kinds;
    for (const json& k : cat["kinds"]) kinds.insert(k["name"].get<std::string>());
    for (const char* k :
         {"fixed", "vegas", "vegas_plus", "miser", "mis", "control_variates", "antithetic"})
        EXPECT_TRUE(kinds.count(k)) << k;
    for (const json& p : cat["estimators"]) EXPECT_TRUE(kinds.count(p["kind"].get<std::string>()));
    EXPECT_EQ(cat["samplers"],
              json({"independent", "stratified", "latin_hypercube", "sobol", "halton", "lattice"}));
    EXPECT_EQ(cat["randomizations"],
              json({{"sobol", {"owen", "lms_shift", "digital_shift", "none"}},
                    {"halton", {"owen", "permutation", "none"}},
                    {"lattice", {"random_shift", "none"}}}));
}

namespace {

// Every estimator's pdf_text in a scene info: beside each pdf, in words (no "=", no "_").
std::vector<std::string> pdf_texts(const std::string& scene) {
    char* out = nullptr;
    std::vector<std::string> texts;
    if (mcp_scene_info(scene.c_str(), &out) != MCP_OK) return texts;
    const json info = json::parse(out);
    mcp_free(out);
    for (const json& d : info["estimator_details"]) {
        EXPECT_TRUE(d.contains("pdf") && d.contains("pdf_text")) << d.dump();
        const std::string text = d.value("pdf_text", "");
        EXPECT_FALSE(text.empty()) << d.dump();
        EXPECT_EQ(text.find_first_of("=_"), std::string::npos) << text;
        texts.push_back(text);
    }
    return texts;
}

} // namespace

// pdf_text beside pdf: in the scene info of every scene file and of scenes made to cover every
// proposal (disks by both maps, triangle, sphere, hemisphere, products, 2D tables, warps,
// mixtures, adaptive kinds), in a study's estimators and in the sample view's.
TEST(Api, PdfTextBesidePdf) {
    std::vector<std::string> all;
    const std::string dir = std::string(MCPLAY_SOURCE_DIR) + "/scenes";
    DIR* d = opendir(dir.c_str());
    ASSERT_NE(d, nullptr);
    int scenes = 0;
    while (dirent* e = readdir(d)) {
        const std::string name = e->d_name;
        if (name.size() < 6 || name.substr(name.size() - 5) != ".json") continue;
        std::ifstream in(dir + "/" + name);
        std::stringstream ss;
        ss << in.rdbuf();
        const std::vector<std::string> texts = pdf_texts(ss.str());
        scenes += !texts.empty();
        all.insert(all.end(), texts.begin(), texts.end());
    }
    closedir(d);
    EXPECT_GE(scenes, 20);
    const char* made[] = {
        R"({"domain": {"type": "disk", "radius": 2, "center": [1, 0]}, "f": "1",
            "estimators": [{"name": "uniform", "warp": "polar"}, {"name": "stratified", "warp": "concentric"}]})",
        R"({"domain": {"type": "triangle", "vertices": [[0, 0], [1, 0], [0, 1]]}, "f": "1",
            "estimators": ["uniform"]})",
        R"({"domain": {"type": "sphere"}, "integrand": {"type": "monomial", "powers": [0, 0, 2]},
            "estimators": ["uniform"]})",
        R"({"domain": {"type": "hemisphere"}, "integrand": {"type": "monomial", "powers": [0, 0, 2]},
            "estimators": [{"name": "c", "pdf": {"type": "cosine_hemisphere"}}]})",
        R"({"domain": {"type": "box", "dim": 2}, "f": "x * y", "estimators": ["uniform", "vegas",
            "miser", {"name": "t", "pdf": {"type": "tabulated_2d", "bins": [4, 3], "shape": "integrand"}},
            {"name": "pr", "pdf": {"type": "product", "factors": [{"type": "power", "k": 1},
                                                                  {"type": "exponential", "rate": 2}]}},
            {"name": "m", "heuristic": "power", "one_sample": true,
             "proposals": ["uniform", {"type": "power", "k": 1}]}]})",
        R"({"domain": {"type": "box", "dim": 3}, "f": "x", "estimators": ["uniform"]})",
        R"({"warp": "concentric_disk", "f": "1", "estimators": ["warp"]})",
        R"({"warp": {"name": "tabulated_1d", "values": [1, 2, 3]}, "f": "x", "estimators": ["warp"]})",
    };
    for (const char* scene : made) {
        const std::vector<std::string> texts = pdf_texts(scene);
        EXPECT_FALSE(texts.empty()) << scene << ": " << mcp_last_error();
        all.insert(all.end(), texts.begin(), texts.end());
    }
    auto found = [&](const std::string& words) {
        return std::any_of(all.begin(), all.end(), [&](const std::string& t) {
            return t.find(words) != std::string::npos;
        });
    };
    for (const char* words :
         {"uniform on [0, 1]", "uniform on [0, 1]^2", "uniform on [0, 1]^3",
          "uniform on the disk of radius 2 centred at (1, 0), by the polar map",
          "by the concentric map", "uniform on the triangle with corners (0, 0), (1, 0), (0, 1)",
          "uniform on the sphere of directions", "cos(theta) / pi on the upper hemisphere",
          "piecewise-constant density on a 4 x 3 grid of cells over [0, 1] x [0, 1]",
          "a product of one density per axis: x1: power-law density proportional to x1 on [0, 1]; "
          "x2: exponential density proportional to e^(-2 x2) on [0, 1]",
          "a mixture of 2 densities (multiple importance sampling, power heuristic, each point "
          "from one density drawn at random): 50% from (uniform on [0, 1]^2); 50% from (a product "
          "of "
          "one density per axis: x1: power-law density proportional to x1 on [0, 1]; x2: "
          "power-law density proportional to x2 on [0, 1])",
          "reshaped by the VEGAS map the run learns", "within the boxes MISER's recursive",
          "normal density of mean", "piecewise-constant density from a table on [0, 1]"})
        EXPECT_TRUE(found(words)) << words;

    // A study's estimators and the sample view's carry it too.
    Outcome o = run(kSmall);
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    for (const json& e : o.result["estimators"])
        EXPECT_EQ(e["pdf_text"], "uniform on [0, 1]") << e.dump();
    char* out = nullptr;
    ASSERT_EQ(mcp_study_samples(kSmall, R"({"n": 16})", &out), MCP_OK) << mcp_last_error();
    const json samples = json::parse(out);
    mcp_free(out);
    for (const json& e : samples["estimators"]) EXPECT_EQ(e["pdf_text"], "uniform on [0, 1]");
}

TEST(Api, TheKindsFactsReachTheJson) {
    // Study records: the kind and whether its error bars are conservative by design.
    Outcome o = run(R"({"f": "x*x", "estimators": ["uniform", "latin_hypercube", "vegas"],
                        "n_min": 64, "n_max": 128, "reps": 2})");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    std::map<std::string, json> by_name;
    for (const json& e : o.result["estimators"]) by_name[e["name"]] = e;
    EXPECT_EQ(by_name["uniform"]["kind"], "fixed");
    EXPECT_EQ(by_name["uniform"]["error_bars_conservative"], false);
    EXPECT_EQ(by_name["latin_hypercube"]["error_bars_conservative"], true);
    EXPECT_EQ(by_name["vegas"]["kind"], "vegas");
    // Integration levels time their median; render levels do not (test_render_scenes).
    EXPECT_TRUE(by_name["uniform"]["levels"][0].contains("time_median_s"));
    // Samples: whether the running mean of the first k points is the estimate at N = k.
    char* out = nullptr;
    ASSERT_EQ(mcp_study_samples(R"({"f": "x*x", "estimators": ["uniform", "stratified",
                                    "vegas", "antithetic"]})",
                                R"({"n": 64})", &out),
              MCP_OK)
        << mcp_last_error();
    const json dump = json::parse(out);
    mcp_free(out);
    std::map<std::string, bool> replay;
    for (const json& e : dump["estimators"]) replay[e["name"]] = e["replay_is_estimate"];
    EXPECT_TRUE(replay["uniform"]);
    EXPECT_FALSE(replay["stratified"]);
    EXPECT_FALSE(replay["vegas"]);
    EXPECT_FALSE(replay["antithetic"]);
    EXPECT_EQ(dump["estimators"][3]["method"], "antithetic");
}

// --- Hardening (issue 10) ----------------------------------------------------------------

TEST(Api, StudySizeIsCheckedBeforeAnyWork) {
    // 2^36 samples at the largest N with 32 replicates: 4.4e12 evaluations, refused at once.
    Outcome o = run(R"({"f": "x*x", "estimators": ["uniform"], "n_max": 68719476736, "reps": 32})");
    EXPECT_EQ(o.status, MCP_ERROR_SCENE);
    EXPECT_EQ(o.error.rfind("scene: n_max = 68719476736, reps = 32 and 1 estimator(s) ask for "
                            "4398046510592 integrand evaluations",
                            0),
              0u)
        << o.error;
    EXPECT_TRUE(o.result.is_null());
}

namespace {
Outcome plan(const std::string& scene, const char* options = nullptr) {
    char* out = nullptr;
    Outcome o;
    o.status = mcp_study_plan(scene.c_str(), options, &out);
    o.error = mcp_last_error();
    if (out) {
        o.result = json::parse(out);
        mcp_free(out);
    }
    return o;
}
} // namespace

TEST(Api, PlanValidatesLikeRunAndPredicts) {
    Outcome p = plan(kSmall);
    ASSERT_EQ(p.status, MCP_OK) << p.error;
    const json& r = p.result;
    EXPECT_EQ(r["evaluations"], (16 + 32 + 64) * 4 * 2);
    EXPECT_EQ(r["levels"], json({16, 32, 64}));
    EXPECT_EQ(r["limit_evaluations"], uint64_t(1) << 40);
    EXPECT_EQ(r["pilot_samples"], 4096);
    ASSERT_EQ(r["estimators"].size(), 2u);
    EXPECT_GT(r["predicted_seconds"].get<double>(), 0.0);
    EXPECT_LT(r["pilot_seconds"].get<double>(), 0.05);
    // Options override as in mcp_study_run.
    EXPECT_EQ(plan(kSmall, R"({"reps": 2, "estimators": ["uniform"]})").result["evaluations"],
              (16 + 32 + 64) * 2);
    // The same errors as mcp_study_run, and no result.
    for (const char* bad :
         {R"({"f": "x*x", "estimators": ["uniform"], "n_max": 68719476736, "reps": 32})",
          R"({"f": "sin(", "estimators": ["uniform"]})", "{"}) {
        Outcome a = run(bad), b = plan(bad);
        EXPECT_EQ(a.status, b.status) << bad;
        EXPECT_EQ(a.error, b.error) << bad;
        EXPECT_TRUE(b.result.is_null());
    }
    char* out = nullptr;
    EXPECT_EQ(mcp_study_plan(kSmall, nullptr, nullptr), MCP_ERROR_ARGUMENT);
    EXPECT_EQ(mcp_study_plan(kSmall, "{", &out), MCP_ERROR_ARGUMENT);
    EXPECT_EQ(out, nullptr);
}

namespace {
Outcome format(const std::string& result, const char* fmt) {
    char* out = nullptr;
    Outcome o;
    o.status = mcp_result_format(result.c_str(), fmt, &out);
    o.error = mcp_last_error();
    if (out) {
        o.result = std::string(out);
        mcp_free(out);
    }
    return o;
}
} // namespace

TEST(Api, FormatRefusesResultsOfTheWrongShape) {
    for (auto [text, message] : std::vector<std::pair<const char*, const char*>>{
             {R"({"estimators": 5})", "result.estimators: expected an array, got number"},
             {R"({"estimators": [3]})", "result.estimators[0]: expected an object, got number"},
             {R"({"estimators": [{"levels": {}}]})",
              "result.estimators[0].levels: expected an array, got object"},
             {R"({"estimators": [{"levels": [null]}]})",
              "result.estimators[0].levels[0]: expected an object, got null"}}) {
        Outcome o = format(text, "table");
        EXPECT_EQ(o.status, MCP_ERROR_ARGUMENT) << text;
        EXPECT_EQ(o.error, message);
        EXPECT_TRUE(o.result.is_null());
    }
}

TEST(Api, NoNumberIsPrintedForAMissingEstimateOrANegativeVariance) {
    Outcome o = run(kSmall);
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    json r = o.result;
    json& l = r["estimators"][0]["levels"][0];
    l["variance"] = -1.0; // hand-edited: not a variance
    l["mean"] = nullptr;
    l["mse"] = -2.0;
    Outcome t = format(r.dump(), "table");
    ASSERT_EQ(t.status, MCP_OK) << t.error;
    const std::string table = t.result.get<std::string>();
    EXPECT_EQ(table.find("-1.0000e+00"), std::string::npos) << table;
    EXPECT_NE(table.find("       16                -            -"), std::string::npos) << table;
    Outcome c = format(r.dump(), "csv");
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    const std::string csv = c.result.get<std::string>();
    const std::string row = csv.substr(csv.find('\n') + 1, csv.find('\n', csv.find('\n') + 1));
    EXPECT_NE(row.find(",16,4,,,"), std::string::npos) << row; // n, reps, mean, variance empty
    EXPECT_EQ(row.find("-1"), std::string::npos) << row;
    EXPECT_EQ(row.find("-2"), std::string::npos) << row;
}

TEST(Api, EveryNaNSampleGivesNullsAndOneWarning) {
    Outcome o = run(R"j({"f": "log(-1-x)", "estimators": ["uniform"], "n_min": 16, "n_max": 32,
                        "reps": 2})j");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    for (const json& l : o.result["estimators"][0]["levels"]) {
        EXPECT_TRUE(l["mean"].is_null());
        EXPECT_TRUE(l["variance"].is_null());
        EXPECT_EQ(l["no_estimate_runs"], 2);
        ASSERT_EQ(l["warnings"].size(), 1u);
        EXPECT_EQ(l["warnings"][0]["code"], "no_estimate");
    }
    EXPECT_TRUE(o.result["estimators"][0]["warnings"].empty());
}

// Every warning has a severity, and each list puts errors first, then warnings, then info:
// is_zero_pdf's estimators carry pdf_support (an error) beside tail flags.
TEST(Api, WarningsCarryASeverityMostSevereFirst) {
    std::ifstream in(std::string(MCPLAY_SOURCE_DIR) + "/scenes/is_zero_pdf.json");
    std::stringstream ss;
    ss << in.rdbuf();
    Outcome o = run(ss.str(), R"j({"n_min": 256, "n_max": 2048, "reps": 8})j");
    ASSERT_EQ(o.status, MCP_OK) << o.error;
    int errors = 0;
    auto check = [&](const json& warnings) {
        int last = -1;
        for (const json& w : warnings) {
            ASSERT_TRUE(w.contains("severity")) << w.dump();
            const std::string s = w["severity"];
            const int rank = s == "error" ? 0 : s == "warning" ? 1 : s == "info" ? 2 : -1;
            ASSERT_GE(rank, 0) << w.dump();
            EXPECT_GE(rank, last) << warnings.dump();
            last = rank;
            errors += rank == 0;
        }
    };
    for (const json& e : o.result["estimators"]) {
        check(e["warnings"]);
        for (const json& l : e["levels"]) check(l["warnings"]);
    }
    EXPECT_GT(errors, 0);
    Outcome t = format(o.result.dump(), "table");
    ASSERT_EQ(t.status, MCP_OK) << t.error;
    EXPECT_NE(t.result.get<std::string>().find("  ERROR   pdf_support: "), std::string::npos);
}

TEST(Api, ErrorMessagesStayOnOneLine) {
    // User text quoted in a message (a key, a type name) may hold control characters: they
    // are written as escapes (found by fuzz/fuzz_scene.cpp).
    for (const char* scene :
         {"{\"\\n\"", R"({"integrand": {"type": "a\nb\u0001"}})", R"({"f": "x", "n\tmax": 3})"}) {
        Outcome o = run(scene);
        EXPECT_EQ(o.status, MCP_ERROR_SCENE) << scene;
        EXPECT_EQ(o.error.find_first_of("\n\t\x01"), std::string::npos) << o.error;
        EXPECT_FALSE(o.error.empty());
    }
    EXPECT_NE(run(R"({"integrand": {"type": "a\nb"}})").error.find("unknown integrand 'a\\nb'"),
              std::string::npos);
}

// Issue 48: a typed warp that leaves its domain is refused by warp-test, and a study with it
// as its proposal ran silently (g = 2u on [0, 1] with f = x reported 0.9968 +- 0.0013 for 0.5).
// Every block of a typed warp is now checked: the study fails with an error naming the
// estimator and the point, as warp-test does; the same study with a warp that stays inside (g =
// u^2, p = 1 / (2 sqrt(x))) runs and covers 0.5 (within 5 standard errors: a fixed seed).
TEST(Api, AStudyWhoseWarpLeavesItsDomainFailsNamingThePoint) {
    auto scene = [](const char* g, const char* p, const char* extra) {
        return std::string(R"({"warp": {"domain": {"type": "interval", "lower": 0, "upper": 1},
            "g": [")") +
               g + R"("], "p": ")" + p + R"("}, "f": "x", "estimators": ["warp"],
            "n_min": 64, "n_max": 1024, "reps": 4, "seed": 3)" +
               extra + "}";
    };
    const Outcome inside = run(scene("u^2", "0.5 / sqrt(x)", ""));
    ASSERT_EQ(inside.status, MCP_OK) << inside.error;
    const json& top = inside.result["estimators"][0]["levels"].back();
    EXPECT_LT(std::fabs(top["mean"].get<double>() - 0.5), 5.0 * top["std_error"].get<double>());
    for (const char* extra : {"", R"(, "rel_tol": 0.01)"}) {
        const Outcome outside = run(scene("2*u", "0.5", extra));
        EXPECT_EQ(outside.status, MCP_ERROR_SCENE) << extra;
        EXPECT_TRUE(outside.result.is_null());
        EXPECT_NE(outside.error.find("estimator 'warp': its warp put a point outside its domain"),
                  std::string::npos)
            << outside.error;
        EXPECT_NE(outside.error.find(", outside its domain, the [0, 1]"), std::string::npos)
            << outside.error;
        EXPECT_EQ(outside.error.find('\n'), std::string::npos);
    }
    // Split into parts, each part is refused too.
    char* out = nullptr;
    EXPECT_EQ(mcp_study_run(scene("2*u", "0.5", "").c_str(), R"({"part": 0, "parts": 2})", nullptr,
                            nullptr, &out),
              MCP_ERROR_SCENE);
    EXPECT_EQ(out, nullptr);
}

namespace {

std::string warp_scene(const json& warp) {
    return json{{"f", "1"}, {"warp", warp}, {"estimators", {"warp"}}, {"n_max", 64}, {"reps", 4}}
        .dump();
}

} // namespace

// Issue 48: a named warp reads its own parameters only. Each warp's own parameters are taken;
// a parameter it does not read (another warp's) is refused, naming it and the warp's own.
TEST(Api, NamedWarpsTakeTheirOwnParametersOnly) {
    const json own = {
        {"uniform", {{"lower", {0, 0}}, {"upper", {2, 1}}}},
        {"polar_disk", {{"center", {1, 0}}, {"radius", 2}}},
        {"concentric_disk", {{"center", {1, 0}}, {"radius", 2}}},
        {"uniform_sphere", json::object()},
        {"uniform_hemisphere", json::object()},
        {"cosine_hemisphere", json::object()},
        {"triangle", {{"vertices", {{0, 0}, {2, 0}, {0, 1}}}}},
        {"tabulated_1d", {{"lower", 0}, {"upper", 2}, {"f", "1 + x"}, {"bins", 8}}},
        {"tabulated_2d", {{"f", "1 + x*y"}, {"nx", 4}, {"ny", 3}}},
        {"ggx_visible_normals", {{"alpha", 0.3}, {"wo", {0, 0, 1}}}},
        {"spherical_triangle",
         {{"a", {1, 0, 1}}, {"b", {0, 1, 1}}, {"c", {0, 0, 1}}, {"viewpoint", {0, 0, -1}}}},
    };
    for (auto it = own.begin(); it != own.end(); ++it) {
        json warp = it.value();
        warp["name"] = it.key();
        const Outcome right = plan(warp_scene(warp));
        EXPECT_EQ(right.status, MCP_OK) << it.key() << ": " << right.error;
        const char* foreign = it.key() == "ggx_visible_normals" ? "radius" : "alpha";
        warp[foreign] = 0.5;
        const Outcome wrong = plan(warp_scene(warp));
        EXPECT_EQ(wrong.status, MCP_ERROR_SCENE) << it.key();
        const std::string says =
            std::string("unknown parameter '") + foreign + "' of the warp '" + it.key() + "' (";
        EXPECT_NE(wrong.error.find(says), std::string::npos) << wrong.error;
        EXPECT_NE(wrong.error.find(it.value().empty() ? "it takes none" : "its parameters: "),
                  std::string::npos)
            << wrong.error;
    }
    // Every warp of the catalog is in the table above (a new warp must say what it reads).
    char* out = nullptr;
    ASSERT_EQ(mcp_catalog(&out), MCP_OK);
    const json catalog = json::parse(out);
    mcp_free(out);
    ASSERT_TRUE(catalog.contains("warps"));
    for (const json& w : catalog["warps"]) EXPECT_TRUE(own.contains(w["name"])) << w.dump();
}

// Issue 48: a table's count given as 0 is refused, not read as the default (bins 0 gave 64);
// 1 is the smallest taken, and leaving it out takes the default.
TEST(Api, NamedWarpCountsOfZeroAreRefused) {
    const json cases[] = {{{"name", "tabulated_1d"}, {"f", "1 + x"}, {"bins", 0}},
                          {{"name", "tabulated_2d"}, {"f", "1 + x"}, {"nx", 0}, {"ny", 4}},
                          {{"name", "tabulated_2d"}, {"f", "1 + x"}, {"nx", 4}, {"ny", 0}}};
    const char* fields[] = {"warp.bins", "warp.nx", "warp.ny"};
    for (size_t k = 0; k < 3; ++k) {
        const Outcome zero = plan(warp_scene(cases[k]));
        EXPECT_EQ(zero.status, MCP_ERROR_SCENE) << cases[k].dump();
        EXPECT_NE(zero.error.find(std::string(fields[k]) + ": must be in 1..4096, got 0"),
                  std::string::npos)
            << zero.error;
        json one = cases[k];
        for (const char* key : {"bins", "nx", "ny"})
            if (one.contains(key) && one[key] == 0) one[key] = 1;
        EXPECT_EQ(plan(warp_scene(one)).status, MCP_OK) << one.dump();
    }
    EXPECT_EQ(plan(warp_scene({{"name", "tabulated_1d"}, {"f", "1 + x"}})).status, MCP_OK);
}

// Issue 48: max_seconds given is a budget, so 0 is refused (it read as "no budget"), in the
// scene or the options, with or without a tolerance; a positive budget with a tolerance runs.
TEST(Api, AZeroTimeBudgetIsRefused) {
    const std::string scene = R"({"f": "x", "estimators": ["uniform"], "reps": 4)";
    for (const char* extra : {R"(, "rel_tol": 0.1, "max_seconds": 0})", R"(, "max_seconds": 0})"}) {
        const Outcome o = plan(scene + extra);
        EXPECT_EQ(o.status, MCP_ERROR_SCENE) << extra;
        EXPECT_NE(o.error.find("scene: max_seconds: must be a finite number > 0, got 0"),
                  std::string::npos)
            << o.error;
    }
    const Outcome in_options = plan(scene + "}", R"({"rel_tol": 0.1, "max_seconds": 0})");
    EXPECT_EQ(in_options.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(in_options.error.find("options: max_seconds: must be a finite number > 0"),
              std::string::npos)
        << in_options.error;
    EXPECT_EQ(plan(scene + R"(, "rel_tol": 0.1, "max_seconds": 5})").status, MCP_OK);
    EXPECT_EQ(plan(scene + "}", R"({"rel_tol": 0.1, "max_seconds": 0.5})").status, MCP_OK);
}

// Issue 48: a heuristic weighs two or more techniques. Given to an estimator of one technique
// (a pdf, or one proposal) it was ignored; it is refused naming the estimator, and taken with
// two proposals or a defensive mixture.
TEST(Api, AHeuristicOverOneTechniqueIsRefused) {
    const std::string pdf = R"({"type": "power", "k": 1})";
    auto scene = [](const std::string& estimator) {
        return R"({"f": "x", "reps": 4, "n_max": 64, "estimators": [)" + estimator + "]}";
    };
    for (const std::string& one :
         {R"({"name": "is_power", "pdf": )" + pdf + R"(, "heuristic": "power"})",
          R"({"name": "is_power", "proposals": [)" + pdf + R"(], "heuristic": "power"})"}) {
        const Outcome o = plan(scene(one));
        EXPECT_EQ(o.status, MCP_ERROR_SCENE) << one;
        EXPECT_NE(o.error.find("scene.estimators[0].heuristic: estimator 'is_power' samples one "
                               "technique"),
                  std::string::npos)
            << o.error;
    }
    const std::string power = R"(, "heuristic": "power"})";
    for (const std::string& two :
         {R"({"name": "mis_power", "proposals": [)" + pdf + R"(, "uniform"])" + power,
          R"({"name": "mis_power", "pdf": )" + pdf + R"(, "defensive": 0.2)" + power})
        EXPECT_EQ(plan(scene(two)).status, MCP_OK) << two << ": " << plan(scene(two)).error;
}
