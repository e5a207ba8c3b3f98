// Scene parsing (src/api/scene.cpp): every bad field is refused with one line naming its JSON
// path, before any work, and nothing runs as something other than what the scene says
// (issue 10).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>

#include "api/json_read.h"
#include "api/mcplay.h"
#include "api/scene.h"

namespace mcp {
namespace {

Made<SceneRequest> build(const std::string& scene, const std::string& options = "null") {
    Made<Json> s = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(s.ok()) << s.error;
    Made<Json> o = parse_json(options.c_str(), "options");
    EXPECT_TRUE(o.ok()) << o.error;
    return build_request(s.value, o.value);
}

std::string error_of(const std::string& scene, const std::string& options = "null") {
    Made<SceneRequest> r = build(scene, options);
    EXPECT_FALSE(r.ok()) << "accepted: " << scene.substr(0, 200);
    return r.error;
}

/// A JSON array of n copies of `item`.
std::string repeated(size_t n, const std::string& item) {
    std::string s = "[";
    for (size_t i = 0; i < n; ++i) s += (i ? "," : "") + item;
    return s + "]";
}

constexpr const char* kNewName = "; a new name needs \"sampler\", \"pdf\", \"vegas\", "
                                 "\"miser\", \"proposals\", \"control_variates\" or \"ris\")";

// The unknown-name message lists every preset of the registry, in its order (a new preset joins
// the message without a change here).
std::string presets_text() {
    std::string names;
    for (const EstimatorPreset& p : estimator_presets())
        names += (names.empty() ? "" : ", ") + std::string(p.name);
    return "presets: " + names;
}

// --- 1. estimator names -----------------------------------------------------------------

TEST(SceneParsing, UnknownEstimatorNamesAreRefused) {
    EXPECT_EQ(error_of(R"({"f": "x*x", "estimators": ["stratifed"]})"),
              std::string("scene.estimators[0]: unknown estimator 'stratifed' (did you mean "
                          "'stratified'? ") +
                  presets_text() + kNewName);
    EXPECT_EQ(error_of(R"({"f": "x*x", "estimators": ["uniform", "faure"]})"),
              std::string("scene.estimators[1]: unknown estimator 'faure' (") + presets_text() +
                  kNewName);
    // An object with only a name is a bare name too.
    EXPECT_EQ(error_of(R"({"f": "x*x", "estimators": [{"name": "latin_hypercub"}]})"),
              std::string("scene.estimators[0]: unknown estimator 'latin_hypercub' (did you "
                          "mean 'latin_hypercube'? ") +
                  presets_text() + kNewName);
    // A new name with its sampler or pdf spelled out is fine, and runs what it says.
    Made<SceneRequest> r = build(
        R"({"f": "x*x", "estimators": [{"name": "jitter", "sampler": "stratified"},
            {"name": "ramp", "pdf": {"type": "power", "k": 1}}]})");
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.value.estimators[0].sampler, SamplerKind::Stratified);
    EXPECT_TRUE(r.value.estimators[1].proposal.importance);
    // Options pick names the scene has, or presets; near misses get a hint.
    EXPECT_EQ(error_of(R"({"f": "x*x"})", R"({"estimators": ["uniform", "stratifed"]})"),
              std::string("options.estimators[1]: unknown estimator 'stratifed' (did you mean "
                          "'stratified'? this scene has: uniform, stratified, latin_hypercube; ") +
                  presets_text() + ")");
}

