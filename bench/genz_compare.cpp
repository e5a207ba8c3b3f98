// genz_compare: GSL's plain, MISER and VEGAS beside mcplay's estimators on Genz's six test
// families, with the same integrand, the same budget of N integrand calls per estimate and
// R replicates per (case, method), on one thread (docs/benchmarks.md).
//
//   genz_compare [--quick] [--n N] [--reps R] [--dims 2,4,8,16] [--families 1,...,6]
//                [--methods uniform,stratified,...] [--gsl plain,miser,vegas|none]
//                [--param-seed S] [--seed S] [--randomizations K] [--params-dir DIR]
//                [--json FILE] [--write-params DIR] [--external FILE.jsonl] [--peaks]
//                [--singular] [--cpu-time] [--ci B]
//
// --cpu-time: time each estimate by its thread's CPU time instead of wall time (t_med, eff).
//
// --ci B: a 95% interval for each case's mcplay/other ratio and for their geometric mean, from
// B bootstrap resamples of each cell's replicates (both cells resampled, rel_rmse and t_med
// recomputed; the best cell of each side as chosen on all replicates). 0 (the default): none.
//
// --randomizations K: the presets sobol, halton and lattice as K randomizations of N/K points
// instead of their 16 (a method may also name its own: "sobol:4", "sobol:lms_shift:4"), to
// compare with bench/qmc_tools.py --randomizations K at equal N and K; as there, a K other than
// 16 shows in the method's name ("sobol:4").
//
// --peaks: instead of genz_random's cases, Genz's product peak with every a_j = a for a in
// {100, 200, 500, 1000} and d in --dims (default 4, 6, 8), u_j the peak positions of
// genz_random(product_peak, d, param seed): sharp separable peaks, where a VEGAS map should be
// at its best (docs/benchmarks.md).
//
// --singular: instead, products of power singularities with finite variance, f = prod_j g_j(x_j)
// on [0,1]^d, d in --dims (default 1..6), each a_j drawn in [0.1, 0.49] from the param seed:
// a corner, g_j = x_j^-a_j; an edge, g_j = x_j^-a_j on the first ceil(d/2) axes and the smooth
// e^(x_j) on the others; an interior point, g_j = |x_j - c_j|^-a_j with c_j in [0.2, 0.8]; and
// x^-0.45 y^-0.2 (issue 49). Both sides call the same point function (singular_point): GSL once
// per point, mcplay per block as a caller's function.
//
// Both sides evaluate mcplay's Genz code: GSL calls genz_evaluate_point (one point per call,
// the only interface GSL has), mcplay runs its own block path (run_estimate ->
// genz_evaluate_block); the two are bit-identical per point (integrands/genz.h).
// Per (case, method), over the R replicates, against the exact integral I:
//   rel_rmse  sqrt(mean((est - I)^2)) / |I|       rel_bias  (mean(est) - I) / |I|
//   sig/rmse  mean(reported sigma) / RMSE: ~1 honest, << 1 over-confident, >> 1 pessimistic
//   cov2      replicates with |est - I| <= 2 sigma (about 95% if the error bars are honest)
//   t_med     median wall seconds per estimate (setup included); --cpu-time: the thread's CPU
//   seconds eff       1 / (rel_rmse^2 t_med): higher is better calls/N   integrand calls actually
//   made / N (mean) eff_sig   1 / (mean(sigma^2) / I^2 t_med): efficiency from the mean reported
//   variance,
//             which for randomized QMC (K randomizations per estimate) pools R (K - 1) degrees
//             of freedom where the RMSE has R; shown beside eff when the error bars are honest
// A reported sigma of 0, NaN or infinity, and a non-finite estimate, are counted and shown in
// the notes column; they make sig/rmse or rel_rmse NaN rather than being dropped.
//
// Other tools join the same tables through --external: JSON lines {"tool", "method", "case",
// "estimate", "reported_sigma", "calls", "seconds"} for cases named as --write-params names
// them (bench/qmc_tools.py writes QMCPy's and scipy's; `make bench-qmc` runs the three steps).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <sys/utsname.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_monte_miser.h>
#include <gsl/gsl_monte_plain.h>
#include <gsl/gsl_monte_vegas.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_version.h>

#include "api/json_read.h"
#include "api/scene.h"
#include "estimators/estimator.h"
#include "integrands/genz.h"

using namespace mcp;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

double now_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// --cpu-time: an estimate's time is this thread's CPU time, which the other processes on a
// loaded machine disturb far less than wall time (only through shared caches and frequency).
bool g_cpu_time = false;

double estimate_clock() {
    if (!g_cpu_time) return now_seconds();
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// ---------------------------------------------------------------------------------------
// Options

struct Options {
    uint64_t n = uint64_t(1) << 20;
    int reps = 10;
    std::vector<int> dims{2, 4, 8, 16};
    std::vector<int> families{1, 2, 3, 4, 5, 6};
    bool dims_given = false, families_given = false;
    std::vector<std::string> methods{"uniform",    "stratified", "latin_hypercube", "sobol",
                                     "halton",     "lattice",    "vegas",           "vegas_sobol",
                                     "vegas_plus", "miser"};
    std::vector<std::string> gsl{"plain", "miser", "vegas"};
    uint64_t param_seed = 1; // genz_random(family, d, param_seed)
    uint64_t seed = 1;       // replicate seeds
    int randomizations = 0;  // --randomizations K for the QMC presets; 0: each preset's own (16)
    int ci = 0;              // --ci B: bootstrap resamples for the ratios' 95% intervals
    std::string params_dir, json_path, write_params_dir, external_path;
    bool quick = false;
    bool peaks = false;    // --peaks: the sharp product peaks instead of genz_random's cases
    bool singular = false; // --singular: products of power singularities
};

std::vector<std::string> split(const std::string& s, char separator = ',') {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, separator))
        if (!item.empty()) out.push_back(item);
    return out;
}

/// Digits only: a count of randomizations in a method's name ("sobol:4").
bool is_count(const std::string& s) {
    return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
}

[[noreturn]] void usage(const char* msg) {
    if (msg) std::fprintf(stderr, "genz_compare: %s\n", msg);
    std::fprintf(stderr,
                 "usage: genz_compare [--quick] [--n N] [--reps R] [--dims 2,4,8,16]\n"
                 "         [--families 1,2,3,4,5,6 | oscillatory,...] [--methods PRESET,...]\n"
                 "         [--gsl plain,miser,vegas|none] [--param-seed S] [--seed S]\n"
                 "         [--randomizations K]\n"
                 "         [--params-dir DIR] [--json FILE] [--write-params DIR]\n"
                 "         [--external FILE.jsonl] [--peaks] [--singular] [--cpu-time]\n"
                 "         [--ci B]\n");
    std::exit(2);
}

const char* kFamilyNames[] = {"oscillatory", "product_peak", "corner_peak",
                              "gaussian",    "continuous",   "discontinuous"};

