// calibrate: mcplay's flags judged both ways on a battery of integrals with exact values
// (docs/benchmarks.md). A flag that fires where every interval covered teaches users to
// ignore flags; an estimate far off with no flag is a confident wrong answer.
//
//   calibrate [--quick] [--reps R] [--n-min N] [--n-max N] [--ns N1,N2] [--param-seeds 1,2,3]
//             [--dims 2,4,8] [--families 1,..,6] [--no-genz] [--singular] [--border]
//             [--blind] [--fine 3t|coverage]
//             [--scenes DIR] [--json FILE] [--cells FILE] [--list N] [--presets a,b]
//             [--stopping REL [--stop-n-max N] [--max-seconds S]]
//
// --no-genz leaves Genz's families out (the scenes, and with --singular the products, alone).
// --ns runs each listed N as a study of its own (instead of the ladder n_min..n_max).
// --presets runs these presets only (default: every preset of kPresets); "sobol:4" (also
// halton:K, lattice:K) is the preset with K randomizations of N/K points instead of 16, run as
// the estimator "sobol_k4", to judge the error bars of few randomizations.
// --border adds, per dimension and parameter seed, two products on either side of an infinite
// variance (tail index 1 / a_1 in (2.22, 2.5) and (1.67, 1.92); add_border_products).
// --blind runs the generated cases (Genz, --singular, --border) without telling the studies
// their exact value ("exact": null), as a user's own integrand is run; judged against it still.
// --singular adds, per dimension and parameter seed, two products prod x_i^-a_i (monomial
// integrands, exact prod 1 / (1 - a_i)): one of finite variance whose weights have an infinite
// fourth moment (every a_i in (0.25, 0.35), tail index 1 / a_i near 3: the sample skewness is
// erratic), and one of infinite variance (one a_i in (0.55, 0.85)); every cell of the latter must
// carry an alarm.
// --fine coverage judges a cell by its coverage instead of its worst replicate (use R = 32):
// fine when at least R - floor(3 R / 32) replicates lie within 1.96 t of their own standard
// error of the exact value (29 of 32) and none beyond 3.5 t.
//
// The battery: Genz's six families [Genz84] at d = 2, 4, 8 with the project's own random
// parameters (genz_random, seeds 1..3), each run with every uniform-density preset, and every
// integration scene of DIR (default scenes/) that states an exact value, with its own
// estimators and with each preset that applies to its domain (a user can pick any). Each is a
// study through the C API, as the CLI and the page run it (N = n_min, 2 n_min, ..., n_max;
// R replicates), so the flags are the ones users see.
//
// Per cell (case, estimator, N) of R replicates, "k t" standard errors being widened_limit(k,
// run dof): k t_0.975(dof) / 1.96 for a run's few degrees of freedom, and below 15 of them never
// a limit an honest replicate crosses more often than it crosses k t at 15 (at 1-3 degrees of
// freedom t's tails reach far beyond k t_0.975 / 1.96):
//   fine     every replicate within 3 t of its own standard error of the exact value
//            (an exact estimator, se = 0 and the error at round-off, is fine)
//   flagged  the level, or the estimator as a whole, carries a flag of severity error or
//            warning (info is worth knowing, not an alarm)
//   false-flag rate = flagged fine cells / fine cells            (target <= 5%, issue 13)
//   confident wrong = replicates beyond 5 t standard errors in unflagged cells   (target 0)
//
// A cell of R = 10 replicates is "fine" by luck as well: an estimator whose intervals cover 80%
// of the time gives ten covering intervals in one cell of nine. --recheck K judges the flags on
// fine cells by what they claim (the error bar cannot be trusted at this N): K flagged and K
// unflagged fine cells, evenly spread over the battery, are run again at the same N with
// --recheck-reps replicates (default 100) and new seeds; a cell's alarm is borne out when that
// run finds its error bars wrong: two or more replicates beyond 3 t standard errors (honest
// intervals: P = 3% with 100 replicates) or 95% coverage at most 88 of 100 (P = 1%).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "api/json_read.h"
#include "api/mcplay.h"
#include "core/rng.h"
#include "core/special.h"
#include "integrands/genz.h"

using namespace mcp;