// A typed density that goes negative is an error at its field, not silently |p| (what the page's
// custom problem did with p = x - 0.5); a density that is zero everywhere too. The integrand's
// own shape is tabulated as |f|, the best density, and stays accepted where f changes sign.
TEST(SceneParsing, TypedDensitiesMustBeNonNegativeAndNotZero) {
    const std::string negative =
        error_of(R"J({"f": "exp(x)", "estimators": [{"name": "is", "pdf": "x - 0.5"}]})J");
    EXPECT_EQ(negative.rfind("scene.estimators[0].pdf.shape: a density must be >= 0", 0), 0u)
        << negative;
    EXPECT_NE(negative.find("write abs(...)"), std::string::npos);
    const std::string zero =
        error_of(R"J({"f": "exp(x)", "estimators": [{"name": "is", "pdf": "0 * x"}]})J");
    EXPECT_EQ(zero.rfind("scene.estimators[0].pdf.shape: the density is 0 at every one", 0), 0u)
        << zero;
    EXPECT_TRUE(build(R"J({"f": "sin(6*x)", "estimators": [{"name": "is", "pdf":
        {"type": "tabulated", "bins": 32, "shape": "integrand"}}]})J")
                    .ok());
    EXPECT_TRUE(
        build(R"J({"f": "exp(x)", "estimators": [{"name": "is", "pdf": "abs(x - 0.5)"}]})J").ok());
}

TEST(SceneParsing, PresetsAreNotRedefined) {
    EXPECT_EQ(
        error_of(R"({"f": "x", "estimators": [{"name": "uniform", "sampler": "stratified"}]})"),
        "scene.estimators[0].sampler: 'uniform' is the preset with the independent sampler; "
        "give the estimator another name to use stratified");
    EXPECT_EQ(error_of(R"({"f": "x", "estimators": [{"name": "stratified", "pdf": "x"}]})"),
              "scene.estimators[0].pdf: 'stratified' is a preset with the uniform density; give "
              "the estimator another name to sample a pdf");
    // Restating a preset's own sampler, or giving the pdf a preset needs, is fine.
    Made<SceneRequest> r = build(
        R"({"f": "x", "estimators": [{"name": "stratified", "sampler": "stratified"},
            {"name": "importance", "pdf": {"type": "power", "k": 1}}]})");
    EXPECT_TRUE(r.ok()) << r.error;
}

// --- 2. dimensions ------------------------------------------------------------------------

TEST(SceneParsing, GenzDimMustBeInRangeAndAgreeWithTheDomain) {
    EXPECT_EQ(error_of(R"({"integrand": {"type": "genz_gaussian", "dim": 10000}})"),
              "scene.integrand.dim: must be in 1..64, got 10000");
    EXPECT_EQ(error_of(R"({"integrand": {"type": "genz_gaussian", "dim": 65}})"),
              "scene.integrand.dim: must be in 1..64, got 65");
    EXPECT_EQ(error_of(R"({"integrand": {"type": "genz_gaussian", "dim": 0}})"),
              "scene.integrand.dim: must be in 1..64, got 0");
    EXPECT_EQ(error_of(R"({"integrand": {"type": "genz_gaussian", "dim": "12"}})"),
              "scene.integrand.dim: expected a non-negative whole number, got a string");
    EXPECT_EQ(error_of(R"({"integrand": {"type": "genz_gaussian", "dim": 2.5}})"),
              "scene.integrand.dim: expected a non-negative whole number, got 2.5");
    EXPECT_EQ(error_of(R"({"domain": {"type": "box", "dim": 2},
                           "integrand": {"type": "genz_gaussian", "dim": 12}})"),
              "scene.integrand.dim: is 12, but the domain has 2 dimensions");
    EXPECT_EQ(error_of(R"({"integrand": {"type": "genz_gaussian", "dim": 3, "a": [1, 2],
                           "u": [0.5, 0.5]}, "domain": {"type": "box", "dim": 3}})"),
              "scene.integrand.dim: is 3, but \"a\" has 2 entries");
    // A consistent "dim" sets the unit cube when there is no domain.
    Made<SceneRequest> r = build(R"({"integrand": {"type": "genz_gaussian", "dim": 12}})");
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.value.problem.domain.point_dim(), 12);
    EXPECT_EQ(r.value.problem.integrand.dim, 12);
}