int family_number(const std::string& s) {
    for (int i = 0; i < 6; ++i)
        if (s == kFamilyNames[i] || s == "genz_" + std::string(kFamilyNames[i])) return i + 1;
    char* end = nullptr;
    long v = std::strtol(s.c_str(), &end, 10);
    if (end && *end == 0 && v >= 1 && v <= 6) return int(v);
    return 0;
}

uint64_t parse_u64(const char* s, const char* what) {
    char* end = nullptr;
    double v = std::strtod(s, &end); // accepts 1048576, 1e6, 2e5
    if (!end || *end || !(v >= 1) || v > 1e15 || v != std::floor(v))
        usage((std::string(what) + ": expected a positive whole number, got '" + s + "'").c_str());
    return uint64_t(v);
}

Options parse_options(int argc, char** argv) {
    Options o;
    bool n_given = false, reps_given = false;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&]() -> const char* {
            if (i + 1 >= argc) usage((a + " needs a value").c_str());
            return argv[++i];
        };
        if (a == "--quick")
            o.quick = true;
        else if (a == "--n")
            o.n = parse_u64(value(), "--n"), n_given = true;
        else if (a == "--reps")
            o.reps = int(parse_u64(value(), "--reps")), reps_given = true;
        else if (a == "--dims") {
            o.dims.clear();
            for (const std::string& s : split(value())) {
                int d = std::atoi(s.c_str());
                if (d < 1 || d > 64) usage(("--dims: " + s + " is not in 1..64").c_str());
                o.dims.push_back(d);
            }
            o.dims_given = true;
        } else if (a == "--families") {
            o.families.clear();
            for (const std::string& s : split(value())) {
                int f = family_number(s);
                if (!f) usage(("--families: unknown family '" + s + "'").c_str());
                o.families.push_back(f);
            }
            o.families_given = true;
        } else if (a == "--methods")
            o.methods = split(value());
        else if (a == "--gsl") {
            std::string v = value();
            o.gsl = v == "none" ? std::vector<std::string>{} : split(v);
            for (const std::string& g : o.gsl)
                if (g != "plain" && g != "miser" && g != "vegas")
                    usage(
                        ("--gsl: unknown method '" + g + "' (plain, miser, vegas, none)").c_str());
        } else if (a == "--param-seed")
            o.param_seed = parse_u64(value(), "--param-seed");
        else if (a == "--seed")
            o.seed = parse_u64(value(), "--seed");
        else if (a == "--randomizations")
            o.randomizations =
                int(std::min<uint64_t>(parse_u64(value(), "--randomizations"), 1u << 30));
        else if (a == "--params-dir")
            o.params_dir = value();
        else if (a == "--json")
            o.json_path = value();
        else if (a == "--write-params")
            o.write_params_dir = value();
        else if (a == "--external")
            o.external_path = value();
        else if (a == "--peaks")
            o.peaks = true;
        else if (a == "--singular")
            o.singular = true;
        else if (a == "--cpu-time")
            g_cpu_time = true;
        else if (a == "--ci")
            o.ci = int(std::min<uint64_t>(parse_u64(value(), "--ci"), 100000));
        else if (a == "-h" || a == "--help")
            usage(nullptr);
        else
            usage(("unknown argument '" + a + "'").c_str());
    }
    if (o.quick) {
        if (!n_given) o.n = uint64_t(1) << 16;
        if (!reps_given) o.reps = 3;
    }
    if (o.reps < 2) usage("--reps must be at least 2");
    // --randomizations K: the QMC presets that name no K take it in their name ("sobol:4"), so
    // the tables say what ran; 16 is their own and leaves the name as it is.
    if (o.randomizations > 0 && o.randomizations != 16)
        for (std::string& m : o.methods) {
            const std::vector<std::string> parts = split(m, ':');
            bool has_k = false;
            for (size_t i = 1; i < parts.size(); ++i) has_k = has_k || is_count(parts[i]);
            if (!has_k && (parts[0] == "sobol" || parts[0] == "halton" || parts[0] == "lattice"))
                m += ":" + std::to_string(o.randomizations);
        }
    if (o.peaks && !o.dims_given) o.dims = {4, 6, 8};
    if (o.peaks && (o.families_given || !o.params_dir.empty()))
        usage("--peaks makes its own cases: no --families or --params-dir with it");
    if (o.singular && !o.dims_given) o.dims = {1, 2, 3, 4, 5, 6};
    if (o.singular && (o.peaks || o.families_given || !o.params_dir.empty()))
        usage("--singular makes its own cases: no --peaks, --families or --params-dir with it");
    return o;
}

// ---------------------------------------------------------------------------------------
// Cases: Genz parameters from genz_random, or from the anchors' params JSON files.

struct Case {
    std::string label; // "oscillatory d=2" (+ file name in --params-dir mode)
    std::string name;  // "f1_d2", or the file's stem in --params-dir mode
    int family = 1;    // 1..6
    GenzParams params;
    double exact = kNaN;        // the value errors are measured against
    double mcplay_exact = kNaN; // genz_exact(params)
    std::string source;
    // --singular: f = prod_j g_j(x_j), g_j = |x_j - c_j|^-power_j, or e^(x_j) where smooth_j.
    bool singular = false;
    std::vector<double> power, centre;
    std::vector<char> smooth;
};

double singular_point(const Case& c, const double* x) {
    double f = 1.0;
    for (size_t j = 0; j < c.power.size(); ++j)
        f *= c.smooth[j] ? std::exp(x[j]) : std::pow(std::fabs(x[j] - c.centre[j]), -c.power[j]);
    return f;
}

/// int_0^1 g_j: (c^(1-a) + (1-c)^(1-a)) / (1 - a) for |x - c|^-a, e - 1 for e^x.
double singular_exact(const Case& c) {
    double v = 1.0;
    for (size_t j = 0; j < c.power.size(); ++j) {
        const double a = c.power[j], m = c.centre[j];
        v *= c.smooth[j] ? std::exp(1.0) - 1.0
                         : (std::pow(m, 1.0 - a) + std::pow(1.0 - m, 1.0 - a)) / (1.0 - a);
    }
    return v;
}

std::vector<Case> singular_cases(const Options& o) {
    std::vector<Case> cases;
    auto add = [&](const std::string& kind, std::vector<double> a, std::vector<double> c,
                   std::vector<char> smooth) {
        Case k;
        const int d = int(a.size());
        k.family = 5; // a placeholder for the scene's domain; the integrand is singular_point
        k.params = genz_random(GenzFamily::Continuous, d, 1);
        k.singular = true;
        k.power = a, k.centre = c, k.smooth = smooth;
        k.mcplay_exact = k.exact = singular_exact(k);
        std::string powers;
        for (int j = 0; j < d; ++j) {
            char b[48];
            std::snprintf(b, sizeof b, "%s%.2f", j ? "," : "", smooth[size_t(j)] ? 0.0 : a[j]);
            powers += b;
        }
        k.label = kind + " d=" + std::to_string(d) + " a=" + powers;
        k.name = kind + "_d" + std::to_string(d);
        k.source = kind + " singular product, a of param seed " + std::to_string(o.param_seed);
        cases.push_back(k);
    };
    add("issue49", {0.45, 0.2}, {0.0, 0.0}, {0, 0});
    for (int d : o.dims) {
        Pcg32 rng(hash_combine(o.param_seed, uint64_t(d)), 49);
        std::vector<double> a(static_cast<size_t>(d)), c(static_cast<size_t>(d));
        for (int j = 0; j < d; ++j) a[j] = 0.1 + 0.39 * rng.next_double();
        for (int j = 0; j < d; ++j) c[j] = 0.2 + 0.6 * rng.next_double();
        add("corner", a, std::vector<double>(size_t(d), 0.0), std::vector<char>(size_t(d), 0));
        if (d > 1) {
            std::vector<char> smooth(size_t(d), 0);
            for (int j = (d + 1) / 2; j < d; ++j) smooth[j] = 1;
            add("edge", a, std::vector<double>(size_t(d), 0.0), smooth);
        }
        add("interior", a, c, std::vector<char>(size_t(d), 0));
    }
    return cases;
}