namespace {

const char* const kPresets[] = {"uniform",     "stratified", "latin_hypercube", "sobol",
                                "sobol_walsh", "halton",     "lattice",         "vegas",
                                "vegas_sobol", "vegas_plus", "miser",           "ris_m4"};

struct Options {
    int reps = 10;
    uint64_t n_min = 1024, n_max = 65536, seed = 2026;
    std::vector<int> dims{2, 4, 8};
    std::vector<uint64_t> param_seeds{1, 2, 3};
    std::vector<uint64_t> ns; // --ns: these N, each a study of its own
    std::vector<std::string> presets{std::begin(kPresets), std::end(kPresets)}; // --presets
    std::vector<int> families{1, 2, 3, 4, 5, 6};
    bool singular = false;         // --singular: singular products too
    bool border = false;           // --border: products whose tail index is near 2 too
    bool blind = false;            // --blind: the studies are not told the exact value
    bool genz = true;              // --no-genz: the scenes (and products) alone
    bool fine_by_coverage = false; // --fine coverage
    std::string scenes_dir = "scenes", json_path, cells_path;
    int recheck = 0, recheck_reps = 100; // --recheck K: fine cells run again, per kind
    int list = 20;                       // confident wrong answers and flag codes listed
    // --stopping REL: the stopping rule's battery instead of the flags' (n_max, seconds: budget)
    double stop_rel = 0.0, stop_seconds = 2.0;
    uint64_t stop_n_max = uint64_t(1) << 22;
};

/// A --presets item as a scene's estimator: the preset's name, or for "sobol:K" (halton:K,
/// lattice:K) the estimator "sobol_kK" with that sampler and K randomizations; null if the item
/// is neither.
Json randomized_nets(const std::string& item) {
    const size_t colon = item.find(':');
    if (colon == std::string::npos) return item;
    const std::string base = item.substr(0, colon), k = item.substr(colon + 1);
    if ((base != "sobol" && base != "halton" && base != "lattice") || k.empty() || k.size() > 6 ||
        k.find_first_not_of("0123456789") != std::string::npos)
        return nullptr;
    return {{"name", base + "_k" + k}, {"sampler", base}, {"randomizations", std::stoi(k)}};
}

[[noreturn]] void usage(const std::string& msg) {
    if (!msg.empty()) std::fprintf(stderr, "calibrate: %s\n", msg.c_str());
    std::fprintf(stderr, "usage: calibrate [--quick] [--reps R] [--n-min N] [--n-max N]\n"
                         "         [--ns N1,N2] [--param-seeds 1,2,3] [--dims 2,4,8]\n"
                         "         [--families 1,..,6] [--no-genz] [--singular] [--border]\n"
                         "         [--blind]\n"
                         "         [--fine 3t|coverage]\n"
                         "         [--scenes DIR]\n"
                         "         [--json FILE] [--cells FILE] [--list N] [--presets a,b]\n"
                         "         [--stopping REL [--stop-n-max N] [--max-seconds S]]\n"
                         "         [--recheck K [--recheck-reps R]]\n");
    std::exit(2);
}

std::vector<uint64_t> parse_list(const std::string& s, const char* what, uint64_t lo, uint64_t hi) {
    std::vector<uint64_t> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) {
        char* end = nullptr;
        const unsigned long long v = std::strtoull(item.c_str(), &end, 10);
        if (item.empty() || !end || *end || v < lo || v > hi)
            usage(std::string(what) + ": '" + item + "' is not a whole number in " +
                  std::to_string(lo) + ".." + std::to_string(hi));
        out.push_back(v);
    }
    if (out.empty()) usage(std::string(what) + ": empty list");
    return out;
}

