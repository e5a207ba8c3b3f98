// Integration studies and stopping runs split over processes: mcp_study_run with options.part
// and options.parts, merged by mcp_study_merge, give one run's result bit for bit (timing fields
// aside); parts that are not of one study, overlap, miss replicates or carry numbers out of
// range are refused with the field named.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/mcplay.h"

using nlohmann::json;

namespace {

// An exact value (so bias, MSE and coverage are computed), a fixed, a stratified, a randomized
// QMC (batch error units) and an adaptive estimator.
const char* kScene = R"({"name": "parts", "integrand": {"type": "monomial", "powers": [2]},
  "estimators": ["uniform", "stratified", "sobol", "vegas"], "n_min": 64, "n_max": 1024,
  "reps": 6, "seed": 5})";

json call_run(const std::string& scene, const json& options, int* status, std::string* error) {
    char* out = nullptr;
    const std::string o = options.dump();
    *status = mcp_study_run(scene.c_str(), o.c_str(), nullptr, nullptr, &out);
    *error = mcp_last_error();
    json j = out ? json::parse(out) : json();
    mcp_free(out);
    return j;
}

json run_ok(const std::string& scene, const json& options) {
    int status = 0;
    std::string error;
    json j = call_run(scene, options, &status, &error);
    EXPECT_EQ(status, MCP_OK) << error;
    return j;
}

struct Merged {
    int status = 0;
    std::string error;
    json result;
};

Merged merge(const std::vector<json>& parts) {
    Merged m;
    char* out = nullptr;
    const std::string in = json{{"parts", parts}}.dump();
    m.status = mcp_study_merge(in.c_str(), &out);
    m.error = mcp_last_error();
    if (out) m.result = json::parse(out);
    mcp_free(out);
    return m;
}

std::vector<json> parts_of(const std::string& scene, json options, int k) {
    std::vector<json> parts;
    for (int i = 0; i < k; ++i) {
        options["part"] = i;
        options["parts"] = k;
        parts.push_back(run_ok(scene, options));
    }
    return parts;
}

/// The result without its timing fields: wall_time_s, the levels' time_* and
/// training_time_mean, efficiency, and the stopping runs' seconds (seconds, seconds_min, ...).
json without_timing(json j) {
    if (j.is_object()) {
        json out = json::object();
        for (auto it = j.begin(); it != j.end(); ++it) {
            const std::string& k = it.key();
            if (k == "wall_time_s" || k == "efficiency" || k.rfind("time_", 0) == 0 ||
                k.rfind("training_time", 0) == 0 || k.find("seconds") != std::string::npos)
                continue;
            out[k] = without_timing(it.value());
        }
        return out;
    }
    if (j.is_array()) {
        json out = json::array();
        for (const json& x : j) out.push_back(without_timing(x));
        return out;
    }
    return j;
}

/// Asserts that the merge refuses and that its message names `field`.
void expect_refused(const std::vector<json>& parts, const std::string& field) {
    const Merged m = merge(parts);
    EXPECT_EQ(m.status, MCP_ERROR_ARGUMENT) << "expected a refusal naming " << field;
    EXPECT_NE(m.error.find(field), std::string::npos) << "message: " << m.error;
}

TEST(StudyParts, MergedPartsEqualOneRunBitForBit) {
    const json whole = run_ok(kScene, json{{"threads", 2}});
    ASSERT_EQ(whole["estimators"].size(), 4u);
    const json expected = without_timing(whole);
    for (int k : {1, 2, 3}) {
        std::vector<json> parts = parts_of(kScene, json{{"threads", 2}}, k);
        for (const json& p : parts) EXPECT_EQ(p["kind"], "study_part");
        const Merged m = merge(parts);
        ASSERT_EQ(m.status, MCP_OK) << m.error;
        // Every number but the timings: means, variances, intervals, coverage, diagnostics
        // (pooled weight moments, tail index), flags, fits and warnings.
        EXPECT_EQ(without_timing(m.result), expected) << "K = " << k;
        EXPECT_EQ(m.result["settings"], whole["settings"]) << "K = " << k;
        // Parts given in any order, and from machines with other thread counts, merge the same.
        if (k == 3) {
            std::swap(parts[0], parts[2]);
            json options{{"threads", 1}, {"part", 1}, {"parts", 3}};
            parts[1] = run_ok(kScene, options);
            const Merged again = merge(parts);
            ASSERT_EQ(again.status, MCP_OK) << again.error;
            EXPECT_EQ(without_timing(again.result), expected);
        }
    }
}

