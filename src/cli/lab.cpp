// mcplay points / analyze / warp-test: argument parsing, file I/O and text formatting only; the
// computations are the C API's (mcp_points, mcp_points_analyze, mcp_warp_test).
#include "cli/lab.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <stb_image_write.h>

#include "api/boundary.h"
#include "api/files.h"
#include "api/mcplay.h"
#include "cli/cli_support.h"
#include "core/special.h"
#include "render_api/mcplay_render.h"

namespace mcp::cli {
namespace {

/// A point file is at most this many bytes (2^20 points of 64 coordinates in 25 characters).
constexpr uint64_t kMaxPointFileBytes = uint64_t(1) << 31;

int api_error(const char* command, int status) {
    std::fprintf(stderr, "mcplay: %s: %s\n", command, mcp_last_error());
    return exit_code(status);
}

/// The C API returned a text that is not a JSON object (it never should).
int bad_result() {
    std::fprintf(stderr, "mcplay: internal error: the C API's result is not a JSON object\n");
    return kExitRuntime;
}

std::string num(double v, const char* format = "%.6g") {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

std::string num_or_dash(const nlohmann::json& v, const char* format = "%.6g") {
    return v.is_number() ? num(v.get<double>(), format) : "-";
}

/// The options --name VALUE of a command: each name at most once, every value given.
struct Options {
    std::vector<std::string> positional;
    std::vector<std::pair<std::string, std::string>> named;
    const std::string* get(const std::string& name) const {
        for (const auto& kv : named)
            if (kv.first == name) return &kv.second;
        return nullptr;
    }
};

bool parse_options(const char* command, const std::vector<std::string>& args,
                   const std::vector<std::string>& known, Options* out, std::string* error) {
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a.rfind("--", 0) != 0) {
            out->positional.push_back(a);
            continue;
        }
        if (std::find(known.begin(), known.end(), a) == known.end()) {
            *error = std::string(command) + ": unknown option '" + a + "'";
            return false;
        }
        if (i + 1 >= args.size()) {
            *error = a + " needs a value";
            return false;
        }
        if (out->get(a)) {
            *error = a + " given twice";
            return false;
        }
        out->named.emplace_back(a, args[++i]);
    }
    return true;
}

/// A whole-number option into the JSON request, or an error.
bool count_option(const Options& o, const char* name, const char* key, nlohmann::json* request,
                  std::string* error) {
    const std::string* v = o.get(name);
    if (!v) return true;
    unsigned long long n = 0;
    if (!parse_count(*v, &n)) {
        *error = std::string(name) + ": expected a whole number, got '" + *v + "'";
        return false;
    }
    (*request)[key] = n;
    return true;
}

/// The spectrum as a grey-level PNG: brightness t = (log10 P + 1) / 2 clipped to [0, 1], so
/// P = 0.1 is black, P = 1 (independent points) mid-grey and P >= 10 white; the centre (k = 0,
/// P = N) is white. Row 0 of the image is the highest ky (the y axis points up).
std::string spectrum_png(const nlohmann::json& spectrum) {
    const int size = spectrum["size"].get<int>();
    const auto& power = spectrum["power"];
    std::vector<unsigned char> pixels(static_cast<size_t>(size) * static_cast<size_t>(size));
    for (int row = 0; row < size; ++row)
        for (int col = 0; col < size; ++col) {
            const nlohmann::json& v = power[static_cast<size_t>((size - 1 - row) * size + col)];
            const double p = v.is_number() ? v.get<double>() : 0.0;
            const double t = p > 0.0 ? (std::log10(p) + 1.0) / 2.0 : 0.0;
            pixels[static_cast<size_t>(row * size + col)] =
                static_cast<unsigned char>(std::lround(255.0 * std::clamp(t, 0.0, 1.0)));
        }
    std::string bytes;
    stbi_write_png_to_func(
        [](void* context, void* data, int n) {
            static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                                       static_cast<size_t>(n));
        },
        &bytes, size, size, 1, pixels.data(), size);
    return bytes;
}