/// The caller's-function form of singular_point, for mcplay: a block of n points, column-major.
int singular_block(void* user, const double* x, uint64_t n, int dim, double* out, int) {
    const Case& c = *static_cast<const Case*>(user);
    std::vector<double> point(static_cast<size_t>(dim));
    for (uint64_t i = 0; i < n; ++i) {
        for (int j = 0; j < dim; ++j) point[size_t(j)] = x[uint64_t(j) * n + i];
        out[i] = singular_point(c, point.data());
    }
    return 0;
}

std::vector<Case> random_cases(const Options& o) {
    std::vector<Case> cases;
    for (int fam : o.families)
        for (int d : o.dims) {
            Case c;
            c.family = fam;
            c.params = genz_random(GenzFamily(fam - 1), d, o.param_seed);
            c.mcplay_exact = c.exact = genz_exact(c.params);
            c.label = std::string(kFamilyNames[fam - 1]) + " d=" + std::to_string(d);
            c.name = "f" + std::to_string(fam) + "_d" + std::to_string(d);
            c.source = "genz_random(" + std::string(kFamilyNames[fam - 1]) + ", " +
                       std::to_string(d) + ", seed " + std::to_string(o.param_seed) + ")";
            cases.push_back(c);
        }
    return cases;
}

/// --peaks: Genz's product peak f = prod_j 1 / (a^-2 + (x_j - u_j)^2) with every a_j = a, so
/// the peak's width is 1/a on every axis; u from genz_random(product_peak, d, param seed).
std::vector<Case> peak_cases(const Options& o) {
    std::vector<Case> cases;
    for (const double a : {100.0, 200.0, 500.0, 1000.0})
        for (int d : o.dims) {
            const GenzParams random = genz_random(GenzFamily::ProductPeak, d, o.param_seed);
            Made<GenzParams> g =
                make_genz(GenzFamily::ProductPeak, std::vector<double>(size_t(d), a), random.u);
            if (!g.ok()) usage(("--peaks: " + g.error).c_str());
            Case c;
            c.family = 2;
            c.params = g.value;
            c.mcplay_exact = c.exact = genz_exact(c.params);
            const std::string an = std::to_string(int(a));
            c.label = "product_peak a=" + an + " d=" + std::to_string(d);
            c.name = "pp" + an + "_d" + std::to_string(d);
            c.source = "product peak a = " + an + ", u of genz_random(product_peak, " +
                       std::to_string(d) + ", seed " + std::to_string(o.param_seed) + ")";
            cases.push_back(c);
        }
    return cases;
}

std::vector<Case> file_cases(const Options& o) {
    namespace fs = std::filesystem;
    std::vector<Case> cases;
    std::error_code ec;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(o.params_dir, ec))
        if (e.path().extension() == ".json") files.push_back(e.path());
    if (ec) usage(("--params-dir " + o.params_dir + ": " + ec.message()).c_str());
    std::sort(files.begin(), files.end());
    for (const fs::path& p : files) {
        std::ifstream in(p);
        std::stringstream ss;
        ss << in.rdbuf();
        Made<Json> j = parse_json(ss.str().c_str(), p.string().c_str());
        auto skip = [&](const std::string& why) {
            std::printf("skipped %s: %s\n", p.filename().string().c_str(), why.c_str());
        };
        if (!j.ok()) {
            skip(j.error);
            continue;
        }
        const Json& v = j.value;
        if (!v.is_object() || !v.contains("family") || !v["family"].is_number_integer() ||
            !v.contains("a") || !v.contains("u") || !v["a"].is_array() || !v["u"].is_array()) {
            skip("needs integer \"family\" and arrays \"a\", \"u\"");
            continue;
        }
        const int fam = v["family"].get<int>();
        if (fam < 1 || fam > 6) {
            skip("family " + std::to_string(fam) + " is not one of Genz's six");
            continue;
        }
        std::vector<double> a, u;
        for (const Json& x : v["a"]) a.push_back(x.is_number() ? x.get<double>() : kNaN);
        for (const Json& x : v["u"]) u.push_back(x.is_number() ? x.get<double>() : kNaN);
        Made<GenzParams> g = make_genz(GenzFamily(fam - 1), a, u);
        if (!g.ok()) {
            skip(g.error);
            continue;
        }
        if (v.contains("d") && v["d"].is_number_integer() && v["d"].get<int>() != g.value.dim()) {
            skip("\"d\" does not match the length of \"a\"");
            continue;
        }
        const int d = g.value.dim();
        if (o.families_given &&
            std::find(o.families.begin(), o.families.end(), fam) == o.families.end())
            continue;
        if (o.dims_given && std::find(o.dims.begin(), o.dims.end(), d) == o.dims.end()) continue;
        Case c;
        c.family = fam;
        c.params = g.value;
        c.mcplay_exact = genz_exact(c.params);
        c.exact = v.contains("exact") && v["exact"].is_number() ? v["exact"].get<double>()
                                                                : c.mcplay_exact;
        c.label = std::string(kFamilyNames[fam - 1]) + " d=" + std::to_string(d) + " (" +
                  p.stem().string() + ")";
        c.source = p.string();
        c.name = p.stem().string();
        cases.push_back(c);
    }
    std::stable_sort(cases.begin(), cases.end(), [](const Case& x, const Case& y) {
        return x.family != y.family ? x.family < y.family : x.params.dim() < y.params.dim();
    });
    return cases;
}

// ---------------------------------------------------------------------------------------
// One estimate

struct Estimate {
    double value = kNaN, sigma = kNaN, seconds = 0.0, chi2 = kNaN;
    uint64_t calls = 0;
    int status = 0;
};

struct GslContext {
    const GenzParams* params;
    uint64_t calls;
    const Case* singular = nullptr; // --singular: singular_point instead of Genz
};

double gsl_integrand(double* x, size_t, void* context) {
    GslContext* c = static_cast<GslContext*>(context);
    ++c->calls;
    return c->singular ? singular_point(*c->singular, x) : genz_evaluate_point(*c->params, x);
}

