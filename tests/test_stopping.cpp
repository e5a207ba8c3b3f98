// Stopping at a requested accuracy (estimators/stopping.h), what a few runs show: randomized
// QMC extends its sequences and pays for its final N only, a peak MISER half missed is not
// "met", the scene's n_max is the budget, budgets end it with the target reported unmet, an
// estimator without an error bar cannot be run to a tolerance, and an integrand the points see
// as 0 stops at once. The promise itself (95% of answers within the tolerance over hundreds of
// runs) is test_stopping_promise.cpp, in `make check` (label statistical).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "stopping_runs.h"

using namespace mcp;
using namespace mcp::test;

// Randomized QMC extends its K randomized sequences: a run costs its final N evaluations (the
// points of N/2 are reused, counted once); test_stopping_promise.cpp runs it to its promise.
TEST(Stopping, RandomizedQmcExtendsItsSequences) {
    StoppingBudget budget;
    budget.n_start = 256;
    Workspace ws;
    for (const char* name : {"sobol", "halton", "lattice"}) {
        Json one = genz_scene(GenzFamily::Gaussian, 4, 3, name);
        SceneRequest q = request(one);
        const EstimatorSpec& spec = q.estimators.front();
        EXPECT_TRUE(stopping_extends(spec, budget)) << name;
        const StoppingResult s =
            run_to_tolerance(q.problem, spec, Tolerance{0.0, 1e-3}, budget, 5, 0, ws);
        EXPECT_TRUE(s.extended) << name;
        EXPECT_EQ(s.evaluations, s.steps.back().n) << name;
        EXPECT_EQ(s.answer.n, s.steps.back().n) << name;
        EXPECT_TRUE(s.met) << name << ": " << stop_reason_name(s.reason);
    }
    // Estimators that are not randomized QMC run each N afresh (and pay for every doubling).
    Json plain = genz_scene(GenzFamily::Gaussian, 4, 3, "uniform");
    SceneRequest u = request(plain);
    EXPECT_FALSE(stopping_extends(u.estimators.front(), budget));
    const StoppingResult f =
        run_to_tolerance(u.problem, u.estimators.front(), Tolerance{0.0, 1e-2}, budget, 5, 0, ws);
    EXPECT_FALSE(f.extended);
    uint64_t sum = 0;
    for (const StoppingStep& st : f.steps) sum += st.n;
    EXPECT_EQ(f.evaluations, sum);
}

// A peak of width 1e-3 (exp(-1e6 (x - 1/2)^2)): MISER stopped "met" on half the integral, 492
// standard errors off. The answer must agree with every earlier doubling, and carry the flags.
TEST(Stopping, MiserThatMissedHalfAPeakIsNotMet) {
    const Json scene{{"name", "narrow"},
                     {"domain", {{"type", "interval"}, {"lower", 0}, {"upper", 1}}},
                     {"f", "exp(-1e6 * (x - 0.5)^2)"},
                     {"exact", std::sqrt(std::acos(-1.0)) * 1e-3}};
    const MetCount c = count_met(scene, "miser", Tolerance{0.0, 1e-2}, uint64_t(1) << 22, 20);
    EXPECT_EQ(c.met_outside, 0);
    // The other way: a smooth integrand still stops met in every run.
    const MetCount smooth =
        count_met(scene_file("exp_1d"), "miser", Tolerance{0.0, 1e-2}, uint64_t(1) << 22, 20);
    EXPECT_EQ(smooth.met, smooth.runs);
    EXPECT_EQ(smooth.met_outside, 0);
}

// A scene that asks for stopping has its n_max as the budget; 2^24 only when neither the scene
// nor the options say. A scene without its own tolerance, given one from outside (the page's
// race), keeps 2^24: its n_max is the top of its study ladder.
TEST(Stopping, TheScenesNMaxIsTheBudget) {
    Json scene = scene_file("exp_1d");
    scene["rel_tol"] = 1e-3;
    scene.erase("n_max");
    EXPECT_EQ(request(scene).settings.n_max, kStoppingDefaultNMax);
    scene["n_max"] = 65536;
    EXPECT_EQ(request(scene).settings.n_max, 65536u);
    Made<SceneRequest> o = build_request(scene, Json{{"n_max", 4096}});
    ASSERT_TRUE(o.ok()) << o.error;
    EXPECT_EQ(o.value.settings.n_max, 4096u);
    Json ladder = scene_file("exp_1d");
    ASSERT_TRUE(ladder.contains("n_max"));
    Made<SceneRequest> raced = build_request(ladder, Json{{"rel_tol", 1e-3}});
    ASSERT_TRUE(raced.ok()) << raced.error;
    EXPECT_EQ(raced.value.settings.n_max, kStoppingDefaultNMax);
}