Options parse_options(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) usage(a + " needs a value");
            return argv[++i];
        };
        auto one = [&](const char* what, uint64_t lo, uint64_t hi) {
            return parse_list(value(), what, lo, hi).front();
        };
        if (a == "--quick") {
            o.reps = 6;
            o.n_max = 4096;
            o.param_seeds = {1};
        } else if (a == "--reps")
            o.reps = int(one("--reps", 4, 1000));
        else if (a == "--n-min")
            o.n_min = one("--n-min", 16, uint64_t(1) << 24);
        else if (a == "--n-max")
            o.n_max = one("--n-max", 16, uint64_t(1) << 24);
        else if (a == "--param-seeds")
            o.param_seeds = parse_list(value(), "--param-seeds", 1, 1000000);
        else if (a == "--ns")
            o.ns = parse_list(value(), "--ns", 16, uint64_t(1) << 24);
        else if (a == "--families") {
            o.families.clear();
            for (uint64_t f : parse_list(value(), "--families", 1, 6)) o.families.push_back(int(f));
        } else if (a == "--presets") {
            o.presets.clear();
            std::stringstream ss(value());
            for (std::string item; std::getline(ss, item, ',');) {
                const std::string base = item.substr(0, item.find(':'));
                if (std::find_if(std::begin(kPresets), std::end(kPresets),
                                 [&](const char* p) { return base == p; }) == std::end(kPresets))
                    usage("--presets: unknown preset '" + item + "'");
                if (base != item && !randomized_nets(item).is_object())
                    usage("--presets: '" + item +
                          "': K randomizations are written sobol:K, halton:K or lattice:K");
                o.presets.push_back(item);
            }
        } else if (a == "--singular")
            o.singular = true;
        else if (a == "--border")
            o.border = true;
        else if (a == "--blind")
            o.blind = true;
        else if (a == "--no-genz")
            o.genz = false;
        else if (a == "--fine") {
            const std::string v = value();
            if (v != "3t" && v != "coverage") usage("--fine: expected 3t or coverage");
            o.fine_by_coverage = v == "coverage";
        } else if (a == "--dims") {
            o.dims.clear();
            for (uint64_t d : parse_list(value(), "--dims", 1, 64)) o.dims.push_back(int(d));
        } else if (a == "--scenes")
            o.scenes_dir = value();
        else if (a == "--json")
            o.json_path = value();
        else if (a == "--stopping") {
            const std::string v = value();
            char* end = nullptr;
            o.stop_rel = std::strtod(v.c_str(), &end);
            if (v.empty() || *end || !(o.stop_rel > 0.0) || !(o.stop_rel < 1.0))
                usage("--stopping: expected a relative tolerance in (0, 1)");
        } else if (a == "--stop-n-max")
            o.stop_n_max = one("--stop-n-max", 16, uint64_t(1) << 30);
        else if (a == "--max-seconds") {
            const std::string v = value();
            char* end = nullptr;
            o.stop_seconds = std::strtod(v.c_str(), &end);
            if (v.empty() || *end || !(o.stop_seconds > 0.0) || !std::isfinite(o.stop_seconds))
                usage("--max-seconds: expected a number of seconds > 0");
        } else if (a == "--cells")
            o.cells_path = value();
        else if (a == "--recheck")
            o.recheck = int(one("--recheck", 0, 100000));
        else if (a == "--recheck-reps")
            o.recheck_reps = int(one("--recheck-reps", 20, 10000));
        else if (a == "--list")
            o.list = int(one("--list", 0, 100000));
        else if (a == "-h" || a == "--help")
            usage("");
        else
            usage("unknown argument '" + a + "'");
    }
    if (o.n_max < o.n_min) usage("--n-max must be at least --n-min");
    return o;
}

struct Case {
    std::string name;
    Json scene;
    Json options;                   // mcp_study_run options (estimators for the Genz cases)
    bool infinite_variance = false; // every cell must carry an alarm
    double exact = std::numeric_limits<double>::quiet_NaN(); // the generated cases' value
};

// Products prod x_i^-a_i on the unit box (E f^2 is finite iff every a_i < 1/2), one with a
// finite and one with an infinite variance per dimension and parameter seed: a_i =
// power(i, infinite_variance, u) for a uniform u, the cases named KIND_finvar/KIND_infvar_dD_sS.
template <class Power>
void add_power_products(const Options& o, const std::string& kind, Power power,
                        std::vector<Case>* cases) {
    Json presets = Json::array();
    for (const std::string& p : o.presets) presets.push_back(randomized_nets(p));
    for (int d : o.dims)
        for (uint64_t seed : o.param_seeds)
            for (const bool infinite_variance : {false, true}) {
                Pcg32 rng(seed, hash_string((kind + (infinite_variance ? "_iv" : "_fv")).c_str()));
                std::vector<double> powers(static_cast<size_t>(d));
                double exact = 1.0;
                for (size_t i = 0; i < powers.size(); ++i) {
                    const double a = power(i, infinite_variance, rng.next_double());
                    powers[i] = -a;
                    exact /= 1.0 - a;
                }
                Case c;
                c.name = kind + (infinite_variance ? "_infvar" : "_finvar") + "_d" +
                         std::to_string(d) + "_s" + std::to_string(seed);
                c.infinite_variance = infinite_variance;
                c.scene = {{"name", c.name},
                           {"domain", {{"type", "box"}, {"dim", d}}},
                           {"integrand", {{"type", "monomial"}, {"powers", powers}}},
                           {"exact", exact},
                           {"estimators", presets}};
                c.exact = exact;
                cases->push_back(c);
            }
}

// --border: products whose weights' tail index 1 / a_1 lies on either side of 2, the
// variance's border (x^-0.45 y^-0.2 has a finite variance, x^-0.55 y^-0.1 z^-0.1 an infinite
// one): one a_1 in (0.40, 0.45) or (0.52, 0.60), the others in (0.05, 0.2) (they leave the tail
// index 1 / a_1: E x^-a_i/a_1 is finite).
void add_border_products(const Options& o, std::vector<Case>* cases) {
    add_power_products(
        o, "border",
        [](size_t i, bool infinite_variance, double u) {
            return i > 0 ? 0.05 + 0.15 * u : infinite_variance ? 0.52 + 0.08 * u : 0.40 + 0.05 * u;
        },
        cases);
}