// VEGAS as GSL's manual recommends: a warm-up of 10^4 calls (stage 0: fresh grid) to train
// the grid, then the main integration on that grid (stage 1: keep the grid, restart the
// averages), all inside the budget of n calls, counted at the integrand. GSL's `calls` is per
// iteration (params.iterations = 5 by default) and rounded down to (calls per box) x boxes^d,
// so: while a whole main iteration still fits, one more is run (stage 3: continue the run;
// GSL sets stage back to 1 after every call, so it is set each time); then the rest is spent
// in single iterations re-binned to it (stage 2: keep grid and averages) while it is at least
// 10^4 calls; a last rest under 10^4 calls goes to one iteration in GSL's importance-only
// mode, the only mode that takes a call count exactly (one box), so the total is exactly n.
// Everything else is GSL's default (alpha 1.5, 50 bins, mode importance or stratified).
Estimate gsl_vegas(gsl_monte_function* F, GslContext* ctx, int d, uint64_t n, gsl_rng* r) {
    Estimate e;
    std::vector<double> lo(size_t(d), 0.0), hi(size_t(d), 1.0);
    gsl_monte_vegas_state* s = gsl_monte_vegas_alloc(size_t(d));
    gsl_monte_vegas_params vp;
    gsl_monte_vegas_params_get(s, &vp);
    const size_t iterations = vp.iterations; // 5
    const uint64_t warm = std::min<uint64_t>(10000, n / 10);
    vp.stage = 0;
    gsl_monte_vegas_params_set(s, &vp);
    e.status |= gsl_monte_vegas_integrate(F, lo.data(), hi.data(), size_t(d), warm / iterations, r,
                                          s, &e.value, &e.sigma);
    const uint64_t before_main = ctx->calls;
    vp.stage = 1;
    gsl_monte_vegas_params_set(s, &vp);
    e.status |= gsl_monte_vegas_integrate(F, lo.data(), hi.data(), size_t(d),
                                          (n - before_main) / iterations, r, s, &e.value, &e.sigma);
    const uint64_t per_iteration = (ctx->calls - before_main) / iterations;
    vp.iterations = 1;
    while (per_iteration > 0 && ctx->calls + per_iteration <= n) {
        vp.stage = 3;
        gsl_monte_vegas_params_set(s, &vp);
        e.status |= gsl_monte_vegas_integrate(F, lo.data(), hi.data(), size_t(d), per_iteration, r,
                                              s, &e.value, &e.sigma);
    }
    while (n - ctx->calls >= 10000) { // GSL never makes more calls than asked for
        vp.stage = 2;
        gsl_monte_vegas_params_set(s, &vp);
        e.status |= gsl_monte_vegas_integrate(F, lo.data(), hi.data(), size_t(d), n - ctx->calls, r,
                                              s, &e.value, &e.sigma);
    }
    if (n - ctx->calls >= 2) { // one box of n - calls points (at least 2 per box)
        vp.stage = 2;
        vp.mode = GSL_VEGAS_MODE_IMPORTANCE_ONLY;
        gsl_monte_vegas_params_set(s, &vp);
        e.status |= gsl_monte_vegas_integrate(F, lo.data(), hi.data(), size_t(d), n - ctx->calls, r,
                                              s, &e.value, &e.sigma);
    }
    e.chi2 = gsl_monte_vegas_chisq(s);
    gsl_monte_vegas_free(s);
    return e;
}

Estimate run_gsl(const std::string& method, const Case& cs, uint64_t n, gsl_rng* r) {
    const GenzParams& p = cs.params;
    GslContext ctx{&p, 0, cs.singular ? &cs : nullptr};
    gsl_monte_function F{&gsl_integrand, size_t(p.dim()), &ctx};
    const int d = p.dim();
    std::vector<double> lo(size_t(d), 0.0), hi(size_t(d), 1.0);
    const double t0 = estimate_clock();
    Estimate e;
    if (method == "plain") {
        gsl_monte_plain_state* s = gsl_monte_plain_alloc(size_t(d));
        e.status = gsl_monte_plain_integrate(&F, lo.data(), hi.data(), size_t(d), n, r, s, &e.value,
                                             &e.sigma);
        gsl_monte_plain_free(s);
    } else if (method == "miser") {
        gsl_monte_miser_state* s = gsl_monte_miser_alloc(size_t(d));
        e.status = gsl_monte_miser_integrate(&F, lo.data(), hi.data(), size_t(d), n, r, s, &e.value,
                                             &e.sigma);
        gsl_monte_miser_free(s);
    } else {
        e = gsl_vegas(&F, &ctx, d, n, r);
    }
    e.seconds = estimate_clock() - t0;
    e.calls = ctx.calls;
    return e;
}

/// Writes one params file per case, in the format --params-dir reads (and other tools'
/// harnesses: bench/qmc_tools.py), named after the case.
void write_params(const std::vector<Case>& cases, const std::string& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) usage(("--write-params " + dir + ": " + ec.message()).c_str());
    for (const Case& c : cases) {
        const Json j = {{"name", c.name},
                        {"family", c.family},
                        {"family_name", kFamilyNames[c.family - 1]},
                        {"d", c.params.dim()},
                        {"a", c.params.a},
                        {"u", c.params.u},
                        {"exact", c.exact},
                        {"source", c.source}};
        const std::string path = dir + "/" + c.name + ".json";
        std::ofstream out(path);
        out << j.dump() << "\n";
        if (!out) usage(("--write-params: cannot write " + path).c_str());
    }
    std::printf("wrote %zu params files to %s\n", cases.size(), dir.c_str());
}

/// Estimates of other tools, JSON lines {"tool", "method", "case", "estimate",
/// "reported_sigma", "calls", "seconds"}: by case name, then method, in file order. A line
/// that is not such an object is reported and skipped; a non-finite value is kept (it shows
/// as NaN in the tables, as for any tool).
struct External {
    std::map<std::string, std::map<std::string, std::vector<Estimate>>> by_case;
    std::map<std::string, std::string> tool_of_method;
};

External read_external(const std::string& path) {
    External ext;
    std::ifstream in(path);
    if (!in) usage(("--external: cannot read " + path).c_str());
    std::string line;
    size_t line_no = 0, skipped = 0;
    auto number = [](const Json& v, const char* key) {
        if (!v.contains(key)) return kNaN;
        const Json& x = v[key];
        return x.is_number() ? x.get<double>() : kNaN;
    };
    while (std::getline(in, line)) {
        ++line_no;
        if (line.empty()) continue;
        Made<Json> j = parse_json(line.c_str(), path.c_str());
        const bool ok = j.ok() && j.value.is_object() && j.value.contains("tool") &&
                        j.value["tool"].is_string() && j.value.contains("method") &&
                        j.value["method"].is_string() && j.value.contains("case") &&
                        j.value["case"].is_string();
        if (!ok) {
            if (++skipped <= 5)
                std::printf("--external %s:%zu: skipped (needs \"tool\", \"method\", \"case\")\n",
                            path.c_str(), line_no);
            continue;
        }
        const Json& v = j.value;
        Estimate e;
        e.value = number(v, "estimate");
        e.sigma = number(v, "reported_sigma");
        e.seconds = number(v, "seconds");
        const double calls = number(v, "calls");
        e.calls = calls >= 0 && calls < 1e18 ? uint64_t(calls) : 0;
        const std::string method = v["method"].get<std::string>();
        ext.by_case[v["case"].get<std::string>()][method].push_back(e);
        ext.tool_of_method[method] = v["tool"].get<std::string>();
    }
    if (skipped) std::printf("--external: %zu lines skipped\n", skipped);
    return ext;
}

