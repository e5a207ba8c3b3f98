// The sampler lab's C functions: a sampler's points, the analysis of point sets a user brings
// (CSV and JSON, with their errors), the rule's estimate with one and with K sets, and the
// discrepancy curve. The measures themselves are tested in test_point_analysis.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "api/mcplay.h"
#include "core/special.h"
#include "render_api/mcplay_render.h"

using nlohmann::json;

namespace {

struct Call {
    int status = 0;
    std::string error;
    json result;
};

template <class F> Call call(F f) {
    char* out = nullptr;
    Call c;
    c.status = f(&out);
    c.error = mcp_last_error();
    if (out) {
        c.result = json::parse(out);
        mcp_free(out);
    }
    return c;
}

Call points(const json& request) {
    const std::string text = request.dump();
    return call([&](char** out) { return mcp_points(text.c_str(), out); });
}
Call analyze(const json& request) {
    const std::string text = request.dump();
    return call([&](char** out) { return mcp_points_analyze(text.c_str(), out); });
}
Call integrate(const json& scene, const json& request) {
    const std::string s = scene.dump(), r = request.dump();
    return call([&](char** out) { return mcp_points_integrate(s.c_str(), r.c_str(), out); });
}

} // namespace

TEST(SamplerLabPoints, DrawsTheRequestedSetInTheUnitCube) {
    for (const char* sampler :
         {"uniform", "stratified", "latin_hypercube", "sobol", "halton", "lattice"}) {
        Call c = points({{"sampler", sampler}, {"n", 64}, {"dim", 3}, {"seed", 5}});
        ASSERT_EQ(c.status, MCP_OK) << sampler << ": " << c.error;
        ASSERT_EQ(c.result["points"].size(), 64u) << sampler;
        for (const json& row : c.result["points"]) {
            ASSERT_EQ(row.size(), 3u);
            for (const json& v : row) {
                EXPECT_GE(v.get<double>(), 0.0);
                EXPECT_LT(v.get<double>(), 1.0);
            }
        }
    }
}

TEST(SamplerLabPoints, LatinHypercubeHasOnePointPerSlab) {
    Call c = points({{"sampler", "latin_hypercube"}, {"n", 50}, {"dim", 2}, {"seed", 2}});
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    for (int k = 0; k < 2; ++k) {
        std::vector<int> slabs(50, 0);
        for (const json& row : c.result["points"]) ++slabs[size_t(row[k].get<double>() * 50)];
        for (int s : slabs) EXPECT_EQ(s, 1);
    }
}

TEST(SamplerLabPoints, UnscrambledSobolIsTheVanDerCorputSequenceInItsFirstAxis) {
    Call c = points({{"sampler", "sobol"}, {"randomization", "none"}, {"n", 8}, {"dim", 1}});
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    // Gray-code order visits the same set as the radical inverse: {0, 1/8, ..., 7/8} (plus the
    // half-step of the 53-bit conversion).
    std::vector<int> seen(8, 0);
    for (const json& row : c.result["points"]) ++seen[size_t(row[0].get<double>() * 8)];
    for (int s : seen) EXPECT_EQ(s, 1);
    EXPECT_EQ(c.result["randomization"], "none");
}

TEST(SamplerLabPoints, SameSeedSamePointsOtherSeedOtherPoints) {
    json r{{"sampler", "sobol"}, {"n", 16}, {"dim", 2}, {"seed", 7}};
    Call a = points(r), b = points(r);
    r["seed"] = 8;
    Call d = points(r);
    EXPECT_EQ(a.result["points"], b.result["points"]);
    EXPECT_NE(a.result["points"], d.result["points"]);
}

TEST(SamplerLabPoints, BadRequestsNameTheField) {
    EXPECT_NE(points({{"sampler", "faure"}, {"n", 4}}).error.find("unknown sampler 'faure'"),
              std::string::npos);
    EXPECT_NE(points({{"sampler", "sobol"}, {"n", 0}}).error.find("n: expected 1 to"),
              std::string::npos);
    EXPECT_NE(points({{"sampler", "sobol"}, {"n", 4}, {"dim", 1000}})
                  .error.find("request.dim: expected 1 to 64, got 1000"),
              std::string::npos);
    EXPECT_NE(points({{"sampler", "uniform"}, {"n", 4}, {"randomization", "owen"}})
                  .error.find("randomization"),
              std::string::npos);
    EXPECT_NE(points({{"sampler", "lattice"}, {"n", 4}, {"randomization", "owen"}})
                  .error.find("randomization"),
              std::string::npos);
    EXPECT_EQ(points({{"sampler", "sobol"}, {"n", 4}, {"seeds", 1}}).status, MCP_ERROR_ARGUMENT);
    EXPECT_EQ(points({{"sampler", "uniform"}, {"n", 1 << 20}, {"dim", 8}}).status,
              MCP_ERROR_ARGUMENT); // 2^23 numbers: beyond one answer's bound
}