std::vector<Case> genz_cases(const Options& o) {
    std::vector<Case> cases;
    Json presets = Json::array();
    for (const std::string& p : o.presets) presets.push_back(randomized_nets(p));
    for (int fam1 : o.genz ? o.families : std::vector<int>())
        for (int d : o.dims)
            for (uint64_t seed : o.param_seeds) {
                const int fam = fam1 - 1;
                const GenzParams g = genz_random(GenzFamily(fam), d, seed);
                Case c;
                c.name = std::string(genz_family_name(GenzFamily(fam))) + "_d" + std::to_string(d) +
                         "_s" + std::to_string(seed);
                c.scene = {{"name", c.name},
                           {"integrand",
                            {{"type", genz_family_name(GenzFamily(fam))}, {"a", g.a}, {"u", g.u}}},
                           {"exact", genz_exact(g)},
                           {"estimators", presets}};
                c.exact = genz_exact(g);
                cases.push_back(c);
            }
    if (o.border) add_border_products(o, &cases);
    if (!o.singular) return cases;
    // Singular products: the first power in (0.55, 0.85) for an infinite variance, the others
    // (and all of a finite-variance case's) in (0.25, 0.35).
    add_power_products(
        o, "singular",
        [](size_t i, bool infinite_variance, double u) {
            return infinite_variance && i == 0 ? 0.55 + 0.3 * u : 0.25 + 0.1 * u;
        },
        &cases);
    return cases;
}

std::vector<Case> scene_cases(const Options& o) {
    namespace fs = std::filesystem;
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(o.scenes_dir, ec))
        if (e.path().extension() == ".json") files.push_back(e.path());
    if (ec) usage("--scenes " + o.scenes_dir + ": " + ec.message());
    std::sort(files.begin(), files.end());
    std::vector<Case> cases;
    for (const fs::path& p : files) {
        std::ifstream in(p);
        std::stringstream ss;
        ss << in.rdbuf();
        Made<Json> j = parse_json(ss.str().c_str(), p.string().c_str());
        // Integration scenes; render scenes (a "render" field) are the renderer's, with their
        // own references. A scene without an exact value (stated or known to mcplay) is dropped
        // after the study with its own estimators.
        if (!j.ok() || !j.value.is_object() || j.value.contains("render")) continue;
        cases.push_back(Case{p.stem().string(), j.value, Json::object()});
        for (const std::string& preset : o.presets)
            cases.push_back(Case{p.stem().string() + "+" + preset,
                                 j.value,
                                 {{"estimators", Json::array({randomized_nets(preset)})}}});
    }
    return cases;
}

double number_or_nan(const Json& v) {
    return v.is_number() ? v.get<double>() : std::nan("");
}

struct Tally {
    long fine = 0, fine_flagged = 0, cells = 0, runs = 0, confident_wrong = 0;
    long infvar_cells = 0, infvar_unflagged = 0;  // cells of infinite-variance cases
    std::map<std::string, long> false_flag_codes; // codes on fine cells
    // Codes that are a cell's only alarm where a replicate missed by more than 5 t standard
    // errors: without them those misses would be confident wrong answers.
    std::map<std::string, long> sole_alarm_on_miss;
};

struct Wrong {
    std::string where;
    double z;
};

/// A fine cell, for --recheck: where it is and whether it carried an alarm.
struct FineCell {
    size_t case_index = 0;
    std::string estimator;
    uint64_t n = 0;
    bool flagged = false;
};