TEST(SceneParsing, ParameterArraysLongerThan64AreRefusedByName) {
    const std::string powers = repeated(1000, "1");
    EXPECT_EQ(error_of(R"({"integrand": {"type": "monomial", "powers": )" + powers + "}}"),
              "scene.integrand.powers: has 1000 entries; mcplay integrates in at most 64 "
              "dimensions");
    EXPECT_EQ(
        error_of(R"({"integrand": {"type": "gaussian", "center": )" + repeated(65, "0") + "}}"),
        "scene.integrand.center: has 65 entries; mcplay integrates in at most 64 "
        "dimensions");
    EXPECT_EQ(
        error_of(R"({"integrand": {"type": "genz_oscillatory", "a": )" + repeated(100, "1") + "}}"),
        "scene.integrand.a: has 100 entries; mcplay integrates in at most 64 dimensions");
    // With a domain too.
    EXPECT_EQ(error_of(R"({"domain": {"type": "box", "dim": 2}, "integrand": {"type":
                           "exponential", "rates": )" +
                       repeated(70, "1") + "}}"),
              "scene.integrand.rates: has 70 entries; mcplay integrates in at most 64 "
              "dimensions");
    EXPECT_EQ(
        error_of(R"({"domain": {"type": "box", "lower": )" + repeated(65, "0") + R"(}, "f": "x"})"),
        "scene.domain.lower: has 65 entries; mcplay integrates in at most 64 dimensions");
}

// --- 3. domain measures -------------------------------------------------------------------

TEST(SceneParsing, DomainMeasuresOutsideTheDoubleRangeAreRefused) {
    EXPECT_EQ(error_of(R"({"domain": {"type": "box", "lower": [-1e200, -1e200],
                           "upper": [1e200, 1e200]}, "f": "1"})"),
              "scene.domain: the box's volume (the product of its 2 widths) overflows the double "
              "range (about 1e400); it must be a finite, normal positive double (2.2e-308 .. "
              "1.8e308): rescale the problem");
    EXPECT_EQ(error_of(R"({"domain": {"type": "box", "lower": [0, 0],
                           "upper": [1e-200, 1e-200]}, "f": "1"})"),
              "scene.domain: the box's volume (the product of its 2 widths) underflows the double "
              "range (about 1e-400); it must be a finite, normal positive double (2.2e-308 .. "
              "1.8e308): rescale the problem");
    EXPECT_EQ(error_of(R"({"domain": {"type": "interval", "lower": -1e308, "upper": 1e308},
                           "f": "1"})"),
              "scene.domain: the width upper - lower of axis 0 (1e+308 - -1e+308) overflows the "
              "double range (about 1e308); it must be a finite, normal positive double (2.2e-308 "
              ".. 1.8e308): rescale the problem");
    EXPECT_EQ(error_of(R"({"domain": {"type": "interval", "lower": 0, "upper": 1e-310},
                           "f": "1"})"),
              "scene.domain: the width upper - lower of axis 0 (1e-310 - 0) underflows the "
              "double range (about 1e-310); it must be a finite, normal positive double (2.2e-308 "
              ".. 1.8e308): rescale the problem");
    EXPECT_EQ(error_of(R"({"domain": {"type": "disk", "radius": 1e-200}, "f": "1"})"),
              "scene.domain.radius: the disk's area pi r^2 with r = 1e-200 underflows the double "
              "range (about 1e-400); it must be a finite, normal positive double (2.2e-308 .. "
              "1.8e308): rescale the problem");
    EXPECT_EQ(error_of(R"({"domain": {"type": "disk", "radius": 1e200}, "f": "1"})"),
              "scene.domain.radius: the disk's area pi r^2 with r = 1e+200 overflows the double "
              "range (about 1e400); it must be a finite, normal positive double (2.2e-308 .. "
              "1.8e308): rescale the problem");
    EXPECT_EQ(error_of(R"({"domain": {"type": "triangle", "vertices": [[0, 0], [1e-200, 0],
                           [0, 1e-200]]}, "f": "1"})"),
              "scene.domain: the triangle's area underflows the double range (about 1e-401); it "
              "must be a finite, normal positive double (2.2e-308 .. 1.8e308): rescale the "
              "problem");
    EXPECT_EQ(error_of(R"({"domain": {"type": "triangle", "vertices": [[0, 0], [1e200, 0],
                           [0, 1e200]]}, "f": "1"})"),
              "scene.domain: the triangle's area overflows the double range (about 1e399); it "
              "must be a finite, normal positive double (2.2e-308 .. 1.8e308): rescale the "
              "problem");
    // Collinear is still collinear; small but normal measures are fine.
    EXPECT_NE(error_of(R"({"domain": {"type": "triangle", "vertices": [[0,0],[1,1],[2,2]]},
                           "f": "1"})")
                  .find("collinear"),
              std::string::npos);
    Made<SceneRequest> r =
        build(R"({"domain": {"type": "box", "lower": [0, 0], "upper": [1e-100, 1e-100]},
                  "integrand": {"type": "constant"}})");
    ASSERT_TRUE(r.ok()) << r.error;
    ASSERT_TRUE(r.value.problem.exact.has_value());
    EXPECT_EQ(*r.value.problem.exact, 1e-100 * 1e-100);
}