TEST(SamplerLabCsv, ReadsHeaderSeparatorsCommentsAndSets) {
    Call c =
        analyze({{"csv", "# a comment\nx;y\n0.1;0.2\n\n0.3;0.4\n0.5 ;0.6\n"}, {"spectrum", false}});
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    EXPECT_EQ(c.result["n"], 3);
    EXPECT_EQ(c.result["dim"], 2);
    EXPECT_EQ(c.result["sets"], 1);
    Call k = analyze({{"csv", "set,x\na,0.1\nb,0.6\na,0.3\nb,0.9\n"}, {"spectrum", false}});
    ASSERT_EQ(k.status, MCP_OK) << k.error;
    EXPECT_EQ(k.result["n"], 2);
    EXPECT_EQ(k.result["dim"], 1);
    EXPECT_EQ(k.result["sets"], 2);
    EXPECT_EQ(k.result["set_names"], json({"a", "b"}));
    EXPECT_EQ(k.result["per_set"]["l2_star_discrepancy"].size(), 2u);
}

TEST(SamplerLabCsv, EachBadFileGetsOneLineNamingTheRow) {
    struct Case {
        const char* csv;
        const char* message;
    } cases[] = {
        {"0.1,0.2\n0.3\n", "row 2: expected 2 columns, got 1"},
        {"0.1,0.2\n0.3,abc\n", "row 2, column 2: 'abc' is not a number"},
        {"0.1,0.2\n0.3,nan\n", "row 2, column 2: NaN is not a coordinate"},
        {"0.1,0.2\n0.3,1\n", "row 2, column 2: '1' is outside [0, 1)"},
        {"0.1,0.2\n-0.0001,0.5\n", "row 2, column 1: '-0.0001' is outside [0, 1)"},
        {"0.1,0.2\n0.3,inf\n", "row 2, column 2: 'inf' is infinite"},
        {"", "the file holds no points"},
        {"x,y\n", "the file holds no points"},
        {"set,x\na,0.1\nb,0.2\na,0.3\n", "set 'b' has 1 points, set 'a' 2"},
    };
    for (const Case& k : cases) {
        Call c = analyze({{"csv", k.csv}, {"spectrum", false}});
        EXPECT_EQ(c.status, MCP_ERROR_ARGUMENT) << k.csv;
        EXPECT_NE(c.error.find(k.message), std::string::npos) << c.error;
        EXPECT_EQ(c.error.find('\n'), std::string::npos);
    }
    // Too many coordinates is refused before anything else is read.
    std::string wide;
    for (int k = 0; k < 65; ++k) wide += (k ? ",0.5" : "0.5");
    EXPECT_NE(analyze({{"csv", wide}}).error.find("at most 64"), std::string::npos);
}

// Issue 48: a header is a row none of whose fields is a number. A first row with one bad field
// among numbers was dropped as a "header" without a word (a point lost); now it is an error
// naming the field, a real header still reads, and a UTF-8 byte-order mark is skipped.
TEST(SamplerLabCsv, AHeaderHasNoNumberAndAByteOrderMarkIsSkipped) {
    auto points = [](const std::string& csv) {
        Call c = analyze({{"csv", csv}, {"spectrum", false}});
        return c.status == MCP_OK ? c.result["n"].get<int>() : -1;
    };
    EXPECT_EQ(points("x,y\n0.5,0.5\n0.25,0.75\n"), 2);
    EXPECT_EQ(points("x,,y\n0.5,0.5,0.5\n"), 1); // a header with an unnamed column: no number
    EXPECT_EQ(points("\xEF\xBB\xBF"
                     "0.5,0.5\n0.25,0.75\n"),
              2);
    EXPECT_EQ(points("\xEF\xBB\xBF"
                     "x,y\n0.5,0.5\n0.25,0.75\n"),
              2);
    struct Case {
        const char* csv;
        const char* message;
    } cases[] = {
        {"0.5e,0.5\n0.25,0.75\n", "row 1, column 1: '0.5e' is not a number (the row's other"},
        {"0.5,,0.5\n0.25,0.5,0.75\n", "row 1, column 2: the field is empty"},
        {"\xEF\xBB\xBF"
         "0.5,x\n",
         "row 1, column 2: 'x' is not a number"},
        {"0.5,0.5\n0.25,\n", "row 2, column 2: the field is empty"},
    };
    for (const Case& k : cases) {
        Call c = analyze({{"csv", k.csv}, {"spectrum", false}});
        EXPECT_EQ(c.status, MCP_ERROR_ARGUMENT) << k.csv;
        EXPECT_NE(c.error.find(k.message), std::string::npos) << c.error;
        EXPECT_EQ(c.error.find('\n'), std::string::npos);
    }
}