// ---------------------------------------------------------------------------------------
// Statistics of one (case, method) cell

struct Cell {
    std::string method; // gsl_plain, ..., the mcplay preset name, or an --external method
    std::string tool;   // "mcplay", "gsl", or the --external line's "tool"
    std::vector<Estimate> reps;
    double rel_rmse = kNaN, rel_bias = kNaN, sig_rmse = kNaN, t_med = kNaN, eff = kNaN,
           eff_sig = kNaN, calls_frac = kNaN, chi2_med = kNaN;
    bool mcplay() const { return tool == "mcplay"; }
    int cov2 = 0, sigma_zero = 0, sigma_nonfinite = 0, est_nonfinite = 0, bad_status = 0;
};

double median(std::vector<double> v) {
    if (v.empty()) return kNaN;
    std::sort(v.begin(), v.end());
    const size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

void summarize(Cell& c, double exact, uint64_t n) {
    double se2 = 0.0, bias = 0.0, sig = 0.0, sig2 = 0.0, calls = 0.0;
    std::vector<double> secs, chi;
    for (const Estimate& e : c.reps) {
        const double err = e.value - exact;
        se2 += err * err; // NaN propagates: a non-finite estimate makes rel_rmse NaN
        bias += err;
        sig += e.sigma; // likewise a NaN sigma makes sig/rmse NaN
        sig2 += e.sigma * e.sigma;
        if (std::fabs(err) <= 2.0 * e.sigma) ++c.cov2;
        if (e.sigma == 0.0) ++c.sigma_zero;
        if (!std::isfinite(e.sigma)) ++c.sigma_nonfinite;
        if (!std::isfinite(e.value)) ++c.est_nonfinite;
        if (e.status) ++c.bad_status;
        secs.push_back(e.seconds);
        calls += double(e.calls);
        if (!std::isnan(e.chi2)) chi.push_back(e.chi2);
    }
    const double R = double(c.reps.size());
    const double rmse = std::sqrt(se2 / R);
    c.rel_rmse = rmse / std::fabs(exact);
    c.rel_bias = bias / R / std::fabs(exact);
    c.sig_rmse = (sig / R) / rmse;
    c.t_med = median(secs);
    c.eff = 1.0 / (c.rel_rmse * c.rel_rmse * c.t_med);
    c.eff_sig = exact * exact / (sig2 / R * c.t_med);
    c.calls_frac = calls / R / double(n);
    c.chi2_med = median(chi);
}

std::string notes(const Cell& c) {
    std::string s;
    auto add = [&](const std::string& t) { s += (s.empty() ? "" : "; ") + t; };
    const int R = int(c.reps.size());
    if (c.est_nonfinite)
        add("estimate non-finite in " + std::to_string(c.est_nonfinite) + "/" + std::to_string(R));
    if (c.sigma_zero) add("sigma = 0 in " + std::to_string(c.sigma_zero) + "/" + std::to_string(R));
    if (c.sigma_nonfinite)
        add("sigma NaN/inf in " + std::to_string(c.sigma_nonfinite) + "/" + std::to_string(R));
    if (c.bad_status)
        add("GSL status != 0 in " + std::to_string(c.bad_status) + "/" + std::to_string(R));
    if (!std::isnan(c.chi2_med)) {
        char b[64];
        std::snprintf(b, sizeof b, "chi2/dof %.2g", c.chi2_med);
        add(b);
    }
    return s;
}

// Error bars that cannot be taken at face value: over-confident (sig/rmse < 0.5, NaN, or
// coverage of the 2-sigma intervals under 70%) or pessimistic (sig/rmse > 2: safe, but the
// estimator is better than it claims). '!' and '^' in the tables.
bool overconfident(const Cell& c) {
    const int R = int(c.reps.size());
    return !(c.sig_rmse >= 0.5) || 10 * c.cov2 < 7 * R;
}
bool pessimistic(const Cell& c) {
    return c.sig_rmse > 2.0;
}
const char* mark(const Cell& c) {
    return overconfident(c) ? "!" : pessimistic(c) ? "^" : " ";
}

std::string fmt_e(double x, int prec = 2) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    char b[32];
    std::snprintf(b, sizeof b, "%.*e", prec, x);
    return b;
}
std::string fmt_f(double x, const char* f) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    char b[32];
    std::snprintf(b, sizeof b, f, x);
    return b;
}

// JSON: non-finite numbers are written as the strings "nan", "inf", "-inf" (JSON has no NaN),
// so that they are visible, never silently null.
Json jnum(double x) {
    if (std::isfinite(x)) return x;
    return std::isnan(x) ? Json("nan") : Json(x > 0 ? "inf" : "-inf");
}

// ---------------------------------------------------------------------------------------

struct CaseResult {
    const Case* c;
    std::vector<Cell> cells;
    int best_other = -1, best_mcplay = -1; // best eff of GSL and --external, best of mcplay
    double ratio = kNaN, ratio_sig = kNaN;
    std::vector<double> boot; // --ci: the ratio in each bootstrap resample
    double ci_lo = kNaN, ci_hi = kNaN;
};

// 1 / (rel_rmse^2 t_med) of a resample of c's replicates (indices idx).
double resampled_eff(const Cell& c, const std::vector<size_t>& idx, double exact) {
    double se2 = 0.0;
    std::vector<double> secs;
    secs.reserve(idx.size());
    for (size_t i : idx) {
        const double err = c.reps[i].value - exact;
        se2 += err * err;
        secs.push_back(c.reps[i].seconds);
    }
    const double rel_mse = se2 / double(idx.size()) / (exact * exact);
    return 1.0 / (rel_mse * median(secs));
}

double quantile(std::vector<double> v, double q) {
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }),
            v.end());
    if (v.empty()) return kNaN;
    std::sort(v.begin(), v.end());
    const double pos = q * double(v.size() - 1);
    const size_t k = size_t(pos);
    return k + 1 < v.size() ? v[k] + (pos - double(k)) * (v[k + 1] - v[k]) : v[k];
}