// A randomization count of 0 is refused by name with the allowed range (it once became the
// default 16), on every sampler; a count in the range is used as given.
TEST(SceneParsing, RandomizationCountsAreCheckedNotDefaulted) {
    const std::string head = R"({"f": "x", "estimators": [)";
    auto est = [&](const std::string& e) { return error_of(head + e + "]}"); };
    EXPECT_EQ(est(R"({"name": "s", "sampler": "sobol", "randomizations": 0})"),
              "scene.estimators[0].randomizations: must be a power of two from 2 to 1024 (the "
              "error bar comes from the spread of the randomizations), got 0");
    EXPECT_EQ(est(R"({"name": "s", "sampler": "sobol", "randomization": "none",
                      "randomizations": 0})"),
              "scene.estimators[0].randomizations: points without randomization are one "
              "deterministic set (randomizations = 1, and the run has no error bar), got 0");
    EXPECT_EQ(est(R"({"name": "s", "sampler": "independent", "randomizations": 0})"),
              "scene.estimators[0].randomizations: applies to the quasi-Monte Carlo samplers only "
              "(sobol, halton, lattice)");
    Made<SceneRequest> ok =
        build(head + R"({"name": "s", "sampler": "sobol", "randomizations": 4}]})");
    ASSERT_TRUE(ok.ok()) << ok.error;
    EXPECT_EQ(ok.value.estimators[0].randomizations, 4);
}

// "exact": null means the exact value is unknown (docs/scene-format.md), even for a Genz family
// with a closed form; a missing key takes the closed form and a number is used as given.
TEST(SceneParsing, ExactNullMeansUnknown) {
    const std::string genz = R"("integrand": {"type": "genz_gaussian", "dim": 2})";
    Made<SceneRequest> unknown = build("{" + genz + R"(, "exact": null})");
    ASSERT_TRUE(unknown.ok()) << unknown.error;
    EXPECT_FALSE(unknown.value.problem.exact.has_value());
    Made<SceneRequest> closed = build("{" + genz + "}");
    ASSERT_TRUE(closed.ok()) << closed.error;
    EXPECT_TRUE(closed.value.problem.exact.has_value());
    Made<SceneRequest> given = build("{" + genz + R"(, "exact": 0.5})");
    ASSERT_TRUE(given.ok()) << given.error;
    ASSERT_TRUE(given.value.problem.exact.has_value());
    EXPECT_EQ(*given.value.problem.exact, 0.5);
}

// --- 4. count limits before work ----------------------------------------------------------