TEST(SamplerLabCsv, JsonRowsAndTheirErrors) {
    Call ok = analyze({{"points", {{0.25, 0.5}, {0.75, 0.0}}}, {"spectrum", false}});
    ASSERT_EQ(ok.status, MCP_OK) << ok.error;
    EXPECT_EQ(ok.result["n"], 2);
    Call sets = analyze({{"points", {{{0.25}, {0.75}}, {{0.1}, {0.6}}}}, {"spectrum", false}});
    ASSERT_EQ(sets.status, MCP_OK) << sets.error;
    EXPECT_EQ(sets.result["sets"], 2);
    EXPECT_NE(
        analyze({{"points", {{0.25, 0.5}, {0.75}}}}).error.find("request.points[1]: expected 2"),
        std::string::npos);
    EXPECT_NE(analyze({{"points", {{0.25, "a"}}}}).error.find("expected a number"),
              std::string::npos);
    EXPECT_NE(analyze({{"points", {{0.25, 1.5}}}}).error.find("outside [0, 1)"), std::string::npos);
    EXPECT_NE(analyze({{"csv", "0.5"}, {"points", {{0.5}}}}).error.find("exactly one"),
              std::string::npos);
}

TEST(SamplerLabAnalysis, AGridHasItsKnownDistanceAndSpectrumPeaks) {
    // The 8 x 8 grid of cell centres: minimum distance 1/8, spectrum peaks at multiples of 8.
    json rows = json::array();
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j) rows.push_back({(i + 0.5) / 8, (j + 0.5) / 8});
    Call c = analyze({{"points", rows}, {"spectrum", {{"size", 32}}}});
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    EXPECT_NEAR(c.result["min_distance"].get<double>(), 0.125, 1e-12);
    EXPECT_NEAR(c.result["min_distance_toroidal"].get<double>(), 0.125, 1e-12);
    const json& power = c.result["spectrum"]["power"];
    ASSERT_EQ(power.size(), 32u * 32u);
    EXPECT_NEAR(power[16 * 32 + 16].get<double>(), 64.0, 1e-9); // k = 0
    EXPECT_NEAR(power[16 * 32 + 24].get<double>(), 64.0, 1e-9); // k = (8, 0)
    EXPECT_NEAR(power[16 * 32 + 17].get<double>(), 0.0, 1e-9);  // k = (1, 0)
    EXPECT_TRUE(c.result["skipped"].empty());
}

TEST(SamplerLabAnalysis, SkipsThePairSumsBeyondTheirBoundAndSaysWhy) {
    // 140000 points in 2-D: 2e10 pair-coordinates, above the bound of 2^33.
    Call c = analyze({{"sampler", {{"sampler", "uniform"}, {"n", 140000}, {"dim", 2}}},
                      {"spectrum", {{"size", 8}}}});
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    EXPECT_TRUE(c.result["l2_star_discrepancy"].is_null());
    EXPECT_NE(c.result["skipped"]["l2_star_discrepancy"].get<std::string>().find("O(N^2 d)"),
              std::string::npos);
    EXPECT_EQ(c.result["spectrum"]["size"], 8);
    // The spectrum is bounded too: 140000 points on 1024 x 1024 frequencies (7e10 operations).
    Call big = analyze({{"sampler", {{"sampler", "uniform"}, {"n", 140000}, {"dim", 2}}},
                        {"spectrum", {{"size", 1024}}},
                        {"pairwise", false}});
    ASSERT_EQ(big.status, MCP_OK) << big.error;
    EXPECT_FALSE(big.result.contains("spectrum"));
    EXPECT_NE(big.result["skipped"]["spectrum"].get<std::string>().find("above the limit"),
              std::string::npos);
}

