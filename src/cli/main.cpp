// mcplay command line: argument parsing and file I/O only; all work goes through the C API.
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/boundary.h"
#include "api/files.h"
#include "api/json_read.h"
#include "api/mcplay.h"
#include "cli/cli_support.h"
#include "cli/lab.h"
#include "render/pixel_sampler.h"
#include "render_api/mcplay_render.h"

namespace {

using namespace mcp::cli;

const char* kUsage =
    "mcplay - Monte Carlo estimator playground\n"
    "\n"
    "usage:\n"
    "  mcplay list [--scenes DIR]\n"
    "  mcplay run SCENE [options]\n"
    "  mcplay render SCENE [--estimator NAME] [--spp N] --out FILE [render options]\n"
    "  mcplay render SCENE --progressive --spp N --out-dir DIR [--estimators A,B,..]\n"
    "                [--long-side L | --width W --height H] [render options]\n"
    "  mcplay reference SCENE --out FILE.mcref [--live [--long-side L]] [--width W] [--height H]\n"
    "                [--threads T]\n"
    "  mcplay merge PART.json... [--format F] [--out FILE]\n"
    "  mcplay points SAMPLER --n N [--dim D] [--seed S] [--randomization R] [--out FILE.csv]\n"
    "  mcplay analyze FILE.csv|FILE.json [--format table|json] [--spectrum-out FILE.png]\n"
    "                [--spectrum-size S] [--axes A,B]\n"
    "  mcplay warp-test SCENE [--samples N] [--seed S] [--significance A] [--tests T]\n"
    "                [--format table|json]\n"
    "  mcplay --help | --version\n"
    "\n"
    "SCENE is a scene JSON file, or the name of one in the scenes directory\n"
    "(--scenes DIR, else $MCPLAY_SCENES, else ./scenes), or a .gltf/.glb file (a render\n"
    "scene whose settings come from its extras.mcplay, else the defaults).\n"
    "\n"
    "run options:\n"
    "  --estimators A,B,..  run only these estimators (names from the scene, or presets)\n"
    "  --n-min N            smallest sample count (default from the scene, else 16)\n"
    "  --n-max N            largest sample count (default from the scene, else 65536)\n"
    "  --reps R             independent replicates per N (>= 2; default 32)\n"
    "  --seed S             random seed (default 1); same seed, same numbers\n"
    "  --threads T          worker threads (0 = all cores; results do not depend on T)\n"
    "  --rel-tol X          stop at a requested accuracy instead of the N ladder: double N\n"
    "                       from --n-min until the 95% error bar is within X |estimate|\n"
    "                       (and the run at N/2 agrees), for each of --reps replicates\n"
    "  --abs-tol X          the same with an absolute tolerance (with both: the larger)\n"
    "  --max-seconds S      with a tolerance: give up an estimate after about S seconds\n"
    "                       (--n-max is the other budget)\n"
    "  --format F           table (default), json or csv\n"
    "  --out FILE           write the result to FILE instead of standard output\n"
    "  --quiet              no progress lines on standard error\n"
    "  --part I/K           run only replicates r with r % K == I (1 <= K <= reps), as JSON\n"
    "                       for merge (needs --format json); integrals, stopping runs and\n"
    "                       render studies alike\n"
    "\n"
    "merge PART.json...: the K parts of one study (any order; same scene and settings, each\n"
    "  part once) give the whole study's result, every number as one run gives it but the\n"
    "  timings; printed like run (--format, --out). Parts that do not fit are refused, the\n"
    "  field named. A result that cannot be written (full disk, closed output) exits 1.\n"
    "\n"
    "render scenes (a scene JSON with a \"render\" object and a glTF file):\n"
    "  run studies relative MSE against spp (--n-min/--n-max are spp) against a reference\n"
    "  image, cached in --cache DIR (default $MCPLAY_CACHE, else ~/.cache/mcplay).\n"
    "  --width W, --height H  image size (default from the scene)\n"
    "  --cache DIR | --no-cache  where high-spp references are kept (DIR must be a folder)\n"
    "  --pixel-sampler P    independent, stratified, sobol or padded_sobol: every\n"
    "                       estimator's pixel sampler (run and render; sobol needs a\n"
    "                       power-of-two spp)\n"
    "  render writes one image: --out FILE (.png tone-mapped sRGB, .hdr linear Radiance,\n"
    "  .pfm linear float32),\n"
    "  --error-out FILE (false-colour relative error against the reference, PNG),\n"
    "  --estimator NAME (default the scene's best: MIS with the power heuristic, or path\n"
    "  tracing with MIS for a path scene; or an estimator object as a scene lists them,\n"
    "  '{\"strategy\": \"mis_power\", \"light_samples\": 4}'), --spp N (default the scene's\n"
    "  spp_max),\n"
    "  --seed S, --threads T, --format json (print the result JSON instead of a summary)\n"
    "  render --progressive writes the live view's progression: each estimator (--estimators,\n"
    "  at most 4, or --estimator; default the scene's first four) is rendered in passes to 1,\n"
    "  2, 4, ... N spp (--spp, a power of two), never restarting; at each power of two its\n"
    "  image goes to DIR/<estimator>_<spp>spp.png and .hdr (--out-dir DIR, created if missing)\n"
    "  and one JSON line to standard output: estimator, spp, seconds, relative_mse,\n"
    "  relative_mse_raw, relative_mse_reason (why they are null, else null), width, height,\n"
    "  png, hdr. The size:\n"
    "  --long-side L (16..4096, default 256; the other side from the camera's aspect) or\n"
    "  --width and --height; --pixel-sampler padded_sobol (default) or independent (the\n"
    "  samplers that extend; stratified and sobol depend on the final spp). The reference is\n"
    "  obtained as run obtains it (cache, else rendered, with progress on standard error)\n"
    "  reference renders (or takes from the cache) the scene's reference image alone and\n"
    "  writes it to --out: a study given it (options.reference_data) renders none, if it was\n"
    "  made from the same glTF, name, image size and reference settings (the site ships\n"
    "  its scenes' references this way); --live: the reference of the live view (render\n"
    "  --progressive) at its default size (or --long-side L) and its reference spp\n"
    "\n"
    "sampler lab (docs/sampler-lab.md):\n"
    "  points writes the points a sampler draws as CSV (x1,...,xD header, one point per row):\n"
    "  SAMPLER uniform, stratified, latin_hypercube, sobol, halton or lattice; --dim default 2,\n"
    "  --randomization none gives the deterministic quasi-Monte Carlo points; pixel_independent,\n"
    "  pixel_stratified, pixel_sobol or pixel_padded_sobol: one pixel's --n samples from the\n"
    "  renderer's pixel sampler (--dim 2, 4, 6 or 8: the first 2D requests of each sample)\n"
    "  analyze reads points in [0,1)^d (CSV with an optional header, a column named set\n"
    "  splitting the rows into randomizations; or a JSON array of rows) and prints their\n"
    "  L2-star, centred and wrap-around L2 discrepancies, minimum distances and the radial\n"
    "  power spectrum; --spectrum-out writes the spectrum of columns --axes A,B (counted from 1\n"
    "  as x1, x2, ... are named; default 1,2) as a PNG; the JSON's spectrum.axes count from 0\n"
    "  warp-test tests a scene's \"warp\" (g and p, or a named warp): the density's integral\n"
    "  and a chi-square test of --samples (default 10^6) samples in equal-measure bins; exits 0\n"
    "  whether the warp passes or fails (a failed test is a result)\n"
    "\n"
    "exit codes: 0 ok, 1 runtime error, 2 bad arguments, 3 bad scene\n";

std::string fmt_number(const char* format, double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, x);
    return buf;
}