// Judges every level of every estimator of one study result.
// cells (if not null) gets one JSON line per cell: the verdict, the alarms and the level's
// statistics, for studying what separates the misses from the fine cells.
void judge(const Options& o, const Case& c, size_t case_index, const Json& result, double exact,
           Tally* t, std::vector<Wrong>* wrong, std::vector<FineCell>* fine_cells,
           std::FILE* cells) {
    const std::string& case_name = c.name;
    for (const Json& e : result["estimators"]) {
        // Alarms only: a flag of severity info says nothing is wrong.
        auto alarms = [](const Json& warnings, std::vector<std::string>* codes) {
            for (const Json& w : warnings)
                if (w.value("severity", "warning") != "info")
                    codes->push_back(w.value("code", "?"));
        };
        std::vector<std::string> estimator_codes;
        alarms(e["warnings"], &estimator_codes);
        for (const Json& l : e["levels"]) {
            std::vector<std::string> codes = estimator_codes;
            alarms(l["warnings"], &codes);
            const double dof = number_or_nan(l["run_dof"]);
            const double run_dof = dof >= 1.0 ? std::min(dof, 1e6) : INFINITY;
            const double widen =
                dof >= 1.0 ? student_t_quantile(0.975, run_dof) / 1.959963985 : 1.0;
            auto limit = [&](double k) { return dof >= 1.0 ? widened_limit(k, run_dof) : k; };
            const double limit3 = limit(3.0), limit35 = limit(3.5), limit5 = limit(5.0);
            const Json& est = l["replicates"]["estimate"];
            const Json& se = l["replicates"]["std_error"];
            bool fine = true;
            long covered = 0, judged = 0, beyond35 = 0;
            std::vector<double> misses;
            for (size_t i = 0; i < est.size() && i < se.size(); ++i) {
                const double x = number_or_nan(est[i]), s = number_or_nan(se[i]);
                const double err = std::fabs(x - exact);
                const double roundoff = 1e-12 * std::max(std::fabs(exact), std::fabs(x));
                ++t->runs;
                ++judged;
                if (!(err <= limit3 * s + roundoff)) fine = false;
                if (err <= 1.959963985 * widen * s + roundoff) ++covered;
                if (!(err <= limit35 * s + roundoff)) ++beyond35;
                if (!(err <= limit5 * s + roundoff)) misses.push_back(s > 0.0 ? err / s : INFINITY);
            }
            if (o.fine_by_coverage) fine = covered >= judged - (3 * judged) / 32 && beyond35 == 0;
            ++t->cells;
            // Infinite variance: an alarm is right on every cell, fine or not (judged apart).
            if (c.infinite_variance) {
                ++t->infvar_cells;
                if (codes.empty()) ++t->infvar_unflagged;
                fine = false;
            }
            if (cells) {
                Json line = {{"case", case_name},
                             {"estimator", e.value("name", "?")},
                             {"n", l.value("n", 0ull)},
                             {"fine", fine},
                             {"misses", misses.size()},
                             {"alarms", codes},
                             {"exact", exact},
                             {"widen", widen},
                             {"level", l}};
                line["level"].erase("warnings");
                std::fprintf(cells, "%s\n", line.dump().c_str());
            }
            if (fine)
                fine_cells->push_back(
                    FineCell{case_index, e.value("name", "?"), l.value("n", 0ull), !codes.empty()});
            if (fine) {
                ++t->fine;
                if (!codes.empty()) {
                    ++t->fine_flagged;
                    std::sort(codes.begin(), codes.end());
                    codes.erase(std::unique(codes.begin(), codes.end()), codes.end());
                    for (const std::string& c : codes) ++t->false_flag_codes[c];
                }
            }
            {
                std::vector<std::string> distinct = codes;
                std::sort(distinct.begin(), distinct.end());
                distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
                if (distinct.size() == 1 && !misses.empty())
                    ++t->sole_alarm_on_miss[distinct.front()];
            }
            if (codes.empty())
                for (double z : misses) {
                    ++t->confident_wrong;
                    wrong->push_back(Wrong{case_name + " " + e.value("name", "?") +
                                               " N=" + std::to_string(l.value("n", 0ull)),
                                           z});
                }
        }
    }
}

/// Runs one fine cell again with o.recheck_reps replicates and new seeds; true when its error
/// bars prove wrong there (see the header: >= 2 beyond 3 t se, or 95% coverage <= 88%).
/// `beyond3` and `covered` get the counts, `reps` the replicates judged.
bool recheck_cell(const Options& o, const Case& c, const FineCell& cell, uint64_t seed,
                  long* beyond3, long* covered, long* reps) {
    Json options = {{"estimators", {cell.estimator}}, {"n_min", cell.n}, {"n_max", cell.n},
                    {"reps", o.recheck_reps},         {"seed", seed},    {"threads", 0}};
    char* out = nullptr;
    const int status =
        mcp_study_run(c.scene.dump().c_str(), options.dump().c_str(), nullptr, nullptr, &out);
    Made<Json> r =
        status == MCP_OK ? parse_json(out, c.name.c_str()) : made_error<Json>("the study failed");
    mcp_free(out);
    if (status != MCP_OK || !r.ok()) {
        std::printf("  recheck %s %s N=%llu: %s\n", c.name.c_str(), cell.estimator.c_str(),
                    (unsigned long long)cell.n, status != MCP_OK ? mcp_last_error() : "not JSON");
        return false;
    }
    const double exact = number_or_nan(r.value["scene"]["exact"]);
    const Json& l = r.value["estimators"][0]["levels"][0];
    const double dof = number_or_nan(l["run_dof"]);
    const double t975 = dof >= 1.0 ? student_t_quantile(0.975, std::min(dof, 1e6)) : 1.959963985;
    const double limit3 = dof >= 1.0 ? widened_limit(3.0, std::min(dof, 1e6)) : 3.0;
    const Json& est = l["replicates"]["estimate"];
    const Json& se = l["replicates"]["std_error"];
    long b = 0, cov = 0, n = 0;
    for (size_t i = 0; i < est.size() && i < se.size(); ++i) {
        const double x = number_or_nan(est[i]), s = number_or_nan(se[i]);
        const double err = std::fabs(x - exact);
        const double roundoff = 1e-12 * std::max(std::fabs(exact), std::fabs(x));
        ++n;
        if (!(err <= limit3 * s + roundoff)) ++b;
        if (err <= t975 * s + roundoff) ++cov;
    }
    *beyond3 += b;
    *covered += cov;
    *reps += n;
    return b >= 2 || double(cov) <= 0.88 * double(n);
}