TEST(SamplerLabAnalysis, ScrambledSobolBeatsIndependentPointsOnL2Star) {
    Call sobol = analyze({{"sampler", {{"sampler", "sobol"}, {"n", 1024}, {"dim", 2}, {"sets", 4}}},
                          {"spectrum", false}});
    Call iid = analyze({{"sampler", {{"sampler", "uniform"}, {"n", 1024}, {"dim", 2}, {"sets", 4}}},
                        {"spectrum", false}});
    ASSERT_EQ(sobol.status, MCP_OK) << sobol.error;
    // Independent points: near the expected rms; Sobol' (N^-1 up to logs): far below it.
    const double expected = iid.result["expected_iid"]["l2_star_discrepancy"].get<double>();
    EXPECT_LT(sobol.result["l2_star_discrepancy"].get<double>(), 0.2 * expected);
    EXPECT_GT(iid.result["l2_star_discrepancy"].get<double>(), 0.4 * expected);
}

TEST(SamplerLabIntegrate, OneSetIsARuleWithoutErrorBarKSetsGetTheTInterval) {
    const json scene{{"name", "x2"}, {"integrand", {{"type", "monomial"}, {"powers", {2}}}}};
    Call one = integrate(scene, {{"points", {{0.25}, {0.75}}}});
    ASSERT_EQ(one.status, MCP_OK) << one.error;
    EXPECT_DOUBLE_EQ(one.result["estimate"].get<double>(), (0.0625 + 0.5625) / 2);
    EXPECT_TRUE(one.result["error_bar"].is_null());
    EXPECT_NEAR(one.result["error"].get<double>(), 0.3125 - 1.0 / 3.0, 1e-15);
    // K = 2 sets: estimates 0.3125 and 0.25: mean 0.28125, s = 0.0441942, SE = s / sqrt(2).
    Call two = integrate(scene, {{"points", {{{0.25}, {0.75}}, {{0.0}, {0.70710678118654752}}}}});
    ASSERT_EQ(two.status, MCP_OK) << two.error;
    const double a = 0.3125, b = 0.25, mean = 0.5 * (a + b);
    const double se = std::sqrt(((a - mean) * (a - mean) + (b - mean) * (b - mean)) / 2.0);
    EXPECT_NEAR(two.result["estimate"].get<double>(), mean, 1e-15);
    EXPECT_NEAR(two.result["error_bar"]["standard_error"].get<double>(), se, 1e-12);
    EXPECT_NEAR(two.result["error_bar"]["half_width_95"].get<double>(),
                mcp::student_t_quantile(0.975, 1.0) * se, 1e-12);
}

// Issue 48: the t interval of K sets never claims a certainty the sets cannot show. Identical
// sets are no randomizations (no error bar, and the note says which); estimates near 1e-170,
// whose squares underflow, keep their true standard error (it was 0); estimates that agree to
// round-off (f constant) get no zero-width interval. The note says why in each case.
TEST(SamplerLabIntegrate, NoZeroWidthErrorBar) {
    const json a = {{0.25}, {0.75}}, b = {{0.0}, {0.70710678118654752}};
    const json x2{{"name", "x2"}, {"f", "x*x"}};
    Call twins = integrate(x2, {{"points", {a, b, a}}});
    ASSERT_EQ(twins.status, MCP_OK) << twins.error;
    EXPECT_TRUE(twins.result["error_bar"].is_null());
    EXPECT_NE(twins.result["note"].get<std::string>().find(
                  "sets 1 and 3 (counting from 1) are identical"),
              std::string::npos)
        << twins.result["note"];
    // Tiny: the same two sets on 1e-170 x^2; its standard error is 1e-170 times x^2's.
    Call plain = integrate(x2, {{"points", {a, b}}});
    Call tiny = integrate({{"name", "tiny"}, {"f", "1e-170*x*x"}}, {{"points", {a, b}}});
    ASSERT_EQ(tiny.status, MCP_OK) << tiny.error;
    ASSERT_TRUE(tiny.result["error_bar"].is_object()) << tiny.result;
    const double se = plain.result["error_bar"]["standard_error"].get<double>();
    EXPECT_NEAR(tiny.result["error_bar"]["standard_error"].get<double>() / 1e-170, se, 1e-12 * se);
    Call flat = integrate({{"name", "one"}, {"f", "1"}}, {{"points", {a, b}}});
    ASSERT_EQ(flat.status, MCP_OK) << flat.error;
    EXPECT_TRUE(flat.result["error_bar"].is_null());
    EXPECT_NE(flat.result["note"].get<std::string>().find("agree to round-off"), std::string::npos)
        << flat.result["note"];
}