/// A scene file: a regular file of at most mcp::kMaxSceneFileBytes (never a device or FIFO).
bool read_scene_file(const std::string& path, std::string* out, std::string* error) {
    return mcp::read_regular_file(path, mcp::kMaxSceneFileBytes, out, error);
}

bool path_exists(const std::string& path) {
    struct stat st;
    return ::stat(path.c_str(), &st) == 0;
}

std::string scenes_dir(const std::string& given) {
    if (!given.empty()) return given;
    if (const char* env = std::getenv("MCPLAY_SCENES"); env && *env) return env;
    return "scenes";
}

std::string dirname_of(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

// The reference cache folder: --cache, else $MCPLAY_CACHE, else $HOME/.cache/mcplay (created
// on demand). A folder given (--cache or $MCPLAY_CACHE) that is not one or cannot be made is an
// error naming it; the default one that cannot be made means no cache (*dir = "").
bool cache_dir(const std::string& given, std::string* dir, std::string* error) {
    std::string where = "--cache";
    *dir = given;
    if (dir->empty()) {
        where = "$MCPLAY_CACHE";
        if (const char* env = std::getenv("MCPLAY_CACHE"); env && *env) {
            *dir = env;
        } else if (const char* home = std::getenv("HOME"); home && *home) {
            where.clear();
            *dir = std::string(home) + "/.cache/mcplay";
        } else {
            return true;
        }
    }
    std::string partial, part;
    std::stringstream ss(*dir);
    while (std::getline(ss, part, '/')) {
        if (part.empty()) continue;
        partial += (partial.empty() && (*dir)[0] != '/' ? "" : "/") + part;
        mkdir(partial.c_str(), 0755);
    }
    if (mcp::is_directory(*dir)) return true;
    const std::string why = path_exists(*dir) ? "is not a directory" : "cannot be created";
    if (where.empty()) {
        dir->clear(); // the default folder: no cache
        return true;
    }
    *error = where + ": '" + *dir + "' " + why + " (the reference cache needs a folder)";
    return false;
}

// A .gltf or .glb given directly is a render scene of its own, its study settings in its
// extras.mcplay (or the defaults).
bool scene_from_gltf(const std::string& path, std::string* text) {
    auto ends = [&](const char* s) {
        size_t n = std::strlen(s);
        return path.size() > n && path.compare(path.size() - n, n, s) == 0;
    };
    if (!ends(".gltf") && !ends(".glb")) return false;
    size_t slash = path.find_last_of('/');
    std::string file = slash == std::string::npos ? path : path.substr(slash + 1);
    std::string stem = file.substr(0, file.find_last_of('.'));
    *text = nlohmann::json{{"name", stem}, {"render", {{"gltf", file}}}}.dump();
    return true;
}

bool is_render_scene_text(const std::string& text) {
    // Checked first (nesting, size): a text that fails goes to mcp_study_run, which says why.
    const mcp::Made<mcp::Json> j = mcp::parse_json(text, "scene");
    return j.ok() && j.value.is_object() && j.value.contains("render");
}

std::string base64_decode(const std::string& in) {
    std::string out;
    uint32_t buf = 0;
    int bits = 0;
    for (char c : in) {
        int v = c >= 'A' && c <= 'Z'   ? c - 'A'
                : c >= 'a' && c <= 'z' ? c - 'a' + 26
                : c >= '0' && c <= '9' ? c - '0' + 52
                : c == '+'             ? 62
                : c == '/'             ? 63
                                       : -1;
        if (v < 0) continue;
        buf = (buf << 6) | uint32_t(v);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += char((buf >> bits) & 0xff);
        }
    }
    return out;
}

// Finds a scene (a path, or a name in the scenes directory) and reads it; a .gltf/.glb file
// becomes a render scene of its own. On failure prints why and returns false.
bool load_scene(const std::string& arg, const std::string& dir_arg, std::string* path,
                std::string* text) {
    *path = arg;
    if (!path_exists(arg)) {
        std::string dir = scenes_dir(dir_arg);
        while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
        const std::string named = dir + "/" + arg + ".json";
        if (arg.find('/') != std::string::npos || !path_exists(named)) {
            std::fprintf(stderr, "mcplay: no scene file '%s' (nor a scene named so in '%s')\n",
                         mcp::boundary::one_line(arg).c_str(),
                         mcp::boundary::one_line(dir).c_str());
            return false;
        }
        *path = named;
    }
    std::string error;
    if (mcp::is_directory(*path)) {
        std::fprintf(stderr, "mcplay: '%s' is a directory, not a scene file\n",
                     mcp::boundary::one_line(*path).c_str());
        return false;
    }
    std::string bytes;
    if (!read_scene_file(*path, &bytes, &error)) {
        std::fprintf(stderr, "mcplay: %s\n", mcp::boundary::one_line(error).c_str());
        return false;
    }
    if (!scene_from_gltf(*path, text)) *text = bytes;
    return true;
}

// An output file must be writable before a long run starts: opened for appending (created
// if missing, and removed again if the run then fails).
struct OutputFile {
    std::string path;
    bool created = false;
    bool check(std::string* error) {
        if (path.empty()) return true;
        if (mcp::is_directory(path)) {
            *error = "'" + path + "' is a directory";
            return false;
        }
        created = !path_exists(path);
        FILE* f = std::fopen(path.c_str(), "ab");
        if (!f) {
            *error = "cannot write '" + path + "': " + std::strerror(errno);
            created = false;
            return false;
        }
        std::fclose(f);
        return true;
    }
    void discard() {
        if (created) std::remove(path.c_str());
    }
};

/// --pixel-sampler's value: one of the render API's pixel samplers (the API checks it again).
bool pixel_sampler_option(const std::string& v, nlohmann::json* options, std::string* error) {
    mcp::PixelSamplerKind kind;
    if (mcp::parse_pixel_sampler(v, &kind)) {
        (*options)["pixel_sampler"] = v;
        return true;
    }
    std::string known;
    for (const std::string& k : mcp::pixel_sampler_names())
        known += (known.empty() ? "" : ", ") + k;
    *error = "--pixel-sampler: unknown pixel sampler '" + v + "' (known: " + known + ")";
    return false;
}