TEST(SceneParsing, TableSizesAreCheckedBeforeAnyWork) {
    // 2,000,000 values without "bins" used to set bins = 2,000,000, past the limit.
    const std::string values = repeated(2000000, "1");
    EXPECT_EQ(error_of(R"({"f": "x", "estimators": [{"name": "t", "pdf": {"type": "tabulated",
                           "values": )" +
                       values + "}}]}"),
              "scene.estimators[0].pdf.values: has 2000000 entries; a tabulated pdf has "
              "1..1048576 bins");
    EXPECT_EQ(error_of(R"({"f": "x", "estimators": [{"name": "t", "pdf": {"type": "tabulated",
                           "values": []}}]})"),
              "scene.estimators[0].pdf.values: has 0 entries; a tabulated pdf has 1..1048576 bins");
    EXPECT_EQ(error_of(R"({"f": "x", "estimators": [{"name": "t", "pdf": {"type": "tabulated",
                           "bins": 2000000, "values": [1]}}]})"),
              "scene.estimators[0].pdf.bins: must be in 1..1048576, got 2000000");
    // 2D: a wrong-sized values array is refused by its size, before it is read.
    EXPECT_EQ(error_of(R"({"f": "x*y", "estimators": [{"name": "t", "pdf": {"type":
                           "tabulated_2d", "values": )" +
                       values + "}}]}"),
              "scene.estimators[0].pdf.values: has 2000000 entries, bins ask for 1024");
    // 4096 x 4096 cells used to be tabulated for seconds before being refused.
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(error_of(R"({"f": "x*y", "estimators": [{"name": "t", "pdf": {"type":
                           "tabulated_2d", "bins": [4096, 4096], "shape": "x + y"}}]})"),
              "scene.estimators[0].pdf.bins: 4096 x 4096 = 16777216 cells, more than the limit "
              "of 1048576");
    EXPECT_EQ(error_of(R"({"f": "x*y", "estimators": [{"name": "t", "pdf": {"type": "expression",
                           "p": "x + y", "bins": [2048, 1024]}}]})"),
              "scene.estimators[0].pdf.bins: 2048 x 1024 = 2097152 cells, more than the limit "
              "of 1048576");
    EXPECT_EQ(error_of(R"({"f": "x*y", "estimators": [{"name": "t", "pdf": {"type":
                           "tabulated_2d", "bins": [4097, 1], "shape": "x"}}]})"),
              "scene.estimators[0].pdf.bins: each count must be a whole number in 1..4096, got "
              "4097");
    EXPECT_EQ(error_of(R"({"f": "x*y", "estimators": [{"name": "t", "pdf": {"type":
                           "tabulated_2d", "bins": [true, 2], "shape": "x"}}]})"),
              "scene.estimators[0].pdf.bins[0]: expected a number, got a boolean");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 1.0); // nothing was tabulated (a 4096^2 table took 3.6 s)
    // The largest tables still work: 1024 x 1024 cells of 16 shape points each.
    Made<SceneRequest> r = build(R"({"f": "x*y", "estimators": [{"name": "t", "pdf": {"type":
                                     "tabulated_2d", "bins": [1024, 1024], "shape": "x + y"}}]})");
    EXPECT_TRUE(r.ok()) << r.error;
}

// --- 5. NaN and infinite pdf shapes -------------------------------------------------------

TEST(SceneParsing, NonFinitePdfShapesAreReportedAsSuch) {
    EXPECT_EQ(error_of(R"J({"f": "x", "estimators": [{"name": "i", "pdf": "log(-1-x)"}]})J"),
              "scene.estimators[0].pdf.shape: the pdf shape is NaN or infinite at 4096 of 4096 "
              "tabulation points (first NaN at x = 0.00012207); a pdf shape must be finite on "
              "the whole domain");
    EXPECT_EQ(error_of(R"J({"f": "x", "estimators": [{"name": "i", "pdf": "log(x - 0.5)"}]})J"),
              "scene.estimators[0].pdf.shape: the pdf shape is NaN or infinite at 2048 of 4096 "
              "tabulation points (first NaN at x = 0.00012207); a pdf shape must be finite on "
              "the whole domain");
    EXPECT_EQ(error_of(R"J({"f": "x*y", "estimators": [{"name": "i", "pdf": {"type": "tabulated_2d",
                           "bins": [2, 2], "shape": "1/(x - 0.0625)"}}]})J"),
              "scene.estimators[0].pdf.shape: the pdf shape is NaN or infinite at 8 of 64 "
              "tabulation points (first inf at (x, y) = (0.0625, 0.0625)); a pdf shape must be "
              "finite on the whole domain");
    EXPECT_EQ(error_of(R"J({"f": "1/(x - 0.5/1024)", "estimators": [{"name": "i", "pdf":
                           {"type": "tabulated", "bins": 256, "shape": "integrand"}}]})J"),
              "scene.estimators[0].pdf.shape: the pdf shape is NaN or infinite at 1 of 1024 "
              "tabulation points (first inf at x = 0.000488281); a pdf shape must be finite on "
              "the whole domain");
    // A shape that is zero somewhere but finite everywhere is fine.
    Made<SceneRequest> r =
        build(R"J({"f": "x", "estimators": [{"name": "i", "pdf": "step(x - 0.5)"}]})J");
    EXPECT_TRUE(r.ok()) << r.error;
}