// The ratio's bootstrap distribution: each side's replicates resampled with replacement.
void bootstrap_ratio(CaseResult& cr, int resamples, uint64_t seed) {
    if (resamples <= 0 || cr.best_other < 0 || cr.best_mcplay < 0) return;
    const Cell& g = cr.cells[size_t(cr.best_other)];
    const Cell& m = cr.cells[size_t(cr.best_mcplay)];
    std::mt19937_64 rng(seed);
    std::vector<size_t> ig(g.reps.size()), im(m.reps.size());
    for (int b = 0; b < resamples; ++b) {
        for (size_t& i : ig) i = size_t(rng() % g.reps.size());
        for (size_t& i : im) i = size_t(rng() % m.reps.size());
        cr.boot.push_back(resampled_eff(m, im, cr.c->exact) / resampled_eff(g, ig, cr.c->exact));
    }
    cr.ci_lo = quantile(cr.boot, 0.025);
    cr.ci_hi = quantile(cr.boot, 0.975);
}

int best_of(const std::vector<Cell>& cells, bool mcplay) {
    int best = -1;
    for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i].mcplay() != mcplay || std::isnan(cells[i].eff)) continue;
        if (best < 0 || cells[i].eff > cells[size_t(best)].eff) best = int(i);
    }
    return best;
}

/// The highest eff_sig among one side's cells whose error bars are not over-confident (an
/// over-confident sigma says nothing about the variance); NaN if there is none.
double best_eff_sig(const std::vector<Cell>& cells, bool mcplay) {
    double best = kNaN;
    for (const Cell& c : cells)
        if (c.mcplay() == mcplay && !overconfident(c) && !(c.eff_sig <= best)) best = c.eff_sig;
    return best;
}

/// A method is a preset name, optionally with a randomization and a count of randomizations:
/// "sobol", "sobol:lms_shift", "sobol:owen:32", "sobol:4"; or a VEGAS preset with options of its
/// "vegas" object, numbers or words: "vegas/alpha=1.5/train_fraction=0.4",
/// "vegas/report=iterations"; "sampler=" is the estimator's own field (a new name:
/// "vegas_strat/sampler=stratified").
Json estimator_for(const std::string& method) {
    if (method.find('/') != std::string::npos) {
        std::vector<std::string> parts = split(method, '/');
        Json options = Json::object(), top = Json::object();
        for (size_t i = 1; i < parts.size(); ++i) {
            const size_t eq = parts[i].find('=');
            const std::string key = parts[i].substr(0, eq);
            const std::string value = eq == std::string::npos ? "" : parts[i].substr(eq + 1);
            char* end = nullptr;
            const double x = std::strtod(value.c_str(), &end);
            if (key == "sampler") // the estimator's own field: "vegas_strat/sampler=stratified"
                top[key] = value;
            else if (!value.empty() && end && *end == 0 &&
                     value.find_first_of(".eE") == std::string::npos)
                options[key] = static_cast<long long>(x);
            else if (!value.empty() && end && *end == 0)
                options[key] = x;
            else
                options[key] = value;
        }
        top["name"] = parts[0];
        top["vegas"] = options;
        return top;
    }
    // "sobol:owen", "sobol:owen:4" or "sobol:4": the randomization and/or the number K of
    // randomizations.
    std::vector<std::string> parts = split(method, ':');
    Json e = {{"name", parts[0]}};
    for (size_t i = 1; i < parts.size(); ++i) {
        if (is_count(parts[i]))
            e["randomizations"] = std::atoll(parts[i].c_str());
        else
            e["randomization"] = parts[i];
    }
    if (e.size() == 1) return method;
    return e;
}

Json scene_for(const Case& c, const std::string& estimator, bool exact_from_file) {
    Json integrand = {
        {"type", genz_family_name(c.params.family)}, {"a", c.params.a}, {"u", c.params.u}};
    Json scene = {{"name", "genz_compare"},
                  {"integrand", integrand},
                  {"estimators", Json::array({estimator_for(estimator)})}};
    if (exact_from_file) scene["exact"] = c.exact;
    return scene;
}

} // namespace