/// --estimators A,B,..: options.estimators, the names in order (`refuse_repeats`: a name given
/// twice is an error). Returns -1 when the list is good, else the exit code of the usage error.
int estimator_list(const std::string& v, bool refuse_repeats, nlohmann::json* options) {
    nlohmann::json list = nlohmann::json::array();
    std::stringstream ss(v);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty()) return usage_error("--estimators: empty name in '" + v + "'");
        if (refuse_repeats)
            for (const auto& seen : list)
                if (seen == item) return usage_error("--estimators: '" + item + "' is named twice");
        list.push_back(item);
    }
    if (list.empty()) return usage_error("--estimators needs at least one name");
    (*options)["estimators"] = list;
    return -1;
}

int cmd_list(const std::vector<std::string>& args) {
    std::string dir_arg;
    for (size_t i = 0; i < args.size(); ++i) {
        if (args[i] == "--scenes") {
            if (i + 1 >= args.size()) return usage_error("--scenes needs a directory");
            dir_arg = args[++i];
        } else {
            return usage_error("list: unexpected argument '" + args[i] + "'");
        }
    }
    const std::string dir = scenes_dir(dir_arg);
    std::vector<std::string> files;
    if (DIR* d = opendir(dir.c_str())) {
        while (dirent* e = readdir(d)) {
            std::string name = e->d_name;
            if (name.size() > 5 && name.compare(name.size() - 5, 5, ".json") == 0)
                files.push_back(name);
        }
        closedir(d);
    } else {
        std::fprintf(stderr, "mcplay: cannot open scenes directory '%s': %s\n", dir.c_str(),
                     std::strerror(errno));
        return kExitUsage;
    }
    std::sort(files.begin(), files.end());
    std::printf("scenes in %s:\n", dir.c_str());
    for (const std::string& f : files) {
        std::string text, error, path = dir + "/" + f;
        char* info = nullptr;
        if (!read_scene_file(path, &text, &error)) {
            std::printf("  %-28s UNREADABLE: %s\n", f.c_str(), error.c_str());
            continue;
        }
        if (is_render_scene_text(text)) {
            nlohmann::json o{{"base_dir", dir}};
            if (mcp_render_scene_info(text.c_str(), o.dump().c_str(), &info) != MCP_OK) {
                std::printf("  %-28s INVALID: %s\n", f.c_str(), mcp_last_error());
                continue;
            }
            nlohmann::json j = mcp::cli::api_json(info);
            mcp_free(info);
            if (!j.is_object()) return kExitRuntime;
            std::string ests;
            for (auto& e : j["estimators"])
                ests += (ests.empty() ? "" : ", ") + e["name"].get<std::string>();
            std::printf("  %-28s render, %d triangles, %d light triangle(s)\n  %-28s %s\n"
                        "  %-28s estimators: %s\n",
                        f.substr(0, f.size() - 5).c_str(), j["triangles"].get<int>(),
                        j["lights"].get<int>(), "", j["description"].get<std::string>().c_str(), "",
                        ests.c_str());
            continue;
        }
        if (mcp_scene_info(text.c_str(), &info) != MCP_OK) {
            std::printf("  %-28s INVALID: %s\n", f.c_str(), mcp_last_error());
            continue;
        }
        nlohmann::json j = mcp::cli::api_json(info);
        mcp_free(info);
        if (!j.is_object()) return kExitRuntime;
        std::string exact = j["exact"].is_number() ? j["exact"].dump() : "unknown";
        std::string ests;
        for (auto& e : j["estimators"]) ests += (ests.empty() ? "" : ", ") + e.get<std::string>();
        std::printf("  %-28s %s, %dD, exact %s\n  %-28s %s\n  %-28s estimators: %s\n",
                    f.substr(0, f.size() - 5).c_str(), j["domain"].get<std::string>().c_str(),
                    j["dimension"].get<int>(), exact.c_str(), "",
                    j["description"].get<std::string>().c_str(), "", ests.c_str());
    }
    char* catalog = nullptr;
    if (mcp_catalog(&catalog) == MCP_OK) {
        nlohmann::json c = mcp::cli::api_json(catalog);
        mcp_free(catalog);
        if (!c.is_object()) return kExitRuntime;
        std::printf("\nestimator presets:\n");
        for (auto& p : c["estimators"])
            std::printf("  %-24s %s%s\n", p["name"].get<std::string>().c_str(),
                        p["summary"].get<std::string>().c_str(),
                        p["needs_pdf"].get<bool>() ? " (needs a pdf in the scene)" : "");
        auto names = [](const nlohmann::json& a) {
            std::string s;
            for (auto& x : a) s += (s.empty() ? "" : ", ") + x.get<std::string>();
            return s;
        };
        std::printf("samplers:   %s\npdfs:       %s\nintegrands: %s\ndomains:    %s\n",
                    names(c["samplers"]).c_str(), names(c["pdfs"]).c_str(),
                    names(c["integrands"]).c_str(), names(c["domains"]).c_str());
    }
    return kExitOk;
}

int progress_line(const char* level_json, void*) {
    nlohmann::json j = mcp::cli::api_json(level_json);
    if (!j.is_object()) return 0;
    if (j["kind"] == "render_reference") {
        // A reference being rendered: one line per tenth of its rows (rows finish out of order
        // on several threads, so rows_done may step over a tenth).
        static int last_tenth = 0;
        const int done = j["rows_done"].get<int>(), rows = std::max(1, j["rows"].get<int>());
        const int tenth = (10 * done) / rows;
        if (done <= 1) last_tenth = 0;
        if (tenth > last_tenth) {
            last_tenth = tenth;
            std::fprintf(stderr, "mcplay: reference %d%% rendered\n", 10 * tenth);
        }
        return 0;
    }
    std::fprintf(stderr, "mcplay: N = %s done\n", j["n"].dump().c_str());
    return 0;
}

