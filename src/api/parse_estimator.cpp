// Scene parsing, estimators: one entry of "estimators" (docs/scene-format.md) is a preset name
// (estimators/registry.h) or an object with a name, the sampler and pdf fields every kind
// shares, and the fields of at most one kind (api/estimator_options.h), which make the
// estimator of that kind. A name runs what it says: a bare name must be a preset, and a preset
// is not redefined. Part of the scene parsers (api/scene_parsers.h).
#include <algorithm>

#include "api/estimator_options.h"
#include "api/scene.h"
#include "api/scene_parsers.h"
#include "estimators/registry.h"

namespace mcp {

std::vector<std::string> preset_names() {
    std::vector<std::string> names;
    for (const EstimatorPreset& p : estimator_presets()) names.push_back(p.name);
    return names;
}

/// Levenshtein distance (insertions, deletions, substitutions), for "did you mean".
size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t k = 0; k <= b.size(); ++k) row[k] = k;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t k = 1; k <= b.size(); ++k) {
            const size_t up = row[k];
            row[k] =
                std::min({row[k] + 1, row[k - 1] + 1, diagonal + (a[i - 1] == b[k - 1] ? 0 : 1)});
            diagonal = up;
        }
    }
    return row[b.size()];
}

/// " (did you mean 'stratified'?" or " (" : the closest preset within a third of its length.
std::string did_you_mean(const std::string& name) {
    if (name.size() > 64) return " (";
    const EstimatorPreset* best = nullptr;
    size_t best_d = 0;
    for (const EstimatorPreset& p : estimator_presets()) {
        const size_t d = edit_distance(name, p.name);
        if (!best || d < best_d) {
            best = &p;
            best_d = d;
        }
    }
    const size_t len = std::string(best->name).size();
    if (best_d > 0 && best_d * 3 <= len)
        return " (did you mean '" + std::string(best->name) + "'? ";
    return " (";
}

/// The text of an estimator name for messages: at most 64 characters.
std::string name_text(const std::string& name) {
    return name.size() <= 64 ? name : name.substr(0, 61) + "...";
}

namespace {

/// The fields that make a new estimator name, for messages: "sampler", "pdf", "vegas", "miser",
/// "proposals" or "control_variates".
std::string new_name_fields() {
    std::vector<std::string> keys = {"\"sampler\"", "\"pdf\""};
    for (const KindFields& k : kind_fields())
        keys.push_back("\"" + std::string(k.selecting[0]) + "\"");
    std::string s;
    for (size_t i = 0; i < keys.size(); ++i)
        s += (i == 0 ? "" : (i + 1 == keys.size() ? " or " : ", ")) + keys[i];
    return s;
}

// The quasi-Monte Carlo options of an estimator: its randomization, the number K of them, and
// where its error bar comes from ("randomizations", or "walsh": one linearly scrambled Sobol'
// sequence and its Walsh coefficients, core/walsh_bound.h).
bool parse_qmc_options(Ctx& c, const std::string& path, const Problem& problem,
                       const EstimatorPreset* preset, const std::string& randomization,
                       int randomizations, const std::string& error_bar, EstimatorSpec* out) {
    const bool preset_walsh = preset && preset->walsh_bound;
    if (!error_bar.empty() && error_bar != "walsh" && error_bar != "randomizations")
        return c.fail(sub(path, "error_bar"),
                      "expected \"randomizations\" (the spread of K independent randomizations) "
                      "or \"walsh\" (one scrambled Sobol' sequence's Walsh coefficients), got \"" +
                          error_bar.substr(0, 64) + "\"");
    if (preset && !error_bar.empty() && (error_bar == "walsh") != preset_walsh)
        return c.fail(sub(path, "error_bar"),
                      "'" + std::string(preset->name) + "' is the preset with the " +
                          (preset_walsh ? "Walsh" : "randomizations'") +
                          " error bar; give the estimator another name for another");
    const bool walsh = preset_walsh || error_bar == "walsh";
    if (!is_qmc(out->sampler)) {
        if (!randomization.empty() || randomizations >= 0 || !error_bar.empty()) {
            const char* field = !randomization.empty() ? "randomization"
                                : randomizations >= 0  ? "randomizations"
                                                       : "error_bar";
            return c.fail(
                sub(path, field),
                "applies to the quasi-Monte Carlo samplers only (sobol, halton, lattice)");
        }
        return true;
    }
    const QmcKind q = qmc_kind_of(out->sampler);
    out->randomization = walsh ? QmcRandomization::LmsShift : default_randomization(q);
    if (!randomization.empty() && !parse_randomization(randomization, &out->randomization))
        return c.fail(sub(path, "randomization"),
                      "unknown randomization '" + randomization +
                          "' (known: owen, lms_shift, digital_shift, permutation, "
                          "random_shift, none)");
    out->randomizations =
        out->randomization == QmcRandomization::None || walsh ? 1 : kDefaultRandomizations;
    if (randomizations >= 0) out->randomizations = randomizations;
    SamplerOptions checked = out->sampler_options();
    if (walsh) {
        // The bound reads the Walsh coefficients of a digital net: Sobol' points that a linear
        // scramble or a digital shift keeps a (shifted) digital net, one sequence of them.
        if (out->sampler != SamplerKind::Sobol)
            return c.fail(sub(path, "error_bar"),
                          std::string("the Walsh bound is for the sobol sampler (a base-2 digital "
                                      "net), not ") +
                              sampler_name(out->sampler));
        if (out->randomization != QmcRandomization::LmsShift &&
            out->randomization != QmcRandomization::DigitalShift)
            return c.fail(sub(path, "randomization"),
                          "the Walsh bound needs points that stay a digital net: lms_shift or "
                          "digital_shift (owen scrambling is not linear, none is not random), "
                          "got " +
                              std::string(randomization_name(out->randomization)));
        if (out->randomizations != 1)
            return c.fail(sub(path, "randomizations"),
                          "the Walsh bound is of one randomized sequence: randomizations must be "
                          "1, got " +
                              std::to_string(out->randomizations));
        out->walsh_bound = true;
        checked.randomizations = 2; // the sampler's own check asks K >= 2 of a spread's error bar
    }
    const std::string bad =
        check_sampler_options(out->sampler, checked, problem.domain.sample_dim());
    if (!bad.empty()) {
        const size_t colon = bad.find(": ");
        const std::string field = bad.substr(0, colon);
        if (field == "randomization" || field == "randomizations")
            return c.fail(sub(path, field.c_str()), bad.substr(colon + 2));
        return c.fail(path, bad);
    }
    return true;
}

} // namespace