TEST(SamplerLabIntegrate, RandomizedSetsCoverTheExactValue) {
    // 32 runs of K = 8 scrambled Sobol' sets on a smooth 3-D integrand: the 95% t interval
    // should cover in about 95% of runs; at least 26 of 32 (binomial tail < 1% at p = 0.95).
    const json scene{{"name", "e"},
                     {"integrand", {{"type", "exponential"}, {"rates", {1, 2, 0.5}}}}};
    int covered = 0;
    for (int run = 0; run < 32; ++run) {
        Call c = integrate(
            scene,
            {{"sampler",
              {{"sampler", "sobol"}, {"n", 64}, {"dim", 3}, {"seed", 100 + run}, {"sets", 8}}}});
        ASSERT_EQ(c.status, MCP_OK) << c.error;
        covered += std::fabs(c.result["error"].get<double>()) <=
                   c.result["error_bar"]["half_width_95"].get<double>();
    }
    EXPECT_GE(covered, 26);
}

TEST(SamplerLabIntegrate, PointsOfTheWrongDimensionAreRefused) {
    const json scene{{"name", "x2"}, {"integrand", {{"type", "monomial"}, {"powers", {2}}}}};
    Call c = integrate(scene, {{"points", {{0.25, 0.5}}}});
    EXPECT_EQ(c.status, MCP_ERROR_ARGUMENT);
    EXPECT_NE(c.error.find("2 coordinates"), std::string::npos) << c.error;
}

TEST(SamplerLabCurve, QmcDiscrepancyFallsFasterThanIndependent) {
    const std::string request =
        R"({"samplers": ["uniform", "sobol"], "dim": 2, "n_min": 64, "n_max": 1024, "reps": 4,
            "scene": {"integrand": {"type": "genz_gaussian", "a": [2, 2], "u": [0.3, 0.6]}}})";
    Call c = call([&](char** out) { return mcp_discrepancy_curve(request.c_str(), out); });
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    ASSERT_EQ(c.result["curves"].size(), 2u);
    const json& iid = c.result["curves"][0];
    const json& sobol = c.result["curves"][1];
    ASSERT_EQ(iid["n"].size(), 5u);
    // From N = 64 to 1024 (16x): independent points fall by about 4x (N^-1/2), Sobol' by more
    // than 8x (N^-1 up to logs).
    const double iid_ratio =
        iid["l2_star_discrepancy"][0].get<double>() / iid["l2_star_discrepancy"][4].get<double>();
    const double sobol_ratio = sobol["l2_star_discrepancy"][0].get<double>() /
                               sobol["l2_star_discrepancy"][4].get<double>();
    EXPECT_GT(iid_ratio, 2.0);
    EXPECT_LT(iid_ratio, 8.0);
    EXPECT_GT(sobol_ratio, 8.0);
    EXPECT_EQ(sobol["rms_error"].size(), 5u);
    EXPECT_LT(sobol["rms_error"][4].get<double>(), iid["rms_error"][4].get<double>());
}

namespace {

Call warp_test(const json& scene, const json& options = json::object()) {
    const std::string s = scene.dump(), o = options.dump();
    return call([&](char** out) { return mcp_warp_test(s.c_str(), o.c_str(), out); });
}

const json kPolarDisk{{"domain", {{"type", "disk"}, {"radius", 1}}},
                      {"g", {"sqrt(u1)*cos(2*pi*u2)", "sqrt(u1)*sin(2*pi*u2)"}},
                      {"p", "1/pi"}};

} // namespace