/// Says up front when a study is predicted to take long (mcp_study_plan and
/// mcp_render_study_plan time a short pilot); a study that cannot be planned is left to the
/// run itself, which reports why.
void announce_long_study(const std::string& scene, const std::string& options, bool render) {
    char* plan = nullptr;
    const int status = render ? mcp_render_study_plan(scene.c_str(), options.c_str(), &plan)
                              : mcp_study_plan(scene.c_str(), options.c_str(), &plan);
    if (status != MCP_OK) return;
    nlohmann::json p = mcp::cli::api_json(plan);
    mcp_free(plan);
    if (p.is_discarded() || !p["predicted_seconds"].is_number()) return;
    double seconds = p["predicted_seconds"].get<double>();
    // A stopping study (rel_tol or abs_tol, from the options or the scene) runs its estimates
    // one at a time on one thread, and the plan's evaluations are its budget (every run to
    // n_max): the prediction is the plan's single-thread seconds, an upper bound.
    bool stopping = false;
    for (const std::string* text : {&options, &scene}) {
        const mcp::Made<mcp::Json> made = mcp::parse_json(*text, "scene");
        const nlohmann::json& j = made.value;
        for (const char* key : {"rel_tol", "abs_tol"})
            stopping = stopping || (j.is_object() && j.contains(key) && j[key].is_number() &&
                                    j[key].get<double>() > 0.0);
    }
    if (stopping && !render)
        seconds *= std::max(1, p["threads"].is_number_integer() ? p["threads"].get<int>() : 1);
    if (seconds < 10.0) return;
    const std::string when = seconds < 120.0    ? fmt_number("%.0f s", seconds)
                             : seconds < 7200.0 ? fmt_number("%.0f min", seconds / 60.0)
                                                : fmt_number("%.1f hours", seconds / 3600.0);
    const char* unit = render ? "samples" : "integrand evaluations";
    const nlohmann::json& count = render ? p["samples"] : p["evaluations"];
    if (stopping && !render) {
        std::fprintf(stderr,
                     "mcplay: this stopping study may take up to about %s (at most %s %s on 1 "
                     "thread, if no run meets the tolerance before n_max); Ctrl-C stops it\n",
                     when.c_str(), fmt_number("%.4g", count.get<double>()).c_str(), unit);
        return;
    }
    std::fprintf(stderr,
                 "mcplay: this study is predicted to take about %s (%s %s on %s thread(s)); "
                 "Ctrl-C stops it\n",
                 when.c_str(), fmt_number("%.4g", count.get<double>()).c_str(), unit,
                 p["threads"].dump().c_str());
}

int cmd_run(const std::vector<std::string>& args) {
    std::string scene_arg, format = "table", out_path, dir_arg, cache_arg, part_arg;
    bool quiet = false, no_cache = false;
    nlohmann::json options = nlohmann::json::object();
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&](std::string* v) {
            if (i + 1 >= args.size() || args[i + 1].rfind("--", 0) == 0) return false;
            *v = args[++i];
            return true;
        };
        std::string v;
        if (a == "--estimators") {
            if (!value(&v))
                return usage_error("--estimators needs a comma-separated list of names");
            if (int rc = estimator_list(v, false, &options); rc >= 0) return rc;
        } else if (a == "--n-min" || a == "--n-max" || a == "--reps" || a == "--seed" ||
                   a == "--threads") {
            if (!value(&v)) return usage_error(a + " needs a value");
            unsigned long long x = 0;
            if (!parse_count(v, &x))
                return usage_error(a + ": expected a whole number >= 0, got '" + v + "'");
            std::string key = a.substr(2);
            std::replace(key.begin(), key.end(), '-', '_');
            options[key] = x;
        } else if (a == "--rel-tol" || a == "--abs-tol" || a == "--max-seconds") {
            if (!value(&v)) return usage_error(a + " needs a value");
            char* end = nullptr;
            const double x = std::strtod(v.c_str(), &end);
            if (v.empty() || *end != '\0' || !std::isfinite(x) || x <= 0.0)
                return usage_error(a + ": expected a number > 0, got '" + v + "'");
            std::string key = a.substr(2);
            std::replace(key.begin(), key.end(), '-', '_');
            options[key] = x;
        } else if (a == "--width" || a == "--height") {
            if (!value(&v)) return usage_error(a + " needs a value");
            unsigned long long x = 0;
            if (!parse_count(v, &x))
                return usage_error(a + ": expected a whole number, got '" + v + "'");
            options[a.substr(2)] = x;
        } else if (a == "--cache") {
            if (!value(&cache_arg)) return usage_error("--cache needs a directory");
        } else if (a == "--no-cache") {
            no_cache = true;
        } else if (a == "--pixel-sampler") {
            if (!value(&v))
                return usage_error(
                    "--pixel-sampler needs independent, stratified, sobol or padded_sobol");
            std::string why;
            if (!pixel_sampler_option(v, &options, &why)) return usage_error(why);
        } else if (a == "--part") {
            const size_t slash = value(&v) ? v.find('/') : std::string::npos;
            unsigned long long part = 0, parts = 0;
            if (slash == std::string::npos || !parse_count(v.substr(0, slash), &part) ||
                !parse_count(v.substr(slash + 1), &parts))
                return usage_error("--part: expected I/K with whole numbers, e.g. 0/4");
            options["part"] = part;
            options["parts"] = parts;
            part_arg = v;
        } else if (a == "--format") {
            if (!value(&v)) return usage_error("--format needs table, json or csv");
            if (v != "table" && v != "json" && v != "csv")
                return usage_error("--format: expected table, json or csv, got '" + v + "'");
            format = v;
        } else if (a == "--out") {
            if (!value(&v)) return usage_error("--out needs a file name");
            out_path = v;
        } else if (a == "--scenes") {
            if (!value(&v)) return usage_error("--scenes needs a directory");
            dir_arg = v;
        } else if (a == "--quiet") {
            quiet = true;
        } else if (a.rfind("-", 0) == 0) {
            return usage_error("unknown option '" + a + "'");
        } else if (scene_arg.empty()) {
            scene_arg = a;
        } else {
            return usage_error("run takes one scene, got '" + scene_arg + "' and '" + a + "'");
        }
    }
    if (scene_arg.empty()) return usage_error("run needs a scene file or name");

    std::string path, text, error;
    if (!load_scene(scene_arg, dir_arg, &path, &text)) return kExitScene;
    const bool render_scene = is_render_scene_text(text);
    if (!render_scene && (options.contains("width") || options.contains("height") ||
                          options.contains("pixel_sampler") || !cache_arg.empty()))
        return usage_error("--width, --height, --cache and --pixel-sampler are for render scenes");
    if (options.contains("part") && format != "json")
        return usage_error("--part needs --format json (its output is the input of merge)");
    OutputFile out_file{out_path};
    if (!out_file.check(&error)) return usage_error("--out: " + error);

    const bool show_progress = !quiet && isatty(fileno(stderr));
    char* result = nullptr;
    int status;
    if (render_scene) {
        // Render studies: N is samples per pixel.
        for (const char* k : {"n_min", "n_max"})
            if (options.contains(k)) {
                options[std::string("spp_") + (k + 2)] = options[k];
                options.erase(k);
            }
        options["base_dir"] = dirname_of(path);
        if (!no_cache) {
            std::string dir;
            if (!cache_dir(cache_arg, &dir, &error)) {
                out_file.discard();
                return usage_error(error);
            }
            if (!dir.empty()) options["cache_dir"] = dir;
        }
        const std::string opts = options.dump();
        if (!quiet) announce_long_study(text, opts, true);
        status = mcp_render_study_run(text.c_str(), opts.c_str(),
                                      show_progress ? progress_line : nullptr, nullptr, &result);
    } else {
        const std::string opts = options.dump();
        if (!quiet) announce_long_study(text, opts, false);
        status = mcp_study_run(text.c_str(), opts.c_str(), show_progress ? progress_line : nullptr,
                               nullptr, &result);
    }
    if (status != MCP_OK && status != MCP_ERROR_CANCELLED) {
        // The limits of --part I/K named as the flag typed, not as the options it sets.
        std::string why =
            flag_named(mcp_last_error(), "options.parts", "--part " + part_arg + " (K)");
        why = flag_named(why, "options.part", "--part " + part_arg + " (I)");
        if (why.compare(0, 7, "--part ") == 0 && why.find("0..parts - 1") != std::string::npos)
            why.replace(why.find("0..parts - 1"), 12, "0..K - 1");
        std::fprintf(stderr, "mcplay: %s: %s\n", mcp::boundary::one_line(path).c_str(),
                     mcp::boundary::one_line(why).c_str());
        out_file.discard();
        return exit_code(status);
    }
    char* formatted = nullptr;
    if (mcp_result_format(result, format.c_str(), &formatted) != MCP_OK) {
        std::fprintf(stderr, "mcplay: %s\n", mcp_last_error());
        mcp_free(result);
        out_file.discard();
        return kExitRuntime;
    }
    mcp_free(result);
    const int rc = write_output(out_path, formatted);
    mcp_free(formatted);
    return status == MCP_ERROR_CANCELLED ? kExitRuntime : rc;
}