TEST(StudyParts, StoppingRunsMergeToOneRun) {
    const json options{{"rel_tol", 2e-3}, {"reps", 5}, {"estimators", {"uniform", "stratified"}}};
    const json whole = run_ok(kScene, options);
    ASSERT_EQ(whole["kind"], "stopping");
    const json expected = without_timing(whole);
    for (int k : {1, 2, 3}) {
        const std::vector<json> parts = parts_of(kScene, options, k);
        for (const json& p : parts) EXPECT_EQ(p["kind"], "stopping_part");
        const Merged m = merge(parts);
        ASSERT_EQ(m.status, MCP_OK) << m.error;
        EXPECT_EQ(without_timing(m.result), expected) << "K = " << k;
    }
}

TEST(StudyParts, PartOptionsAreChecked) {
    int status = 0;
    std::string error;
    call_run(kScene, json{{"part", 0}, {"parts", 7}}, &status, &error);
    EXPECT_EQ(status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(error.find("options.parts"), std::string::npos) << error;
    call_run(kScene, json{{"part", 2}, {"parts", 2}}, &status, &error);
    EXPECT_EQ(status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(error.find("options.part"), std::string::npos) << error;
    call_run(kScene, json{{"part", -1}, {"parts", 2}}, &status, &error);
    EXPECT_EQ(status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(error.find("options.part"), std::string::npos) << error;
    // the largest K accepted: one replicate per part
    call_run(kScene, json{{"part", 5}, {"parts", 6}}, &status, &error);
    EXPECT_EQ(status, MCP_OK) << error;
}

TEST(StudyParts, PartsOfDifferentStudiesAreRefusedNamingTheField) {
    const json base{{"estimators", {"uniform", "stratified"}}, {"n_max", 256}};
    auto part = [&](int i, int k, json extra) {
        json o = base;
        for (auto it = extra.begin(); it != extra.end(); ++it) o[it.key()] = it.value();
        o["part"] = i;
        o["parts"] = k;
        return run_ok(kScene, o);
    };
    const json p0 = part(0, 2, json::object());
    const json p1 = part(1, 2, json::object());
    ASSERT_EQ(merge({p0, p1}).status, MCP_OK); // the accepted case
    expect_refused({p0, part(1, 2, {{"seed", 9}})}, "seed");
    expect_refused({p0, part(1, 2, {{"reps", 8}})}, "reps");
    expect_refused({p0, part(1, 2, {{"n_max", 512}})}, "n_max");
    expect_refused({p0, part(1, 2, {{"n_min", 128}})}, "n_min");
    expect_refused({p0, part(1, 2, {{"estimators", {"uniform", "sobol"}}})}, "estimators");
    expect_refused({p0, part(1, 2, {{"rel_tol", 1e-2}})}, "kind");
    // a different scene (same settings): its text differs
    json other = json::parse(kScene);
    other["integrand"]["powers"] = {3};
    json o = base;
    o["part"] = 1;
    o["parts"] = 2;
    expect_refused({p0, run_ok(other.dump(), o)}, "scene");
    // the accumulator is a scene setting: float32 sums make another scene
    json float32 = json::parse(kScene);
    float32["accumulator"] = "float32";
    expect_refused({p0, run_ok(float32.dump(), o)}, "scene");
    // stopping runs at different tolerances
    const json s0 = part(0, 2, {{"rel_tol", 1e-2}});
    ASSERT_EQ(merge({s0, part(1, 2, {{"rel_tol", 1e-2}})}).status, MCP_OK);
    expect_refused({s0, part(1, 2, {{"rel_tol", 2e-2}})}, "rel_tol");
    expect_refused({s0, part(1, 2, {{"rel_tol", 1e-2}, {"abs_tol", 1e-3}})}, "abs_tol");
}

TEST(StudyParts, MissingOverlappingAndForeignPartsAreRefused) {
    const json base{{"estimators", {"uniform"}}, {"n_max", 256}};
    std::vector<json> three = parts_of(kScene, base, 3);
    ASSERT_EQ(merge(three).status, MCP_OK);
    expect_refused({three[0], three[2]}, "part 1 of 3 is missing"); // 2 files, parts of 3
    expect_refused({three[0], three[1], three[1]}, "given twice");  // overlapping replicates
    std::vector<json> two = parts_of(kScene, base, 2);
    expect_refused({two[0], three[1]}, "part.of"); // parts of different splits
    // a part relabelled: its replicates are not the ones of its index
    json relabelled = two[1];
    relabelled["part"]["index"] = 0;
    expect_refused({relabelled, two[1]}, "replicate");
    // a part that lost a replicate's run
    json short_part = two[1];
    short_part["estimators"][0]["levels"][0]["runs"].erase(0);
    expect_refused({two[0], short_part}, "runs");
    // not a part at all: a whole study's result
    expect_refused({run_ok(kScene, base), two[1]}, "kind");
    // empty and oversized lists
    expect_refused({}, "parts");
    const std::vector<json> many(1025, two[0]);
    expect_refused(many, "parts");
}

TEST(StudyParts, NumbersOutOfRangeAreRefusedNamingTheField) {
    const json base{{"estimators", {"uniform"}}, {"n_max", 256}};
    const std::vector<json> parts = parts_of(kScene, base, 2);
    ASSERT_EQ(merge(parts).status, MCP_OK);
    struct Edit {
        const char* field;
        std::function<void(json&)> apply;
    };
    const std::vector<Edit> edits = {
        {"std_error", [](json& r) { r["std_error"] = -1.0; }},
        {"dof", [](json& r) { r["dof"] = -3; }},
        {"seconds", [](json& r) { r["seconds"] = "nan"; }},
        {"estimate", [](json& r) { r["estimate"] = "huge"; }},
        {"estimate", [](json& r) { r.erase("estimate"); }},
        {".n", [](json& r) { r["n"] = 65; }},
        {"nonfinite", [](json& r) { r["diagnostics"]["nonfinite"] = 1000000; }},
        {"max_weight_share", [](json& r) { r["diagnostics"]["max_weight_share"] = 1.5; }},
        {"ess", [](json& r) { r["diagnostics"]["ess"] = -2.0; }},
        {"m2", [](json& r) { r["diagnostics"]["weights"]["m2"] = -1.0; }},
        {"weights.n", [](json& r) { r["diagnostics"]["weights"]["n"] = 1u << 30; }},
        {"top", [](json& r) { r["top"].push_back(1e300); }},
        {"training_n", [](json& r) { r["training_n"] = 1u << 20; }},
    };
    for (const Edit& e : edits) {
        std::vector<json> bad = parts;
        e.apply(bad[1]["estimators"][0]["levels"][0]["runs"][1]);
        expect_refused(bad, e.field);
    }
    // The accepted side of the same fields: a run without an estimate (NaN) merges.
    std::vector<json> nan_estimate = parts;
    nan_estimate[1]["estimators"][0]["levels"][0]["runs"][1]["estimate"] = "nan";
    EXPECT_EQ(merge(nan_estimate).status, MCP_OK) << merge(nan_estimate).error;
}

} // namespace
