// The extern "C" boundary. The library is built without exceptions: every error is a value
// returned up to here and turned into a status code plus a message (like sqlite3_errmsg).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "api/boundary.h"
#include "api/mcplay.h"
#include "api/report.h"
#include "api/scene.h"
#include "api/study_parts.h"
#include "estimators/named_warps.h"
#include "estimators/stopping.h"

using mcp::boundary::copy_out;
using mcp::boundary::dump;
using mcp::boundary::fail;
using mcp::boundary::g_last_error;

namespace {

/// The start of a study call: the scene and the options parsed and turned into a request (which
/// may name the caller's functions).
int load_request(const char* scene_json, const char* options_json, mcp::SceneRequest* out,
                 const mcp::CallerFunctions* functions = nullptr) {
    mcp::Made<mcp::Json> scene = mcp::parse_json(scene_json, "scene");
    if (!scene.ok()) return fail(MCP_ERROR_SCENE, scene.error);
    mcp::Json options;
    if (options_json && *options_json) {
        mcp::Made<mcp::Json> o = mcp::parse_json(options_json, "options");
        if (!o.ok()) return fail(MCP_ERROR_ARGUMENT, o.error);
        options = o.value;
    }
    mcp::Made<mcp::SceneRequest> req = mcp::build_request(scene.value, options, functions);
    if (!req.ok()) return mcp::boundary::request_error(req.error);
    *out = std::move(req.value);
    return MCP_OK;
}

/// The caller's functions of a context, or the status of a bad context.
int load_functions(const mcp_context* ctx, mcp::CallerFunctions* out) {
    mcp::Made<mcp::CallerFunctions> made = mcp::caller_functions(ctx);
    if (!made.ok()) return fail(MCP_ERROR_ARGUMENT, made.error);
    *out = std::move(made.value);
    return MCP_OK;
}

int run_study_call(const char* scene_json, const char* options_json, const mcp_context* ctx,
                   mcp_progress_fn progress, void* user, char** result_json);
int plan_study_call(const char* scene_json, const char* options_json, const mcp_context* ctx,
                    char** plan_json);

} // namespace

extern "C" {

const char* mcp_version(void) {
    return MCPLAY_VERSION;
}

const char* mcp_last_error(void) {
    return g_last_error.c_str();
}

void mcp_free(char* p) {
    std::free(p);
}

int mcp_study_run(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                  void* user, char** result_json) {
    return run_study_call(scene_json, options_json, nullptr, progress, user, result_json);
}

int mcp_study_run_with(const char* scene_json, const char* options_json, const mcp_context* ctx,
                       mcp_progress_fn progress, void* user, char** result_json) {
    return run_study_call(scene_json, options_json, ctx, progress, user, result_json);
}

int mcp_study_plan(const char* scene_json, const char* options_json, char** plan_json) {
    return plan_study_call(scene_json, options_json, nullptr, plan_json);
}

int mcp_study_plan_with(const char* scene_json, const char* options_json, const mcp_context* ctx,
                        char** plan_json) {
    return plan_study_call(scene_json, options_json, ctx, plan_json);
}

} // extern "C"