/// What `render` and `reference` are told: the scene, the files and the options the C API gets.
struct ImageCommand {
    std::string scene_arg, out_path, error_path, out_dir, dir_arg, cache_arg, format;
    bool no_cache = false, quiet = false, progressive = false, live = false;
    nlohmann::json options = nlohmann::json::object();
};

/// Parses the arguments of `command` (render or reference): `counts` are its whole-number
/// options (--spp, --width, ...), `render_only` adds --estimator, --estimators,
/// --pixel-sampler, --error-out, --progressive and --out-dir; `reference` takes --live.
/// Returns -1 when the arguments are good, else the exit code of the usage error.
int parse_image_command(const char* command, const std::vector<std::string>& args,
                        const std::vector<std::string>& counts, bool render_only, ImageCommand* c) {
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        std::string v;
        auto value = [&](std::string* out) {
            if (i + 1 >= args.size() || args[i + 1].rfind("--", 0) == 0) return false;
            *out = args[++i];
            return true;
        };
        if (std::find(counts.begin(), counts.end(), a) != counts.end()) {
            if (!value(&v)) return usage_error(a + " needs a value");
            unsigned long long x = 0;
            if (!parse_count(v, &x))
                return usage_error(a + ": expected a whole number, got '" + v + "'");
            std::string key = a.substr(2);
            std::replace(key.begin(), key.end(), '-', '_');
            c->options[key] = x;
        } else if (render_only && a == "--estimator") {
            if (!value(&v)) return usage_error("--estimator needs a name");
            c->options["estimator"] = v;
            if (!v.empty() && v[0] == '{') { // an estimator object, as a scene lists them
                c->options["estimator"] = nlohmann::json::parse(v, nullptr, false);
                if (c->options["estimator"].is_discarded())
                    return usage_error("--estimator: '" + v + "' is not valid JSON");
            }
        } else if (render_only && a == "--estimators") {
            if (!value(&v))
                return usage_error("--estimators needs a comma-separated list of names");
            if (int rc = estimator_list(v, true, &c->options); rc >= 0) return rc;
        } else if (render_only && a == "--progressive") {
            c->progressive = true;
        } else if (render_only && a == "--out-dir") {
            if (!value(&c->out_dir)) return usage_error("--out-dir needs a directory");
        } else if (!render_only && a == "--live") {
            c->live = true;
        } else if (render_only && a == "--pixel-sampler") {
            if (!value(&v))
                return usage_error(
                    "--pixel-sampler needs independent, stratified, sobol or padded_sobol");
            std::string why;
            if (!pixel_sampler_option(v, &c->options, &why)) return usage_error(why);
        } else if (render_only && a == "--error-out") {
            if (!value(&c->error_path)) return usage_error("--error-out needs a file name");
        } else if (a == "--out") {
            if (!value(&c->out_path)) return usage_error("--out needs a file name");
        } else if (a == "--scenes") {
            if (!value(&c->dir_arg)) return usage_error("--scenes needs a directory");
        } else if (a == "--cache") {
            if (!value(&c->cache_arg)) return usage_error("--cache needs a directory");
        } else if (a == "--no-cache") {
            c->no_cache = true;
        } else if (a == "--quiet") {
            c->quiet = true;
        } else if (a == "--format") {
            if (!value(&c->format) || (c->format != "json" && c->format != "summary"))
                return usage_error("--format: expected json or summary");
        } else if (a.rfind("-", 0) == 0) {
            return usage_error("unknown option '" + a + "'");
        } else if (c->scene_arg.empty()) {
            c->scene_arg = a;
        } else {
            return usage_error(std::string(command) + " takes one scene, got '" + c->scene_arg +
                               "' and '" + a + "'");
        }
    }
    if (c->scene_arg.empty())
        return usage_error(std::string(command) + " needs a scene file or name");
    return -1;
}

/// A live session of the render C API, closed when it goes out of scope.
struct LiveSession {
    int id = 0;
    ~LiveSession() {
        if (id > 0) mcp_render_live_close(id);
    }
};

/// A file name's part for an estimator name: letters, digits, '-', '_' and '.' kept, the rest '_'.
std::string file_stem(const std::string& name) {
    std::string out;
    for (char ch : name)
        out += std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.'
                   ? ch
                   : '_';
    return out.empty() || out[0] == '.' ? "estimator" + out : out;
}

/// --long-side (the live view's image size): 16..4096, not with --width or --height. Returns -1
/// when it is good or absent, else the exit code of the usage error.
int check_long_side(const nlohmann::json& options) {
    if (!options.contains("long_side")) return -1;
    const unsigned long long side = options["long_side"].get<unsigned long long>();
    if (side < 16 || side > 4096)
        return usage_error("--long-side: expected 16 to 4096 pixels, got " + std::to_string(side));
    if (options.contains("width") || options.contains("height"))
        return usage_error("--long-side or --width and --height: give one of them");
    return -1;
}

/// The largest spp a progressive pass takes (mcp_render_live_pass's limit).
constexpr unsigned long long kMaxLiveSpp = 1ull << 20;

/// Why a live pass's relative MSE is null, from its error sums and the session's reference.
std::string null_error_reason(const nlohmann::json& error, const nlohmann::json& reference) {
    if (!error.is_object() || !reference.is_object()) return "no reference image to compare with";
    if (!(error["terms"].is_number() && error["terms"].get<double>() > 0))
        return "no pixel of the reference to compare with";
    if (!(reference["mean_luminance"].is_number() && reference["mean_luminance"].get<double>() > 0))
        return "the reference is black: a relative error has no scale";
    return "the error is not finite: the image holds non-finite or overflowing pixels";
}