int main(int argc, char** argv) {
    const Options o = parse_options(argc, argv);
    const double t_start = now_seconds();
    gsl_set_error_handler_off();
    const bool from_files = !o.params_dir.empty();
    std::FILE* json = nullptr;
    if (!o.json_path.empty()) {
        json = std::fopen(o.json_path.c_str(), "w");
        if (!json) usage(("--json: cannot write " + o.json_path).c_str());
    }
    auto emit = [&](const Json& j) {
        if (json) std::fprintf(json, "%s\n", j.dump().c_str());
    };

    struct utsname un;
    uname(&un);
    char date[64];
    std::time_t tt = std::time(nullptr);
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&tt));
    std::printf("genz_compare: GSL %s (plain, MISER, VEGAS; mt19937, seeds %llu..%llu) vs mcplay "
                "run_estimate, one thread%s\n",
                GSL_VERSION, (unsigned long long)o.seed,
                (unsigned long long)(o.seed + uint64_t(o.reps) - 1),
                g_cpu_time ? ", times in thread CPU seconds" : "");
    std::printf("  N = %llu integrand calls per estimate, R = %d replicates, %s\n",
                (unsigned long long)o.n, o.reps,
                from_files
                    ? ("parameters from " + o.params_dir + " (exact values from the files)").c_str()
                : o.singular ? ("--singular: power-singular products, a of param seed " +
                                std::to_string(o.param_seed) + ", exact values in closed form")
                                   .c_str()
                             : ((o.peaks ? "--peaks: product peaks a = 100, 200, 500, 1000 at u of "
                                           "genz_random(product_peak, d, seed "
                                         : "parameters genz_random(family, d, seed ") +
                                std::to_string(o.param_seed) + "), exact values genz_exact")
                                   .c_str());
    if (o.randomizations > 0)
        std::printf(
            "  sobol, halton, lattice: %d randomizations of N/%d points (--randomizations)\n",
            o.randomizations, o.randomizations);
    std::printf("  %s, %s %s; %s\n", date, un.machine, un.release,
                o.quick ? "--quick" : "full run");
    std::printf("  VEGAS: warm-up 10^4 calls (stage 0), then the main run (stage 1) on the trained "
                "grid; total calls = N (see docs/benchmarks.md)\n");
    std::fflush(stdout);
    std::vector<Case> cases =
        from_files ? file_cases(o)
                   : (o.peaks ? peak_cases(o) : (o.singular ? singular_cases(o) : random_cases(o)));
    if (cases.empty()) usage("no cases to run");
    if (!o.write_params_dir.empty()) {
        write_params(cases, o.write_params_dir);
        return 0;
    }
    const External ext = o.external_path.empty() ? External() : read_external(o.external_path);

    // mcplay methods whose presets the scene API does not know are skipped, one line each.
    std::vector<std::string> methods;
    std::map<std::string, std::string> skipped;
    for (const std::string& m : o.methods) {
        Made<SceneRequest> r = build_request(scene_for(cases[0], m, from_files), Json());
        if (!r.ok()) {
            std::printf("skipped %s: %s\n", m.c_str(), r.error.c_str());
            skipped[m] = r.error;
        } else
            methods.push_back(m);
    }
    std::printf("\n");
    emit({{"kind", "meta"},
          {"gsl_version", GSL_VERSION},
          {"N", o.n},
          {"R", o.reps},
          {"seed", o.seed},
          {"randomizations", o.randomizations > 0 ? Json(o.randomizations) : Json(nullptr)},
          {"param_seed", from_files ? Json(nullptr) : Json(o.param_seed)},
          {"params_dir", from_files ? Json(o.params_dir) : Json(nullptr)},
          {"quick", o.quick},
          {"date", date},
          {"machine", std::string(un.machine) + " " + un.release},
          {"gsl_methods", o.gsl},
          {"mcplay_methods", methods},
          {"skipped", skipped}});

    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    std::vector<CaseResult> results;
    for (size_t ci = 0; ci < cases.size(); ++ci) {
        const Case& cs = cases[ci];
        CaseResult cr;
        cr.c = &cs;
        std::fprintf(stderr, "[%5.0f s] case %zu/%zu: %s\n", now_seconds() - t_start, ci + 1,
                     cases.size(), cs.label.c_str());
        for (const std::string& g : o.gsl) {
            Cell cell;
            cell.method = "gsl_" + g;
            cell.tool = "gsl";
            for (int rep = 0; rep < o.reps; ++rep) {
                gsl_rng_set(rng, o.seed + uint64_t(rep));
                cell.reps.push_back(run_gsl(g, cs, o.n, rng));
            }
            cr.cells.push_back(cell);
        }
        for (const std::string& m : methods) {
            Made<SceneRequest> r = build_request(scene_for(cs, m, from_files), Json());
            if (!r.ok()) {
                std::printf("skipped %s on %s: %s\n", m.c_str(), cs.label.c_str(), r.error.c_str());
                continue;
            }
            SceneRequest& req = r.value;
            if (cs.singular) // the same point function as GSL's, a block at a time
                req.problem.integrand = make_function_integrand(
                    make_caller_function("singular", &singular_block, const_cast<Case*>(&cs),
                                         std::make_shared<CallControl>()),
                    cs.params.dim());
            // The scene carries the same parameters GSL integrates (same a, u, same family).
            const GenzParams& q = cs.singular ? cs.params : req.problem.integrand.genz;
            const bool genz = cs.singular || req.problem.integrand.kind == IntegrandKind::Genz;
            if (!genz || q.family != cs.params.family || q.a != cs.params.a || q.u != cs.params.u ||
                req.estimators.size() != 1) {
                std::fprintf(stderr, "genz_compare: the scene for %s did not reproduce the case\n",
                             cs.label.c_str());
                return 1;
            }
            Cell cell;
            cell.method = m;
            cell.tool = "mcplay";
            Workspace ws;
            for (int rep = 0; rep < o.reps; ++rep) {
                Pcg32 prng(hash_combine(hash_combine(o.seed, ci), uint64_t(rep)),
                           hash_string(m.c_str()));
                const double t0 = estimate_clock();
                RunResult rr = run_estimate(req.problem, req.estimators[0], o.n, prng, ws);
                Estimate e;
                e.seconds = estimate_clock() - t0;
                e.value = rr.estimate;
                e.sigma = rr.std_error;
                e.calls = rr.n;
                cell.reps.push_back(e);
            }
            cr.cells.push_back(cell);
        }
        if (auto it = ext.by_case.find(cs.name); it != ext.by_case.end())
            for (const auto& [method, reps] : it->second) {
                Cell cell;
                cell.method = method;
                cell.tool = ext.tool_of_method.at(method);
                cell.reps = reps;
                cr.cells.push_back(cell);
            }
        for (Cell& cell : cr.cells) summarize(cell, cs.exact, o.n);
        cr.best_other = best_of(cr.cells, false);
        cr.best_mcplay = best_of(cr.cells, true);
        if (cr.best_other >= 0 && cr.best_mcplay >= 0)
            cr.ratio = cr.cells[size_t(cr.best_mcplay)].eff / cr.cells[size_t(cr.best_other)].eff;
        cr.ratio_sig = best_eff_sig(cr.cells, true) / best_eff_sig(cr.cells, false);
        bootstrap_ratio(cr, o.ci, hash_combine(o.seed, ci));

        // Table for this case.
        std::printf("== %s: exact %.15e  [%s]\n", cs.label.c_str(), cs.exact, cs.source.c_str());
        if (from_files)
            std::printf("   mcplay genz_exact %.15e (relative difference %.1e)\n", cs.mcplay_exact,
                        (cs.mcplay_exact - cs.exact) / std::fabs(cs.exact));
        std::printf("   %-16s %9s %9s %8s %6s %9s %9s %7s  %s\n", "method", "rel_rmse", "rel_bias",
                    "sig/rmse", "cov2", "t_med_s", "eff", "calls/N", "notes");
        for (const Cell& c : cr.cells) {
            std::printf("   %-16s %9s %9s %8s %3d/%-2d %9s %9s %7s  %s\n", c.method.c_str(),
                        fmt_e(c.rel_rmse).c_str(), fmt_f(c.rel_bias, "%+.1e").c_str(),
                        fmt_f(c.sig_rmse, "%.2f").c_str(), c.cov2, int(c.reps.size()),
                        fmt_e(c.t_med).c_str(), fmt_e(c.eff, 1).c_str(),
                        fmt_f(c.calls_frac, "%.4f").c_str(), notes(c).c_str());
            Json cell = {{"kind", "cell"},
                         {"case", cs.label},
                         {"family", cs.family},
                         {"family_name", kFamilyNames[cs.family - 1]},
                         {"d", cs.params.dim()},
                         {"exact", jnum(cs.exact)},
                         {"method", c.method},
                         {"tool", c.tool},
                         {"N", o.n},
                         {"R", c.reps.size()},
                         {"rel_rmse", jnum(c.rel_rmse)},
                         {"rel_bias", jnum(c.rel_bias)},
                         {"sig_over_rmse", jnum(c.sig_rmse)},
                         {"cov2", c.cov2},
                         {"t_med", jnum(c.t_med)},
                         {"eff", jnum(c.eff)},
                         {"eff_sig", jnum(c.eff_sig)},
                         {"calls_over_N", jnum(c.calls_frac)},
                         {"sigma_zero", c.sigma_zero},
                         {"sigma_nonfinite", c.sigma_nonfinite},
                         {"estimate_nonfinite", c.est_nonfinite},
                         {"gsl_status_nonzero", c.bad_status},
                         {"chi2_dof_median", jnum(c.chi2_med)}};
            emit(cell);
            for (size_t rep = 0; rep < c.reps.size(); ++rep) {
                const Estimate& e = c.reps[rep];
                emit({{"kind", "estimate"},
                      {"case", cs.label},
                      {"method", c.method},
                      {"rep", rep},
                      {"estimate", jnum(e.value)},
                      {"reported_sigma", jnum(e.sigma)},
                      {"calls", e.calls},
                      {"seconds", jnum(e.seconds)},
                      {"chi2_dof", jnum(e.chi2)},
                      {"status", e.status}});
            }
        }
        if (cr.best_other >= 0 && cr.best_mcplay >= 0) {
            const Cell& g = cr.cells[size_t(cr.best_other)];
            const Cell& m = cr.cells[size_t(cr.best_mcplay)];
            std::printf("   best other %s (eff %s), best mcplay %s (eff %s): mcplay/other %s",
                        g.method.c_str(), fmt_e(g.eff, 1).c_str(), m.method.c_str(),
                        fmt_e(m.eff, 1).c_str(), fmt_e(cr.ratio, 1).c_str());
            if (o.ci > 0)
                std::printf(" (95%% bootstrap %s to %s)", fmt_e(cr.ci_lo, 1).c_str(),
                            fmt_e(cr.ci_hi, 1).c_str());
            std::printf("\n\n");
        } else
            std::printf("   (no finite efficiency on one side: no comparison)\n\n");
        emit({{"kind", "case"},
              {"case", cs.label},
              {"family", cs.family},
              {"d", cs.params.dim()},
              {"best_other",
               cr.best_other >= 0 ? Json(cr.cells[size_t(cr.best_other)].method) : Json(nullptr)},
              {"best_mcplay",
               cr.best_mcplay >= 0 ? Json(cr.cells[size_t(cr.best_mcplay)].method) : Json(nullptr)},
              {"eff_ratio_mcplay_over_other", jnum(cr.ratio)},
              {"eff_ratio_ci95",
               o.ci > 0 ? Json::array({jnum(cr.ci_lo), jnum(cr.ci_hi)}) : Json(nullptr)},
              {"eff_sig_ratio_mcplay_over_other", jnum(cr.ratio_sig)}});
        std::fflush(stdout);
        results.push_back(cr);
    }
    gsl_rng_free(rng);

    // Summary: best of the other tools against best mcplay per case.
    std::printf("== summary: best other method (GSL%s) vs best mcplay method per case (efficiency "
                "1/(rel_rmse^2 t_med));\n"
                "   after sig/rmse: '!' over-confident error bars (sig/rmse < 0.5 or cov2 < 70%%), "
                "'^' pessimistic "
                "ones (sig/rmse > 2);\n"
                "   by_sigma: the same ratio from eff_sig, best honest cell of each side\n",
                o.external_path.empty() ? "" : " and --external");
    std::printf("   %-28s %-16s %9s %8s  %-16s %9s %8s  %11s %9s\n", "case", "best other", "eff",
                "sig/rmse", "best mcplay", "eff", "sig/rmse", "mcplay/other", "by_sigma");
    double log_sum = 0.0;
    int compared = 0, ahead = 0, ahead_sig = 0;
    for (const CaseResult& cr : results) {
        if (cr.best_other < 0 || cr.best_mcplay < 0) {
            std::printf("   %-28s (no comparison)\n", cr.c->label.c_str());
            continue;
        }
        const Cell& g = cr.cells[size_t(cr.best_other)];
        const Cell& m = cr.cells[size_t(cr.best_mcplay)];
        std::printf("   %-28s %-16s %9s %7s%s  %-16s %9s %7s%s  %11s %9s\n", cr.c->label.c_str(),
                    g.method.c_str(), fmt_e(g.eff, 1).c_str(), fmt_f(g.sig_rmse, "%.2f").c_str(),
                    mark(g), m.method.c_str(), fmt_e(m.eff, 1).c_str(),
                    fmt_f(m.sig_rmse, "%.2f").c_str(), mark(m), fmt_e(cr.ratio, 1).c_str(),
                    fmt_e(cr.ratio_sig, 1).c_str());
        if (o.ci > 0)
            std::printf("   %-28s 95%% bootstrap interval of mcplay/other: %s to %s\n", "",
                        fmt_e(cr.ci_lo, 1).c_str(), fmt_e(cr.ci_hi, 1).c_str());
        if (std::isfinite(cr.ratio) && cr.ratio > 0) {
            log_sum += std::log(cr.ratio);
            ++compared;
            if (cr.ratio > 1.0) ++ahead;
        }
        if (cr.ratio_sig > 1.0) ++ahead_sig;
    }
    const double geomean = compared ? std::exp(log_sum / compared) : kNaN;
    std::printf("   geometric mean of mcplay/other: %s over %d cases; mcplay ahead on %d of %zu "
                "(by_sigma: on %d)\n",
                fmt_e(geomean, 2).c_str(), compared, ahead, results.size(), ahead_sig);
    double geo_lo = kNaN, geo_hi = kNaN;
    if (o.ci > 0 && compared) {
        std::vector<double> geo(size_t(o.ci), 0.0);
        for (const CaseResult& cr : results) {
            if (!(std::isfinite(cr.ratio) && cr.ratio > 0) || cr.boot.size() != geo.size())
                continue;
            for (size_t b = 0; b < geo.size(); ++b) geo[b] += std::log(cr.boot[b]) / compared;
        }
        for (double& x : geo) x = std::exp(x);
        geo_lo = quantile(geo, 0.025);
        geo_hi = quantile(geo, 0.975);
        std::printf("   95%% bootstrap interval of the geometric mean: %s to %s (%d resamples)\n",
                    fmt_e(geo_lo, 2).c_str(), fmt_e(geo_hi, 2).c_str(), o.ci);
    }

    // Error bars that cannot be taken at face value, mcplay's and GSL's.
    int flagged = 0;
    for (int pass = 0; pass < 2; ++pass) {
        std::printf("\n== %s (R = %d: sig/rmse itself is uncertain by about +-%.0f%%)\n",
                    pass == 0 ? "over-confident error bars: sig/rmse < 0.5 or cov2 < 70%"
                              : "pessimistic error bars: sig/rmse > 2",
                    o.reps, 100.0 / std::sqrt(2.0 * o.reps));
        int listed = 0;
        for (const CaseResult& cr : results)
            for (const Cell& c : cr.cells) {
                if (pass == 0 ? !overconfident(c) : (overconfident(c) || !pessimistic(c))) continue;
                ++listed;
                const std::string n = notes(c);
                std::printf("   %-28s %-16s sig/rmse %s, cov2 %d/%zu, rel_bias %s%s%s\n",
                            cr.c->label.c_str(), c.method.c_str(),
                            fmt_f(c.sig_rmse, "%.2f").c_str(), c.cov2, c.reps.size(),
                            fmt_f(c.rel_bias, "%+.1e").c_str(), n.empty() ? "" : "; ", n.c_str());
            }
        if (!listed) std::printf("   none\n");
        if (pass == 0) flagged = listed;
    }
    for (const auto& [m, why] : skipped) std::printf("skipped %s: %s\n", m.c_str(), why.c_str());
    const double total = now_seconds() - t_start;
    std::printf("\ntotal wall time %.0f s\n", total);
    emit({{"kind", "summary"},
          {"cases", results.size()},
          {"compared", compared},
          {"mcplay_ahead", ahead},
          {"geomean_eff_ratio_mcplay_over_other", jnum(geomean)},
          {"geomean_ci95", o.ci > 0 ? Json::array({jnum(geo_lo), jnum(geo_hi)}) : Json(nullptr)},
          {"mcplay_ahead_by_sigma", ahead_sig},
          {"overconfident_cells", flagged},
          {"seconds", total}});
    if (json) std::fclose(json);
    return 0;
}