/// --recheck K: K flagged and K unflagged fine cells, evenly spaced over the battery, run again.
void recheck_fine_cells(const Options& o, const std::vector<Case>& cases,
                        const std::vector<FineCell>& fine_cells) {
    std::printf("\nrecheck: fine cells run again at the same N with %d replicates and new seeds; "
                "an alarm is\nborne out when the new run finds the error bars wrong (>= 2 "
                "beyond 3 t se, or 95%% coverage <= 88%%)\n",
                o.recheck_reps);
    std::printf("  %-16s %6s %12s %14s %14s\n", "fine cells", "cells", "wrong there",
                "beyond 3 t se", "95% coverage");
    for (const bool flagged : {true, false}) {
        std::vector<const FineCell*> pool;
        for (const FineCell& f : fine_cells)
            if (f.flagged == flagged) pool.push_back(&f);
        const size_t k = std::min<size_t>(size_t(o.recheck), pool.size());
        long wrong_there = 0, beyond3 = 0, covered = 0, reps = 0;
        for (size_t j = 0; j < k; ++j) {
            const FineCell& cell = *pool[j * pool.size() / k];
            const uint64_t seed = o.seed + 1000003 * (j + 1) + (flagged ? 7 : 0);
            if (recheck_cell(o, cases[cell.case_index], cell, seed, &beyond3, &covered, &reps))
                ++wrong_there;
        }
        std::printf("  %-16s %6zu %5ld (%4.1f%%) %7ld (%4.2f%%) %13.1f%%\n",
                    flagged ? "with an alarm" : "without", k, wrong_there,
                    k ? 100.0 * double(wrong_there) / double(k) : 0.0, beyond3,
                    reps ? 100.0 * double(beyond3) / double(reps) : 0.0,
                    reps ? 100.0 * double(covered) / double(reps) : 0.0);
    }
}

} // namespace

// --stopping REL: every case run to a relative tolerance (each preset, R replicates), and the
// promise judged: among the runs that met the tolerance, the share whose answer lies within it
// of the exact value (target >= 95%), with its Wilson 95% interval; runs a budget ended are
// counted apart.
int stopping_battery(const Options& o, const std::vector<Case>& cases) {
    std::printf("calibrate --stopping: %zu studies, rel_tol %.3g, n_min %llu, n_max %llu, "
                "max_seconds %.3g, R = %d\n",
                cases.size(), o.stop_rel, (unsigned long long)o.n_min,
                (unsigned long long)o.stop_n_max, o.stop_seconds, o.reps);
    long runs = 0, met = 0, within = 0, unmet_within = 0;
    std::map<std::string, std::pair<long, long>> by_estimator; // met, within
    struct Miss {
        std::string where;
        long within, met;
    };
    std::vector<Miss> worst;
    for (size_t ci = 0; ci < cases.size(); ++ci) {
        const Case& c = cases[ci];
        Json options = c.options;
        options["n_min"] = o.n_min;
        options["n_max"] = o.stop_n_max;
        options["reps"] = o.reps;
        options["seed"] = o.seed + ci;
        options["rel_tol"] = o.stop_rel;
        options["max_seconds"] = o.stop_seconds;
        char* out = nullptr;
        const int status =
            mcp_study_run(c.scene.dump().c_str(), options.dump().c_str(), nullptr, nullptr, &out);
        Made<Json> r = status == MCP_OK ? parse_json(out, c.name.c_str()) : Made<Json>();
        mcp_free(out);
        std::fprintf(stderr, "[%zu/%zu] %s\n", ci + 1, cases.size(), c.name.c_str());
        if (status != MCP_OK || !r.ok() || !r.value["scene"]["exact"].is_number()) continue;
        for (const Json& e : r.value["estimators"]) {
            long case_met = 0, case_within = 0;
            for (const Json& run : e["runs"]) {
                ++runs;
                const bool in = run.value("within_tolerance", false);
                if (run.value("met", false)) {
                    ++case_met;
                    case_within += in;
                } else
                    unmet_within += in;
            }
            met += case_met;
            within += case_within;
            auto& [m, w] = by_estimator[e.value("name", "?")];
            m += case_met;
            w += case_within;
            if (case_met > case_within)
                worst.push_back(Miss{c.name + " " + e.value("name", "?"), case_within, case_met});
        }
    }
    // Wilson's score interval for a binomial proportion [Wilson27].
    auto wilson = [](long k, long n) {
        const double z = 1.959963985, p = n ? double(k) / double(n) : 0.0, nn = double(n);
        const double centre = (p + z * z / (2 * nn)) / (1 + z * z / nn);
        const double half =
            z * std::sqrt(p * (1 - p) / nn + z * z / (4 * nn * nn)) / (1 + z * z / nn);
        return std::pair<double, double>(centre - half, centre + half);
    };
    const auto [lo, hi] = wilson(within, met);
    std::printf(
        "\nruns %ld, met the tolerance %ld (%.1f%%); of those, within it of the exact value "
        "%ld = %.2f%% (95%% interval %.2f-%.2f%%; target >= 95%%)\n",
        runs, met, 100.0 * met / std::max(runs, 1L), within, 100.0 * within / std::max(met, 1L),
        100.0 * lo, 100.0 * hi);
    std::printf("runs a budget ended: %ld (their answers within the tolerance anyway: %ld)\n",
                runs - met, unmet_within);
    std::printf("\nper estimator (met, within):\n");
    for (const auto& [name, mw] : by_estimator)
        std::printf("  %-28s %6ld %6ld  %.1f%%\n", name.c_str(), mw.first, mw.second,
                    mw.first ? 100.0 * mw.second / mw.first : 0.0);
    std::sort(worst.begin(), worst.end(), [](const Miss& a, const Miss& b) {
        return double(a.within) / a.met < double(b.within) / b.met;
    });
    std::printf("\ncases whose met runs missed the tolerance (within / met; first %d):\n", o.list);
    for (size_t i = 0; i < worst.size() && i < size_t(o.list); ++i)
        std::printf("  %-60s %ld / %ld\n", worst[i].where.c_str(), worst[i].within, worst[i].met);
    return 0;
}