/// `mcplay render SCENE --progressive --spp N --out-dir DIR`: the live view's progression.
/// Each estimator's image is taken pass by pass to 1, 2, 4, ..., N spp (the estimators in turn,
/// so that a run stopped early leaves them all at one spp); at each power of two its PNG and HDR
/// go to DIR/<estimator>_<spp>spp.png|.hdr and one JSON line to standard output.
int cmd_render_progressive(ImageCommand& c) {
    nlohmann::json& options = c.options;
    if (c.out_dir.empty()) return usage_error("--progressive needs --out-dir DIR");
    if (!c.out_path.empty() || !c.error_path.empty())
        return usage_error(
            "--out and --error-out write one image; --progressive writes its images to --out-dir");
    if (!c.format.empty())
        return usage_error("--format: --progressive prints one JSON line per image");
    if (!options.contains("spp"))
        return usage_error("--progressive needs --spp N, a power of two (the last pass)");
    const unsigned long long spp = options["spp"].get<unsigned long long>();
    if (spp == 0 || (spp & (spp - 1)) != 0) {
        unsigned long long below = 1;
        while (below * 2 <= spp) below *= 2;
        return usage_error("--spp: --progressive needs a power of two, got " + std::to_string(spp) +
                           (spp == 0 ? std::string(" (the nearest is 1)")
                                     : " (the nearest are " + std::to_string(below) + " and " +
                                           std::to_string(below * 2) + ")"));
    }
    if (spp > kMaxLiveSpp)
        return usage_error("--spp: --progressive takes at most " + std::to_string(kMaxLiveSpp) +
                           ", got " + std::to_string(spp));
    options.erase("spp");
    if (options.contains("estimator") && options.contains("estimators"))
        return usage_error("--estimator and --estimators: give one of them");
    if (options.contains("estimator")) {
        options["estimators"] = nlohmann::json::array({options["estimator"]});
        options.erase("estimator");
    }
    if (options.contains("estimators") && options["estimators"].size() > 4)
        return usage_error("--estimators: at most 4 side by side, got " +
                           std::to_string(options["estimators"].size()));
    if (int rc = check_long_side(options); rc >= 0) return rc;
    if (options.contains("width") != options.contains("height"))
        return usage_error(
            "--progressive takes --width and --height together (or --long-side alone)");

    std::string path, text;
    if (!load_scene(c.scene_arg, c.dir_arg, &path, &text)) return kExitScene;
    if (!is_render_scene_text(text))
        return usage_error("--progressive is for render scenes; '" + c.scene_arg +
                           "' is an integral");
    std::string dir = c.out_dir;
    while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
    // Created up front (a long reference render must not end in "cannot create"), and removed
    // again when the session cannot be opened.
    struct CreatedDir {
        std::string path;
        ~CreatedDir() {
            if (!path.empty()) ::rmdir(path.c_str()); // only when still empty
        }
    } created;
    if (path_exists(dir)) {
        if (!mcp::is_directory(dir))
            return usage_error("--out-dir: '" + dir + "' exists and is not a directory");
    } else if (::mkdir(dir.c_str(), 0755) != 0) {
        return usage_error("--out-dir: cannot create '" + dir + "': " + std::strerror(errno));
    } else {
        created.path = dir;
    }

    options["base_dir"] = dirname_of(path);
    if (!c.no_cache) {
        std::string cache, why;
        if (!cache_dir(c.cache_arg, &cache, &why)) return usage_error(why);
        if (!cache.empty()) options["cache_dir"] = cache;
    }
    options["live_reference"] = "obtain";
    char* result = nullptr;
    int status = mcp_render_live_open(text.c_str(), options.dump().c_str(),
                                      c.quiet ? nullptr : progress_line, nullptr, &result);
    if (status != MCP_OK) {
        std::fprintf(stderr, "mcplay: %s: %s\n", mcp::boundary::one_line(path).c_str(),
                     mcp_last_error());
        return exit_code(status);
    }
    nlohmann::json open = mcp::cli::api_json(result);
    mcp_free(result);
    if (open.is_discarded() || !open["session"].is_number_integer()) return kExitRuntime;
    LiveSession session{open["session"].get<int>()};
    created.path.clear();
    const int width = open["width"].get<int>(), height = open["height"].get<int>();
    if (!c.quiet)
        for (const auto& w : open["warnings"])
            if (w.is_object() && w["message"].is_string())
                std::fprintf(stderr, "mcplay: WARNING: %s\n",
                             mcp::boundary::one_line(w["message"].get<std::string>()).c_str());

    // Each estimator's name, and the stem of its files (made unique).
    std::vector<std::string> names, stems;
    for (const auto& e : open["estimators"]) {
        const std::string name = e.is_object() && e["name"].is_string()
                                     ? e["name"].get<std::string>()
                                     : "estimator" + std::to_string(names.size());
        std::string stem = file_stem(name);
        if (std::find(stems.begin(), stems.end(), stem) != stems.end())
            stem += "_" + std::to_string(names.size());
        names.push_back(name);
        stems.push_back(stem);
    }
    for (unsigned long long s = 1; s <= spp; s *= 2) {
        for (size_t i = 0; i < names.size(); ++i) {
            const nlohmann::json pass = {
                {"estimator", i}, {"spp", s}, {"outputs", nlohmann::json::array({"png", "hdr"})}};
            status =
                mcp_render_live_pass(session.id, pass.dump().c_str(), nullptr, nullptr, &result);
            if (status != MCP_OK) {
                std::fprintf(stderr, "mcplay: %s: %s at %llu spp: %s\n",
                             mcp::boundary::one_line(path).c_str(),
                             mcp::boundary::one_line(names[i]).c_str(), s, mcp_last_error());
                return exit_code(status);
            }
            nlohmann::json r = mcp::cli::api_json(result);
            mcp_free(result);
            if (r.is_discarded() || !r["images"].is_object()) return kExitRuntime;
            const std::string base = dir + "/" + stems[i] + "_" + std::to_string(s) + "spp";
            for (const char* kind : {"png", "hdr"}) {
                const std::string file = base + "." + kind;
                if (!r["images"][kind].is_string() ||
                    !write_file(file, base64_decode(r["images"][kind].get<std::string>()))) {
                    std::fprintf(stderr, "mcplay: cannot write '%s'\n",
                                 mcp::boundary::one_line(file).c_str());
                    return kExitRuntime;
                }
            }
            nlohmann::ordered_json line = {{"estimator", names[i]},
                                           {"spp", s},
                                           {"seconds", r["seconds"]},
                                           {"relative_mse", nullptr},
                                           {"relative_mse_raw", nullptr},
                                           {"relative_mse_reason", nullptr},
                                           {"width", width},
                                           {"height", height},
                                           {"png", base + ".png"},
                                           {"hdr", base + ".hdr"}};
            const nlohmann::json& error = r["error"];
            if (error.is_object() && error["terms"].is_number() &&
                error["terms"].get<double>() > 0) {
                const double terms = error["terms"].get<double>();
                for (const auto& [key, field] :
                     {std::pair<const char*, const char*>{"sum", "relative_mse"},
                      {"sum_raw", "relative_mse_raw"}})
                    if (error[key].is_number() && std::isfinite(error[key].get<double>()))
                        line[field] = error[key].get<double>() / terms;
            }
            // A null relative MSE says why (render_study.cpp, band_error_sums).
            if (line["relative_mse"].is_null())
                line["relative_mse_reason"] = null_error_reason(error, open["reference"]);
            std::printf("%s\n", line.dump().c_str());
            std::fflush(stdout);
        }
    }
    return kExitOk;
}