// --- 6. expressions -----------------------------------------------------------------------

TEST(SceneParsing, ExpressionConstantsAndSizes) {
    EXPECT_EQ(error_of(R"({"f": "10^400"})"),
              "scene.f: at position 1: the constant '10^400' is +infinite (it overflows); "
              "constants must be finite");
    EXPECT_EQ(error_of(R"({"f": "x", "estimators": [{"name": "i", "pdf": "x + 1/0"}]})"),
              "scene.estimators[0].pdf.shape: at position 5: the constant '1/0' is +infinite (it "
              "overflows); constants must be finite");
    const std::string deep = std::string(100000, '(') + "x" + std::string(100000, ')');
    EXPECT_EQ(error_of(R"({"f": ")" + deep + "\"}"),
              "scene.f: at position 10001: expression is longer than 10000 characters");
    const std::string nested = std::string(300, '(') + "x" + std::string(300, ')');
    EXPECT_EQ(error_of(R"({"f": ")" + nested + "\"}"),
              "scene.f: at position 201: expression nested too deeply (more than 200 levels)");
    EXPECT_EQ(error_of(R"({"f": ")" + std::string(100000, '-') + "x\"}"),
              "scene.f: at position 10001: expression is longer than 10000 characters");
    EXPECT_EQ(error_of(R"({"f": ")" + std::string(10u << 20, 'x') + "\"}"),
              "scene.f: at position 10001: expression is longer than 10000 characters");
}

// --- 7. settings report the value given ---------------------------------------------------

TEST(SceneParsing, SettingsErrorsNameTheValueGiven) {
    EXPECT_EQ(error_of(R"({"f": "x"})", R"({"reps": 1000000000})"),
              "options: reps must be in 2..100000 (a variance needs two replicates), got "
              "1000000000");
    EXPECT_EQ(error_of(R"({"f": "x", "reps": 1099511627776})"),
              "scene: reps must be in 2..100000 (a variance needs two replicates), got "
              "1099511627776");
    EXPECT_EQ(error_of(R"({"f": "x"})", R"({"threads": 10000})"),
              "options: threads must be in 0..256 (0 = all cores), got 10000");
    EXPECT_EQ(error_of(R"({"f": "x"})", R"({"threads": 18446744073709551615})"),
              "options: threads must be in 0..256 (0 = all cores), got 18446744073709551615");
}

// --- 8. other silently wrong values -------------------------------------------------------