namespace {

int run_study_call(const char* scene_json, const char* options_json, const mcp_context* ctx,
                   mcp_progress_fn progress, void* user, char** result_json) {
    if (!result_json) return fail(MCP_ERROR_ARGUMENT, "mcp_study_run: result_json is NULL");
    *result_json = nullptr;
    mcp::CallerFunctions functions;
    if (int st = load_functions(ctx, &functions)) return st;
    // A part of a study split over processes (options.part of options.parts): the study
    // without them, restricted to the replicates r with r % parts == part (study_parts.h).
    mcp::Json options = mcp::Json::object();
    if (options_json && *options_json) {
        mcp::Made<mcp::Json> o = mcp::parse_json(options_json, "options");
        if (!o.ok()) return fail(MCP_ERROR_ARGUMENT, o.error);
        options = o.value;
    }
    if (options.is_object() && (options.contains("part") || options.contains("parts"))) {
        mcp::Ctx c;
        uint64_t part = 0, parts = 1;
        if (!mcp::get_count(c, options, "part", "options", &part) ||
            !mcp::get_count(c, options, "parts", "options", &parts))
            return fail(MCP_ERROR_ARGUMENT, c.error);
        options.erase("part");
        options.erase("parts");
        const std::string rest = options.dump();
        mcp::SceneRequest req;
        if (int st = load_request(scene_json, rest.c_str(), &req, &functions)) return st;
        const int reps = req.settings.reps;
        if (parts < 1 || parts > uint64_t(std::min(reps, mcp::kMaxStudyParts)))
            return fail(MCP_ERROR_ARGUMENT,
                        "options.parts: must be in 1..reps = " +
                            std::to_string(std::min(reps, mcp::kMaxStudyParts)) + ", got " +
                            std::to_string(parts));
        if (part >= parts)
            return fail(MCP_ERROR_ARGUMENT,
                        "options.part: must be in 0..parts - 1 = " + std::to_string(parts - 1) +
                            ", got " + std::to_string(part));
        mcp::Made<mcp::Json> scene = mcp::parse_json(scene_json, "scene");
        if (!scene.ok()) return fail(MCP_ERROR_SCENE, scene.error);
        const mcp::Json part_result =
            mcp::run_study_part(req, scene.value, options, int(part), int(parts));
        // A part cut short by the caller is no part: nothing to merge.
        if (int st = mcp::caller_outcome(functions)) return st;
        if (std::string why = mcp::warp_escape_error(req); !why.empty())
            return fail(MCP_ERROR_SCENE, why);
        *result_json = copy_out(dump(part_result));
        if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
        g_last_error.clear();
        return MCP_OK;
    }
    mcp::SceneRequest req;
    if (int st = load_request(scene_json, options_json, &req, &functions)) return st;

    if (req.settings.stopping()) {
        // Stopping at a requested accuracy: no N ladder, so no per-level progress.
        const mcp::StoppingStudy st =
            mcp::run_stopping_study(req.problem, req.estimators, req.settings);
        // Answers cut short by the caller are no answers: no result.
        if (int status = mcp::caller_outcome(functions)) return status;
        if (std::string why = mcp::warp_escape_error(req); !why.empty())
            return fail(MCP_ERROR_SCENE, why);
        *result_json = copy_out(dump(mcp::stopping_to_json(st)));
        if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
        g_last_error.clear();
        return MCP_OK;
    }
    mcp::StudyProgress on_level;
    if (progress) {
        on_level = [&](const mcp::StudyResult& partial, size_t level) {
            std::string text = dump(mcp::progress_to_json(partial, level));
            return progress(text.c_str(), user) == 0;
        };
    }
    mcp::StudyResult result = mcp::run_study(req.problem, req.estimators, req.settings, on_level);
    // A failed function's numbers are not the function's: no result. A cancel keeps the levels
    // completed before it, as a cancelling progress callback does.
    if (functions.control && functions.control->failed()) return mcp::caller_outcome(functions);
    // A warp that left its domain: its numbers average f where it is not defined.
    if (std::string why = mcp::warp_escape_error(req); !why.empty())
        return fail(MCP_ERROR_SCENE, why);
    *result_json = copy_out(dump(mcp::study_to_json(result)));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    if (int st = mcp::caller_outcome(functions)) return st;
    if (result.cancelled) return fail(MCP_ERROR_CANCELLED, "study cancelled by the caller");
    g_last_error.clear();
    return MCP_OK;
}

int plan_study_call(const char* scene_json, const char* options_json, const mcp_context* ctx,
                    char** plan_json) {
    if (!plan_json) return fail(MCP_ERROR_ARGUMENT, "mcp_study_plan: plan_json is NULL");
    *plan_json = nullptr;
    mcp::CallerFunctions functions;
    if (int st = load_functions(ctx, &functions)) return st;
    mcp::SceneRequest req;
    if (int st = load_request(scene_json, options_json, &req, &functions)) return st;
    const mcp::StudySettings& s = req.settings;
    const mcp::StudyPlan plan = mcp::plan_study(req.problem, req.estimators, s);
    if (int st = mcp::caller_outcome(functions)) return st;
    mcp::Json estimators = mcp::Json::array();
    for (const mcp::EstimatorPlan& e : plan.estimators)
        estimators.push_back({{"name", e.name},
                              {"evaluations", e.evaluations},
                              {"seconds_per_evaluation", mcp::num(e.seconds_per_evaluation)},
                              {"predicted_seconds", mcp::num(e.predicted_seconds)}});
    mcp::Json out{{"version", mcp::kResultSchemaVersion},
                  {"evaluations", plan.evaluations},
                  {"limit_evaluations", mcp::kMaxStudyEvaluations},
                  {"predicted_seconds", mcp::num(plan.predicted_seconds)},
                  {"threads", plan.threads},
                  {"levels", plan.levels},
                  {"n_min", s.n_min},
                  {"n_max", s.n_max},
                  {"reps", s.reps},
                  {"pilot_samples", mcp::kPilotSamples},
                  {"pilot_seconds", mcp::num(plan.pilot_seconds)},
                  {"estimators", estimators}};
    *plan_json = copy_out(dump(out));
    if (!*plan_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the plan");
    g_last_error.clear();
    return MCP_OK;
}

} // namespace

extern "C" {

int mcp_study_merge(const char* parts_json, char** result_json) {
    if (!result_json) return fail(MCP_ERROR_ARGUMENT, "mcp_study_merge: result_json is NULL");
    *result_json = nullptr;
    mcp::Made<mcp::Json> in = mcp::parse_json(parts_json, "parts");
    if (!in.ok()) return fail(MCP_ERROR_ARGUMENT, in.error);
    mcp::Ctx c;
    mcp::Json merged;
    if (!mcp::merge_study_parts(c, in.value, &merged)) return fail(MCP_ERROR_ARGUMENT, c.error);
    *result_json = copy_out(dump(merged));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    g_last_error.clear();
    return MCP_OK;
}

} // extern "C"

namespace {

/// An MIS estimator's weight for each technique over the grid xs (q_k = c_k p_k; the optimal
/// combination is drawn with the balance weights it starts from, as its own depend on a run).
mcp::Json mis_weight_curves(const mcp::EstimatorSpec& spec, const mcp::Domain& domain,
                            const mcp::PointBlock& xs) {
    const mcp::MisOptions& m = spec.mis_options;
    const size_t k_count = m.proposals.size();
    std::vector<std::vector<double>> q(k_count, std::vector<double>(xs.n));
    std::vector<const double*> rows(k_count);
    for (size_t k = 0; k < k_count; ++k) {
        mcp::proposal_pdf_block(m.proposals[k], domain, xs, q[k].data());
        for (double& v : q[k]) v *= m.fractions[k];
        rows[k] = q[k].data();
    }
    const mcp::MisWeighting weighting = m.optimal ? mcp::MisWeighting{} : m.weighting;
    mcp::Json out = mcp::Json::array();
    std::vector<double> w(xs.n);
    for (size_t k = 0; k < k_count; ++k) {
        mcp::mis_weight_block(weighting, rows.data(), static_cast<int>(k_count),
                              static_cast<int>(k), xs.n, w.data());
        out.push_back(w);
    }
    return out;
}

} // namespace

extern "C" {

int mcp_study_samples(const char* scene_json, const char* options_json, char** samples_json) {
    if (!samples_json) return fail(MCP_ERROR_ARGUMENT, "mcp_study_samples: samples_json is NULL");
    *samples_json = nullptr;
    mcp::Made<mcp::Json> scene = mcp::parse_json(scene_json, "scene");
    if (!scene.ok()) return fail(MCP_ERROR_SCENE, scene.error);
    mcp::Json options = mcp::Json::object();
    if (options_json && *options_json) {
        mcp::Made<mcp::Json> o = mcp::parse_json(options_json, "options");
        if (!o.ok()) return fail(MCP_ERROR_ARGUMENT, o.error);
        options = o.value;
    }
    if (!options.is_object()) return fail(MCP_ERROR_ARGUMENT, "options: expected an object");
    // "n", "grid" and "adaptive_n" belong to this call; the rest selects estimators and the
    // seed. Adaptive estimators run at N = adaptive_n (up to 2^20) and show n of its points.
    uint64_t n = 256, grid = 256, adaptive_n = 0;
    struct Bounded {
        const char* key;
        uint64_t* target;
        int64_t most;
        const char* text;
    };
    for (const Bounded& b :
         {Bounded{"n", &n, 4096, "1..4096"}, Bounded{"grid", &grid, 4096, "1..4096"},
          Bounded{"adaptive_n", &adaptive_n, int64_t(1) << 20, "1..1048576"}}) {
        auto it = options.find(b.key);
        if (it == options.end()) continue;
        if (!it->is_number_integer() || it->get<int64_t>() < 1 || it->get<int64_t>() > b.most)
            return fail(MCP_ERROR_ARGUMENT,
                        std::string("options.") + b.key + ": expected a whole number in " + b.text);
        *b.target = static_cast<uint64_t>(it->get<int64_t>());
        options.erase(b.key);
    }
    mcp::Made<mcp::SceneRequest> req = mcp::build_request(scene.value, options);
    if (!req.ok()) return mcp::boundary::request_error(req.error);
    const mcp::Problem& problem = req.value.problem;
    const mcp::Domain& domain = problem.domain;
    mcp::Json estimators = mcp::Json::array();
    for (const mcp::EstimatorSpec& spec : req.value.estimators) {
        mcp::SampleDump d =
            mcp::dump_samples(problem, spec, n, req.value.settings.seed, adaptive_n);
        auto axes = [&](const std::vector<double>& flat, int dim) {
            mcp::Json out = mcp::Json::array();
            for (int j = 0; j < dim; ++j) {
                mcp::Json axis = mcp::Json::array();
                for (size_t i = static_cast<size_t>(j); i < flat.size();
                     i += static_cast<size_t>(dim))
                    axis.push_back(flat[i]);
                out.push_back(axis);
            }
            return out;
        };
        auto values = [](const std::vector<double>& v) {
            mcp::Json out = mcp::Json::array();
            for (double x : v) out.push_back(std::isfinite(x) ? mcp::Json(x) : mcp::Json(nullptr));
            return out;
        };
        const mcp::EstimatorKind& kind = mcp::kind_of(spec);
        const mcp::PointWords words = mcp::point_words(spec);
        estimators.push_back(
            {{"name", spec.name},
             {"kind", kind.name},
             {"method", mcp::estimator_method(spec)},
             // whether the mean of the first k points' weights is the estimate at N = k
             {"replay_is_estimate", kind.replay_is_estimate(spec)},
             {"sampler", words.sampler},
             {"pdf", mcp::describe_sampling(spec)},
             {"pdf_text", mcp::describe_sampling_text(spec, domain)},
             {"strata", d.strata},
             {"samples_per_stratum", d.per_stratum},
             {"randomization",
              words.randomization ? mcp::Json(words.randomization) : mcp::Json(nullptr)},
             {"randomizations", d.randomizations},
             {"u", axes(d.u, d.sample_dim)},
             {"x", axes(d.x, d.point_dim)},
             {"f", values(d.f)},
             {"density", values(d.pdf)},
             {"weight", values(d.weight)}});
        // What an adaptive estimator learnt: VEGAS's map (increment edges per axis of the
        // unit cube) and MISER's leaf boxes (lo and hi corners).
        mcp::Json& e = estimators.back();
        if (!d.adaptive.edges.empty()) e["map_edges"] = d.adaptive.edges;
        if (!d.adaptive.history.empty()) e["map_history"] = d.adaptive.history;
        if (kind.adaptive) e["run_n"] = std::max(n, adaptive_n);
        if (!d.adaptive.box_lo.empty())
            e["boxes"] = {{"lo", d.adaptive.box_lo}, {"hi", d.adaptive.box_hi}};
        // MIS: each technique's density and share, in the order of curve.mis_weights.
        if (spec.has_techniques()) {
            const mcp::MisOptions& m = spec.mis_options;
            mcp::Json techniques = mcp::Json::array();
            for (size_t k = 0; k < m.proposals.size(); ++k)
                techniques.push_back({{"pdf", m.proposals[k].describe()},
                                      {"pdf_text", m.proposals[k].describe_text(domain)},
                                      {"share", m.fractions[k]}});
            e["techniques"] = techniques;
            e["heuristic"] = m.optimal ? "optimal" : mcp::mis_heuristic_name(m.weighting.heuristic);
        }
    }
    mcp::Json result{{"version", mcp::kResultSchemaVersion},
                     {"n", n},
                     {"seed", req.value.settings.seed},
                     {"domain", mcp::domain_kind_name(domain.kind)},
                     {"dimension", domain.point_dim()},
                     {"sample_dimension", domain.sample_dim()},
                     {"estimators", estimators}};
    // 1D boxes: f and every estimator's density on a grid of cell midpoints.
    if (domain.kind == mcp::DomainKind::Box && domain.lo.size() == 1) {
        mcp::PointBlock xs;
        xs.reset(1, grid);
        xs.n = grid;
        for (uint64_t i = 0; i < grid; ++i)
            xs.coord(0)[i] = domain.lo[0] + (domain.hi[0] - domain.lo[0]) * (i + 0.5) / grid;
        std::vector<double> fv(grid), pv(grid);
        mcp::evaluate_block(problem.integrand, xs, fv.data());
        mcp::Json pdfs = mcp::Json::object(), xj = mcp::Json::array(), fj = mcp::Json::array();
        for (uint64_t i = 0; i < grid; ++i) {
            xj.push_back(xs.coord(0)[i]);
            fj.push_back(std::isfinite(fv[i]) ? mcp::Json(fv[i]) : mcp::Json(nullptr));
        }
        mcp::Json mis_weights = mcp::Json::object();
        for (const mcp::EstimatorSpec& spec : req.value.estimators) {
            mcp::sampling_density_block(spec, domain, xs, pv.data());
            pdfs[spec.name] = std::vector<double>(pv.begin(), pv.end());
            if (spec.has_techniques()) mis_weights[spec.name] = mis_weight_curves(spec, domain, xs);
        }
        result["curve"] = {{"x", xj}, {"f", fj}, {"pdf", pdfs}};
        if (!mis_weights.empty()) result["curve"]["mis_weights"] = mis_weights;
    }
    *samples_json = copy_out(dump(result));
    g_last_error.clear();
    return MCP_OK;
}

int mcp_result_format(const char* result_json, const char* format, char** text) {
    if (!text) return fail(MCP_ERROR_ARGUMENT, "mcp_result_format: text is NULL");
    *text = nullptr;
    if (!format) return fail(MCP_ERROR_ARGUMENT, "mcp_result_format: format is NULL");
    mcp::Made<mcp::Json> r = mcp::parse_json(result_json, "result");
    if (!r.ok()) return fail(MCP_ERROR_ARGUMENT, r.error);
    if (!r.value.is_object() || !r.value.contains("estimators"))
        return fail(MCP_ERROR_ARGUMENT, "result: not an mcplay study result (no \"estimators\")");
    // The shape the formatters read: estimators[] of objects, each with levels[] of objects.
    const mcp::Json& ests = r.value["estimators"];
    if (!ests.is_array())
        return fail(MCP_ERROR_ARGUMENT,
                    std::string("result.estimators: expected an array, got ") + ests.type_name());
    for (size_t i = 0; i < ests.size(); ++i) {
        const std::string at = "result.estimators[" + std::to_string(i) + "]";
        if (!ests[i].is_object())
            return fail(MCP_ERROR_ARGUMENT,
                        at + ": expected an object, got " + ests[i].type_name());
        auto levels = ests[i].find("levels");
        if (levels == ests[i].end()) continue; // a progress record carries "level" instead
        if (!levels->is_array())
            return fail(MCP_ERROR_ARGUMENT,
                        at + ".levels: expected an array, got " + levels->type_name());
        for (size_t k = 0; k < levels->size(); ++k)
            if (!(*levels)[k].is_object())
                return fail(MCP_ERROR_ARGUMENT, at + ".levels[" + std::to_string(k) +
                                                    "]: expected an object, got " +
                                                    (*levels)[k].type_name());
    }
    std::string out;
    const std::string f = format;
    if (f == "table")
        out = mcp::format_table(r.value);
    else if (f == "csv")
        out = mcp::format_csv(r.value);
    else if (f == "json")
        out = dump(r.value, 2) + "\n";
    else
        return fail(MCP_ERROR_ARGUMENT, "unknown format '" + f + "' (known: table, json, csv)");
    *text = copy_out(out);
    g_last_error.clear();
    return MCP_OK;
}

int mcp_scene_info(const char* scene_json, char** info_json) {
    if (!info_json) return fail(MCP_ERROR_ARGUMENT, "mcp_scene_info: info_json is NULL");
    *info_json = nullptr;
    mcp::Made<mcp::Json> scene = mcp::parse_json(scene_json, "scene");
    if (!scene.ok()) return fail(MCP_ERROR_SCENE, scene.error);
    mcp::Made<mcp::SceneRequest> req = mcp::build_request(scene.value, mcp::Json());
    if (!req.ok()) return mcp::boundary::request_error(req.error);
    const mcp::Problem& p = req.value.problem;
    mcp::Json names = mcp::Json::array(), more = mcp::Json::array(), details = mcp::Json::array();
    auto detail = [&p](const mcp::EstimatorSpec& e) {
        return mcp::Json{{"name", e.name},
                         {"kind", mcp::kind_of(e).name},
                         {"summary", mcp::kind_of(e).summary},
                         {"method", mcp::estimator_method(e)},
                         {"sampler", mcp::point_words(e).sampler},
                         {"pdf", mcp::describe_sampling(e)},
                         {"pdf_text", mcp::describe_sampling_text(e, p.domain)}};
    };
    for (const mcp::EstimatorSpec& e : req.value.estimators) {
        names.push_back(e.name);
        details.push_back(detail(e));
    }
    // The uniform-density presets the scene does not list: options.estimators can run them too.
    for (const mcp::EstimatorPreset& preset : mcp::estimator_presets()) {
        bool listed = false;
        for (const mcp::EstimatorSpec& e : req.value.estimators)
            listed = listed || e.name == preset.name;
        if (listed || preset.needs_pdf) continue;
        more.push_back(preset.name);
        // its method, from the estimator the preset gives on this scene's problem (the scene is
        // not built again: its own tabulated pdfs may cost millions of evaluations)
        const mcp::Made<mcp::EstimatorSpec> e = mcp::preset_estimator(p, preset.name);
        if (e.ok()) details.push_back(detail(e.value));
    }
    mcp::Json info{{"name", p.name},
                   {"description", p.description},
                   {"domain", mcp::domain_kind_name(p.domain.kind)},
                   {"dimension", p.domain.point_dim()},
                   {"exact", p.exact ? mcp::Json(*p.exact) : mcp::Json(nullptr)},
                   {"estimators", names},
                   {"more_estimators", more},
                   {"estimator_details", details},
                   {"n_min", req.value.settings.n_min},
                   {"n_max", req.value.settings.n_max},
                   {"reps", req.value.settings.reps},
                   {"seed", req.value.settings.seed}};
    *info_json = copy_out(dump(info));
    g_last_error.clear();
    return MCP_OK;
}

int mcp_catalog(char** catalog_json) {
    if (!catalog_json) return fail(MCP_ERROR_ARGUMENT, "mcp_catalog: catalog_json is NULL");
    mcp::Json presets = mcp::Json::array();
    for (const mcp::EstimatorPreset& p : mcp::estimator_presets()) {
        mcp::EstimatorSpec spec; // the preset's words for its points are its kind's
        spec.kind = mcp::find_estimator_kind(p.kind);
        spec.sampler = p.sampler;
        presets.push_back({{"name", p.name},
                           {"kind", p.kind},
                           {"sampler", mcp::point_words(spec).sampler},
                           {"needs_pdf", p.needs_pdf},
                           {"summary", p.summary}});
    }
    mcp::Json kinds = mcp::Json::array();
    for (const mcp::EstimatorKind* k : mcp::estimator_kinds())
        kinds.push_back({{"name", k->name}, {"summary", k->summary}});
    // The samplers parse_sampler knows, and per quasi-Monte Carlo sampler the randomizations
    // that apply to its points (the randomized ones first, "none" last), from the core's tables.
    mcp::Json samplers = mcp::Json::array(), randomizations = mcp::Json::object();
    for (const mcp::SamplerKind sk : mcp::kSamplerKinds) {
        const char* name = mcp::sampler_name(sk);
        samplers.push_back(name);
        if (!mcp::is_qmc(sk)) continue;
        mcp::Json applicable = mcp::Json::array();
        for (const mcp::QmcRandomization rnd : mcp::kQmcRandomizations)
            if (mcp::check_randomization(mcp::qmc_kind_of(sk), rnd).empty())
                applicable.push_back(mcp::randomization_name(rnd));
        randomizations[name] = applicable;
    }
    // The named warps a scene's "warp" may name (estimators/named_warps.h).
    mcp::Json warps = mcp::Json::array();
    for (const mcp::NamedWarpInfo& w : mcp::named_warp_infos())
        warps.push_back({{"name", w.name}, {"summary", w.summary}});
    mcp::Json catalog{{"version", mcp::kResultSchemaVersion},
                      {"estimators", presets},
                      {"kinds", kinds},
                      {"samplers", samplers},
                      {"randomizations", randomizations},
                      {"pdfs",
                       {"uniform", "power", "exponential", "gaussian", "cosine", "tabulated",
                        "product", "tabulated_2d", "cosine_hemisphere", "expression", "warp"}},
                      {"integrands",
                       {"constant", "monomial", "exponential", "gaussian", "indicator_ball",
                        "expression", "genz_oscillatory", "genz_product_peak", "genz_corner_peak",
                        "genz_gaussian", "genz_continuous", "genz_discontinuous"}},
                      {"domains", {"box", "interval", "disk", "triangle", "sphere", "hemisphere"}},
                      {"warps", warps}};
    *catalog_json = copy_out(dump(catalog));
    g_last_error.clear();
    return MCP_OK;
}

} // extern "C"