int cmd_render(const std::vector<std::string>& args) {
    ImageCommand c;
    if (int rc = parse_image_command(
            "render", args, {"--spp", "--width", "--height", "--seed", "--threads", "--long-side"},
            true, &c);
        rc >= 0)
        return rc;
    if (c.progressive) return cmd_render_progressive(c);
    if (!c.out_dir.empty() || c.options.contains("estimators") || c.options.contains("long_side"))
        return usage_error("--out-dir, --estimators and --long-side are for --progressive");
    // --quiet is accepted as for run: a single render prints no progress lines anyway
    const std::string &scene_arg = c.scene_arg, &out_path = c.out_path, &error_path = c.error_path,
                      &dir_arg = c.dir_arg, &cache_arg = c.cache_arg, &format = c.format;
    const bool no_cache = c.no_cache;
    nlohmann::json& options = c.options;
    if (out_path.empty() && error_path.empty() && format != "json")
        return usage_error("render needs --out FILE (.png or .hdr) or --error-out FILE");
    auto ends_with = [](const std::string& s, const char* suffix) {
        size_t n = std::strlen(suffix);
        return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
    };
    nlohmann::json outputs = nlohmann::json::array();
    if (!out_path.empty()) {
        if (ends_with(out_path, ".png"))
            outputs.push_back("png");
        else if (ends_with(out_path, ".hdr"))
            outputs.push_back("hdr");
        else if (ends_with(out_path, ".pfm"))
            outputs.push_back("pfm");
        else
            return usage_error("--out: the file name must end in .png, .hdr or .pfm");
    }
    if (!error_path.empty()) {
        if (!ends_with(error_path, ".png")) return usage_error("--error-out: must be a .png file");
        outputs.push_back("error_png");
    }
    options["outputs"] = outputs;
    std::string path, text, error;
    if (!load_scene(scene_arg, dir_arg, &path, &text)) return kExitScene;
    OutputFile out_file{out_path}, error_file{error_path};
    if (!out_file.check(&error)) return usage_error("--out: " + error);
    if (!error_file.check(&error)) {
        out_file.discard();
        return usage_error("--error-out: " + error);
    }
    options["base_dir"] = dirname_of(path);
    if (!no_cache) {
        std::string dir;
        if (!cache_dir(cache_arg, &dir, &error)) {
            out_file.discard();
            error_file.discard();
            return usage_error(error);
        }
        if (!dir.empty()) options["cache_dir"] = dir;
    }
    char* result = nullptr;
    int status = mcp_render_image(text.c_str(), options.dump().c_str(), &result);
    if (status != MCP_OK) {
        std::fprintf(stderr, "mcplay: %s: %s\n", mcp::boundary::one_line(path).c_str(),
                     mcp_last_error());
        out_file.discard();
        error_file.discard();
        return exit_code(status);
    }
    nlohmann::json j = mcp::cli::api_json(result);
    mcp_free(result);
    if (!j.is_object()) return kExitRuntime;
    const nlohmann::json& images = j["images"];
    if (!out_path.empty()) {
        const char* key = ends_with(out_path, ".png")   ? "png"
                          : ends_with(out_path, ".hdr") ? "hdr"
                                                        : "pfm";
        if (!write_file(out_path, base64_decode(images[key].get<std::string>()))) {
            std::fprintf(stderr, "mcplay: cannot write '%s'\n", out_path.c_str());
            return kExitRuntime;
        }
    }
    if (!error_path.empty() &&
        !write_file(error_path, base64_decode(images["error_png"].get<std::string>()))) {
        std::fprintf(stderr, "mcplay: cannot write '%s'\n", error_path.c_str());
        return kExitRuntime;
    }
    if (format == "json") {
        j.erase("images");
        std::printf("%s\n", j.dump(2).c_str());
        return kExitOk;
    }
    std::printf("%s: %s at %s spp, %dx%d, %.3f s, %.3g rays/s\n",
                j["scene"]["name"].get<std::string>().c_str(),
                j["estimator"]["name"].get<std::string>().c_str(), j["spp"].dump().c_str(),
                j["scene"]["width"].get<int>(), j["scene"]["height"].get<int>(),
                j["seconds"].is_number() ? j["seconds"].get<double>() : 0.0,
                j["rays_per_second"].is_number() ? j["rays_per_second"].get<double>() : 0.0);
    if (j.contains("relative_mse"))
        std::printf("relative MSE against the reference: %s, pixel 95%% coverage %s\n",
                    j["relative_mse"].dump().c_str(), j["pixel_coverage95"].dump().c_str());
    const auto& d = j["diagnostics"];
    std::printf("samples %s, discarded (NaN/Inf) %s, rays %s\n", d["samples"].dump().c_str(),
                d["discarded_nonfinite"].dump().c_str(), d["rays"].dump().c_str());
    for (const auto& w : j["warnings"])
        std::printf("WARNING: %s\n", w["message"].get<std::string>().c_str());
    for (const auto& w : j["scene"]["warnings"])
        std::printf("NOTE: %s\n", w["message"].get<std::string>().c_str());
    return kExitOk;
}