TEST(SceneParsing, FieldsThatDoNotApplyOrDisagreeAreRefused) {
    EXPECT_EQ(error_of(R"({"domain": {"type": "disk", "dim": 5}, "f": "x"})"),
              "scene.domain.dim: does not apply to a disk domain (its fields: type, center, "
              "radius)");
    EXPECT_EQ(error_of(R"({"domain": {"type": "box", "radius": 2}, "f": "x"})"),
              "scene.domain.radius: does not apply to a box domain (its fields: type, dim, lower, "
              "upper)");
    EXPECT_EQ(error_of(R"({"domain": {"type": "sphere", "vertices": []}, "f": "x"})"),
              "scene.domain.vertices: does not apply to a sphere domain (its fields: type)");
    EXPECT_EQ(error_of(R"({"domain": {"type": "box", "dim": 3, "lower": [0, 0],
                           "upper": [1, 1]}, "f": "x"})"),
              "scene.domain.dim: is 3, but \"lower\" has 2 entries");
    // An exact value outside the double range is not compared with estimates.
    EXPECT_EQ(error_of(R"({"domain": {"type": "interval", "lower": 0, "upper": 2},
                           "integrand": {"type": "monomial", "powers": [2000]}})"),
              "scene.integrand: the exact integral over [0, 2] is inf, outside double "
              "precision: rescale the integrand or the domain");
    // Booleans and strings where numbers are expected.
    EXPECT_EQ(error_of(R"({"f": "x", "n_max": true})"),
              "scene.n_max: expected a non-negative whole number, got a boolean");
    EXPECT_EQ(error_of(R"({"f": "x", "exact": "0.5"})"),
              "scene.exact: expected a number, got a string");
    EXPECT_EQ(error_of(R"({"domain": {"type": "disk", "radius": "1"}, "f": "x"})"),
              "scene.domain.radius: expected a number, got a string");
    EXPECT_EQ(error_of(R"({"f": "x", "estimators": [{"name": "t", "pdf": {"type": "tabulated",
                           "bins": true, "values": [1]}}]})"),
              "scene.estimators[0].pdf.bins: expected a non-negative whole number, got a boolean");
}

