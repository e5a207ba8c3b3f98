// The live view's sessions (mcplay_render.h, mcp_render_live_*): a scene, its estimators'
// image bands carried from pass to pass (render/progressive.h), and the reference the passes
// are measured against.
#include <algorithm>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>

#include "api/boundary.h"
#include "api/files.h"
#include "api/json_read.h"
#include "api/report.h"
#include "api/scene.h" // parse_json
#include "estimators/study.h"
#include "render/progressive.h"
#include "render/render_study.h"
#include "render_api/image_io.h"
#include "render_api/mcplay_render.h"
#include "render_api/render_call.h"
#include "render_api/render_json.h"
#include "render_api/render_reference.h"

namespace mcp {

namespace {

using boundary::copy_out;
using boundary::dump;
using boundary::fail;

constexpr size_t kMaxLiveEstimators = 4;
constexpr size_t kMaxLiveSessions = 16;
constexpr uint64_t kMaxLiveSpp = uint64_t(1) << 20;
/// Bytes a band pixel holds per estimator (ImageBand: mean, m2, kept, luminance sum and
/// maximum, the generator, the emission edge flag), and per pixel of an image (RenderImage):
/// the reference, held whole, and the band's image made for a pass's result, of the band's rows.
constexpr double kBandPixelBytes = 89.0, kImagePixelBytes = 48.0;

struct LiveSession {
    LoadedRender loaded;
    std::vector<ImageBand> bands; ///< one per estimator
    std::vector<uint64_t> streams;
    RenderImage reference; ///< width 0: none yet
    Json reference_info;
    int threads = 1;
    bool pixels = false;
};

std::mutex g_sessions_lock;
std::map<int, std::shared_ptr<LiveSession>> g_sessions;
int g_next_session = 1;

std::shared_ptr<LiveSession> find_session(int id) {
    std::lock_guard<std::mutex> lock(g_sessions_lock);
    auto it = g_sessions.find(id);
    return it == g_sessions.end() ? nullptr : it->second;
}

/// Rows [begin, end) of an image as base64 of little-endian float32 RGB (the page's pixels).
std::string float_pixels(const std::vector<double>& rgb, size_t first, size_t count) {
    std::string bytes(count * sizeof(float), '\0');
    for (size_t k = 0; k < count; ++k) {
        // Little-endian whatever the host (wasm and x86 are; this keeps the format defined).
        const float v = float(rgb[first + k]);
        uint32_t u = 0;
        std::memcpy(&u, &v, sizeof(u));
        for (size_t i = 0; i < sizeof(u); ++i)
            bytes[k * sizeof(u) + i] = static_cast<char>((u >> (8 * i)) & 0xffu);
    }
    return base64_encode(bytes);
}

/// The session's "reference" block: null without one.
Json reference_json_of(const LiveSession& s) {
    if (s.reference.width == 0) return nullptr;
    Json j = s.reference_info;
    j["mean_luminance"] = num(mean_luminance(s.reference));
    j["relative_mse_floor"] = num(relative_mse_floor(s.reference));
    if (s.pixels) {
        const ImageBand& b = s.bands.front();
        j["rgb_f32"] = float_pixels(s.reference.rgb, 3 * size_t(b.row_begin) * size_t(b.width),
                                    3 * b.pixel_count());
    }
    return j;
}

/// options.rows: [begin, end) within the image's height.
bool parse_rows(const Json& options, int height, int* begin, int* end, std::string* error) {
    *begin = 0;
    *end = height;
    const Json* rows = find(options, "rows");
    if (!rows) return true;
    if (!rows->is_array() || rows->size() != 2 || !(*rows)[0].is_number_integer() ||
        !(*rows)[1].is_number_integer()) {
        *error = "options.rows: expected [row_begin, row_end], two integers";
        return false;
    }
    const long long b = (*rows)[0].get<long long>(), e = (*rows)[1].get<long long>();
    if (b < 0 || e <= b || e > height) {
        *error = "options.rows: [" + std::to_string(b) + ", " + std::to_string(e) +
                 "] is not a non-empty range of the image's rows 0.." + std::to_string(height);
        return false;
    }
    *begin = int(b);
    *end = int(e);
    return true;
}

int open_session(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                 void* user, char** result_json) {
    if (!result_json)
        return fail(MCP_ERROR_ARGUMENT, "mcp_render_live_open: the result pointer is NULL");
    *result_json = nullptr;
    // The options the live view adds are taken out here; the rest are the render options.
    Json options = Json::object();
    if (options_json && *options_json) {
        Made<Json> o = parse_json(options_json, "options");
        if (!o.ok()) return fail(MCP_ERROR_ARGUMENT, o.error);
        if (!o.value.is_object()) return fail(MCP_ERROR_ARGUMENT, "options: expected an object");
        options = o.value;
    }
    Json live_options = Json::object();
    for (const char* key : {"rows", "live_reference", "pixels"})
        if (options.contains(key)) {
            live_options[key] = options[key];
            options.erase(key);
        }
    if (options.contains("live"))
        return fail(MCP_ERROR_ARGUMENT, "options.live: implied by the live view; leave it out");
    options["live"] = true;
    if (!options.contains("pixel_sampler")) options["pixel_sampler"] = "padded_sobol";
    std::string live_reference = "obtain";
    if (const Json* v = find(live_options, "live_reference")) {
        if (!v->is_string() || (*v != "obtain" && *v != "available"))
            return fail(MCP_ERROR_ARGUMENT, "options.live_reference: expected \"obtain\" or "
                                            "\"available\"");
        live_reference = v->get<std::string>();
    }
    bool pixels = false;
    if (const Json* v = find(live_options, "pixels")) {
        if (!v->is_boolean())
            return fail(MCP_ERROR_ARGUMENT, "options.pixels: expected true or false");
        pixels = v->get<bool>();
    }
    // Without a list, the scene's first four estimators.
    const Json* listed = find(options, "estimators");
    if (listed && listed->is_array() && listed->size() > kMaxLiveEstimators)
        return fail(MCP_ERROR_ARGUMENT, "options.estimators: the live view compares at most " +
                                            std::to_string(kMaxLiveEstimators) +
                                            " estimators, got " + std::to_string(listed->size()));

    auto session = std::make_shared<LiveSession>();
    Json parsed;
    const std::string text = dump(options);
    if (int st = begin_render_call("mcp_render_live_open", result_json, scene_json, text.c_str(),
                                   &session->loaded, &parsed))
        return st;
    RenderRequest& r = *session->loaded.request;
    if (r.estimators.size() > kMaxLiveEstimators) r.estimators.resize(kMaxLiveEstimators);
    for (const RenderEstimator& e : r.estimators)
        if (!sampler_extends(e.pixel_sampler))
            return fail(
                MCP_ERROR_ARGUMENT,
                "options.pixel_sampler: the live view adds samples pass by pass, and the '" +
                    std::string(pixel_sampler_name(e.pixel_sampler)) +
                    "' sampler cannot (its samples depend on the final spp): use "
                    "'padded_sobol' or 'independent'");
    for (const RenderEstimator& e : r.estimators)
        if (e.pixel_allocation == PixelAllocation::Adaptive)
            return fail(MCP_ERROR_ARGUMENT,
                        "estimator '" + e.name +
                            "': pixel_allocation 'adaptive' spreads a whole image's samples "
                            "after a first pass; the live view renders every pixel alike, pass "
                            "by pass: use 'uniform' here");
    for (const RenderEstimator& e : r.estimators)
        if (e.light_samples == 0 || e.candidates == 0 ||
            e.emission_samples == 0) // each band would run its own pilot
            return fail(MCP_ERROR_ARGUMENT,
                        "estimator '" + e.name + "': " +
                            (e.light_samples == 0 ? "light_samples"
                             : e.candidates == 0  ? "candidates"
                                                  : "emission_samples") +
                            " \"auto\" is chosen by a timed pilot, which the live view's bands "
                            "would each run: give a count");
    const int width = r.settings.width, height = r.settings.height;
    int row_begin = 0, row_end = height;
    std::string error;
    if (!parse_rows(live_options, height, &row_begin, &row_end, &error))
        return fail(MCP_ERROR_ARGUMENT, error);
    const double band_pixels = double(width) * double(row_end - row_begin);
    const double bytes =
        band_pixels * (kBandPixelBytes * double(r.estimators.size()) + kImagePixelBytes) +
        double(width) * double(height) * kImagePixelBytes;
    if (!(bytes <= kMaxImageBytes))
        return fail(MCP_ERROR_ARGUMENT,
                    "options: a live view of rows [" + std::to_string(row_begin) + ", " +
                        std::to_string(row_end) + ") of a " + std::to_string(width) + "x" +
                        std::to_string(height) + " image and " +
                        std::to_string(r.estimators.size()) + " estimator(s) needs " +
                        fmt("%.0f", bytes / 1048576.0) + " MiB (its rows, and the reference " +
                        "whole), more than the limit of " +
                        fmt("%.0f", kMaxImageBytes / 1048576.0) +
                        " MiB: lower the image size, the rows or the estimators");
    {
        std::lock_guard<std::mutex> lock(g_sessions_lock);
        if (g_sessions.size() >= kMaxLiveSessions)
            return fail(MCP_ERROR_ARGUMENT,
                        "mcp_render_live_open: " + std::to_string(kMaxLiveSessions) +
                            " sessions are open already: close one first");
    }
    const bool may_render = live_reference == "obtain";
    if (may_render && r.reference.file.empty()) {
        if (!check_render_work(r, 0.0, 1, true, &error)) return fail(MCP_ERROR_SCENE, error);
    }
    if (int st = obtain_reference_reporting(session->loaded, progress, user, &session->reference,
                                            &session->reference_info, &error, may_render))
        return fail(st, error);
    session->threads = resolve_threads(r.settings.threads);
    session->pixels = pixels;
    for (const RenderEstimator& e : r.estimators) {
        session->bands.push_back(make_band(width, height, row_begin, row_end, e.pixel_sampler));
        // The live image's stream: the seed and the estimator, not the spp (spp 0), so that
        // every pass continues the same image.
        session->streams.push_back(replicate_stream(r.settings.seed, e.name, 0, 0));
    }
    Json ests = Json::array();
    for (const RenderEstimator& e : r.estimators) ests.push_back(estimator_to_json(e));
    Json warnings = Json::array();
    for (const std::string& w : r.warnings) warnings.push_back(w);
    int id;
    {
        std::lock_guard<std::mutex> lock(g_sessions_lock);
        id = g_next_session++;
        if (g_next_session <= 0) g_next_session = 1; // after 2^31 sessions: wrap, skip 0
        g_sessions[id] = session;
    }
    Json j{{"version", kResultSchemaVersion},
           {"kind", "render_live"},
           {"mcplay", mcp_version()},
           {"session", id},
           {"scene", r.name},
           {"width", width},
           {"height", height},
           {"rows", {row_begin, row_end}},
           {"pixel_sampler", pixel_sampler_name(r.estimators.front().pixel_sampler)},
           {"seed", r.settings.seed},
           {"estimators", ests},
           {"reference", reference_json_of(*session)},
           {"warnings", warnings}};
    *result_json = copy_out(dump(j));
    if (!*result_json) {
        std::lock_guard<std::mutex> lock(g_sessions_lock);
        g_sessions.erase(id);
        return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    }
    return boundary::succeed();
}

int pass_session(int id, const char* pass_json, mcp_progress_fn progress, void* user,
                 char** result_json) {
    if (!result_json)
        return fail(MCP_ERROR_ARGUMENT, "mcp_render_live_pass: the result pointer is NULL");
    *result_json = nullptr;
    std::shared_ptr<LiveSession> s = find_session(id);
    if (!s)
        return fail(MCP_ERROR_ARGUMENT,
                    "mcp_render_live_pass: no open session " + std::to_string(id));
    Made<Json> parsed = parse_json(pass_json ? pass_json : "", "pass");
    if (!parsed.ok()) return fail(MCP_ERROR_ARGUMENT, parsed.error);
    const Json& p = parsed.value;
    Ctx c;
    if (!p.is_object() || !check_keys(c, p, "pass", {"estimator", "spp", "pixels", "outputs"}))
        return fail(MCP_ERROR_ARGUMENT, p.is_object() ? c.error : "pass: expected an object");
    uint64_t index = 0, spp = 0;
    if (!get_count(c, p, "estimator", "pass", &index) || !get_count(c, p, "spp", "pass", &spp))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    if (!find(p, "spp")) return fail(MCP_ERROR_ARGUMENT, "pass.spp: missing");
    if (index >= s->bands.size())
        return fail(MCP_ERROR_ARGUMENT, "pass.estimator: " + std::to_string(index) +
                                            " is not an index of the session's " +
                                            std::to_string(s->bands.size()) + " estimator(s)");
    if (spp < 1 || spp > kMaxLiveSpp)
        return fail(MCP_ERROR_ARGUMENT, "pass.spp: " + std::to_string(spp) + " is not in 1.." +
                                            std::to_string(kMaxLiveSpp));
    bool pixels = s->pixels, png = false, hdr = false;
    if (const Json* v = find(p, "pixels")) {
        if (!v->is_boolean())
            return fail(MCP_ERROR_ARGUMENT, "pass.pixels: expected true or false");
        pixels = v->get<bool>();
    }
    if (const Json* outs = find(p, "outputs")) {
        if (!outs->is_array()) return fail(MCP_ERROR_ARGUMENT, "pass.outputs: expected an array");
        for (const Json& o : *outs) {
            if (o == "png")
                png = true;
            else if (o == "hdr")
                hdr = true;
            else
                return fail(MCP_ERROR_ARGUMENT,
                            "pass.outputs: unknown output " + o.dump() + " (known: png, hdr)");
        }
    }
    const RenderRequest& r = *s->loaded.request;
    const RenderEstimator& est = r.estimators[index];
    ImageBand& band = s->bands[index];
    if (std::string why = check_pass(band, est, spp); !why.empty())
        return fail(MCP_ERROR_ARGUMENT, "pass.spp: " + why);
    RenderSettings rs;
    rs.width = band.width;
    rs.height = band.height;
    rs.spp = spp;
    rs.stream = s->streams[index];
    rs.threads = s->threads;
    rs.jitter_pixels = r.settings.jitter_pixels;
    bool cancelled = false;
    rs.progress = rows_progress(progress, user, "render_live_pass", &cancelled);
    const double before = band.seconds;
    const uint64_t samples_before = band.diagnostics.samples;
    if (!render_pass(s->loaded.scene, est, rs, band))
        return fail(MCP_ERROR_CANCELLED, "cancelled: the estimator's image takes no more passes");
    const RenderImage image = band_image(band);
    const RenderDiagnostics& d = image.diagnostics;
    Json error = nullptr;
    if (s->reference.width > 0) {
        const ErrorSums e = band_error_sums(image, s->reference, band.row_begin);
        error = Json{{"sum", num(e.sum)}, {"sum_raw", num(e.sum_raw)}, {"terms", e.terms}};
    }
    Json j{{"version", kResultSchemaVersion},
           {"kind", "render_live_pass"},
           {"estimator", est.name},
           {"index", index},
           {"spp", band.spp},
           {"rows", {band.row_begin, band.row_end}},
           {"seconds", num(band.seconds)},
           {"pass_seconds", num(band.seconds - before)},
           {"pass_samples", d.samples - samples_before},
           {"samples", d.samples},
           {"rays", d.rays},
           {"discarded_nonfinite", d.discarded_nonfinite},
           {"dominated_pixels", d.dominated_pixels},
           {"error", error}};
    if (pixels) j["rgb_f32"] = float_pixels(image.rgb, 0, image.rgb.size());
    if (png || hdr) {
        Json images = Json::object();
        if (png) images["png"] = base64_encode(encode_png(image, r.exposure));
        if (hdr) images["hdr"] = base64_encode(encode_hdr(image));
        j["images"] = images;
    }
    *result_json = copy_out(dump(j));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    return boundary::succeed();
}

int give_reference(int id, const char* reference_json, char** result_json) {
    if (!result_json)
        return fail(MCP_ERROR_ARGUMENT, "mcp_render_live_reference: the result pointer is NULL");
    *result_json = nullptr;
    std::shared_ptr<LiveSession> s = find_session(id);
    if (!s)
        return fail(MCP_ERROR_ARGUMENT,
                    "mcp_render_live_reference: no open session " + std::to_string(id));
    Made<Json> parsed = parse_json(reference_json ? reference_json : "", "reference");
    if (!parsed.ok()) return fail(MCP_ERROR_ARGUMENT, parsed.error);
    const Json& p = parsed.value;
    Ctx c;
    std::string data;
    if (!p.is_object() || !check_keys(c, p, "reference", {"reference_data"}) ||
        !get_string(c, p, "reference_data", "reference", &data))
        return fail(MCP_ERROR_ARGUMENT, p.is_object() ? c.error : "reference: expected an object");
    RenderRequest& r = *s->loaded.request;
    std::string bytes;
    if (data.size() > (kMaxCacheFileBytes + 2) / 3 * 4 || !base64_decode(data, &bytes) ||
        !is_encoded_reference(bytes))
        return fail(MCP_ERROR_ARGUMENT, "reference.reference_data: not a reference image made by "
                                        "mcplay (base64 of what `mcplay reference` writes)");
    if (encoded_reference_key(bytes) != reference_key(r))
        return fail(MCP_ERROR_ARGUMENT,
                    "reference.reference_data: made from another scene, image size, reference "
                    "estimator, spp or seed than this live view's (" +
                        std::to_string(r.settings.width) + "x" + std::to_string(r.settings.height) +
                        ", " + std::to_string(r.reference.spp) + " spp)");
    r.supplied_reference = bytes;
    RenderImage ref;
    Json info;
    std::string error;
    if (!obtain_reference(s->loaded, &ref, &info, &error, nullptr, false))
        return fail(MCP_ERROR_ARGUMENT, error);
    s->reference = std::move(ref);
    s->reference_info = info;
    *result_json = copy_out(dump(reference_json_of(*s)));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    return boundary::succeed();
}

} // namespace

} // namespace mcp

extern "C" {

int mcp_render_live_open(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                         void* user, char** result_json) {
    return mcp::open_session(scene_json, options_json, progress, user, result_json);
}

int mcp_render_live_pass(int session, const char* pass_json, mcp_progress_fn progress, void* user,
                         char** result_json) {
    return mcp::pass_session(session, pass_json, progress, user, result_json);
}

int mcp_render_live_reference(int session, const char* reference_json, char** result_json) {
    return mcp::give_reference(session, reference_json, result_json);
}

int mcp_render_live_close(int session) {
    std::lock_guard<std::mutex> lock(mcp::g_sessions_lock);
    if (mcp::g_sessions.erase(session) == 0)
        return mcp::boundary::fail(MCP_ERROR_ARGUMENT, "mcp_render_live_close: no open session " +
                                                           std::to_string(session));
    return mcp::boundary::succeed();
}

} // extern "C"
