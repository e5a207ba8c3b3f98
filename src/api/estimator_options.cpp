// The estimator kinds' own JSON fields (api/estimator_options.h): VEGAS and VEGAS+ ("vegas"),
// MISER ("miser"), multiple importance sampling ("proposals", "heuristic", ...), control
// variates ("control_variates", "coefficients") and resampled importance sampling ("ris"). Each
// parse validates its fields up front, bounded before any work, and checks the sampler its kind
// accepts.
#include "api/estimator_options.h"

#include <cmath>
#include <optional>

#include "api/scene_parsers.h"
#include "estimators/registry.h"

namespace mcp {
namespace {

/// The "vegas" object of an estimator: every field optional, each bounded before any work.
bool parse_vegas_options(Ctx& c, const Json& j, const std::string& path, int dim,
                         VegasOptions* out) {
    if (!check_keys(c, j, path,
                    {"increments", "alpha", "train_fraction", "train_iterations", "uniform_share",
                     "report", "iterations", "stratify", "beta", "train_stop"}))
        return false;
    uint64_t increments = 0, iterations = static_cast<uint64_t>(out->train_iterations);
    uint64_t rounds = static_cast<uint64_t>(out->iterations);
    std::string report, train_stop;
    if (!get_count(c, j, "increments", path, &increments) ||
        !get_number(c, j, "alpha", path, &out->alpha) ||
        !get_number(c, j, "train_fraction", path, &out->train_fraction) ||
        !get_number(c, j, "uniform_share", path, &out->uniform_share) ||
        !get_count(c, j, "train_iterations", path, &iterations) ||
        !get_count(c, j, "iterations", path, &rounds) ||
        !get_string(c, j, "report", path, &report) || !get_number(c, j, "beta", path, &out->beta) ||
        !get_string(c, j, "train_stop", path, &train_stop))
        return false;
    // The map holds dim x increments edges and sums: at most 2^22 of each.
    if (find(j, "increments") &&
        (increments < 1 || increments * static_cast<uint64_t>(dim) > (uint64_t(1) << 22)))
        return c.fail(sub(path, "increments"),
                      "must be >= 1 and at most 4194304 / dimension (" +
                          std::to_string((uint64_t(1) << 22) / static_cast<uint64_t>(dim)) +
                          " here), got " + std::to_string(increments));
    if (find(j, "alpha") && !(out->alpha >= 0.0 && out->alpha <= 4.0))
        return c.fail(
            sub(path, "alpha"),
            "must be in [0, 4] (default 1 for the map alone, else 0.5 as in vegas; GSL 1.5)");
    if (!(out->train_fraction >= 0.0 && out->train_fraction <= 0.9))
        return c.fail(sub(path, "train_fraction"),
                      "must be in [0, 0.9]: the share of N that trains the map");
    if (find(j, "uniform_share") && !(out->uniform_share >= 0.0 && out->uniform_share <= 1.0))
        return c.fail(sub(path, "uniform_share"), "must be in [0, 1]");
    if (find(j, "train_iterations") && (iterations < 1 || iterations > 1000))
        return c.fail(sub(path, "train_iterations"), "must be in [1, 1000]");
    // Left out: the estimator's default (vegas_resolved).
    if (train_stop == "settled")
        out->train_stop = VegasTrainStop::Settled;
    else if (train_stop == "budget")
        out->train_stop = VegasTrainStop::Budget;
    else if (!train_stop.empty())
        return c.fail(sub(path, "train_stop"), "expected \"settled\" (stop training once the map "
                                               "has settled) or \"budget\" (train on the whole "
                                               "train_fraction), got \"" +
                                                   train_stop.substr(0, 64) + "\"");
    if (report == "iterations")
        out->report = VegasReport::Iterations;
    else if (report == "frozen" || report.empty())
        out->report = VegasReport::Frozen;
    else
        return c.fail(sub(path, "report"), "expected \"frozen\" (train, then estimate with the "
                                           "frozen map) or \"iterations\" (the weighted average "
                                           "of adapting iterations), got \"" +
                                               report.substr(0, 64) + "\"");
    if (const Json* st = find(j, "stratify")) {
        if (!st->is_boolean())
            return c.fail(sub(path, "stratify"), "expected true or false, got " + type_of(*st));
        out->stratify = st->get<bool>();
    }
    if (!(out->beta >= 0.0 && out->beta <= 2.0))
        return c.fail(sub(path, "beta"),
                      "must be in [0, 2] (0: equal points per hypercube; vegas uses 0.75)");
    if (out->stratify && out->report == VegasReport::Iterations)
        return c.fail(sub(path, "report"), "adaptive stratification (\"stratify\") reports the "
                                           "frozen map and allocation only");
    if (rounds < 2 || rounds > 1000) return c.fail(sub(path, "iterations"), "must be in [2, 1000]");
    out->iterations = static_cast<int>(rounds);
    out->increments = static_cast<int>(increments);
    out->train_iterations = static_cast<int>(iterations);
    return true;
}

/// The "miser" object of an estimator: every field optional, each bounded.
bool parse_miser_options(Ctx& c, const Json& j, const std::string& path, MiserOptions* out) {
    if (!check_keys(
            c, j, path,
            {"estimate_fraction", "min_calls", "min_calls_per_bisection", "alpha", "dither"}))
        return false;
    if (!get_number(c, j, "estimate_fraction", path, &out->estimate_fraction) ||
        !get_count(c, j, "min_calls", path, &out->min_calls) ||
        !get_count(c, j, "min_calls_per_bisection", path, &out->min_calls_per_bisection) ||
        !get_number(c, j, "alpha", path, &out->alpha) ||
        !get_number(c, j, "dither", path, &out->dither))
        return false;
    if (!(out->estimate_fraction > 0.0 && out->estimate_fraction <= 0.5))
        return c.fail(sub(path, "estimate_fraction"),
                      "must be in (0, 0.5]: the share of a region's calls that probe it");
    if (find(j, "min_calls") && (out->min_calls < 2 || out->min_calls > (uint64_t(1) << 30)))
        return c.fail(sub(path, "min_calls"), "must be in [2, 2^30]");
    if (out->min_calls_per_bisection > (uint64_t(1) << 40))
        return c.fail(sub(path, "min_calls_per_bisection"), "must be at most 2^40");
    if (!(out->alpha >= 0.0 && out->alpha <= 10.0))
        return c.fail(sub(path, "alpha"), "must be in [0, 10] (GSL uses 2)");
    if (!(out->dither >= 0.0 && out->dither <= 0.25))
        return c.fail(sub(path, "dither"), "must be in [0, 0.25] (typical: 0.05 to 0.1)");
    return true;
}

/// Multiple importance sampling fields of an estimator object: "proposals" (pdfs, or "uniform"
/// for the domain's uniform density), "fractions", "heuristic" (with "beta" or "cutoff"),
/// "one_sample" and "defensive" (Hesterberg's mixture: the uniform density joins with that
/// share). A lone "pdf" with "defensive" is the first proposal.
bool parse_mis_options(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                       const Json* pdf, MisOptions* out) {
    const Json* proposals = find(j, "proposals");
    std::vector<Json> entries;
    if (proposals) {
        if (pdf)
            return c.fail(sub(path, "pdf"), "an estimator has \"pdf\" or \"proposals\", not both");
        if (!proposals->is_array())
            return c.fail(sub(path, "proposals"),
                          "expected an array of pdfs (or \"uniform\"), got " + type_of(*proposals));
        if (proposals->empty())
            return c.fail(sub(path, "proposals"),
                          "is empty: multiple importance sampling needs at least one proposal");
        if (proposals->size() > static_cast<size_t>(kMaxMisTechniques))
            return c.fail(sub(path, "proposals"),
                          "has " + std::to_string(proposals->size()) + " entries; at most " +
                              std::to_string(kMaxMisTechniques) + " techniques are combined");
        for (const Json& e : *proposals) entries.push_back(e);
    } else if (pdf) {
        entries.push_back(*pdf);
    } else {
        entries.push_back("uniform");
    }
    for (size_t k = 0; k < entries.size(); ++k) {
        const std::string at =
            (proposals ? sub(path, "proposals") + "[" + std::to_string(k) + "]" : sub(path, "pdf"));
        Proposal prop = uniform_proposal(problem.domain);
        if (!(entries[k].is_string() && entries[k] == "uniform") &&
            !parse_pdf(c, entries[k], at, problem, &prop))
            return false;
        out->proposals.push_back(prop);
    }
    const size_t k_count = out->proposals.size();
    out->fractions.assign(k_count, 1.0 / static_cast<double>(k_count));
    if (find(j, "fractions")) {
        std::vector<double> f;
        if (!get_numbers(c, j, "fractions", path, &f)) return false;
        if (f.size() != k_count)
            return c.fail(sub(path, "fractions"), "has " + std::to_string(f.size()) +
                                                      " entries for " + std::to_string(k_count) +
                                                      " proposals");
        double total = 0.0;
        for (double x : f) {
            if (!(x > 0.0 && x <= 1e6))
                return c.fail(sub(path, "fractions"),
                              "each share must be positive (and at most 1e6), got " +
                                  number_text(x));
            total += x;
        }
        for (size_t k = 0; k < k_count; ++k) out->fractions[k] = f[k] / total;
    }
    double defensive = 0.0;
    if (!get_number(c, j, "defensive", path, &defensive)) return false;
    if (find(j, "defensive")) {
        if (!(defensive > 0.0 && defensive < 1.0))
            return c.fail(sub(path, "defensive"),
                          "must be in (0, 1): the uniform density's share of the mixture "
                          "(Hesterberg suggests 0.1 to 0.5), got " +
                              number_text(defensive));
        if (k_count + 1 > static_cast<size_t>(kMaxMisTechniques))
            return c.fail(sub(path, "defensive"), "the uniform density would be technique " +
                                                      std::to_string(k_count + 1) + "; at most " +
                                                      std::to_string(kMaxMisTechniques));
        for (double& f : out->fractions) f *= 1.0 - defensive;
        out->proposals.push_back(uniform_proposal(problem.domain));
        out->fractions.push_back(defensive);
    }
    std::string heuristic = "balance";
    if (!get_string(c, j, "heuristic", path, &heuristic)) return false;
    if (heuristic == "balance")
        out->weighting.heuristic = MisHeuristic::Balance;
    else if (heuristic == "power")
        out->weighting.heuristic = MisHeuristic::Power;
    else if (heuristic == "maximum")
        out->weighting.heuristic = MisHeuristic::Maximum;
    else if (heuristic == "cutoff")
        out->weighting.heuristic = MisHeuristic::Cutoff;
    else if (heuristic == "optimal")
        out->optimal = true;
    else
        return c.fail(sub(path, "heuristic"),
                      "unknown heuristic '" + heuristic.substr(0, 64) +
                          "' (known: balance, power, maximum, cutoff, optimal)");
    if (find(j, "beta")) {
        if (out->weighting.heuristic != MisHeuristic::Power || out->optimal)
            return c.fail(sub(path, "beta"), "applies to the power heuristic only");
        if (!get_number(c, j, "beta", path, &out->weighting.beta)) return false;
        if (!(out->weighting.beta >= 1.0 && out->weighting.beta <= 16.0))
            return c.fail(sub(path, "beta"), "must be in [1, 16] (Veach uses 2), got " +
                                                 number_text(out->weighting.beta));
    }
    if (find(j, "cutoff")) {
        if (out->weighting.heuristic != MisHeuristic::Cutoff || out->optimal)
            return c.fail(sub(path, "cutoff"), "applies to the cutoff heuristic only");
        if (!get_number(c, j, "cutoff", path, &out->weighting.cutoff)) return false;
        if (!(out->weighting.cutoff >= 0.0 && out->weighting.cutoff <= 1.0))
            return c.fail(sub(path, "cutoff"), "must be in [0, 1] (Veach uses 0.1), got " +
                                                   number_text(out->weighting.cutoff));
    }
    if (const Json* one = find(j, "one_sample")) {
        if (!one->is_boolean())
            return c.fail(sub(path, "one_sample"), "expected true or false, got " + type_of(*one));
        out->one_sample = one->get<bool>();
    }
    // A heuristic weighs two or more techniques: over one it would be ignored without a word.
    if (out->proposals.size() < 2)
        for (const char* key : {"heuristic", "beta", "cutoff"})
            if (find(j, key)) {
                const Json* name = find(j, "name");
                return c.fail(sub(path, key),
                              "estimator '" +
                                  name_text(name && name->is_string() ? name->get<std::string>()
                                                                      : std::string()) +
                                  "' samples one technique, and a heuristic weighs two or more: "
                                  "give two or more \"proposals\" (or \"defensive\")");
            }
    return true;
}

/// Control-variate fields: "control_variates": [{"g": integrand, "integral": G}, ...] and the
/// optional "coefficients" (one per variate; fitted when absent).
bool parse_control_variates(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                            ControlVariateOptions* out) {
    const Json* list = find(j, "control_variates");
    const std::string at = sub(path, "control_variates");
    if (!list->is_array() || list->empty())
        return c.fail(at, "expected an array of {\"g\": ..., \"integral\": ...}, got " +
                              type_of(*list));
    if (list->size() > static_cast<size_t>(kMaxControlVariates))
        return c.fail(at, "has " + std::to_string(list->size()) + " entries; at most " +
                              std::to_string(kMaxControlVariates));
    for (size_t k = 0; k < list->size(); ++k) {
        const std::string here = at + "[" + std::to_string(k) + "]";
        const Json& e = (*list)[k];
        if (!e.is_object())
            return c.fail(here, "expected {\"g\": ..., \"integral\": ...}, got " + type_of(e));
        if (!check_keys(c, e, here, {"g", "integral"})) return false;
        const Json* g = find(e, "g");
        if (!g) return c.fail(here, "a control variate needs \"g\": an expression or integrand");
        ControlVariate cv;
        if (!parse_integrand(c, *g, sub(here, "g"), problem.domain.point_dim(), &cv.g))
            return false;
        cv.text = g->is_string() ? g->get<std::string>().substr(0, 200) : g->dump().substr(0, 200);
        if (find(e, "integral")) {
            if (!get_number(c, e, "integral", here, &cv.integral)) return false;
            if (!std::isfinite(cv.integral))
                return c.fail(sub(here, "integral"), "must be a finite number");
        } else {
            std::optional<double> known =
                problem.domain.kind == DomainKind::Box
                    ? exact_integral_over_box(cv.g, problem.domain.lo, problem.domain.hi)
                    : std::nullopt;
            if (!known)
                return c.fail(here, "needs \"integral\": the integral of g over the domain (known "
                                    "in closed form only for built-in integrands on boxes)");
            cv.integral = *known;
        }
        out->variates.push_back(cv);
    }
    if (find(j, "coefficients")) {
        if (!get_numbers(c, j, "coefficients", path, &out->coefficients)) return false;
        if (out->coefficients.size() != out->variates.size())
            return c.fail(sub(path, "coefficients"),
                          "has " + std::to_string(out->coefficients.size()) + " entries for " +
                              std::to_string(out->variates.size()) + " control variates");
        for (double x : out->coefficients)
            if (!std::isfinite(x))
                return c.fail(sub(path, "coefficients"), "must be finite numbers");
    }
    return true;
}

bool parse_vegas_fields(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                        const Json* /*pdf*/, EstimatorSpec* out) {
    // "stratify" defaults to what the preset is (vegas_plus: true).
    out->vegas_options.stratify = out->kind && std::string(out->kind->name) == "vegas_plus";
    if (!parse_vegas_options(c, *find(j, "vegas"), sub(path, "vegas"), problem.domain.sample_dim(),
                             &out->vegas_options))
        return false;
    const bool plus = out->vegas_options.stratify;
    out->kind = find_estimator_kind(plus ? "vegas_plus" : "vegas");
    if (plus && out->sampler != SamplerKind::Independent)
        return c.fail(sub(path, "sampler"), "VEGAS+ (\"stratify\": true) draws its own points in "
                                            "its hypercubes: the sampler must be independent");
    return true;
}

bool parse_miser_fields(Ctx& c, const Json& j, const std::string& path, const Problem& /*problem*/,
                        const Json* /*pdf*/, EstimatorSpec* out) {
    out->kind = find_estimator_kind("miser");
    if (out->sampler != SamplerKind::Independent)
        return c.fail(sub(path, "sampler"), "MISER draws its own points in its regions: the "
                                            "sampler must be independent");
    return parse_miser_options(c, *find(j, "miser"), sub(path, "miser"), &out->miser_options);
}

bool parse_mis_fields(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                      const Json* pdf, EstimatorSpec* out) {
    out->kind = find_estimator_kind("mis");
    if (out->sampler != SamplerKind::Independent)
        return c.fail(sub(path, "sampler"), "multiple importance sampling needs the independent "
                                            "sampler (its error bar is that of independent "
                                            "points)");
    if (!parse_mis_options(c, j, path, problem, pdf, &out->mis_options)) return false;
    out->proposal = out->mis_options.proposals[0];
    return true;
}

bool parse_control_variate_fields(Ctx& c, const Json& j, const std::string& path,
                                  const Problem& problem, const Json* /*pdf*/, EstimatorSpec* out) {
    out->kind = find_estimator_kind("control_variates");
    if (out->sampler != SamplerKind::Independent)
        return c.fail(sub(path, "sampler"), "control variates needs the independent sampler (its "
                                            "error bar is that of independent points)");
    return parse_control_variates(c, j, path, problem, &out->control_variate_options);
}

/// Resampled importance sampling: "ris": {"candidates": M, "target": "pdf" or "f"}. The target
/// is the estimator's "pdf" when it has one (the candidates are then uniform), else |f| at the
/// candidates (drawn from the "pdf" under "target": "f", else uniform).
bool parse_ris_fields(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                      const Json* pdf, EstimatorSpec* out) {
    out->kind = find_estimator_kind("ris");
    const std::string at = sub(path, "ris");
    const Json& r = *find(j, "ris");
    if (!r.is_object())
        return c.fail(at, "expected an object {\"candidates\", \"target\"}, got " + type_of(r));
    uint64_t m = static_cast<uint64_t>(out->ris_options.candidates);
    std::string target;
    if (!check_keys(c, r, at, {"candidates", "target"}) || !get_count(c, r, "candidates", at, &m) ||
        !get_string(c, r, "target", at, &target))
        return false;
    if (m < 1 || m > static_cast<uint64_t>(RisOptions::kMaxCandidates))
        return c.fail(sub(at, "candidates"),
                      "must be in [1, " + std::to_string(RisOptions::kMaxCandidates) +
                          "] (candidates per point), got " + std::to_string(m));
    if (!target.empty() && target != "pdf" && target != "f")
        return c.fail(sub(at, "target"), "expected \"pdf\" (the estimator's pdf) or \"f\" (|f| "
                                         "at the candidates), got \"" +
                                             target + "\"");
    if (target == "pdf" && !pdf)
        return c.fail(sub(at, "target"), "\"pdf\" needs the estimator's \"pdf\" as the target");
    if (out->sampler != SamplerKind::Independent)
        return c.fail(sub(path, "sampler"), "resampled importance sampling needs the independent "
                                            "sampler (its error bar is that of independent "
                                            "points)");
    out->ris_options.candidates = static_cast<int>(m);
    out->ris_options.target_pdf = pdf && target != "f";
    out->proposal = uniform_proposal(problem.domain);
    if (!pdf) return true;
    Proposal* into = out->ris_options.target_pdf ? &out->ris_options.target : &out->proposal;
    return parse_pdf(c, *pdf, sub(path, "pdf"), problem, into);
}

} // namespace

const std::vector<KindFields>& kind_fields() {
    static const std::vector<KindFields> fields = {
        {{"vegas", "vegas_plus"}, {"vegas"}, {}, false, parse_vegas_fields},
        {{"miser"}, {"miser"}, {}, false, parse_miser_fields},
        {{"mis"},
         {"proposals", "fractions", "heuristic", "beta", "cutoff", "one_sample", "defensive"},
         {},
         true,
         parse_mis_fields},
        {{"control_variates"},
         {"control_variates"},
         {"coefficients"},
         false,
         parse_control_variate_fields},
        {{"ris"}, {"ris"}, {}, true, parse_ris_fields},
    };
    return fields;
}

} // namespace mcp