std::string analysis_table(const nlohmann::json& a) {
    std::string out;
    out += "points: " + a["n"].dump() + " in " + a["dim"].dump() + " dimensions";
    if (a["sets"].get<int>() > 1)
        out += ", " + a["sets"].dump() + " sets (measures are means over the sets)";
    out += "\n";
    const auto& iid = a["expected_iid"];
    auto line = [&](const char* label, const char* key, const char* iid_key) {
        out += std::string(label) + num_or_dash(a[key]);
        if (iid_key) out += "   (independent points: " + num_or_dash(iid[iid_key]) + " rms)";
        out += "\n";
    };
    line("L2-star discrepancy (Warnock)        ", "l2_star_discrepancy", "l2_star_discrepancy");
    line("centred L2 discrepancy (Hickernell)  ", "centered_l2_discrepancy",
         "centered_l2_discrepancy");
    line("wrap-around L2 discrepancy           ", "wraparound_l2_discrepancy",
         "wraparound_l2_discrepancy");
    line("minimum distance                     ", "min_distance", nullptr);
    line("minimum distance on the torus        ", "min_distance_toroidal", nullptr);
    for (auto it = a["skipped"].begin(); it != a["skipped"].end(); ++it)
        out += "skipped " + it.key() + ": " + it.value().get<std::string>() + "\n";
    if (a.contains("spectrum")) {
        const auto& s = a["spectrum"];
        const auto& radial = s["radial"];
        out += "power spectrum of x" + std::to_string(s["axes"][0].get<int>() + 1) + ", x" +
               std::to_string(s["axes"][1].get<int>() + 1) + " on a " + s["size"].dump() + " x " +
               s["size"].dump() + " frequency grid; radial average (1 = independent points):\n";
        const size_t rings = radial["frequency"].size();
        for (size_t r = 0; r < rings; r += std::max<size_t>(1, rings / 16))
            out += "  |k| " + num(radial["frequency"][r].get<double>(), "%6.1f") + "  " +
                   num_or_dash(radial["power"][r], "%.4g") + "\n";
    }
    return out;
}

std::string warp_table(const nlohmann::json& r) {
    std::string out;
    out +=
        "warp " + r["warp"].get<std::string>() + " on the " + r["domain"].get<std::string>() + "\n";
    out += "density integrates to " + num_or_dash(r["pdf_integral"], "%.8g") + " (+- " +
           num_or_dash(r["pdf_integral_error"], "%.2g") + ")\n";
    out += "chi-square " + num_or_dash(r["statistic"]) + " on " + r["dof"].dump() +
           " degrees of freedom (" + r["cells"].dump() + " cells; " + r["pooled_bins"].dump() +
           " bins with fewer than 5 expected pooled), " +
           (r["p_value"].is_number() ? p_value_text(r["p_value"].get<double>(), 4) : "p = -") +
           ", level " + num_or_dash(r["level"], "%.4g") + "\n";
    out += "verdict: " + r["verdict"].get<std::string>() + "\n";
    // Which bins lie farthest from the density matters only when the samples do not follow it.
    const auto& worst = r["worst_bins"];
    if (!worst.empty() && r.value("outcome", "") == "failed") {
        out += "bins farthest from the density (standardised residual (observed - expected) / "
               "sqrt(expected)):\n";
        for (const auto& b : worst) {
            std::string where;
            for (size_t k = 0; k < b["range"].size(); ++k)
                where += (k ? ", " : "") + r["coordinates"][k].get<std::string>() + " in [" +
                         num(b["range"][k][0].get<double>(), "%.4g") + ", " +
                         num(b["range"][k][1].get<double>(), "%.4g") + ")";
            out += "  " + where + ": observed " + num(b["observed"].get<double>(), "%.0f") +
                   ", expected " + num(b["expected"].get<double>(), "%.1f") + ", residual " +
                   num_or_dash(b["residual"], "%+.2f") + "\n";
        }
    }
    return out;
}

} // namespace

