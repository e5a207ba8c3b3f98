// Split integration studies and stopping runs (study_parts.h). A part is the study restricted
// to some replicates: replicate r of estimator e at N draws from replicate_rng(seed, e, N, r)
// wherever it runs, so the parts' replicates are the one run's. Doubles are written exactly
// (shortest round-trip decimal; NaN and infinities as the strings "nan", "inf", "-inf"), and the
// weights' pooled moments as their raw state, so that the merge rebuilds every RunResult bit for
// bit and summarises the levels with the same functions as run_study (begin_estimator_study,
// add_level).
#include "api/study_parts.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "api/report.h"
#include "estimators/block_driver.h"
#include "estimators/stopping.h"
#include "estimators/study.h"

namespace mcp {

// A named namespace: src/api builds as one unity translation unit, where anonymous ones merge.
namespace study_parts {

constexpr const char* kStudyPartKind = "study_part";
constexpr const char* kStoppingPartKind = "stopping_part";
constexpr int kMaxRunDof = 1000000;

/// A double written exactly: finite values as numbers, the others as strings.
Json exact(double x) {
    if (std::isfinite(x)) return Json(x);
    if (std::isnan(x)) return Json("nan");
    return Json(x > 0.0 ? "inf" : "-inf");
}

/// Reads a double written by exact(); "nan", "inf" and "-inf" only where allow_nonfinite.
bool read_exact(Ctx& c, const Json& j, const char* key, const std::string& path, double* out,
                bool allow_nonfinite = true) {
    const Json* v = find(j, key);
    if (!v) return c.fail(sub(path, key), "missing");
    if (v->is_number()) {
        *out = v->get<double>();
        if (std::isfinite(*out)) return true;
        return c.fail(sub(path, key), "expected a finite number");
    }
    if (allow_nonfinite && v->is_string()) {
        const std::string s = v->get<std::string>();
        if (s == "nan" || s == "inf" || s == "-inf") {
            *out = s == "nan" ? NAN : (s == "inf" ? INFINITY : -INFINITY);
            return true;
        }
    }
    return c.fail(sub(path, key), allow_nonfinite
                                      ? "expected a number, \"nan\", \"inf\" or \"-inf\""
                                      : "expected a finite number, got " + type_of(*v));
}

bool read_count(Ctx& c, const Json& j, const char* key, const std::string& path, uint64_t* out,
                uint64_t most) {
    const Json* v = find(j, key);
    if (!v) return c.fail(sub(path, key), "missing");
    if (!v->is_number_unsigned() || v->get<uint64_t>() > most)
        return c.fail(sub(path, key), "expected a whole number in 0.." + std::to_string(most));
    *out = v->get<uint64_t>();
    return true;
}

bool read_flag(Ctx& c, const Json& j, const char* key, const std::string& path, bool* out) {
    const Json* v = find(j, key);
    if (!v || !v->is_boolean()) return c.fail(sub(path, key), "expected true or false");
    *out = v->get<bool>();
    return true;
}

/// A range check of a read value: NaN passes where allowed (a run without an estimate).
bool in_range(Ctx& c, const std::string& path, const char* key, double x, double lo, double hi,
              bool nan_ok) {
    if (std::isnan(x) ? nan_ok : (x >= lo && x <= hi)) return true;
    return c.fail(sub(path, key),
                  "out of range: expected " + fmt("%.17g", lo) + ".." + fmt("%.17g", hi));
}

Json moments_to_json(const RunningMoments& m) {
    const RunningMoments::State s = m.state();
    return Json{{"n", s.n},
                {"sum", exact(s.sum)},
                {"compensation", exact(s.compensation)},
                {"mean", exact(s.mean)},
                {"m2", exact(s.m2)},
                {"m3", exact(s.m3)}};
}

bool moments_from_json(Ctx& c, const Json& j, const std::string& path, uint64_t most,
                       RunningMoments* out) {
    if (!j.is_object()) return c.fail(path, "expected an object, got " + type_of(j));
    RunningMoments::State s;
    if (!read_count(c, j, "n", path, &s.n, most) || !read_exact(c, j, "sum", path, &s.sum) ||
        !read_exact(c, j, "compensation", path, &s.compensation) ||
        !read_exact(c, j, "mean", path, &s.mean) || !read_exact(c, j, "m2", path, &s.m2) ||
        !read_exact(c, j, "m3", path, &s.m3))
        return false;
    if (!in_range(c, path, "m2", s.m2, 0.0, INFINITY, true)) return false;
    *out = RunningMoments::from_state(s);
    return true;
}

Json run_to_json(const RunResult& r) {
    const RunDiagnostics& d = r.diagnostics;
    Json top = Json::array();
    for (double w : r.top) top.push_back(exact(w));
    return Json{{"n", r.n},
                {"estimate", exact(r.estimate)},
                {"std_error", exact(r.std_error)},
                {"dof", r.dof},
                {"seconds", exact(r.seconds)},
                {"top", top},
                {"iteration_chi2", exact(r.iteration_chi2)},
                {"iteration_dof", r.iteration_dof},
                {"training_n", r.training_n},
                {"training_seconds", exact(r.training_seconds)},
                {"diagnostics",
                 {{"nonfinite", d.nonfinite},
                  {"zero_pdf", d.zero_pdf},
                  {"nonzero", d.nonzero},
                  {"max_weight_share", exact(d.max_weight_share)},
                  {"ess", exact(d.ess)},
                  {"weights", moments_to_json(d.weights)},
                  {"error_units", moments_to_json(d.error_units)},
                  {"batch_units", d.batch_units}}}};
}

/// One replicate's run read back, every count and range checked against its N.
bool run_from_json(Ctx& c, const Json& j, const std::string& path, uint64_t n, RunResult* r) {
    if (!j.is_object()) return c.fail(path, "expected an object, got " + type_of(j));
    uint64_t dof = 0, iteration_dof = 0;
    if (!read_count(c, j, "n", path, &r->n, UINT64_MAX)) return false;
    if (r->n != n)
        return c.fail(sub(path, "n"),
                      "is " + std::to_string(r->n) + ", the level's N is " + std::to_string(n));
    if (!read_exact(c, j, "estimate", path, &r->estimate) ||
        !read_exact(c, j, "std_error", path, &r->std_error) ||
        !read_count(c, j, "dof", path, &dof, kMaxRunDof) ||
        !read_exact(c, j, "seconds", path, &r->seconds, false) ||
        !read_exact(c, j, "iteration_chi2", path, &r->iteration_chi2) ||
        !read_count(c, j, "iteration_dof", path, &iteration_dof, kMaxRunDof) ||
        !read_count(c, j, "training_n", path, &r->training_n, n) ||
        !read_exact(c, j, "training_seconds", path, &r->training_seconds, false))
        return false;
    r->dof = static_cast<int>(dof);
    r->iteration_dof = static_cast<int>(iteration_dof);
    if (!in_range(c, path, "std_error", r->std_error, 0.0, INFINITY, true) ||
        !in_range(c, path, "seconds", r->seconds, 0.0, 1e9, false) ||
        !in_range(c, path, "training_seconds", r->training_seconds, 0.0, 1e9, false) ||
        !in_range(c, path, "iteration_chi2", r->iteration_chi2, 0.0, INFINITY, true))
        return false;
    const Json* top = find(j, "top");
    if (!top || !top->is_array() || top->size() > kTailWeights)
        return c.fail(sub(path, "top"),
                      "expected an array of at most " + std::to_string(kTailWeights) + " weights");
    r->top.clear();
    for (size_t i = 0; i < top->size(); ++i) {
        const std::string at = sub(path, "top") + "[" + std::to_string(i) + "]";
        double w = 0.0;
        const Json holder{{"w", (*top)[i]}};
        if (!read_exact(c, holder, "w", at, &w)) return false;
        // the largest |w| in decreasing order (+inf allowed: an overflowing weight)
        if (!(w >= 0.0) || (i > 0 && w > r->top.back()))
            return c.fail(at, "expected |w| >= 0, in decreasing order");
        r->top.push_back(w);
    }
    const Json* dj = find(j, "diagnostics");
    const std::string dp = sub(path, "diagnostics");
    if (!dj || !dj->is_object()) return c.fail(dp, "expected an object");
    RunDiagnostics& d = r->diagnostics;
    if (!read_count(c, *dj, "nonfinite", dp, &d.nonfinite, n) ||
        !read_count(c, *dj, "zero_pdf", dp, &d.zero_pdf, n) ||
        !read_count(c, *dj, "nonzero", dp, &d.nonzero, n) ||
        !read_exact(c, *dj, "max_weight_share", dp, &d.max_weight_share) ||
        !read_exact(c, *dj, "ess", dp, &d.ess) ||
        !read_flag(c, *dj, "batch_units", dp, &d.batch_units))
        return false;
    // (a share and Kish's ESS are at most 1 and n, to round-off)
    if (!in_range(c, dp, "max_weight_share", d.max_weight_share, 0.0, 1.0 + 1e-9, true) ||
        !in_range(c, dp, "ess", d.ess, 0.0, static_cast<double>(n) * (1.0 + 1e-9), true))
        return false;
    const Json* wj = find(*dj, "weights");
    const Json* uj = find(*dj, "error_units");
    if (!wj) return c.fail(sub(dp, "weights"), "missing");
    if (!uj) return c.fail(sub(dp, "error_units"), "missing");
    return moments_from_json(c, *wj, sub(dp, "weights"), n, &d.weights) &&
           moments_from_json(c, *uj, sub(dp, "error_units"), n, &d.error_units);
}

const StopReason kStopReasons[] = {StopReason::ToleranceMet,      StopReason::NMax,
                                   StopReason::TimeBudget,        StopReason::NoErrorBar,
                                   StopReason::UntrustedErrorBar, StopReason::AllZero};

Json stopping_run_to_json(const StoppingResult& s) {
    Json steps = Json::array();
    for (const StoppingStep& st : s.steps)
        steps.push_back({{"n", st.n},
                         {"estimate", exact(st.estimate)},
                         {"std_error", exact(st.std_error)},
                         {"half_width", exact(st.half_width)},
                         {"seconds", exact(st.seconds)},
                         {"dof", st.dof},
                         {"trusted", st.trusted},
                         {"agrees", st.agrees},
                         {"flagged", st.flagged}});
    return Json{{"answer", run_to_json(s.answer)},
                {"extended", s.extended},
                {"half_width", exact(s.half_width)},
                {"target", exact(s.target)},
                {"met", s.met},
                {"reason", stop_reason_name(s.reason)},
                {"evaluations", s.evaluations},
                {"seconds", exact(s.seconds)},
                {"steps", steps}};
}

bool stopping_run_from_json(Ctx& c, const Json& j, const std::string& path,
                            const StudySettings& settings, StoppingResult* s) {
    if (!j.is_object()) return c.fail(path, "expected an object, got " + type_of(j));
    std::string reason;
    if (!read_exact(c, j, "half_width", path, &s->half_width) ||
        !read_exact(c, j, "target", path, &s->target) || !read_flag(c, j, "met", path, &s->met) ||
        !get_string(c, j, "reason", path, &reason) ||
        !read_count(c, j, "evaluations", path, &s->evaluations, kMaxStudyEvaluations) ||
        !read_exact(c, j, "seconds", path, &s->seconds, false) ||
        !read_flag(c, j, "extended", path, &s->extended))
        return false;
    bool known = false;
    for (StopReason r : kStopReasons)
        if (reason == stop_reason_name(r)) {
            s->reason = r;
            known = true;
        }
    if (!known) return c.fail(sub(path, "reason"), "unknown stop reason '" + reason + "'");
    if (!in_range(c, path, "half_width", s->half_width, 0.0, INFINITY, true) ||
        !in_range(c, path, "target", s->target, 0.0, INFINITY, true) ||
        !in_range(c, path, "seconds", s->seconds, 0.0, 1e9, false))
        return false;
    const Json* steps = find(j, "steps");
    if (!steps || !steps->is_array() || steps->size() > 64)
        return c.fail(sub(path, "steps"), "expected an array of at most 64 doublings");
    for (size_t i = 0; i < steps->size(); ++i) {
        const std::string sp = sub(path, "steps") + "[" + std::to_string(i) + "]";
        const Json& sj = (*steps)[i];
        if (!sj.is_object()) return c.fail(sp, "expected an object");
        StoppingStep st;
        uint64_t dof = 0;
        if (!read_count(c, sj, "n", sp, &st.n, settings.n_max) ||
            !read_exact(c, sj, "estimate", sp, &st.estimate) ||
            !read_exact(c, sj, "std_error", sp, &st.std_error) ||
            !read_exact(c, sj, "half_width", sp, &st.half_width) ||
            !read_exact(c, sj, "seconds", sp, &st.seconds, false) ||
            !read_count(c, sj, "dof", sp, &dof, kMaxRunDof) ||
            !read_flag(c, sj, "trusted", sp, &st.trusted) ||
            !read_flag(c, sj, "agrees", sp, &st.agrees) ||
            !read_flag(c, sj, "flagged", sp, &st.flagged))
            return false;
        st.dof = static_cast<int>(dof);
        if (!in_range(c, sp, "std_error", st.std_error, 0.0, INFINITY, true) ||
            !in_range(c, sp, "seconds", st.seconds, 0.0, 1e9, false))
            return false;
        s->steps.push_back(st);
    }
    const Json* answer = find(j, "answer");
    if (!answer) return c.fail(sub(path, "answer"), "missing");
    const Json* an = answer->is_object() ? find(*answer, "n") : nullptr;
    if (!an || !an->is_number_unsigned() || an->get<uint64_t>() > settings.n_max)
        return c.fail(sub(path, "answer.n"),
                      "expected a whole number in 0..n_max = " + std::to_string(settings.n_max));
    return run_from_json(c, *answer, sub(path, "answer"), an->get<uint64_t>(), &s->answer);
}

/// The replicates of part `part` of `parts`: r = part, part + parts, ... below reps.
std::vector<int> part_replicates(int reps, int part, int parts) {
    std::vector<int> rs;
    for (int r = part; r < reps; r += parts) rs.push_back(r);
    return rs;
}

} // namespace study_parts

bool is_study_part(const Json& j) {
    using namespace study_parts;
    const Json* kind = j.is_object() ? find(j, "kind") : nullptr;
    return kind && (*kind == kStudyPartKind || *kind == kStoppingPartKind);
}

Json run_study_part(const SceneRequest& req, const Json& scene, const Json& options, int part,
                    int parts) {
    using namespace study_parts;
    const auto start = std::chrono::steady_clock::now();
    const StudySettings& settings = req.settings;
    const std::vector<int> mine = part_replicates(settings.reps, part, parts);
    const int threads = resolve_threads(settings.threads);
    Json estimators = Json::array();
    if (settings.stopping()) {
        // As run_stopping_study: one estimate at a time on one thread.
        Workspace ws;
        for (const EstimatorSpec& spec : req.estimators) {
            Json runs = Json::array();
            for (int r : mine) {
                Json run = stopping_run_to_json(
                    run_to_tolerance(req.problem, spec, tolerance_of(settings), budget_of(settings),
                                     settings.seed, r, ws, settings.accumulator));
                run["replicate"] = r;
                runs.push_back(run);
            }
            estimators.push_back({{"name", spec.name}, {"runs", runs}});
        }
    } else {
        // As run_study, over this part's replicates: task e * |mine| + k runs replicate mine[k].
        for (const EstimatorSpec& spec : req.estimators)
            estimators.push_back({{"name", spec.name}, {"levels", Json::array()}});
        const std::vector<uint64_t> ladder = n_ladder(settings.n_min, settings.n_max);
        std::vector<Workspace> workspaces(static_cast<size_t>(std::max(threads, 1)));
        auto run = [&](size_t e, uint64_t n, int k, int worker) {
            const int r = mine[static_cast<size_t>(k)];
            Pcg32 rng = replicate_rng(settings.seed, req.estimators[e].name, n, r);
            return run_estimate(req.problem, req.estimators[e], n, rng, workspaces[size_t(worker)],
                                settings.accumulator);
        };
        const size_t per = mine.size();
        auto end_level = [&](size_t level, const std::vector<RunResult>& results) {
            for (size_t e = 0; e < req.estimators.size(); ++e) {
                Json runs = Json::array();
                for (size_t k = 0; k < per; ++k) {
                    Json one = run_to_json(results[e * per + k]);
                    one["replicate"] = mine[k];
                    runs.push_back(one);
                }
                estimators[e]["levels"].push_back({{"n", ladder[level]}, {"runs", runs}});
            }
            return true;
        };
        run_ladder<RunResult>(ladder, req.estimators.size(), static_cast<int>(per), threads, run,
                              end_level);
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return Json{{"version", kResultSchemaVersion},
                {"mcplay", MCPLAY_VERSION},
                {"kind", settings.stopping() ? kStoppingPartKind : kStudyPartKind},
                {"part", {{"index", part}, {"of", parts}}},
                {"scene", scene},
                {"options", options},
                {"threads", threads},
                {"wall_time_s", exact(wall)},
                {"estimators", estimators}};
}

bool merge_study_parts(Ctx& c, const Json& in, Json* out) {
    using namespace study_parts;
    if (!in.is_object()) return c.fail("parts", "expected an object {\"parts\": [...]}");
    if (!check_keys(c, in, "parts", {"parts"})) return false;
    const Json* list = find(in, "parts");
    if (!list || !list->is_array() || list->empty() ||
        list->size() > static_cast<size_t>(kMaxStudyParts))
        return c.fail("parts", "expected an array of 1.." + std::to_string(kMaxStudyParts) +
                                   " parts (the results of run --part I/K)");
    const size_t given = list->size();
    // Every part's envelope: the same kind, scene, options (threads aside) and K; each index once.
    const Json& p0 = (*list)[0];
    std::vector<const Json*> parts;
    uint64_t of = 0;
    for (size_t i = 0; i < given; ++i) {
        const Json& p = (*list)[i];
        const std::string pp = "parts[" + std::to_string(i) + "]";
        if (!is_study_part(p))
            return c.fail(sub(pp, "kind"), "expected \"study_part\" or \"stopping_part\" (the "
                                           "result of run --part I/K with --format json)");
        if (!check_keys(c, p, pp,
                        {"version", "mcplay", "kind", "part", "scene", "options", "threads",
                         "wall_time_s", "estimators"}))
            return false;
        for (const char* key : {"version", "mcplay", "kind", "scene"})
            if (!p.contains(key) || p[key] != p0[key])
                return c.fail(
                    sub(pp, key),
                    std::string("differs from parts[0]'s") +
                        (std::string(key) == "scene" ? ": the parts ran different scenes" : ""));
        const Json* options = find(p, "options");
        if (!options || !options->is_object())
            return c.fail(sub(pp, "options"), "expected an object");
        Json a = *options, b = p0["options"];
        a.erase("threads");
        if (b.is_object()) b.erase("threads");
        const std::string d = first_difference(a, b, sub(pp, "options"));
        if (!d.empty())
            return c.fail(d, "differs from parts[0]'s: the parts ran different settings");
        const Json* pj = find(p, "part");
        if (!pj || !pj->is_object()) return c.fail(sub(pp, "part"), "expected {\"index\", \"of\"}");
        uint64_t index = 0, k = 0;
        if (!read_count(c, *pj, "of", sub(pp, "part"), &k, kMaxStudyParts) ||
            !read_count(c, *pj, "index", sub(pp, "part"), &index, kMaxStudyParts))
            return false;
        if (i == 0) {
            of = k;
            if (of < 1) return c.fail(sub(pp, "part.of"), "must be at least 1");
            parts.assign(static_cast<size_t>(of), nullptr);
        } else if (k != of) {
            return c.fail(sub(pp, "part.of"),
                          "is " + std::to_string(k) + ", parts[0]'s is " + std::to_string(of));
        }
        if (index >= of)
            return c.fail(sub(pp, "part.index"), "must be in 0.." + std::to_string(of - 1) +
                                                     " (part.of = " + std::to_string(of) + ")");
        if (parts[index])
            return c.fail(sub(pp, "part.index"),
                          "part " + std::to_string(index) + " of " + std::to_string(of) +
                              " is given twice: its replicates would overlap");
        parts[index] = &p;
    }
    for (size_t index = 0; index < parts.size(); ++index)
        if (!parts[index])
            return c.fail("parts", "part " + std::to_string(index) + " of " + std::to_string(of) +
                                       " is missing (replicates r with r % " + std::to_string(of) +
                                       " = " + std::to_string(index) + ")");
    // The study itself, built again from the scene and options as run built it.
    Json options = p0["options"];
    Made<SceneRequest> req = build_request(p0["scene"], options);
    if (!req.ok()) return c.fail("parts[0].scene", req.error);
    const SceneRequest& rq = req.value;
    const StudySettings& settings = rq.settings;
    if (settings.stopping() != (p0["kind"] == kStoppingPartKind))
        return c.fail("parts[0].kind", "does not match its scene and options");
    if (of > static_cast<uint64_t>(settings.reps))
        return c.fail("parts[0].part.of", "must be in 1..reps = " + std::to_string(settings.reps));
    const size_t estimators = rq.estimators.size();
    for (size_t index = 0; index < parts.size(); ++index) {
        const Json* ests = find(*parts[index], "estimators");
        const std::string pp = "part " + std::to_string(index) + ".estimators";
        if (!ests || !ests->is_array() || ests->size() != estimators)
            return c.fail(pp, "expected " + std::to_string(estimators) + " estimators");
        for (size_t e = 0; e < estimators; ++e)
            if (!(*ests)[e].is_object() || !(*ests)[e].contains("name") ||
                (*ests)[e]["name"] != rq.estimators[e].name)
                return c.fail(pp + "[" + std::to_string(e) + "].name",
                              "expected '" + rq.estimators[e].name + "'");
    }
    // The runs of replicate r come from part r % K, at position r / K of its list.
    auto runs_of = [&](size_t index, size_t e, const char* level_key, size_t level,
                       const Json** runs) {
        const Json& est = (*parts[index])["estimators"][e];
        std::string path =
            "part " + std::to_string(index) + ".estimators[" + std::to_string(e) + "]";
        const Json* holder = &est;
        if (level_key) {
            const Json* levels = find(est, level_key);
            const size_t want = n_ladder(settings.n_min, settings.n_max).size();
            if (!levels || !levels->is_array() || levels->size() != want)
                return c.fail(sub(path, level_key),
                              "expected " + std::to_string(want) + " levels (the N ladder)");
            holder = &(*levels)[level];
            path += std::string(".") + level_key + "[" + std::to_string(level) + "]";
            if (!holder->is_object()) return c.fail(path, "expected an object");
        }
        const Json* rs = find(*holder, "runs");
        const size_t want = part_replicates(settings.reps, int(index), int(of)).size();
        if (!rs || !rs->is_array() || rs->size() != want)
            return c.fail(sub(path, "runs"), "expected the " + std::to_string(want) +
                                                 " replicates r with r % " + std::to_string(of) +
                                                 " = " + std::to_string(index));
        for (size_t k = 0; k < want; ++k) {
            const Json& run = (*rs)[k];
            const Json* r = run.is_object() ? find(run, "replicate") : nullptr;
            const uint64_t expected = index + k * of;
            if (!r || !r->is_number_unsigned() || r->get<uint64_t>() != expected)
                return c.fail(sub(path, "runs") + "[" + std::to_string(k) + "].replicate",
                              "expected replicate " + std::to_string(expected));
        }
        *runs = rs;
        return true;
    };
    double wall = 0.0;
    int threads = 1;
    for (const Json* p : parts) {
        double w = 0.0;
        uint64_t t = 0;
        if (!read_exact(c, *p, "wall_time_s", "part", &w, false) ||
            !read_count(c, *p, "threads", "part", &t, 4096))
            return false;
        wall = std::max(wall, w);
        threads = std::max(threads, static_cast<int>(t));
    }
    if (settings.stopping()) {
        StoppingStudy st;
        st.problem = rq.problem;
        st.settings = settings;
        st.specs = rq.estimators;
        st.wall_seconds = wall;
        for (size_t e = 0; e < estimators; ++e) {
            std::vector<StoppingResult> runs(static_cast<size_t>(settings.reps));
            for (size_t index = 0; index < parts.size(); ++index) {
                const Json* rs = nullptr;
                if (!runs_of(index, e, nullptr, 0, &rs)) return false;
                for (size_t k = 0; k < rs->size(); ++k) {
                    const size_t r = index + k * of;
                    const std::string path = "part " + std::to_string(index) + ".estimators[" +
                                             std::to_string(e) + "].runs[" + std::to_string(k) +
                                             "]";
                    if (!stopping_run_from_json(c, (*rs)[k], path, settings, &runs[r]))
                        return false;
                    // The answer's flags are a function of its run: recomputed, not carried.
                    bool blocking = false;
                    runs[r].integrand =
                        stopping_integrand_tail(rq.problem, rq.estimators[e], settings.seed);
                    const IntegrandTail* tail =
                        runs[r].integrand.k > 0 ? &runs[r].integrand : nullptr;
                    runs[r].flags = stopping_answer_flags(runs[r].answer, rq.problem,
                                                          rq.estimators[e], &blocking, tail);
                }
            }
            st.runs.push_back(std::move(runs));
        }
        *out = stopping_to_json(st);
        return true;
    }
    StudyResult result;
    result.problem = rq.problem;
    result.settings = settings;
    result.threads_used = threads;
    result.wall_seconds = wall;
    const std::vector<uint64_t> ladder = n_ladder(settings.n_min, settings.n_max);
    IntegrandTail shared_tail; // measured once for the merged study, as run_study does
    for (size_t e = 0; e < estimators; ++e) {
        EstimatorStudy es =
            begin_estimator_study(rq.problem, rq.estimators[e], settings, &shared_tail);
        for (size_t level = 0; level < ladder.size(); ++level) {
            std::vector<RunResult> runs(static_cast<size_t>(settings.reps));
            for (size_t index = 0; index < parts.size(); ++index) {
                const Json* rs = nullptr;
                if (!runs_of(index, e, "levels", level, &rs)) return false;
                const Json& lj = (*parts[index])["estimators"][e]["levels"][level];
                const Json* n = find(lj, "n");
                if (!n || *n != ladder[level])
                    return c.fail("part " + std::to_string(index) + ".estimators[" +
                                      std::to_string(e) + "].levels[" + std::to_string(level) +
                                      "].n",
                                  "expected N = " + std::to_string(ladder[level]));
                for (size_t k = 0; k < rs->size(); ++k) {
                    const size_t r = index + k * of;
                    const std::string path =
                        "part " + std::to_string(index) + ".estimators[" + std::to_string(e) +
                        "].levels[" + std::to_string(level) + "].runs[" + std::to_string(k) + "]";
                    if (!run_from_json(c, (*rs)[k], path, ladder[level], &runs[r])) return false;
                }
            }
            add_level(es, runs, rq.problem);
        }
        result.estimators.push_back(std::move(es));
    }
    *out = study_to_json(result);
    return true;
}

} // namespace mcp
