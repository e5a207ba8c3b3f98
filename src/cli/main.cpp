// mcplay command line: argument parsing and file I/O only; all work goes through the C API.
#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/mcplay.h"

namespace {

// Exit codes.
constexpr int kExitOk = 0;
constexpr int kExitRuntime = 1; // I/O failure, cancelled study, internal error
constexpr int kExitUsage = 2;   // bad command line
constexpr int kExitScene = 3;   // bad scene file

const char* kUsage =
    "mcplay - Monte Carlo estimator playground\n"
    "\n"
    "usage:\n"
    "  mcplay list [--scenes DIR]\n"
    "  mcplay run SCENE [options]\n"
    "  mcplay --help | --version\n"
    "\n"
    "SCENE is a scene JSON file, or the name of one in the scenes directory\n"
    "(--scenes DIR, else $MCPLAY_SCENES, else ./scenes).\n"
    "\n"
    "run options:\n"
    "  --estimators A,B,..  run only these estimators (names from the scene, or presets)\n"
    "  --n-min N            smallest sample count (default from the scene, else 16)\n"
    "  --n-max N            largest sample count (default from the scene, else 65536)\n"
    "  --reps R             independent replicates per N (>= 2; default 32)\n"
    "  --seed S             random seed (default 1); same seed, same numbers\n"
    "  --threads T          worker threads (0 = all cores; results do not depend on T)\n"
    "  --format F           table (default), json or csv\n"
    "  --out FILE           write the result to FILE instead of standard output\n"
    "  --quiet              no progress lines on standard error\n"
    "\n"
    "exit codes: 0 ok, 1 runtime error, 2 bad arguments, 3 bad scene\n";

int usage_error(const std::string& msg) {
    std::fprintf(stderr, "mcplay: %s (see mcplay --help)\n", msg.c_str());
    return kExitUsage;
}

bool read_file(const std::string& path, std::string* out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    std::ostringstream ss;
    ss << in.rdbuf();
    *out = ss.str();
    return true;
}

bool is_regular_file(const std::string& path) {
    std::ifstream in(path);
    if (!in) return false;
    DIR* d = opendir(path.c_str());
    if (d) {
        closedir(d);
        return false;
    }
    return true;
}

std::string scenes_dir(const std::string& given) {
    if (!given.empty()) return given;
    if (const char* env = std::getenv("MCPLAY_SCENES"); env && *env) return env;
    return "scenes";
}

// Strict whole-number parsing: digits only, no sign, no trailing text, no overflow.
bool parse_count(const std::string& text, unsigned long long* out) {
    if (text.empty() || text.size() > 20) return false;
    for (char c : text)
        if (c < '0' || c > '9') return false;
    errno = 0;
    char* end = nullptr;
    unsigned long long v = std::strtoull(text.c_str(), &end, 10);
    if (errno == ERANGE || *end != '\0') return false;
    *out = v;
    return true;
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
        std::fprintf(stderr, "mcplay: cannot open scenes directory '%s'\n", dir.c_str());
        return kExitRuntime;
    }
    std::sort(files.begin(), files.end());
    std::printf("scenes in %s:\n", dir.c_str());
    for (const std::string& f : files) {
        std::string text, path = dir + "/" + f;
        char* info = nullptr;
        if (!read_file(path, &text)) {
            std::printf("  %-28s (unreadable)\n", f.c_str());
            continue;
        }
        if (mcp_scene_info(text.c_str(), &info) != MCP_OK) {
            std::printf("  %-28s INVALID: %s\n", f.c_str(), mcp_last_error());
            continue;
        }
        nlohmann::json j = nlohmann::json::parse(info);
        mcp_free(info);
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
        nlohmann::json c = nlohmann::json::parse(catalog);
        mcp_free(catalog);
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
    nlohmann::json j = nlohmann::json::parse(level_json, nullptr, false);
    if (!j.is_discarded()) std::fprintf(stderr, "mcplay: N = %s done\n", j["n"].dump().c_str());
    return 0;
}

int cmd_run(const std::vector<std::string>& args) {
    std::string scene_arg, format = "table", out_path, dir_arg;
    bool quiet = false;
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
            nlohmann::json list = nlohmann::json::array();
            std::stringstream ss(v);
            std::string item;
            while (std::getline(ss, item, ',')) {
                if (item.empty()) return usage_error("--estimators: empty name in '" + v + "'");
                list.push_back(item);
            }
            if (list.empty()) return usage_error("--estimators needs at least one name");
            options["estimators"] = list;
        } else if (a == "--n-min" || a == "--n-max" || a == "--reps" || a == "--seed" ||
                   a == "--threads") {
            if (!value(&v)) return usage_error(a + " needs a value");
            unsigned long long x = 0;
            if (!parse_count(v, &x))
                return usage_error(a + ": expected a whole number >= 0, got '" + v + "'");
            std::string key = a.substr(2);
            std::replace(key.begin(), key.end(), '-', '_');
            options[key] = x;
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

    std::string path = scene_arg;
    if (!is_regular_file(path)) path = scenes_dir(dir_arg) + "/" + scene_arg + ".json";
    std::string text;
    if (!is_regular_file(path) || !read_file(path, &text)) {
        std::fprintf(stderr, "mcplay: no scene file '%s' (nor '%s')\n", scene_arg.c_str(),
                     path.c_str());
        return kExitScene;
    }

    const bool show_progress = !quiet && isatty(fileno(stderr));
    char* result = nullptr;
    const std::string opts = options.dump();
    int status = mcp_study_run(text.c_str(), opts.c_str(), show_progress ? progress_line : nullptr,
                               nullptr, &result);
    if (status != MCP_OK && status != MCP_ERROR_CANCELLED) {
        std::fprintf(stderr, "mcplay: %s: %s\n", path.c_str(), mcp_last_error());
        return status == MCP_ERROR_SCENE ? kExitScene : kExitUsage;
    }
    char* formatted = nullptr;
    if (mcp_result_format(result, format.c_str(), &formatted) != MCP_OK) {
        std::fprintf(stderr, "mcplay: %s\n", mcp_last_error());
        mcp_free(result);
        return kExitRuntime;
    }
    mcp_free(result);
    int rc = kExitOk;
    if (out_path.empty()) {
        std::fputs(formatted, stdout);
    } else {
        std::ofstream out(out_path, std::ios::binary);
        out << formatted;
        if (!out) {
            std::fprintf(stderr, "mcplay: cannot write '%s'\n", out_path.c_str());
            rc = kExitRuntime;
        }
    }
    mcp_free(formatted);
    return status == MCP_ERROR_CANCELLED ? kExitRuntime : rc;
}

} // namespace

int main(int argc, char** argv) {
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
    return usage_error("unknown command '" + cmd + "'");
}