int cmd_points(const std::vector<std::string>& args) {
    Options o;
    std::string error;
    if (!parse_options("points", args, {"--n", "--dim", "--seed", "--out", "--randomization"}, &o,
                       &error))
        return usage_error(error);
    if (o.positional.size() != 1)
        return usage_error("points needs one SAMPLER (uniform, stratified, latin_hypercube, sobol, "
                           "halton, lattice, pixel_independent, pixel_stratified, pixel_sobol, "
                           "pixel_padded_sobol)");
    // pixel_independent, pixel_stratified, pixel_sobol, pixel_padded_sobol: one pixel's samples
    // from the renderer's pixel samplers (--n is its spp).
    const std::string& sampler = o.positional[0];
    const bool pixel = sampler.rfind("pixel_", 0) == 0;
    nlohmann::json request = pixel ? nlohmann::json{{"pixel_sampler", sampler.substr(6)}}
                                   : nlohmann::json{{"sampler", sampler}};
    if (!o.get("--n")) return usage_error("points needs --n N");
    if (!count_option(o, "--n", pixel ? "spp" : "n", &request, &error) ||
        !count_option(o, "--dim", "dim", &request, &error) ||
        !count_option(o, "--seed", "seed", &request, &error))
        return usage_error(error);
    if (const std::string* r = o.get("--randomization")) {
        if (pixel) return usage_error("--randomization: the pixel samplers have their own");
        request["randomization"] = *r;
    }
    char* text = nullptr;
    const int status = pixel ? mcp_render_pixel_points(request.dump().c_str(), &text)
                             : mcp_points(request.dump().c_str(), &text);
    if (status != MCP_OK) return api_error("points", status);
    const nlohmann::json result = api_json(text);
    mcp_free(text);
    if (!result.is_object()) return bad_result();
    // One point per row, 17 significant digits: the file reads back as the same doubles.
    std::string csv;
    const int dim = result["dim"].get<int>();
    for (int k = 0; k < dim; ++k) csv += (k ? ",x" : "x") + std::to_string(k + 1);
    csv += "\n";
    for (const auto& row : result["points"]) {
        for (size_t k = 0; k < row.size(); ++k)
            csv += (k ? "," : "") + num(row[k].get<double>(), "%.17g");
        csv += "\n";
    }
    const std::string* out = o.get("--out");
    return write_output(out ? *out : "", csv);
}