// Multiple importance sampling and control variates: every field bounded and named.
TEST(SceneParsing, MisAndControlVariateFieldsAreChecked) {
    const std::string head = R"({"f": "x", "estimators": [)";
    auto est = [&](const std::string& e) { return error_of(head + e + "]}"); };
    const std::string g = R"({"type": "gaussian", "mu": 0.5, "sigma": 0.1})";
    EXPECT_EQ(est(R"({"name": "m", "proposals": []})"),
              "scene.estimators[0].proposals: is empty: multiple importance sampling needs at "
              "least one proposal");
    EXPECT_EQ(est(R"({"name": "m", "proposals": {}})"),
              "scene.estimators[0].proposals: expected an array of pdfs (or \"uniform\"), got an "
              "object");
    EXPECT_EQ(est(R"({"name": "m", "proposals": [)" + g + R"(, "uniform"], "fractions": [1]})"),
              "scene.estimators[0].fractions: has 1 entries for 2 proposals");
    EXPECT_EQ(est(R"({"name": "m", "proposals": [)" + g + R"(, "uniform"], "fractions": [1, 0]})"),
              "scene.estimators[0].fractions: each share must be positive (and at most 1e6), "
              "got 0");
    EXPECT_EQ(est(R"({"name": "m", "proposals": [)" + g + R"(], "heuristic": "veach"})"),
              "scene.estimators[0].heuristic: unknown heuristic 'veach' (known: balance, power, "
              "maximum, cutoff, optimal)");
    EXPECT_EQ(est(R"({"name": "m", "proposals": [)" + g + R"(], "beta": 2})"),
              "scene.estimators[0].beta: applies to the power heuristic only");
    EXPECT_EQ(
        est(R"({"name": "m", "proposals": [)" + g + R"(], "heuristic": "power", "beta": 0.5})"),
        "scene.estimators[0].beta: must be in [1, 16] (Veach uses 2), got 0.5");
    EXPECT_EQ(
        est(R"({"name": "m", "proposals": [)" + g + R"(], "heuristic": "cutoff", "cutoff": 2})"),
        "scene.estimators[0].cutoff: must be in [0, 1] (Veach uses 0.1), got 2");
    EXPECT_EQ(est(R"({"name": "m", "pdf": )" + g + R"(, "defensive": 1})"),
              "scene.estimators[0].defensive: must be in (0, 1): the uniform density's share of "
              "the mixture (Hesterberg suggests 0.1 to 0.5), got 1");
    EXPECT_EQ(est(R"({"name": "m", "pdf": )" + g + R"(, "proposals": ["uniform"]})"),
              "scene.estimators[0].pdf: an estimator has \"pdf\" or \"proposals\", not both");
    EXPECT_EQ(est(R"({"name": "m", "sampler": "sobol", "proposals": ["uniform"]})"),
              "scene.estimators[0].sampler: multiple importance sampling needs the independent "
              "sampler (its error bar is that of independent points)");
    EXPECT_EQ(est(R"({"name": "m", "proposals": [)" + g + R"(], "one_sample": 1})"),
              "scene.estimators[0].one_sample: expected true or false, got a number");
    EXPECT_EQ(est(R"({"name": "m", "proposals": )" + repeated(17, "\"uniform\"") + "}"),
              "scene.estimators[0].proposals: has 17 entries; at most 16 techniques are combined");
    EXPECT_EQ(est(R"({"name": "c", "control_variates": [{"g": "x*x"}]})"),
              "scene.estimators[0].control_variates[0]: needs \"integral\": the integral of g "
              "over the domain (known in closed form only for built-in integrands on boxes)");
    EXPECT_EQ(est(R"({"name": "c", "control_variates": [{"g": "x", "integral": 0.5}],
                      "coefficients": [1, 2]})"),
              "scene.estimators[0].coefficients: has 2 entries for 1 control variates");
    EXPECT_EQ(est(R"({"name": "c", "coefficients": [1]})"),
              "scene.estimators[0].coefficients: applies with \"control_variates\" only");
    EXPECT_EQ(est(R"({"name": "c", "control_variates": [{"g": "x", "integral": 0.5, "G": 1}]})"),
              "scene.estimators[0].control_variates[0]: unknown field 'G' (known: g, integral)");
    // An estimator is of one kind: the fields of two kinds, or a preset of another kind, are
    // refused by name.
    EXPECT_EQ(est(R"({"name": "vm", "vegas": {}, "miser": {}})"),
              "scene.estimators[0]: an estimator is of one kind: the fields of vegas (\"vegas\") "
              "and of miser (\"miser\") do not combine");
    EXPECT_EQ(est(R"({"name": "mc", "proposals": ["uniform"],
                      "control_variates": [{"g": "x", "integral": 0.5}]})"),
              "scene.estimators[0]: an estimator is of one kind: the fields of mis "
              "(\"proposals\") and of control_variates (\"control_variates\") do not combine");
    EXPECT_EQ(est(R"({"name": "uniform", "vegas": {}})"),
              "scene.estimators[0]: 'uniform' is a preset of kind fixed; give the estimator "
              "another name to use \"vegas\"");
    EXPECT_EQ(est(R"({"name": "m", "sampler": "stratified", "miser": {}})"),
              "scene.estimators[0].sampler: MISER draws its own points in its regions: the "
              "sampler must be independent");
    // A built-in g brings its own integral; a defensive pdf is MIS with the uniform density.
    Made<SceneRequest> ok = build(
        R"({"f": "x*x", "estimators": [{"name": "c", "control_variates": [{"g": {"type":
            "monomial", "powers": [1]}}]}, {"name": "d", "pdf": )" +
        g + R"(, "defensive": 0.2}]})");
    ASSERT_TRUE(ok.ok()) << ok.error;
    EXPECT_DOUBLE_EQ(ok.value.estimators[0].control_variate_options.variates[0].integral, 0.5);
    const MisOptions& d = ok.value.estimators[1].mis_options;
    ASSERT_EQ(d.proposals.size(), 2u);
    EXPECT_EQ(d.proposals[1].kind, ProposalKind::UniformBox);
    EXPECT_DOUBLE_EQ(d.fractions[0], 0.8);
    EXPECT_DOUBLE_EQ(d.fractions[1], 0.2);
}

TEST(SceneParsing, SceneInfoReportsTheSameErrors) {
    char* out = nullptr;
    const int status = mcp_scene_info(R"({"f": "x", "estimators": ["stratifed"]})", &out);
    EXPECT_EQ(status, MCP_ERROR_SCENE);
    const std::string error = mcp_last_error();
    EXPECT_EQ(error.rfind("scene.estimators[0]: unknown estimator 'stratifed'", 0), 0u) << error;
    if (out) mcp_free(out);
}

} // namespace
} // namespace mcp