int cmd_reference(const std::vector<std::string>& args) {
    ImageCommand c;
    if (int rc = parse_image_command(
            "reference", args, {"--width", "--height", "--threads", "--long-side"}, false, &c);
        rc >= 0)
        return rc;
    const std::string &scene_arg = c.scene_arg, &out_path = c.out_path, &dir_arg = c.dir_arg,
                      &cache_arg = c.cache_arg, &format = c.format;
    const bool no_cache = c.no_cache, quiet = c.quiet;
    nlohmann::json& options = c.options;
    if (out_path.empty()) return usage_error("reference needs --out FILE.mcref");
    // --live: the live view's reference (its default size and reference spp)
    if (c.live) options["live"] = true;
    if (options.contains("long_side") && !c.live)
        return usage_error("--long-side sizes the live view's reference: it needs --live");
    if (int rc = check_long_side(options); rc >= 0) return rc;
    std::string path, text, error;
    if (!load_scene(scene_arg, dir_arg, &path, &text)) return kExitScene;
    if (!is_render_scene_text(text))
        return usage_error("reference is for render scenes; '" + scene_arg + "' is an integral");
    OutputFile out_file{out_path};
    if (!out_file.check(&error)) return usage_error("--out: " + error);
    options["base_dir"] = dirname_of(path);
    if (!no_cache) {
        std::string dir;
        if (!cache_dir(cache_arg, &dir, &error)) {
            out_file.discard();
            return usage_error(error);
        }
        if (!dir.empty()) options["cache_dir"] = dir;
    }
    const bool show_progress = !quiet && isatty(fileno(stderr));
    char* result = nullptr;
    int status = mcp_render_reference(text.c_str(), options.dump().c_str(),
                                      show_progress ? progress_line : nullptr, nullptr, &result);
    if (status != MCP_OK) {
        std::fprintf(stderr, "mcplay: %s: %s\n", mcp::boundary::one_line(path).c_str(),
                     mcp_last_error());
        out_file.discard();
        return exit_code(status);
    }
    nlohmann::json j = mcp::cli::api_json(result);
    mcp_free(result);
    if (!j.is_object()) return kExitRuntime;
    if (!write_file(out_path, base64_decode(j["reference_data"].get<std::string>()))) {
        std::fprintf(stderr, "mcplay: cannot write '%s'\n", out_path.c_str());
        return kExitRuntime;
    }
    j.erase("reference_data");
    if (format == "json") {
        std::printf("%s\n", j.dump(2).c_str());
        return kExitOk;
    }
    std::printf("%s: reference %dx%d at %s spp (%s, %s), mean luminance %s\n",
                j["scene"].get<std::string>().c_str(), j["width"].get<int>(),
                j["height"].get<int>(), j["spp"].dump().c_str(),
                j["estimator"]["strategy"].get<std::string>().c_str(),
                j["source"].get<std::string>().c_str(), j["mean_luminance"].dump().c_str());
    return kExitOk;
}

/// `mcplay merge PART.json...`: the parts of a render study run with --part, merged by the C API
/// (mcp_render_study_merge) and printed as `run` prints a study.
int cmd_merge(const std::vector<std::string>& args) {
    std::string format = "table", out_path;
    std::vector<std::string> files;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--format" || a == "--out") {
            if (i + 1 >= args.size()) return usage_error(a + " needs a value");
            const std::string& v = args[++i];
            if (a == "--out") {
                out_path = v;
            } else if (v != "table" && v != "json" && v != "csv") {
                return usage_error("--format: expected table, json or csv, got '" + v + "'");
            } else {
                format = v;
            }
        } else if (a == "--quiet") {
            // nothing to report while merging
        } else if (a.rfind("-", 0) == 0) {
            return usage_error("unknown option '" + a + "'");
        } else {
            files.push_back(a);
        }
    }
    if (files.empty()) return usage_error("merge needs the JSON results of run --part");
    if (files.size() > 1024) return usage_error("merge: at most 1024 parts");
    std::string text = "{\"parts\":[", error, first_part;
    for (size_t i = 0; i < files.size(); ++i) {
        std::string part;
        if (!mcp::read_regular_file(files[i], mcp::kMaxJsonBytes / 4, &part, &error)) {
            std::fprintf(stderr, "mcplay: %s\n", mcp::boundary::one_line(error).c_str());
            return kExitUsage;
        }
        if (text.size() + part.size() > mcp::kMaxJsonBytes) {
            std::fprintf(stderr, "mcplay: merge: the parts exceed %llu bytes together\n",
                         static_cast<unsigned long long>(mcp::kMaxJsonBytes));
            return kExitUsage;
        }
        // Each part checked on its own first, so that an error names its file.
        const std::string why = mcp::check_json_text(part.c_str(), part.size());
        if (!why.empty()) {
            std::fprintf(stderr, "mcplay: %s: %s\n", mcp::boundary::one_line(files[i]).c_str(),
                         why.c_str());
            return kExitUsage;
        }
        text += (i ? "," : "") + part;
        if (i == 0) first_part = std::move(part);
    }
    text += "]}";
    OutputFile out_file{out_path};
    if (!out_file.check(&error)) return usage_error("--out: " + error);
    // Integration studies and stopping runs ("kind": "study_part" or "stopping_part") merge in
    // the study API, render studies in the render API; each refuses the other's parts.
    const nlohmann::json first = mcp::cli::api_json(first_part.c_str());
    const bool study_parts = first.is_object() && first.contains("kind") &&
                             (first["kind"] == "study_part" || first["kind"] == "stopping_part");
    char* result = nullptr;
    if ((study_parts ? mcp_study_merge(text.c_str(), &result)
                     : mcp_render_study_merge(text.c_str(), &result)) != MCP_OK) {
        std::fprintf(stderr, "mcplay: merge: %s\n", mcp_last_error());
        out_file.discard();
        return kExitUsage;
    }
    char* formatted = nullptr;
    const int status = mcp_result_format(result, format.c_str(), &formatted);
    mcp_free(result);
    if (status != MCP_OK) {
        std::fprintf(stderr, "mcplay: %s\n", mcp_last_error());
        out_file.discard();
        return kExitRuntime;
    }
    const int rc = write_output(out_path, formatted);
    mcp_free(formatted);
    return rc;
}

} // namespace

static int run_command(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty()) {
        std::fputs(kUsage, stderr);
        return kExitUsage;
    }
    const std::string cmd = args[0];
    std::vector<std::string> rest(args.begin() + 1, args.end());
    if (cmd == "--help" || cmd == "-h" || cmd == "help") {
        std::fputs(kUsage, stdout);
        return kExitOk;
    }
    if (cmd == "--version") {
        std::printf("mcplay %s\n", mcp_version());
        return kExitOk;
    }
    for (const std::string& a : rest)
        if (a == "--help" || a == "-h") {
            std::fputs(kUsage, stdout);
            return kExitOk;
        }
    if (cmd == "list") return cmd_list(rest);
    if (cmd == "run") return cmd_run(rest);
    if (cmd == "render") return cmd_render(rest);
    if (cmd == "reference") return cmd_reference(rest);
    if (cmd == "merge") return cmd_merge(rest);
    if (cmd == "points") return mcp::cli::cmd_points(rest);
    if (cmd == "analyze") return mcp::cli::cmd_analyze(rest);
    if (cmd == "warp-test") return mcp::cli::cmd_warp_test(rest, load_scene);
    return usage_error("unknown command '" + cmd + "'");
}

int main(int argc, char** argv) {
    const int rc = run_command(argc, argv);
    // A result written to standard output is only delivered once flushed: a failed flush or
    // close (a full disk, a closed descriptor) is a failed command.
    if (!mcp::cli::close_stdout() && rc == kExitOk) return kExitRuntime;
    return rc;
}