int cmd_analyze(const std::vector<std::string>& args) {
    Options o;
    std::string error;
    if (!parse_options("analyze", args, {"--format", "--spectrum-out", "--spectrum-size", "--axes"},
                       &o, &error))
        return usage_error(error);
    if (o.positional.size() != 1) return usage_error("analyze needs one FILE (.csv or .json)");
    const std::string format = o.get("--format") ? *o.get("--format") : "table";
    if (format != "table" && format != "json")
        return usage_error("--format: expected table or json, got '" + format + "'");
    const std::string& path = o.positional[0];
    std::string bytes;
    if (!read_regular_file(path, kMaxPointFileBytes, &bytes, &error)) {
        std::fprintf(stderr, "mcplay: %s\n", boundary::one_line(error).c_str());
        return kExitUsage;
    }
    nlohmann::json request;
    const bool json_file = path.size() > 5 && path.compare(path.size() - 5, 5, ".json") == 0;
    if (json_file) {
        // Read as every JSON text is (bounded nesting and size), so that no file can exhaust
        // the stack here or in the request built from it.
        Made<Json> points = parse_json(bytes, "points");
        if (!points.ok()) {
            std::fprintf(stderr, "mcplay: %s: %s\n", boundary::one_line(path).c_str(),
                         boundary::one_line(points.error).c_str());
            return kExitUsage;
        }
        request["points"] = std::move(points.value);
    } else {
        request["csv"] = std::move(bytes);
    }
    nlohmann::json spectrum = nlohmann::json::object();
    if (!count_option(o, "--spectrum-size", "size", &spectrum, &error)) return usage_error(error);
    // --axes counts from 1, as the columns x1, x2, ... are named (mcplay points, the table's
    // "power spectrum of x1, x2"); the request's spectrum.axes counts from 0.
    const std::string* axes = o.get("--axes");
    if (axes) {
        unsigned long long a = 0, b = 0;
        const size_t comma = axes->find(',');
        if (comma == std::string::npos || !parse_count(axes->substr(0, comma), &a) ||
            !parse_count(axes->substr(comma + 1), &b) || a < 1 || b < 1 || a > 64 || b > 64 ||
            a == b)
            return usage_error("--axes: expected two different columns counted from 1, such as "
                               "1,2 (x1 and x2), got '" +
                               *axes + "'");
        spectrum["axes"] = {a - 1, b - 1};
    }
    request["spectrum"] = spectrum;
    char* text = nullptr;
    const int status = mcp_points_analyze(boundary::dump(request).c_str(), &text);
    if (status != MCP_OK) {
        // The request's fields named as the flags that set them, the columns counted from 1.
        std::string why = flag_named(mcp_last_error(), "request.spectrum.size", "--spectrum-size");
        int dim = 0;
        if (axes &&
            std::sscanf(why.c_str(), "request.spectrum.axes: the points have %d", &dim) == 1)
            why = "--axes " + *axes + ": the points have " + std::to_string(dim) +
                  " coordinates (x1 to x" + std::to_string(dim) + ")";
        std::fprintf(stderr, "mcplay: analyze: %s: %s\n", boundary::one_line(path).c_str(),
                     boundary::one_line(why).c_str());
        return exit_code(status);
    }
    const nlohmann::json result = api_json(text);
    mcp_free(text);
    if (!result.is_object()) return bad_result();
    if (const std::string* png = o.get("--spectrum-out")) {
        if (!result.contains("spectrum")) {
            std::fprintf(stderr, "mcplay: analyze: no spectrum to write\n");
            return kExitRuntime;
        }
        if (!write_file(*png, spectrum_png(result["spectrum"]))) {
            std::fprintf(stderr, "mcplay: cannot write '%s'\n", boundary::one_line(*png).c_str());
            return kExitRuntime;
        }
    }
    if (format == "json") {
        // The spectrum's grid goes to the image; the JSON keeps the radial average only.
        nlohmann::json shown = result;
        if (shown.contains("spectrum")) shown["spectrum"].erase("power");
        return write_output("", shown.dump(2) + "\n");
    }
    return write_output("", analysis_table(result));
}

int cmd_warp_test(const std::vector<std::string>& args, LoadScene load_scene) {
    Options o;
    std::string error;
    if (!parse_options("warp-test", args,
                       {"--samples", "--seed", "--format", "--scenes", "--significance", "--tests"},
                       &o, &error))
        return usage_error(error);
    if (o.positional.size() != 1) return usage_error("warp-test needs one SCENE");
    const std::string format = o.get("--format") ? *o.get("--format") : "table";
    if (format != "table" && format != "json")
        return usage_error("--format: expected table or json, got '" + format + "'");
    nlohmann::json options = nlohmann::json::object();
    if (!count_option(o, "--samples", "samples", &options, &error) ||
        !count_option(o, "--seed", "seed", &options, &error) ||
        !count_option(o, "--tests", "tests", &options, &error))
        return usage_error(error);
    if (const std::string* s = o.get("--significance")) {
        char* end = nullptr;
        const double v = std::strtod(s->c_str(), &end);
        if (s->empty() || *end != '\0' || !(v > 0.0 && v < 1.0))
            return usage_error("--significance: expected a number in (0, 1), got '" + *s + "'");
        options["significance"] = v;
    }
    std::string path, scene;
    const std::string* dir = o.get("--scenes");
    if (!load_scene(o.positional[0], dir ? *dir : "", &path, &scene)) return kExitScene;
    char* text = nullptr;
    const int status = mcp_warp_test(scene.c_str(), options.dump().c_str(), &text);
    if (status != MCP_OK) {
        std::fprintf(stderr, "mcplay: warp-test: %s: %s\n", boundary::one_line(path).c_str(),
                     mcp_last_error());
        return exit_code(status);
    }
    const nlohmann::json result = api_json(text);
    mcp_free(text);
    if (!result.is_object()) return bad_result();
    if (format == "json") return write_output("", result.dump(2) + "\n");
    return write_output("", warp_table(result));
}

} // namespace mcp::cli