TEST(SamplerLabWarpTest, ReportsTheDocumentedFields) {
    Call c = warp_test({{"warp", kPolarDisk}}, {{"samples", 100000}, {"seed", 3}});
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    for (const char* key : {"p_value", "passed", "pdf_integral", "bins", "worst_bins", "verdict",
                            "coordinates", "observed", "expected", "dof", "level"})
        EXPECT_TRUE(c.result.contains(key)) << key;
    EXPECT_EQ(c.result["bins"].size(), 2u);
    EXPECT_EQ(c.result["observed"].size(),
              c.result["bins"][0].get<size_t>() * c.result["bins"][1].get<size_t>());
    EXPECT_NEAR(c.result["pdf_integral"].get<double>(), 1.0, 1e-9);
    EXPECT_EQ(c.result["samples"], 100000);
}

TEST(SamplerLabWarpTest, TheCourseNotesMistakeFailsAndItsFixPasses) {
    json wrong = kPolarDisk;
    wrong["g"] = {"u1*cos(2*pi*u2)", "u1*sin(2*pi*u2)"};
    Call bad = warp_test({{"warp", wrong}}, {{"samples", 1000000}});
    ASSERT_EQ(bad.status, MCP_OK) << bad.error; // a failed test is a result
    EXPECT_FALSE(bad.result["passed"].get<bool>());
    EXPECT_LT(bad.result["p_value"].get<double>(), 1e-12);
    // The worst bins are at the centre (the wrong map crowds it): the first radial bin.
    EXPECT_EQ(bad.result["worst_bins"][0]["index"][0], 0);
    EXPECT_GT(bad.result["worst_bins"][0]["residual"].get<double>(), 10.0);
    Call good = warp_test({{"warp", kPolarDisk}}, {{"samples", 1000000}, {"seed", 2}});
    ASSERT_EQ(good.status, MCP_OK) << good.error;
    // A right warp fails at level 0.01 with probability 0.01: seed 2 fixed.
    EXPECT_TRUE(good.result["passed"].get<bool>()) << good.result["verdict"];
}

// The three outcomes in JSON: "passed" true, false, or null with "outcome": "unverified" where
// the test could not settle the verdict (here 4 samples: one cell after pooling).
TEST(SamplerLabWarpTest, OutcomesPassedFailedUnverified) {
    Call good = warp_test({{"warp", kPolarDisk}}, {{"samples", 100000}, {"seed", 2}});
    ASSERT_EQ(good.status, MCP_OK) << good.error;
    EXPECT_EQ(good.result["outcome"], "passed") << good.result["verdict"];
    EXPECT_EQ(good.result["passed"], true);
    EXPECT_EQ(good.result["p_value_range"][0], good.result["p_value"]); // a constant pdf: exact
    json wrong = kPolarDisk;
    wrong["g"] = {"u1*cos(2*pi*u2)", "u1*sin(2*pi*u2)"};
    Call bad = warp_test({{"warp", wrong}}, {{"samples", 100000}});
    ASSERT_EQ(bad.status, MCP_OK) << bad.error;
    EXPECT_EQ(bad.result["outcome"], "failed");
    EXPECT_EQ(bad.result["passed"], false);
    Call few = warp_test({{"warp", kPolarDisk}}, {{"samples", 4}});
    ASSERT_EQ(few.status, MCP_OK) << few.error;
    EXPECT_EQ(few.result["outcome"], "unverified") << few.result["verdict"];
    EXPECT_TRUE(few.result["passed"].is_null());
    EXPECT_EQ(few.result["verdict"].get<std::string>().rfind("could not verify: ", 0), 0u);
    EXPECT_EQ(few.result["expected_error"].size(), few.result["expected"].size());
}

TEST(SamplerLabWarpTest, NamedWarpsTheirParametersAndErrors) {
    Call named = warp_test({{"warp", "cosine_hemisphere"}}, {{"samples", 100000}});
    ASSERT_EQ(named.status, MCP_OK) << named.error;
    EXPECT_EQ(named.result["warp"], "cosine_hemisphere");
    Call ggx = warp_test({{"warp",
                           {{"name", "ggx_visible_normals"},
                            {"alpha", 0.3},
                            {"wo", {0.5, 0.0, 0.8660254037844386}}}}},
                         {{"samples", 100000}});
    ASSERT_EQ(ggx.status, MCP_OK) << ggx.error;
    Call unknown = warp_test({{"warp", "square_disk"}});
    EXPECT_EQ(unknown.status, MCP_ERROR_SCENE);
    EXPECT_NE(unknown.error.find("concentric_disk"), std::string::npos) << unknown.error;
    Call typo = warp_test({{"warp", {{"name", "polar_disk"}, {"radios", 2}}}});
    EXPECT_NE(typo.error.find("radios"), std::string::npos) << typo.error;
}