bool parse_estimator(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                     EstimatorSpec* out) {
    std::string name, sampler_name_str, warp, randomization, error_bar;
    int randomizations = -1; // -1: not given (0 is given, and refused below)
    const Json* pdf = nullptr;
    const KindFields* fields = nullptr; // the kind whose fields the object has
    if (j.is_string()) {
        name = j.get<std::string>();
    } else if (j.is_object()) {
        std::vector<std::string> known = {
            "name",          "sampler",        "pdf",      "warp", "samples_per_stratum",
            "randomization", "randomizations", "error_bar"};
        for (const KindFields& k : kind_fields()) {
            for (const char* key : k.selecting) known.push_back(key);
            for (const char* key : k.extra) known.push_back(key);
        }
        if (!check_keys(c, j, path, known)) return false;
        uint64_t m = 1;
        if (!get_count(c, j, "samples_per_stratum", path, &m)) return false;
        if (m != 1 && m != 2)
            return c.fail(
                sub(path, "samples_per_stratum"),
                "must be 1 (one jittered point per cell) or 2 (unbiased error bars), got " +
                    std::to_string(m));
        out->per_stratum = m;
        if (!get_string(c, j, "name", path, &name) ||
            !get_string(c, j, "sampler", path, &sampler_name_str) ||
            !get_string(c, j, "warp", path, &warp) ||
            !get_string(c, j, "randomization", path, &randomization) ||
            !get_string(c, j, "error_bar", path, &error_bar))
            return false;
        if (find(j, "randomizations")) {
            uint64_t k = 0;
            if (!get_count(c, j, "randomizations", path, &k)) return false;
            // Capped past the largest allowed count, so the range check below refuses it.
            randomizations = static_cast<int>(std::min<uint64_t>(k, 1u << 30));
        }
        pdf = find(j, "pdf");
        for (const KindFields& k : kind_fields()) {
            bool selected = false;
            for (const char* key : k.selecting) selected = selected || find(j, key);
            if (!selected) {
                for (const char* key : k.extra)
                    if (find(j, key))
                        return c.fail(sub(path, key),
                                      "applies with \"" + std::string(k.selecting[0]) + "\" only");
                continue;
            }
            if (fields)
                return c.fail(path, std::string("an estimator is of one kind: the fields of ") +
                                        fields->kinds[0] + " (\"" + fields->selecting[0] +
                                        "\") and of " + k.kinds[0] + " (\"" + k.selecting[0] +
                                        "\") do not combine");
            fields = &k;
        }
    } else {
        return c.fail(path, "expected an estimator name or object, got " + type_of(j));
    }
    if (name.empty()) return c.fail(path, "an estimator needs a \"name\"");
    const EstimatorPreset* preset = find_preset(name);
    out->name = name;
    out->kind = preset ? find_estimator_kind(preset->kind) : nullptr;
    out->sampler = preset ? preset->sampler : SamplerKind::Independent;
    if (preset && preset->ris_candidates > 0) out->ris_options.candidates = preset->ris_candidates;
    if (!sampler_name_str.empty() && !parse_sampler(sampler_name_str, &out->sampler))
        return c.fail(sub(path, "sampler"), "unknown sampler '" + sampler_name_str +
                                                "' (known: " + sampler_names() + ")");
    if (out->per_stratum != 1 && out->sampler != SamplerKind::Stratified)
        return c.fail(sub(path, "samples_per_stratum"), "applies to the stratified sampler only");
    if (!parse_qmc_options(c, path, problem, preset, randomization, randomizations, error_bar, out))
        return false;
    if (!warp.empty() && warp != "polar" && warp != "concentric")
        return c.fail(sub(path, "warp"), "unknown warp '" + warp + "' (known: polar, concentric)");
    if (!warp.empty() && problem.domain.kind != DomainKind::Disk)
        return c.fail(sub(path, "warp"), "only disk domains have a choice of warp");
    // A name runs what it says: a bare name must be a preset, and a preset is not redefined.
    if (!preset && sampler_name_str.empty() && !pdf && !fields)
        return c.fail(path, "unknown estimator '" + name_text(name) + "'" + did_you_mean(name) +
                                "presets: " + join(preset_names()) + "; a new name needs " +
                                new_name_fields() + ")");
    if (preset && !sampler_name_str.empty() && out->sampler != preset->sampler)
        return c.fail(sub(path, "sampler"),
                      "'" + name + "' is the preset with the " + sampler_name(preset->sampler) +
                          " sampler; give the estimator another name to use " + sampler_name_str);
    if (preset && pdf && !preset->needs_pdf)
        return c.fail(sub(path, "pdf"), "'" + name +
                                            "' is a preset with the uniform density; give the "
                                            "estimator another name to sample a pdf");
    if (preset && fields &&
        std::none_of(fields->kinds.begin(), fields->kinds.end(),
                     [&](const char* k) { return std::string(k) == preset->kind; }))
        return c.fail(path, "'" + name + "' is a preset of kind " + preset->kind +
                                "; give the estimator another name to use \"" +
                                fields->selecting[0] + "\"");
    if (fields) {
        if (!fields->parse(c, j, path, problem, pdf, out)) return false;
        if (fields->takes_pdf) return true;
    }
    out->proposal = uniform_proposal(problem.domain, warp == "polar");
    if (pdf) {
        if (!parse_pdf(c, *pdf, sub(path, "pdf"), problem, &out->proposal)) return false;
    } else if (preset && preset->needs_pdf) {
        return c.fail(path, "estimator '" + name + "' needs a pdf: give \"pdf\": {\"type\": ...}");
    }
    return true;
}

bool parse_accumulator(Ctx& c, const Json& obj, const std::string& path, Accumulator* out) {
    std::string name;
    if (!get_string(c, obj, "accumulator", path, &name)) return false;
    if (name.empty()) return true;
    if (name == "compensated")
        *out = Accumulator::Compensated;
    else if (name == "float32")
        *out = Accumulator::Float32;
    else
        return c.fail(sub(path, "accumulator"),
                      "expected \"compensated\" or \"float32\", got \"" + name + "\"");
    return true;
}

Made<EstimatorSpec> preset_estimator(const Problem& problem, const std::string& name) {
    Ctx c;
    EstimatorSpec spec;
    if (!parse_estimator(c, Json(name), "estimator", problem, &spec))
        return made_error<EstimatorSpec>(c.error);
    return Made<EstimatorSpec>{spec, ""};
}

} // namespace mcp