TEST(Stopping, BudgetsEndItUnmetAndAPointSetWithoutErrorBarCannotBeRun) {
    SceneRequest r = request(scene_file("exp_1d"));
    Workspace ws;
    StoppingBudget budget;
    budget.n_start = 64;
    budget.n_max = 1024;
    const StoppingResult s =
        run_to_tolerance(r.problem, r.estimators.front(), Tolerance{1e-9, 0.0}, budget, 1, 0, ws);
    EXPECT_FALSE(s.met);
    EXPECT_EQ(s.reason, StopReason::NMax);
    EXPECT_EQ(s.steps.back().n, 1024u);
    EXPECT_EQ(s.evaluations, uint64_t(64 + 128 + 256 + 512 + 1024));

    budget.n_max = uint64_t(1) << 30;
    budget.max_seconds = 1e-9;
    const StoppingResult t =
        run_to_tolerance(r.problem, r.estimators.front(), Tolerance{1e-9, 0.0}, budget, 1, 0, ws);
    EXPECT_FALSE(t.met);
    EXPECT_EQ(t.reason, StopReason::TimeBudget);
    EXPECT_EQ(t.steps.size(), 1u);

    // Points that never see f (a peak of width 1e-8 under uniform points) give 0 +- 0 at every
    // N: not an answer within an absolute tolerance of 1e-9, whatever its error bar says.
    SceneRequest peak = request(scene_file("stiff_peak_1e-8"));
    budget.n_max = 16384;
    budget.max_seconds = 10.0;
    const StoppingResult unseen = run_to_tolerance(peak.problem, peak.estimators.front(),
                                                   Tolerance{1e-9, 0.0}, budget, 1, 0, ws);
    EXPECT_EQ(peak.estimators.front().name, "uniform");
    EXPECT_EQ(unseen.answer.estimate, 0.0);
    EXPECT_FALSE(unseen.met);
    // Its 0 +- 0 met the tolerance, but every point gave 0 up to N = 4096: all_zero, not
    // doubled on to n_max.
    EXPECT_EQ(unseen.reason, StopReason::AllZero);
    EXPECT_EQ(unseen.steps.back().n, 4096u);

    Json sobol = scene_file("exp_1d");
    sobol["estimators"] =
        Json::array({{{"name", "net"}, {"sampler", "sobol"}, {"randomization", "none"}}});
    SceneRequest q = request(sobol);
    budget.max_seconds = 10.0;
    const StoppingResult u =
        run_to_tolerance(q.problem, q.estimators.front(), Tolerance{0.0, 1e-3}, budget, 1, 0, ws);
    EXPECT_FALSE(u.met);
    EXPECT_EQ(u.reason, StopReason::NoErrorBar);

    EXPECT_NE(check_stopping(Tolerance{0.0, 0.0}, StoppingBudget{}), "");
    EXPECT_NE(check_stopping(Tolerance{-1.0, 0.0}, StoppingBudget{}), "");
    EXPECT_NE(check_stopping(Tolerance{0.0, NAN}, StoppingBudget{}), "");
    EXPECT_EQ(check_stopping(Tolerance{0.0, 1e-3}, StoppingBudget{}), "");
}

// An integrand that is 0 wherever the points fall, under a relative tolerance: the target
// rel |0| is 0, and the rule doubled to n_max (2^25 evaluations in all by default). It stops
// after two doublings that saw only zeros, the last at N = 4096, unmet, with the reason
// all_zero; fresh runs, runs
// extending randomized QMC and the Walsh bound alike. The other way: an integrand that is 0 on
// most of the domain but seen by the points is run as before (and meets its tolerance).
TEST(Stopping, AnAllZeroIntegrandStopsAtOnceAndSaysWhy) {
    StoppingBudget budget;
    budget.n_start = 1024;
    budget.n_max = uint64_t(1) << 24;
    Workspace ws;
    for (const char* name : {"uniform", "sobol", "sobol_walsh", "vegas", "miser"}) {
        const Json scene{{"name", "zero"},
                         {"domain", {{"type", "box"}, {"dim", 2}}},
                         {"f", "0 * x * y"},
                         {"estimators", {name}}};
        SceneRequest r = request(scene);
        const StoppingResult s = run_to_tolerance(r.problem, r.estimators.front(),
                                                  Tolerance{0.0, 1e-2}, budget, 1, 0, ws);
        EXPECT_FALSE(s.met) << name;
        EXPECT_EQ(s.reason, StopReason::AllZero) << name;
        EXPECT_EQ(s.answer.estimate, 0.0) << name;
        EXPECT_EQ(s.steps.back().n, 4096u) << name;
        EXPECT_LE(s.evaluations, uint64_t(1024 + 2048 + 4096)) << name;
        EXPECT_STREQ(stop_reason_name(s.reason), "all_zero");
    }
    const Json mostly_zero{{"name", "corner"},
                           {"domain", {{"type", "box"}, {"dim", 2}}},
                           {"f", "step(x - 0.9)"},
                           {"exact", 0.1},
                           {"estimators", {"uniform"}}};
    SceneRequest r = request(mostly_zero);
    const StoppingResult s =
        run_to_tolerance(r.problem, r.estimators.front(), Tolerance{0.0, 5e-2}, budget, 1, 0, ws);
    EXPECT_TRUE(s.met) << stop_reason_name(s.reason);
}