TEST(SamplerLabWarpTest, BadWarpsGetOneLineNamingTheSampleOrThePoint) {
    json outside = kPolarDisk;
    outside["g"] = {"2*sqrt(u1)*cos(2*pi*u2)", "2*sqrt(u1)*sin(2*pi*u2)"};
    Call a = warp_test({{"warp", outside}}, {{"samples", 1000}});
    EXPECT_EQ(a.status, MCP_ERROR_SCENE);
    EXPECT_NE(a.error.find("sample"), std::string::npos) << a.error;
    EXPECT_NE(a.error.find("outside"), std::string::npos) << a.error;
    json negative = kPolarDisk;
    negative["p"] = "x/pi";
    Call b = warp_test({{"warp", negative}}, {{"samples", 1000}});
    EXPECT_EQ(b.status, MCP_ERROR_SCENE);
    EXPECT_NE(b.error.find("the pdf is -"), std::string::npos) << b.error;
    EXPECT_NE(b.error.find("at x = ("), std::string::npos) << b.error;
    json nan = kPolarDisk;
    nan["p"] = "sqrt(x)/pi";
    Call d = warp_test({{"warp", nan}}, {{"samples", 1000}});
    EXPECT_EQ(d.status, MCP_ERROR_SCENE);
    EXPECT_NE(d.error.find("NaN"), std::string::npos) << d.error;
    json bad_expr = kPolarDisk;
    bad_expr["g"] = {"sqrt(u1)*cos(2*pi*u3)", "u2"};
    EXPECT_NE(warp_test({{"warp", bad_expr}}).error.find("u3"), std::string::npos);
    EXPECT_NE(warp_test({{"warp", kPolarDisk}}, {{"samples", 0}}).error.find("options.samples"),
              std::string::npos);
    EXPECT_NE(warp_test({{"f", "x"}}).error.find("no \"warp\""), std::string::npos);
    for (const Call& c : {a, b, d}) EXPECT_EQ(c.error.find('\n'), std::string::npos);
}

TEST(SamplerLabWarpTest, ATestedWarpBecomesTheImportanceSamplerOfAStudy) {
    // f = exp(-(x^2 + y^2)) on the unit disk: pi (1 - 1/e). The right warp's estimator must
    // agree with the exact value within its error bar; the wrong one is biased by far more.
    json scene{{"warp", kPolarDisk},
               {"f", "exp(-(x^2 + y^2))"},
               {"exact", 1.9858653037988714},
               {"estimators", {"uniform", "warp"}},
               {"n_min", 4096},
               {"n_max", 4096},
               {"reps", 8}};
    const std::string text = scene.dump();
    Call c = call(
        [&](char** out) { return mcp_study_run(text.c_str(), nullptr, nullptr, nullptr, out); });
    ASSERT_EQ(c.status, MCP_OK) << c.error;
    const json& warp = c.result["estimators"][1];
    EXPECT_EQ(warp["name"], "warp");
    const json& level = warp["levels"][0];
    const double exact = 1.9858653037988714;
    // The mean of 8 replicates within 4 standard errors of it (4.5 SE: t with 7 dof, p < 0.01).
    EXPECT_LT(std::fabs(level["mean"].get<double>() - exact),
              4.5 * level["std_error"].get<double>())
        << level["mean"] << " +- " << level["std_error"];
    // The wrong warp as an importance sampler: biased far beyond its error bar.
    json wrong = kPolarDisk;
    wrong["g"] = {"u1*cos(2*pi*u2)", "u1*sin(2*pi*u2)"};
    scene["warp"] = wrong;
    const std::string wrong_text = scene.dump();
    Call w = call([&](char** out) {
        return mcp_study_run(wrong_text.c_str(), nullptr, nullptr, nullptr, out);
    });
    ASSERT_EQ(w.status, MCP_OK) << w.error;
    const json& biased = w.result["estimators"][1]["levels"][0];
    EXPECT_GT(std::fabs(biased["mean"].get<double>() - exact),
              10.0 * biased["std_error"].get<double>());
    // Without an integrand a warp scene is for the warp test only, and says so.
    json alone{{"warp", kPolarDisk}};
    const std::string t2 = alone.dump();
    Call e =
        call([&](char** out) { return mcp_study_run(t2.c_str(), nullptr, nullptr, nullptr, out); });
    EXPECT_EQ(e.status, MCP_ERROR_SCENE);
    EXPECT_NE(e.error.find("warp-test"), std::string::npos) << e.error;
}

