// The scene-file reader: a scene JSON and its options -> the problem, the estimators and the
// study settings (docs/scene-format.md), checked as a whole (the study's size, each QMC
// estimator's ladder). The parts are parsed by the scene parsers (api/scene_parsers.h).
#include "api/scene.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "api/json_read.h"
#include "api/report.h" // fmt
#include "api/scene_parsers.h"
#include "core/rng.h"
#include "core/walsh_bound.h"
#include "estimators/named_warps.h"
#include "estimators/registry.h"
#include "estimators/stopping.h"

namespace mcp {

namespace {

/// The estimator "warp" of a scene with a warp: importance sampling with the warp's density.
Json warp_estimator(const Json& warp) {
    return Json{{"name", "warp"}, {"pdf", {{"type", "warp"}, {"warp", warp}}}};
}

} // namespace

Made<SceneRequest> build_request(const Json& scene, const Json& options,
                                 const CallerFunctions* functions) {
    Ctx c;
    c.functions = functions;
    SceneRequest req;
    if (functions) req.problem.control = functions->control;
    const std::string path = "scene";
    if (!check_keys(c, scene, path,
                    {"name", "description", "domain", "integrand", "f", "quantity", "exact",
                     "estimators", "n_min", "n_max", "reps", "seed", "threads", "accumulator",
                     "rel_tol", "abs_tol", "max_seconds", "notes", "warp"}))
        return made_error<SceneRequest>(c.error);
    Problem& pr = req.problem;
    pr.name = "scene";
    if (!get_string(c, scene, "name", path, &pr.name) ||
        !get_string(c, scene, "description", path, &pr.description))
        return made_error<SceneRequest>(c.error);

    // "f": "expression" is shorthand for "integrand": "expression".
    const Json* integrand = find(scene, "integrand");
    const char* integrand_path = "scene.integrand";
    if (const Json* f = find(scene, "f")) {
        if (integrand)
            return made_error<SceneRequest>("scene: give \"integrand\" or \"f\", not both");
        integrand = f;
        integrand_path = "scene.f";
    }
    // A scene's warp (the sampler lab) is tested by mcp_warp_test; in a study it is the
    // importance density of the estimator "warp", on the warp's domain unless one is given.
    const Json* warp = find(scene, "warp");
    NamedWarp named_warp;
    if (warp && !parse_warp(c, *warp, "scene.warp", &named_warp))
        return made_error<SceneRequest>(c.error);
    if (!integrand && warp)
        return made_error<SceneRequest>(
            "scene: a warp and no integrand: test the warp with mcplay warp-test (or the page's "
            "sampler lab), or add \"f\" to integrate with it as an importance sampler");
    if (!integrand)
        return made_error<SceneRequest>("scene: missing \"integrand\" (or \"f\": an expression)");
    int default_dim = 1;
    if (!integrand_dimension(c, *integrand, integrand_path, &default_dim))
        return made_error<SceneRequest>(c.error);
    if (const Json* d = find(scene, "domain")) {
        if (!parse_domain(c, *d, "scene.domain", default_dim, &pr.domain))
            return made_error<SceneRequest>(c.error);
    } else if (warp) {
        pr.domain = named_warp.domain;
    } else {
        Made<Domain> unit = make_box(std::vector<double>(static_cast<size_t>(default_dim), 0.0),
                                     std::vector<double>(static_cast<size_t>(default_dim), 1.0));
        if (!unit.ok())
            return made_error<SceneRequest>(std::string(integrand_path) + ": " + unit.error);
        pr.domain = unit.value;
    }
    if (!parse_integrand(c, *integrand, integrand_path, pr.domain.point_dim(), &pr.integrand))
        return made_error<SceneRequest>(c.error);

    std::string quantity = "integral";
    if (!get_string(c, scene, "quantity", path, &quantity))
        return made_error<SceneRequest>(c.error);
    if (quantity == "integral")
        pr.quantity = Quantity::Integral;
    else if (quantity == "mean")
        pr.quantity = Quantity::Mean;
    else
        return made_error<SceneRequest>(
            "scene.quantity: expected \"integral\" or \"mean\", got \"" + quantity + "\"");

    // "exact": null says the exact value is unknown (docs/scene-format.md): no closed form is
    // looked up, so bias, MSE and coverage stay null. Only a missing key takes the closed form.
    const Json* exact_field = find(scene, "exact");
    if (exact_field && exact_field->is_null()) {
        pr.exact = std::nullopt;
    } else if (exact_field) {
        double exact = 0.0;
        if (!get_number(c, scene, "exact", path, &exact)) return made_error<SceneRequest>(c.error);
        pr.exact = exact;
    } else if (pr.domain.kind == DomainKind::Box) {
        std::optional<double> v = exact_integral_over_box(pr.integrand, pr.domain.lo, pr.domain.hi);
        if (v && pr.quantity == Quantity::Mean) *v /= pr.domain.measure();
        // A closed form outside the double range would be compared with estimates as inf or
        // NaN: refuse the scene rather than report a meaningless error.
        if (v && !std::isfinite(*v))
            return made_error<SceneRequest>(
                std::string(integrand_path) + ": the exact " +
                (pr.quantity == Quantity::Mean ? "mean" : "integral") + " over " +
                pr.domain.describe() + " is " + number_text(*v) +
                ", outside double precision: rescale the integrand or the domain");
        pr.exact = v;
    }

    // Estimators: the scene's list, or the three uniform-density presets.
    std::vector<EstimatorSpec> all;
    std::set<std::string> names;
    if (const Json* list = find(scene, "estimators")) {
        if (!list->is_array() || list->empty())
            return made_error<SceneRequest>("scene.estimators: expected a non-empty array");
        for (size_t i = 0; i < list->size(); ++i) {
            EstimatorSpec spec;
            // "warp" names the importance sampler of the scene's warp.
            const Json entry = warp && (*list)[i] == "warp" ? warp_estimator(*warp) : (*list)[i];
            if (!parse_estimator(c, entry, "scene.estimators[" + std::to_string(i) + "]", pr,
                                 &spec))
                return made_error<SceneRequest>(c.error);
            if (!names.insert(spec.name).second)
                return made_error<SceneRequest>("scene.estimators[" + std::to_string(i) +
                                                "]: duplicate estimator name '" + spec.name + "'");
            all.push_back(spec);
        }
    } else {
        for (const char* n : {"uniform", "stratified", "latin_hypercube"}) {
            EstimatorSpec spec;
            parse_estimator(c, Json(n), "scene.estimators", pr, &spec);
            all.push_back(spec);
        }
        if (warp) {
            EstimatorSpec spec;
            if (!parse_estimator(c, warp_estimator(*warp), "scene.warp", pr, &spec))
                return made_error<SceneRequest>(c.error);
            all.push_back(spec);
        }
    }

    // Settings: defaults, then the scene, then the options.
    StudySettings& s = req.settings;
    uint64_t reps = static_cast<uint64_t>(s.reps), threads = 0;
    if (!get_count(c, scene, "n_min", path, &s.n_min) ||
        !get_count(c, scene, "n_max", path, &s.n_max) ||
        !get_count(c, scene, "reps", path, &reps) || !get_count(c, scene, "seed", path, &s.seed) ||
        !get_count(c, scene, "threads", path, &threads) ||
        !parse_accumulator(c, scene, path, &s.accumulator) ||
        !get_number(c, scene, "rel_tol", path, &s.rel_tol) ||
        !get_number(c, scene, "abs_tol", path, &s.abs_tol) ||
        !get_number(c, scene, "max_seconds", path, &s.max_seconds))
        return made_error<SceneRequest>(c.error);

    req.estimators = all;
    if (!options.is_null()) {
        if (!check_keys(c, options, "options",
                        {"estimators", "n_min", "n_max", "reps", "seed", "threads", "rel_tol",
                         "abs_tol", "max_seconds"}) ||
            !get_number(c, options, "rel_tol", "options", &s.rel_tol) ||
            !get_number(c, options, "abs_tol", "options", &s.abs_tol) ||
            !get_number(c, options, "max_seconds", "options", &s.max_seconds) ||
            !get_count(c, options, "n_min", "options", &s.n_min) ||
            !get_count(c, options, "n_max", "options", &s.n_max) ||
            !get_count(c, options, "reps", "options", &reps) ||
            !get_count(c, options, "seed", "options", &s.seed) ||
            !get_count(c, options, "threads", "options", &threads))
            return made_error<SceneRequest>(c.error);
        if (const Json* sel = find(options, "estimators")) {
            if (!sel->is_array() || sel->empty())
                return made_error<SceneRequest>(
                    "options.estimators: expected a non-empty array of names");
            req.estimators.clear();
            std::set<std::string> chosen;
            for (size_t i = 0; i < sel->size(); ++i) {
                const Json& item = (*sel)[i];
                if (!item.is_string())
                    return made_error<SceneRequest>("options.estimators[" + std::to_string(i) +
                                                    "]: expected a name");
                const std::string name = item.get<std::string>();
                if (!chosen.insert(name).second) continue;
                bool found = false;
                for (const EstimatorSpec& e : all)
                    if (e.name == name) {
                        req.estimators.push_back(e);
                        found = true;
                    }
                if (found) continue;
                const EstimatorPreset* preset = find_preset(name);
                if (preset && !preset->needs_pdf) {
                    EstimatorSpec spec;
                    parse_estimator(c, item, "options.estimators", pr, &spec);
                    req.estimators.push_back(spec);
                    continue;
                }
                std::vector<std::string> have;
                for (const EstimatorSpec& e : all) have.push_back(e.name);
                std::string hint = did_you_mean(name);
                for (const EstimatorSpec& e : all) // a scene's own name may be the near miss
                    if (hint == " (" && edit_distance(name, e.name) > 0 &&
                        edit_distance(name, e.name) * 3 <= e.name.size() && name.size() <= 64)
                        hint = " (did you mean '" + name_text(e.name) + "'? ";
                return made_error<SceneRequest>(
                    "options.estimators[" + std::to_string(i) + "]: unknown estimator '" +
                    name_text(name) + "'" + hint + "this scene has: " + join(have) +
                    (preset ? "; '" + name + "' needs a pdf, which only a scene can give)"
                            : "; presets: " + join(preset_names()) + ")"));
            }
        }
    }
    // check_settings takes ints: a count beyond int is passed as INT_MAX (beyond every limit)
    // and the message then names the count actually given.
    constexpr uint64_t kIntMax = static_cast<uint64_t>(std::numeric_limits<int>::max());
    s.reps = static_cast<int>(std::min(reps, kIntMax));
    s.threads = static_cast<int>(std::min(threads, kIntMax));
    std::string bad = check_settings(s);
    if (!bad.empty()) {
        for (auto [given, passed] :
             {std::pair<uint64_t, int>{reps, s.reps}, {threads, s.threads}}) {
            const std::string tail = "got " + std::to_string(passed);
            if (given != static_cast<uint64_t>(passed) && bad.size() >= tail.size() &&
                bad.compare(bad.size() - tail.size(), tail.size(), tail) == 0) {
                bad = bad.substr(0, bad.size() - tail.size()) + "got " + std::to_string(given);
                break;
            }
        }
        // Whose value is it: the options' (a bad argument) when they set a field the message
        // is about, else the scene's.
        bool from_options = false;
        for (const char* key : {"n_min", "n_max", "reps", "threads"})
            from_options = from_options || (options.is_object() && find(options, key) &&
                                            bad.find(key) != std::string::npos);
        return made_error<SceneRequest>((from_options ? "options: " : "scene: ") + bad);
    }
    // Stopping at a requested accuracy: the tolerances and the time budget. N doubles up to the
    // n_max the options give, or the scene's when the scene itself asks for stopping (then its
    // n_max is its budget); else up to 2^24 (a scene's n_max without its own tolerance is the top
    // of its study ladder, not a budget for a tolerance given from outside, as the page's race).
    const bool scene_stops =
        scene.is_object() && (find(scene, "rel_tol") || find(scene, "abs_tol"));
    if (s.stopping() && !(options.is_object() && find(options, "n_max")) &&
        !(scene_stops && find(scene, "n_max")))
        s.n_max = kStoppingDefaultNMax;
    const bool max_seconds_given = find(scene, "max_seconds") || find(options, "max_seconds");
    if (s.stopping() || s.abs_tol != 0.0 || s.rel_tol != 0.0 || max_seconds_given) {
        const bool from_options =
            options.is_object() &&
            (find(options, "rel_tol") || find(options, "abs_tol") || find(options, "max_seconds"));
        const char* who = from_options ? "options: " : "scene: ";
        // Given, a budget is a budget: 0 is refused rather than read as "none".
        if (!(s.max_seconds > 0.0 || !max_seconds_given) || !std::isfinite(s.max_seconds))
            return made_error<SceneRequest>(
                std::string(find(options, "max_seconds") ? "options: " : "scene: ") +
                "max_seconds: must be a finite number > 0, got " + fmt("%.3g", s.max_seconds) +
                " (leave it out for no time budget)");
        if (!s.stopping() && s.max_seconds > 0.0)
            return made_error<SceneRequest>(std::string(who) +
                                            "max_seconds: applies with rel_tol or abs_tol only");
        const std::string bad_tol = check_stopping(tolerance_of(s), budget_of(s));
        if (!bad_tol.empty()) return made_error<SceneRequest>(who + bad_tol);
    }
    // The whole study's size, before any work (a run of 2^36 points is refused, not begun).
    const std::string too_big = check_study_size(s, req.estimators.size());
    if (!too_big.empty()) {
        bool from_options = false;
        for (const char* key : {"n_min", "n_max", "reps", "estimators"})
            from_options = from_options || (options.is_object() && find(options, key));
        return made_error<SceneRequest>((from_options ? "options: " : "scene: ") + too_big);
    }
    for (const EstimatorSpec& e : req.estimators) {
        const bool plus = e.kind && std::string(e.kind->name) == "vegas_plus";
        const bool vegas_kind = plus || (e.kind && std::string(e.kind->name) == "vegas");
        const std::string untrainable =
            vegas_kind ? vegas_untrainable(vegas_resolved(e.vegas_options, e.sampler, plus,
                                                          req.problem.domain.sample_dim()),
                                           s.n_max)
                       : std::string();
        if (!untrainable.empty())
            return made_error<SceneRequest>("estimator '" + name_text(e.name) +
                                            "': " + untrainable);
        // The estimator's own checks (its file's): N doubles from the ladder's first power of
        // two, or from n_min when stopping at a tolerance.
        const std::vector<uint64_t> runs_n = n_ladder(s.n_min, s.n_max);
        const uint64_t n_first = s.stopping() || runs_n.empty() ? s.n_min : runs_n.front();
        const std::string refused =
            check_estimator(e, StudyShape{req.problem.domain.sample_dim(), n_first, s.n_max});
        if (!refused.empty())
            return made_error<SceneRequest>(
                (options.is_object() && (find(options, "n_min") || find(options, "n_max"))
                     ? "options: estimator '"
                     : "scene: estimator '") +
                name_text(e.name) + "': " + refused);
        if (e.per_stratum > 1 && s.n_min < e.per_stratum)
            return made_error<SceneRequest>("estimator '" + e.name + "': samples_per_stratum = " +
                                            std::to_string(e.per_stratum) +
                                            " needs n_min >= " + std::to_string(e.per_stratum));
        if (!is_qmc(e.sampler)) continue;
        const uint64_t k = static_cast<uint64_t>(e.randomizations);
        const std::string who =
            (options.is_object() && (find(options, "n_min") || find(options, "n_max"))
                 ? "options: estimator '"
                 : "scene: estimator '") +
            name_text(e.name) + "': ";
        const std::vector<uint64_t> ladder = n_ladder(s.n_min, s.n_max);
        if (e.walsh_bound) {
            // The bound transforms N = 2^m values, at most 2^kWalshMaxLog2 (its coefficients are
            // kept); runs below 2^kWalshMinLog2 (where the cone's bands begin) have no error
            // bar. Stopping doubles from n_min (raised to 2^kWalshMinLog2).
            const uint64_t least = uint64_t(1) << kWalshMinLog2, most = uint64_t(1)
                                                                        << kWalshMaxLog2;
            if (s.n_max < least)
                return made_error<SceneRequest>(
                    who + "the Walsh bound needs N = 2^m points, at least " +
                    std::to_string(least) + ": n_max must be at least " + std::to_string(least) +
                    ", got " + std::to_string(s.n_max));
            if (s.stopping() && (s.n_min & (s.n_min - 1)) != 0)
                return made_error<SceneRequest>(who +
                                                "the Walsh bound doubles N = 2^m: n_min must "
                                                "be a power of two, got " +
                                                std::to_string(s.n_min));
            if (s.n_max > most)
                return made_error<SceneRequest>(who +
                                                "the Walsh bound keeps N coefficients: n_max "
                                                "must be at most 2^" +
                                                std::to_string(kWalshMaxLog2) + " = " +
                                                std::to_string(most) + ", got " +
                                                std::to_string(s.n_max));
        }
        if (!ladder.empty() && ladder.front() < k)
            return made_error<SceneRequest>(
                who + std::to_string(k) + " randomizations need n_min >= " + std::to_string(k) +
                " (each run is " + std::to_string(k) + " randomizations of N/" + std::to_string(k) +
                " points), got n_min = " + std::to_string(s.n_min));
        const uint64_t most = qmc_max_points(qmc_kind_of(e.sampler));
        if (s.n_max / k > most)
            return made_error<SceneRequest>(
                who + "n_max = " + std::to_string(s.n_max) + " would give " +
                std::to_string(s.n_max / k) + " points per randomization, beyond the " +
                std::to_string(most) + " the " + sampler_name(e.sampler) +
                " points are built for; lower n_max or raise randomizations");
    }
    // A typed warp that leaves its domain is refused before any work when a probe of 256 points
    // of its unit cube shows it (every block of the runs is checked as well: warp_block).
    for (const EstimatorSpec& e : req.estimators)
        for (const Proposal* p : proposals_of(e)) {
            if (p->kind != ProposalKind::Warp || !p->warp || !p->warp->escape) continue;
            PointBlock u, x;
            u.reset(req.problem.domain.sample_dim(), kBlockSize);
            x.reset(req.problem.domain.point_dim(), kBlockSize);
            std::vector<double> pdf(kBlockSize);
            Pcg32 probe(0x5eed, 47);
            u.n = kBlockSize;
            for (size_t i = 0; i < kBlockSize; ++i)
                for (int j = 0; j < u.dim; ++j) u.coord(j)[i] = probe.next_double();
            warp_block(*p, req.problem.domain, u, x, pdf.data());
        }
    if (std::string why = warp_escape_error(req); !why.empty())
        return made_error<SceneRequest>("scene: " + why);
    return {req, {}};
}

std::string warp_escape_error(const SceneRequest& req) {
    for (const EstimatorSpec& e : req.estimators)
        for (const Proposal* p : proposals_of(e))
            if (p->kind == ProposalKind::Warp && p->warp && p->warp->escape &&
                p->warp->escape->seen())
                return "estimator '" + e.name + "': its warp put a point outside its domain (" +
                       p->warp->escape->describe(p->warp_domain) +
                       "): a proposal must map the unit cube into the domain, so the study "
                       "has no estimate (mcplay warp-test shows such points)";
    return "";
}

} // namespace mcp