int main(int argc, char** argv) {
    const Options o = parse_options(argc, argv);
    if (o.stop_rel > 0.0) {
        std::vector<Case> all = genz_cases(o);
        for (Case& c : scene_cases(o)) all.push_back(std::move(c));
        return stopping_battery(o, all);
    }
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<Case> cases = genz_cases(o);
    const size_t genz_count = cases.size();
    for (Case& c : scene_cases(o)) cases.push_back(std::move(c));
    std::printf("calibrate: %zu studies (%zu Genz and singular cases; %zu on the scenes of %s, "
                "with their own estimators and each preset), N = %llu..%llu%s, R = %d, fine by "
                "%s\n",
                cases.size(), genz_count, cases.size() - genz_count, o.scenes_dir.c_str(),
                (unsigned long long)o.n_min, (unsigned long long)o.n_max,
                o.ns.empty() ? "" : " (--ns: each N alone)", o.reps,
                o.fine_by_coverage ? "coverage (29 of 32 within 1.96 t se, none beyond 3.5)"
                                   : "every replicate within 3 t se");
    std::FILE* json = o.json_path.empty() ? nullptr : std::fopen(o.json_path.c_str(), "w");
    if (!o.json_path.empty() && !json) usage("--json: cannot write " + o.json_path);
    std::FILE* cells = o.cells_path.empty() ? nullptr : std::fopen(o.cells_path.c_str(), "w");
    if (!o.cells_path.empty() && !cells) usage("--cells: cannot write " + o.cells_path);

    Tally genz, scenes;
    std::vector<Wrong> wrong;
    std::vector<FineCell> fine_cells;
    // Presets a scene does not take (a domain MISER cannot split, ...): count, first reason.
    std::map<std::string, std::pair<int, std::string>> not_applicable;
    std::set<std::string> no_exact; // scenes dropped, by the name before "+preset"
    // The N ranges each case is run over: the ladder, or each --ns value on its own.
    std::vector<std::pair<uint64_t, uint64_t>> ranges;
    if (o.ns.empty())
        ranges.push_back({o.n_min, o.n_max});
    else
        for (uint64_t n : o.ns) ranges.push_back({n, n});
    for (size_t ci = 0; ci < cases.size(); ++ci)
        for (size_t ri = 0; ri < ranges.size(); ++ri) {
            const Case& c = cases[ci];
            const std::string base = c.name.substr(0, c.name.find('+'));
            if (no_exact.count(base)) continue;
            Json options = c.options;
            options["n_min"] = ranges[ri].first;
            options["n_max"] = ranges[ri].second;
            options["reps"] = o.reps;
            options["seed"] = o.seed + ci + 7919 * ri;
            options["threads"] = 0;
            char* out = nullptr;
            Json run_scene = c.scene;
            if (o.blind && ci < genz_count) run_scene["exact"] = nullptr;
            const int status = mcp_study_run(run_scene.dump().c_str(), options.dump().c_str(),
                                             nullptr, nullptr, &out);
            if (status == MCP_ERROR_SCENE && c.options.contains("estimators")) {
                auto& [count, reason] =
                    not_applicable[c.options["estimators"][0].get<std::string>()];
                if (ri == 0 && count++ == 0) reason = c.name + ": " + mcp_last_error();
                mcp_free(out);
                continue;
            }
            if (status != MCP_OK) {
                std::printf("  %s: error %d: %s\n", c.name.c_str(), status, mcp_last_error());
                mcp_free(out);
                continue;
            }
            Made<Json> r = parse_json(out, c.name.c_str());
            mcp_free(out);
            if (!r.ok()) {
                std::printf("  %s: result is not JSON: %s\n", c.name.c_str(), r.error.c_str());
                continue;
            }
            const Json& scene = r.value["scene"];
            const bool told = !(o.blind && ci < genz_count);
            if (told && (!scene.contains("exact") || !scene["exact"].is_number())) {
                std::printf("  %s: no exact value, skipped\n", c.name.c_str());
                no_exact.insert(base);
                continue;
            }
            const double exact = told ? scene["exact"].get<double>() : c.exact;
            Tally& t = ci < genz_count ? genz : scenes;
            const size_t before = wrong.size();
            judge(o, c, ci, r.value, exact, &t, &wrong, &fine_cells, cells);
            if (json)
                std::fprintf(json, "%s\n",
                             Json({{"case", c.name}, {"confident_wrong", wrong.size() - before}})
                                 .dump()
                                 .c_str());
            std::fprintf(stderr, "[%zu/%zu] %s N=%llu\n", ci + 1, cases.size(), c.name.c_str(),
                         (unsigned long long)ranges[ri].first);
        }

    if (!not_applicable.empty()) {
        std::printf("presets skipped on scenes that do not take them:\n");
        for (const auto& [k, v] : not_applicable)
            std::printf("  %-16s %3d scenes (first: %s)\n", k.c_str(), v.first, v.second.c_str());
    }
    auto report = [&](const char* label, const Tally& t) {
        const double rate = t.fine ? double(t.fine_flagged) / double(t.fine) : 0.0;
        std::printf("%-7s cells %6ld  fine %6ld  flagged among fine %6ld (%.1f%%)  confident wrong "
                    "%ld of %ld runs\n",
                    label, t.cells, t.fine, t.fine_flagged, 100.0 * rate, t.confident_wrong,
                    t.runs);
    };
    std::printf("\n");
    report("genz", genz);
    report("scenes", scenes);
    Tally all = genz;
    all.cells += scenes.cells;
    all.fine += scenes.fine;
    all.fine_flagged += scenes.fine_flagged;
    all.confident_wrong += scenes.confident_wrong;
    all.runs += scenes.runs;
    for (const auto& [k, v] : scenes.false_flag_codes) all.false_flag_codes[k] += v;
    for (const auto& [k, v] : scenes.sole_alarm_on_miss) all.sole_alarm_on_miss[k] += v;
    all.infvar_cells += scenes.infvar_cells;
    all.infvar_unflagged += scenes.infvar_unflagged;
    report("all", all);
    if (all.infvar_cells)
        std::printf("infinite-variance cases: %ld cells, %ld of them without an alarm (target 0)\n",
                    all.infvar_cells, all.infvar_unflagged);
    std::printf("\nalarms on fine cells (cells carrying each), and cells with a miss beyond 5 t "
                "standard errors\nwhere it is the only alarm (without it they would be "
                "confident wrong answers):\n");
    std::vector<std::pair<long, std::string>> codes;
    for (const auto& [k, v] : all.false_flag_codes) codes.push_back({v, k});
    for (const auto& [k, v] : all.sole_alarm_on_miss)
        if (!all.false_flag_codes.count(k)) codes.push_back({0, k});
    std::sort(codes.rbegin(), codes.rend());
    std::printf("  %-24s %10s %10s\n", "code", "on fine", "sole alarm");
    for (const auto& [v, k] : codes)
        std::printf("  %-24s %10ld %10ld\n", k.c_str(), v,
                    all.sole_alarm_on_miss.count(k) ? all.sole_alarm_on_miss.at(k) : 0L);
    std::printf("\nconfident wrong answers (|error| / se; first %d):\n", o.list);
    std::sort(wrong.begin(), wrong.end(), [](const Wrong& a, const Wrong& b) { return a.z > b.z; });
    for (size_t i = 0; i < wrong.size() && int(i) < o.list; ++i)
        std::printf("  %-60s %10.3g\n", wrong[i].where.c_str(), wrong[i].z);
    if (wrong.empty()) std::printf("  none\n");
    if (o.recheck > 0) recheck_fine_cells(o, cases, fine_cells);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("\ntotal wall time %.0f s\n", secs);
    if (json) {
        std::fprintf(json, "%s\n",
                     Json({{"kind", "summary"},
                           {"cells", all.cells},
                           {"fine", all.fine},
                           {"fine_flagged", all.fine_flagged},
                           {"confident_wrong", all.confident_wrong},
                           {"runs", all.runs}})
                         .dump()
                         .c_str());
        std::fclose(json);
    }
    if (cells) std::fclose(cells);
    return 0;
}
