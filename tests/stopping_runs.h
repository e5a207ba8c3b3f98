// Scenes and runs shared by the stopping tests (test_stopping.cpp, test_stopping_promise.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "api/scene.h"
#include "estimators/stopping.h"
#include "integrands/genz.h"

namespace mcp::test {

inline SceneRequest request(const Json& scene) {
    Made<SceneRequest> r = build_request(scene, Json::object());
    EXPECT_TRUE(r.ok()) << r.error;
    return r.value;
}

inline Json scene_file(const std::string& name) {
    std::ifstream in(std::string(MCPLAY_SOURCE_DIR) + "/scenes/" + name + ".json");
    std::stringstream ss;
    ss << in.rdbuf();
    Made<Json> j = parse_json(ss.str().c_str(), name.c_str());
    EXPECT_TRUE(j.ok()) << j.error;
    return j.value;
}

inline Json genz_scene(GenzFamily family, int dim, uint64_t seed, const char* estimator) {
    const GenzParams p = genz_random(family, dim, seed);
    return Json{{"name", "genz"},
                {"integrand", {{"type", genz_family_name(p.family)}, {"a", p.a}, {"u", p.u}}},
                {"estimators", {estimator}}};
}

// Runs `reps` seeded replicates of each estimator and counts the runs that said "met" with an
// answer outside the tolerance of the exact value, and the runs that said "met" at all.
struct MetCount {
    int met = 0, met_outside = 0, runs = 0, heavy_tail = 0;
};
inline MetCount count_met(const Json& scene, const char* estimator, Tolerance tol, uint64_t n_max,
                          int reps) {
    Json one = scene;
    one["estimators"] = Json::array({estimator});
    SceneRequest r = request(one);
    const double exact = *r.problem.exact;
    StoppingBudget budget;
    budget.n_start = 1024;
    budget.n_max = n_max;
    Workspace ws;
    MetCount c;
    for (int k = 0; k < reps; ++k) {
        const StoppingResult s =
            run_to_tolerance(r.problem, r.estimators.front(), tol, budget, 2026, k, ws);
        const double target = std::fmax(tol.abs, tol.rel * std::fabs(exact));
        ++c.runs;
        c.met += s.met;
        c.met_outside += s.met && std::fabs(s.answer.estimate - exact) > target;
        for (const Flag& f : s.flags) c.heavy_tail += f.code == FlagCode::HeavyTail;
    }
    return c;
}

} // namespace mcp::test
