// Study results as text: the human table and the CSV (api/report.h format_table, format_csv),
// rendered from a result's JSON (api/report.cpp, docs/result-schema.md), so that any client
// holding a result can format it; integration, stopping and render studies alike.
#include <cmath>
#include <cstdio>
#include <sstream>

#include "api/report.h"
#include "core/special.h"

namespace mcp {

namespace {

std::string padl(const std::string& s, size_t w) {
    return s.size() >= w ? s : std::string(w - s.size(), ' ') + s;
}
std::string padr(const std::string& s, size_t w) {
    return s.size() >= w ? s : s + std::string(w - s.size(), ' ');
}

// Accessors that never throw, whatever shape of JSON a client hands back to us.
const Json& get(const Json& j, const char* key) {
    static const Json null_json;
    if (!j.is_object()) return null_json;
    auto it = j.find(key);
    return it == j.end() ? null_json : *it;
}

const Json& at_index(const Json& j, size_t i) {
    static const Json null_json;
    return j.is_array() && i < j.size() ? j[i] : null_json;
}

// Iterates arrays only (a number or string is not a list of levels).
const Json& list(const Json& j, const char* key) {
    static const Json empty = Json::array();
    const Json& v = get(j, key);
    return v.is_array() ? v : empty;
}

double jnum(const Json& j, const char* key) {
    const Json& v = get(j, key);
    return v.is_number() ? v.get<double>() : NAN;
}

std::string jstr(const Json& j, const char* key) {
    const Json& v = get(j, key);
    return v.is_string() ? v.get<std::string>() : "";
}

bool jbool(const Json& j, const char* key) {
    const Json& v = get(j, key);
    return v.is_boolean() && v.get<bool>();
}

// After a fitted order: " (not a power law: chi^2 p = 3e-12)" when the fit's goodness of fit
// rejects a straight line in log-log (p_value below kPowerLawP), else "".
std::string power_law_note(const Json& fit) {
    const double p = jnum(fit, "p_value");
    if (!jbool(fit, "valid") || !(p < kPowerLawP)) return "";
    return " (not a power law: chi^2 " + p_value_text(p) + ")";
}

} // namespace

namespace {

// The table that closes a study: each estimator at its largest level, with its error, time
// per estimate, efficiency 1 / (error x time), and efficiency relative to the first estimator.
struct ComparisonLabels {
    const char* title;
    const char *n, *error, *time;
    size_t name_width, n_width, error_width, time_width;
};

void comparison_table(std::ostringstream& out, const Json& ests, const ComparisonLabels& c) {
    if (ests.size() < 2) return;
    out << "\n" << c.title << "\n";
    out << padr("  estimator", c.name_width) << padl(c.n, c.n_width) << padl(c.error, c.error_width)
        << padl(c.time, c.time_width) << padl("efficiency", 12) << padl("vs first", 10) << "\n";
    double first = NAN;
    for (const Json& e : ests) {
        const Json& levels = list(e, "levels");
        if (levels.empty()) continue;
        const Json& l = levels.back();
        const double eff = jnum(l, "efficiency");
        if (std::isnan(first)) first = eff;
        out << padr("  " + jstr(e, "name"), c.name_width)
            << padl(fmt("%.0f", jnum(l, "n")), c.n_width)
            << padl(fmt("%.4e", jnum(l, "variance") >= 0.0 ? jnum(l, "variance") : NAN),
                    c.error_width)
            << padl(fmt("%.2e", jnum(l, "time_mean_s")), c.time_width) << padl(fmt("%.3e", eff), 12)
            << padl(first > 0 && std::isfinite(eff) ? fmt("%.3gx", eff / first) : "-", 10) << "\n";
    }
}

} // namespace

// Render studies: relative MSE against spp, with the image's mean luminance for the bias.
/// Warnings as lines, most severe first: "  ERROR   code: message" (WARNING, info).
void print_warnings(std::ostringstream& out, Json warnings) {
    sort_by_severity(warnings);
    for (const Json& w : warnings) {
        const std::string severity = jstr(w, "severity");
        const std::string label = severity == "error"     ? "ERROR"
                                  : severity == "warning" ? "WARNING"
                                  : severity == "info"    ? "info"
                                                          : "note";
        out << "  " << padr(label, 8) << jstr(w, "code") << ": " << jstr(w, "message") << "\n";
    }
}

std::string format_render_table(const Json& r) {
    std::ostringstream out;
    const Json& scene = get(r, "scene");
    const Json& settings = get(r, "settings");
    const Json& ref = get(scene, "reference");
    out << "mcplay " << jstr(r, "mcplay") << "  render scene " << jstr(scene, "name");
    if (!jstr(scene, "description").empty()) out << ": " << jstr(scene, "description");
    out << "\n  " << fmt("%.0f", jnum(scene, "width")) << "x" << fmt("%.0f", jnum(scene, "height"))
        << ", " << fmt("%.0f", jnum(scene, "triangles")) << " triangles, "
        << fmt("%.0f", jnum(scene, "lights")) << " light triangle(s), reference "
        << jstr(ref, "source");
    if (get(ref, "spp").is_number()) out << " at " << fmt("%.0f", jnum(ref, "spp")) << " spp";
    out << "\n  spp = " << fmt("%.0f", jnum(settings, "n_min")) << " .. "
        << fmt("%.0f", jnum(settings, "n_max")) << ", " << fmt("%.0f", jnum(settings, "reps"))
        << " images per spp, seed " << fmt("%.0f", jnum(settings, "seed")) << ", "
        << fmt("%.0f", jnum(settings, "threads")) << " thread(s), "
        << fmt("%.2f", jnum(r, "wall_time_s")) << " s\n";
    print_warnings(out, list(scene, "warnings"));
    if (jbool(r, "cancelled")) out << "  (cancelled: partial result)\n";
    for (const Json& e : list(r, "estimators")) {
        out << "\n"
            << jstr(e, "name") << "  [" << jstr(e, "strategy") << ", lights by "
            << jstr(e, "light_selection") << ", " << jstr(e, "pixel_sampler") << " pixels";
        if (get(e, "candidates").is_number())
            out << ", " << fmt("%.0f", jnum(e, "candidates")) << " candidates";
        out << "]\n";
        out << padl("spp", 7) << padl("rel.MSE", 12) << padl("mean lum.", 13) << padl("bias/se", 9)
            << padl("px cover", 9) << padl("s/image", 10) << padl("efficiency", 12)
            << padl("discarded", 10) << "\n";
        for (const Json& l : list(e, "levels")) {
            const double se = jnum(l, "std_error"), bias = jnum(l, "bias");
            out << padl(fmt("%.0f", jnum(l, "n")), 7) << padl(fmt("%.4e", jnum(l, "variance")), 12)
                << padl(fmt("%.6g", jnum(l, "mean")), 13)
                << padl(se > 0 ? fmt("%+.2f", bias / se) : "-", 9)
                << padl(fmt("%.3f", jnum(l, "coverage95")), 9)
                << padl(fmt("%.2e", jnum(l, "time_mean_s")), 10)
                << padl(fmt("%.3e", jnum(l, "efficiency")), 12)
                << padl(fmt("%.0f", jnum(get(l, "diagnostics"), "nonfinite")), 10) << "\n";
        }
        const Json& fit = get(e, "fit");
        if (jbool(fit, "valid"))
            out << "  fitted order: relative MSE ~ spp^(" << fmt("%.3f", jnum(fit, "order"))
                << " +/- " << fmt("%.3f", jnum(fit, "order_se")) << ")" << power_law_note(fit);
        else
            out << "  fitted order: none";
        if (!jstr(fit, "note").empty()) out << " (" << jstr(fit, "note") << ")";
        out << ";  " << fmt("%.3g", jnum(e, "rays_per_second")) << " rays/s\n";
        Json shown = list(e, "warnings");
        const Json& levels = list(e, "levels");
        if (!levels.empty())
            for (const Json& w : list(levels.back(), "warnings")) shown.push_back(w);
        print_warnings(out, shown);
    }
    // Equal-time comparison at the largest spp: which estimator buys the least error per
    // second of rendering.
    comparison_table(out, list(r, "estimators"),
                     ComparisonLabels{"comparison at the largest spp (efficiency = 1 / (relative "
                                      "MSE x seconds); higher is better)",
                                      "spp", "rel.MSE", "s/image", 30, 7, 12, 10});
    return out.str();
}

namespace {
// Stopping studies: per estimator, how often the tolerance was met, the answers' spread, and
// the evaluations and seconds it took (median and range over the replicates).
std::string format_stopping_table(const Json& r) {
    std::ostringstream out;
    const Json& scene = get(r, "scene");
    const Json& settings = get(r, "settings");
    const Json& stop = get(r, "stopping");
    const double exact = jnum(scene, "exact");
    const bool has_exact = std::isfinite(exact);
    out << "mcplay " << jstr(r, "mcplay") << "  scene " << jstr(scene, "name") << "\n  "
        << jstr(scene, "quantity") << " of f = " << jstr(scene, "integrand") << " over "
        << jstr(scene, "domain_text") << "\n  exact "
        << (has_exact ? fmt("%.12g", exact) : std::string("unknown")) << "   stopping at ";
    if (jnum(stop, "rel_tol") > 0.0) out << "rel_tol " << fmt("%.3g", jnum(stop, "rel_tol"));
    if (jnum(stop, "abs_tol") > 0.0)
        out << (jnum(stop, "rel_tol") > 0.0 ? " or " : "") << "abs_tol "
            << fmt("%.3g", jnum(stop, "abs_tol"));
    out << " (95% half-width), N from " << fmt("%.0f", jnum(settings, "n_min")) << " doubling to "
        << fmt("%.0f", jnum(settings, "n_max"));
    if (std::isfinite(jnum(stop, "max_seconds")))
        out << ", at most " << fmt("%.3g", jnum(stop, "max_seconds")) << " s per estimate";
    out << ", " << fmt("%.0f", jnum(settings, "reps")) << " replicates, seed "
        << fmt("%.0f", jnum(settings, "seed")) << "\n  rule: " << jstr(stop, "rule") << "\n\n";
    out << padr("estimator", 24) << padl("met", 8) << padl("within", 8) << padl("estimate", 17)
        << padl("+/- (95%)", 12) << padl("evals (median)", 16) << padl("s (median)", 12)
        << padl("s (min-max)", 20) << "\n";
    Json shown = Json::array();
    for (const Json& e : list(r, "estimators")) {
        const Json& runs = list(e, "runs");
        const std::string of = "/" + std::to_string(runs.size());
        const Json first = runs.empty() ? Json::object() : runs.front();
        out << padr(jstr(e, "name"), 24) << padl(fmt("%.0f", jnum(e, "met")) + of, 8)
            << padl(has_exact ? fmt("%.0f", jnum(e, "within_tolerance")) + of : "-", 8)
            << padl(fmt("%.10g", jnum(first, "estimate")), 17)
            << padl(fmt("%.3g", jnum(first, "half_width")), 12)
            << padl(fmt("%.0f", jnum(e, "evaluations_median")), 16)
            << padl(fmt("%.3g", jnum(e, "seconds_median")), 12)
            << padl(fmt("%.3g", jnum(e, "seconds_min")) + "-" + fmt("%.3g", jnum(e, "seconds_max")),
                    20)
            << "\n";
        for (const Json& w : list(e, "warnings")) {
            Json named = w;
            named["message"] = jstr(e, "name") + ": " + jstr(w, "message");
            shown.push_back(named);
        }
    }
    out << "  (estimate and +/-: the first replicate's answer; met: runs whose rule was satisfied; "
           "within: answers within the tolerance of the exact value)\n";
    print_warnings(out, shown);
    return out.str();
}
} // namespace

std::string format_table(const Json& r) {
    if (jstr(r, "kind") == "render") return format_render_table(r);
    if (jstr(r, "kind") == "stopping") return format_stopping_table(r);
    std::ostringstream out;
    const Json& scene = get(r, "scene");
    const Json& settings = get(r, "settings");
    const double exact = jnum(scene, "exact");
    const bool has_exact = std::isfinite(exact);
    out << "mcplay " << jstr(r, "mcplay") << "  scene " << jstr(scene, "name");
    if (!jstr(scene, "description").empty()) out << ": " << jstr(scene, "description");
    out << "\n  " << jstr(scene, "quantity") << " of f = " << jstr(scene, "integrand") << " over "
        << jstr(scene, "domain_text");
    out << "\n  exact " << (has_exact ? fmt("%.12g", exact) : std::string("unknown"))
        << "   N = " << fmt("%.0f", jnum(settings, "n_min")) << " .. "
        << fmt("%.0f", jnum(settings, "n_max")) << ", " << fmt("%.0f", jnum(settings, "reps"))
        << " replicates per N, seed " << fmt("%.0f", jnum(settings, "seed")) << ", "
        << fmt("%.0f", jnum(settings, "threads")) << " thread(s), "
        << fmt("%.2f", jnum(r, "wall_time_s")) << " s\n";
    if (jbool(r, "cancelled")) out << "  (cancelled: partial result)\n";

    const Json& ests = list(r, "estimators");
    for (const Json& e : ests) {
        out << "\n" << jstr(e, "name") << "  [sampler " << jstr(e, "sampler");
        if (get(e, "randomization").is_string()) {
            const double k = jnum(e, "randomizations");
            out << " (" << jstr(e, "randomization") << ", "
                << (k == 1.0 ? std::string("one sequence") : fmt("%.0f", k) + " randomizations")
                << ")";
        }
        out << ", pdf " << jstr(e, "pdf") << ", per-run error: " << jstr(e, "error_method")
            << "]\n";
        out << padl("N", 9) << padl("mean", 17) << padl("variance", 13) << padl("rel.err", 10);
        if (has_exact) out << padl("rmse", 11) << padl("bias/se", 9) << padl("cover", 7);
        out << padl("time/est", 11) << padl("efficiency", 12) << "\n";
        // Level warnings repeat from N to N: the table shows each code once, at the largest N,
        // after the estimator's own.
        Json shown = list(e, "warnings"), level_shown = Json::array();
        std::vector<std::string> codes;
        for (const Json& l : list(e, "levels")) {
            // A negative variance (a hand-edited result) is shown as "-" like a missing one.
            const double mean = jnum(l, "mean"), raw_var = jnum(l, "variance");
            const double var = raw_var >= 0.0 ? raw_var : NAN;
            const double ref = has_exact ? exact : mean;
            out << padl(fmt("%.0f", jnum(l, "n")), 9) << padl(fmt("%.9g", mean), 17)
                << padl(fmt("%.4e", var), 13)
                << padl(ref != 0.0 ? fmt("%.2e", std::sqrt(var) / std::fabs(ref)) : "-", 10);
            if (has_exact) {
                const double se = jnum(l, "std_error"), bias = jnum(l, "bias");
                const bool exact_level = l.contains("exact_to_roundoff") &&
                                         l["exact_to_roundoff"].is_boolean() &&
                                         l["exact_to_roundoff"].get<bool>();
                out << padl(fmt("%.3e", jnum(l, "rmse")), 11)
                    << padl(exact_level ? "exact"
                            : se > 0    ? fmt("%+.2f", bias / se)
                                        : "-",
                            9)
                    << padl(fmt("%.2f", jnum(l, "coverage95")), 7);
            }
            out << padl(fmt("%.2e", jnum(l, "time_mean_s")), 11)
                << padl(fmt("%.3e", jnum(l, "efficiency")), 12) << "\n";
            for (const Json& w : list(l, "warnings")) {
                const std::string code = jstr(w, "code");
                const size_t at = static_cast<size_t>(std::find(codes.begin(), codes.end(), code) -
                                                      codes.begin());
                if (at == codes.size()) {
                    codes.push_back(code);
                    level_shown.push_back(w);
                } else
                    level_shown[at] = w;
            }
        }
        const Json& fit = get(e, "fit");
        if (jbool(fit, "valid"))
            out << "  fitted order: variance ~ N^(" << fmt("%.3f", jnum(fit, "order")) << " +/- "
                << fmt("%.3f", jnum(fit, "order_se")) << ")" << power_law_note(fit);
        else
            out << "  fitted order: none";
        if (!jstr(fit, "note").empty()) out << " (" << jstr(fit, "note") << ")";
        const Json& mse_fit = get(e, "mse_fit");
        if (jbool(mse_fit, "valid"))
            out << "; MSE ~ N^(" << fmt("%.3f", jnum(mse_fit, "order")) << " +/- "
                << fmt("%.3f", jnum(mse_fit, "order_se")) << ")" << power_law_note(mse_fit);
        out << "\n";
        for (const Json& w : level_shown) shown.push_back(w);
        print_warnings(out, shown);
    }

    // Equal-N and equal-time comparison at the largest N every estimator reached.
    comparison_table(out, ests,
                     ComparisonLabels{"comparison at the largest N (efficiency = 1 / (variance x "
                                      "time); higher is better)",
                                      "N", "variance", "time/est", 26, 9, 13, 11});
    return out.str();
}

namespace {
// A number at full precision, empty for null and NaN (which JSON holds as null).
std::string csv_number(const Json& v) {
    if (!v.is_number()) return "";
    std::ostringstream s;
    s.precision(17);
    s << v.get<double>();
    return s.str();
}

std::string csv_quoted(const std::string& s) {
    std::string q = "\"";
    for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
}

// Stopping studies: one row per run.
std::string format_stopping_csv(const Json& r) {
    const auto cell = csv_number;
    std::ostringstream out;
    out << "estimator,replicate,estimate,std_error,half_width,target,met,reason,n,evaluations,"
           "seconds,within_tolerance\n";
    for (const Json& e : list(r, "estimators")) {
        int k = 0;
        for (const Json& run : list(e, "runs")) {
            const Json& within = get(run, "within_tolerance");
            out << csv_quoted(jstr(e, "name")) << "," << k++ << "," << cell(get(run, "estimate"))
                << "," << cell(get(run, "std_error")) << "," << cell(get(run, "half_width")) << ","
                << cell(get(run, "target")) << "," << (jbool(run, "met") ? "true" : "false") << ","
                << jstr(run, "reason") << "," << cell(get(run, "n")) << ","
                << cell(get(run, "evaluations")) << "," << cell(get(run, "seconds")) << ","
                << (within.is_boolean() ? (within.get<bool>() ? "true" : "false") : "") << "\n";
        }
    }
    return out.str();
}
} // namespace

std::string format_csv(const Json& r) {
    if (jstr(r, "kind") == "stopping") return format_stopping_csv(r);
    std::ostringstream out;
    out.precision(17);
    out << "scene,estimator,sampler,pdf,n,reps,mean,variance,variance_lo,variance_hi,std_error,ci_"
           "lo,"
           "ci_hi,exact,bias,mse,rmse,coverage95,mean_run_std_error,time_mean_s,efficiency,"
           "nonfinite,zero_pdf,max_weight_share\n";
    const Json& scene = get(r, "scene");
    const auto cell = csv_number;
    const auto quoted = csv_quoted;
    // Spreads that are negative are not spreads: empty cells, like missing numbers.
    auto spread = [&](const Json& v) -> std::string {
        return v.is_number() && v.get<double>() < 0.0 ? std::string() : cell(v);
    };
    const Json exact = get(scene, "exact");
    for (const Json& e : list(r, "estimators")) {
        for (const Json& l : list(e, "levels")) {
            const Json& d = get(l, "diagnostics");
            const Json& vci = get(l, "variance_ci95");
            const Json& ci = get(l, "ci95");
            out << quoted(jstr(scene, "name")) << "," << quoted(jstr(e, "name")) << ","
                << jstr(e, "sampler") << "," << quoted(jstr(e, "pdf")) << "," << cell(get(l, "n"))
                << "," << cell(get(l, "reps")) << "," << cell(get(l, "mean")) << ","
                << spread(get(l, "variance")) << "," << spread(at_index(vci, 0)) << ","
                << spread(at_index(vci, 1)) << "," << spread(get(l, "std_error")) << ","
                << cell(at_index(ci, 0)) << "," << cell(at_index(ci, 1)) << "," << cell(exact)
                << "," << cell(get(l, "bias")) << "," << spread(get(l, "mse")) << ","
                << spread(get(l, "rmse")) << "," << cell(get(l, "coverage95")) << ","
                << cell(get(l, "mean_run_std_error")) << "," << cell(get(l, "time_mean_s")) << ","
                << cell(get(l, "efficiency")) << "," << cell(get(d, "nonfinite")) << ","
                << cell(get(d, "zero_pdf")) << "," << cell(get(d, "max_weight_share")) << "\n";
        }
    }
    return out.str();
}

} // namespace mcp