namespace {

Call pixel_points(const json& request) {
    const std::string text = request.dump();
    return call([&](char** out) { return mcp_render_pixel_points(text.c_str(), out); });
}

/// Whether every cell of a kx x ky grid over the unit square holds exactly one of the points.
bool one_per_cell(const json& rows, int kx, int ky) {
    std::vector<int> cells(size_t(kx * ky), 0);
    for (const json& r : rows)
        ++cells[size_t(int(r[0].get<double>() * kx) + kx * int(r[1].get<double>() * ky))];
    for (int c : cells)
        if (c != 1) return false;
    return true;
}

} // namespace

TEST(SamplerLabPixelPoints, SobolPixelsAreNetsAndStratifiedPixelsFillTheirStrata) {
    // A pixel's 64 Sobol' samples are a (0, 6, 2)-net: one point in every elementary interval
    // of area 1/64, whatever the pixel and image.
    for (const json& pixel : {json{0, 0}, json{5, 3}}) {
        Call c = pixel_points({{"pixel_sampler", "sobol"},
                               {"spp", 64},
                               {"width", 8},
                               {"height", 6},
                               {"pixel", pixel},
                               {"seed", 9}});
        ASSERT_EQ(c.status, MCP_OK) << c.error;
        ASSERT_EQ(c.result["points"].size(), 64u);
        for (int k = 0; k <= 6; ++k)
            EXPECT_TRUE(one_per_cell(c.result["points"], 1 << k, 1 << (6 - k))) << k;
    }
    Call st = pixel_points({{"pixel_sampler", "stratified"}, {"spp", 64}});
    ASSERT_EQ(st.status, MCP_OK) << st.error;
    EXPECT_TRUE(one_per_cell(st.result["points"], 8, 8));
    Call four = pixel_points({{"pixel_sampler", "independent"}, {"spp", 16}, {"dim", 4}});
    ASSERT_EQ(four.status, MCP_OK) << four.error;
    EXPECT_EQ(four.result["points"][0].size(), 4u);
    // The rows go straight into the analysis.
    Call a = analyze({{"points", four.result["points"]}, {"spectrum", false}});
    EXPECT_EQ(a.status, MCP_OK) << a.error;
}

TEST(SamplerLabPixelPoints, BadRequestsNameTheField) {
    EXPECT_NE(pixel_points({{"pixel_sampler", "halton"}}).error.find("unknown pixel sampler"),
              std::string::npos);
    EXPECT_NE(pixel_points({{"pixel_sampler", "sobol"}, {"spp", 48}}).error.find("power-of-two"),
              std::string::npos);
    EXPECT_NE(pixel_points({{"spp", 0}}).error.find("request.spp"), std::string::npos);
    EXPECT_NE(pixel_points({{"dim", 3}}).error.find("request.dim"), std::string::npos);
    EXPECT_NE(pixel_points({{"pixel", {4, 0}}, {"width", 4}}).error.find("request.pixel"),
              std::string::npos);
    EXPECT_EQ(pixel_points({{"spp", 4}, {"sampler", "sobol"}}).status, MCP_ERROR_ARGUMENT);
}

TEST(SamplerLabWarpTest, EveryNamedWarpOfTheCatalogIsTestableByName) {
    char* out = nullptr;
    ASSERT_EQ(mcp_catalog(&out), MCP_OK);
    const json catalog = json::parse(out);
    mcp_free(out);
    ASSERT_GE(catalog["warps"].size(), 11u);
    for (const json& w : catalog["warps"]) {
        EXPECT_FALSE(w["summary"].get<std::string>().empty());
        Call c = warp_test({{"warp", w["name"]}}, {{"samples", 20000}, {"seed", 4}});
        EXPECT_EQ(c.status, MCP_OK) << w["name"] << ": " << c.error;
        EXPECT_EQ(c.result["warp"], w["name"]);
    }
}
