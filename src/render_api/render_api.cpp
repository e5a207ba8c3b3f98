// The render C API's entry points (mcplay_render.h): each loads the scene (render_call.h),
// gets the reference when it needs one (render_reference.h), renders, and writes its JSON
// (render_json.h). Built without exceptions like the integration API; every failure is a
// status code plus mcp_last_error.
#include "render_api/mcplay_render.h"

#include <algorithm>
#include <cmath>

#include "api/boundary.h"
#include "api/files.h"
#include "api/report.h"
#include "api/scene.h"
#include "estimators/study.h"
#include "render/splitting.h"
#include "render_api/image_io.h"
#include "render_api/render_call.h"
#include "render_api/render_json.h"
#include "render_api/render_merge.h"
#include "render_api/render_reference.h"
#include "render_api/render_request.h"

using mcp::boundary::copy_out;
using mcp::boundary::dump;
using mcp::boundary::fail;

namespace mcp {

namespace {

constexpr int kPlanPilotSide = 64; ///< a plan's pilot images are at most this many pixels a side

bool wants(const Json& options, const char* key, bool fallback) {
    auto it = options.find(key);
    return it != options.end() && it->is_boolean() ? it->get<bool>() : fallback;
}

} // namespace

} // namespace mcp

extern "C" {

int mcp_render_scene_info(const char* scene_json, const char* options_json, char** info_json) {
    using namespace mcp;
    LoadedRender l;
    Json options;
    if (int st = begin_render_call("mcp_render_scene_info", info_json, scene_json, options_json, &l,
                                   &options))
        return st;
    Json j = render_scene_to_json(l);
    Json ests = Json::array();
    for (const RenderEstimator& e : l.request->estimators) ests.push_back(estimator_to_json(e));
    j["estimators"] = ests;
    j["settings"] =
        render_settings_to_json(l.request->settings, resolve_threads(l.request->settings.threads));
    j["reference"] = Json{{"estimator", estimator_to_json(l.request->reference.estimator)},
                          {"spp", l.request->reference.spp},
                          {"file", l.request->reference.file}};
    // The live view's default image (mcp_render_live_open), or why the scene has none.
    const Camera& camera = l.request->scene->camera;
    j["camera"] = Json{
        {"aspect_ratio", camera.aspect_ratio > 0.0 ? Json(camera.aspect_ratio) : Json(nullptr)},
        {"yfov", camera.yfov}};
    int live_width = 0, live_height = 0;
    std::string why;
    if (live_image_size(camera, l.request->settings.width, l.request->settings.height,
                        kLiveDefaultLongSide, &live_width, &live_height, &why))
        j["live_size"] = Json{{"width", live_width}, {"height", live_height}};
    else
        j["live_size"] = Json{{"error", why}};
    *info_json = copy_out(dump(j));
    if (!*info_json) return fail(MCP_ERROR_INTERNAL, "out of memory");
    return boundary::succeed();
}

int mcp_render_image(const char* scene_json, const char* options_json, char** result_json) {
    using namespace mcp;
    LoadedRender l;
    Json options;
    if (int st = begin_render_call("mcp_render_image", result_json, scene_json, options_json, &l,
                                   &options))
        return st;
    const RenderRequest& r = *l.request;
    // Without options.estimator, the scene's best estimator: the reference's (MIS with the power
    // heuristic, or path tracing with MIS for a path scene), with the scene's pixel sampler; a
    // scene's list may well start with a teaching baseline (uniform hemisphere sampling).
    RenderEstimator est = r.reference.estimator;
    est.name = strategy_name(est.strategy);
    est.pixel_sampler = r.estimators.front().pixel_sampler;
    if (auto it = options.find("estimator"); it != options.end()) {
        bool found = false;
        if (it->is_string())
            for (const RenderEstimator& e : r.estimators)
                if (e.name == it->get<std::string>()) {
                    est = e;
                    found = true;
                }
        if (!found) {
            Made<RenderEstimator> m = parse_render_estimator(*it, "options.estimator");
            if (!m.ok()) return fail(MCP_ERROR_ARGUMENT, m.error);
            est = m.value;
        }
    }
    // options.pixel_sampler (checked when the request was built) overrides the estimator's,
    // as it does every estimator of a study.
    if (auto it = options.find("pixel_sampler"); it != options.end() && it->is_string())
        parse_pixel_sampler(it->get<std::string>(), &est.pixel_sampler);
    if (std::string why = check_pixel_allocation(est); !why.empty())
        return fail(MCP_ERROR_ARGUMENT, "options.estimator.pixel_allocation: " + why);
    uint64_t spp = r.settings.spp_max;
    const bool spp_given = options.find("spp") != options.end();
    if (auto it = options.find("spp"); it != options.end()) {
        if (!it->is_number_integer() || it->get<int64_t>() < 1 || it->get<int64_t>() > (1 << 20))
            return fail(MCP_ERROR_ARGUMENT, "options.spp: expected a whole number in 1..1048576");
        spp = uint64_t(it->get<int64_t>());
    }
    // Never a silent change of method: a spp the pixel sampler cannot take is an error.
    if (std::string why = check_pixel_sampler_spp(est.pixel_sampler, spp); !why.empty()) {
        if (spp_given) return fail(MCP_ERROR_ARGUMENT, "options.spp: " + why);
        const bool from_options = options.find("spp_max") != options.end();
        return fail(from_options ? MCP_ERROR_ARGUMENT : MCP_ERROR_SCENE,
                    std::string(from_options ? "options" : "scene.render") + ".spp_max: " + why +
                        " (an image is rendered at spp_max unless spp is given)");
    }
    bool png = true, hdr = false, pfm = false, error_png = false, reference_png = false,
         reference_hdr = false;
    if (auto it = options.find("outputs"); it != options.end()) {
        png = false;
        if (!it->is_array()) return fail(MCP_ERROR_ARGUMENT, "options.outputs: expected an array");
        for (const Json& o : *it) {
            std::string s = o.is_string() ? o.get<std::string>() : "";
            if (s == "png")
                png = true;
            else if (s == "hdr")
                hdr = true;
            else if (s == "pfm")
                pfm = true;
            else if (s == "error_png")
                error_png = true;
            else if (s == "reference_png")
                reference_png = true;
            else if (s == "reference_hdr")
                reference_hdr = true;
            else
                return fail(MCP_ERROR_ARGUMENT,
                            "options.outputs: unknown output " + o.dump() +
                                " (known: png, hdr, pfm, error_png, reference_png, reference_hdr)");
        }
    }
    if (reference_png || reference_hdr) {
        // The study's reference image itself (from options.reference_data, the cache, a file,
        // or rendered), as PNG and/or Radiance HDR; no estimator image is rendered with it.
        if (png || hdr || pfm || error_png)
            return fail(MCP_ERROR_ARGUMENT, "options.outputs: reference_png and reference_hdr go "
                                            "alone (the reference image, no estimator's)");
        std::string err;
        if (!check_render_work(r, 0.0, 1, r.reference.file.empty(), &err))
            return fail(MCP_ERROR_SCENE, err);
        RenderImage ref;
        Json info;
        if (!obtain_reference(l, &ref, &info, &err)) return fail(MCP_ERROR_SCENE, err);
        Json images = Json::object();
        if (reference_png) images["reference_png"] = base64_encode(encode_png(ref, r.exposure));
        if (reference_hdr) images["reference_hdr"] = base64_encode(encode_hdr(ref));
        Json j{
            {"version", kResultSchemaVersion},  {"kind", "render_image"}, {"mcplay", mcp_version()},
            {"scene", render_scene_to_json(l)}, {"reference", info},      {"images", images}};
        *result_json = copy_out(dump(j));
        if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
        return boundary::succeed();
    }
    {
        std::string err;
        bool ref_rendered = error_png && r.reference.file.empty();
        if (!check_render_work(r, double(spp), 2, ref_rendered, &err))
            return fail(MCP_ERROR_SCENE, err);
    }
    RenderSettings rs;
    rs.width = r.settings.width;
    rs.height = r.settings.height;
    rs.spp = spp;
    // A sampler that extends keys the image by the seed and estimator alone (spp 0), as the
    // live view's passes do: its image at N spp is the live view's at N spp, bit for bit.
    rs.stream = replicate_stream(r.settings.seed, est.name,
                                 sampler_extends(est.pixel_sampler) ? 0 : spp, 0);
    rs.threads = resolve_threads(r.settings.threads);
    rs.jitter_pixels = r.settings.jitter_pixels;
    est = resolve_split(l.scene, est, rs); // light_samples "auto" (splitting.h)
    RenderImage image = render_image(l.scene, est, rs);
    const RenderDiagnostics& d = image.diagnostics;
    Json diag{{"samples", d.samples},
              {"discarded_nonfinite", d.discarded_nonfinite},
              {"rays", d.rays},
              {"light_misses", d.light_misses},
              {"dominated_pixels", d.dominated_pixels},
              {"max_sample_share", num(d.max_sample_share)}};
    // Finite in double yet inf in the float32 images (HDR, PFM, the page's pixels; black in
    // the PNG): flagged beside the discarded samples, with the same code.
    const uint64_t beyond_float32 = pixels_beyond_float32(image);
    diag["pixels_beyond_float32"] = beyond_float32;
    Json warnings = Json::array();
    if (d.discarded_nonfinite)
        warnings.push_back(warning("nonfinite", Severity::Error,
                                   std::to_string(d.discarded_nonfinite) +
                                       " sample(s) with NaN/Inf radiance were "
                                       "discarded: the image is biased there"));
    if (beyond_float32)
        warnings.push_back(warning("nonfinite", Severity::Error,
                                   std::to_string(beyond_float32) +
                                       " pixel(s) exceed the float32 range of the images (above "
                                       "3.4e38): they are inf in the HDR/PFM and black in the "
                                       "PNG; lower the emission"));
    // Penumbrae legitimately have pixels where one sample of many sees the light; a share of
    // the image above 1% is fireflies.
    if (d.dominated_pixels * 100 > image.pixel_count())
        warnings.push_back(warning("fireflies", Severity::Warning,
                                   std::to_string(d.dominated_pixels) +
                                       " pixel(s) owe more than half their value "
                                       "to one sample (fireflies)"));
    Json images = Json::object();
    if (png) images["png"] = base64_encode(encode_png(image, r.exposure));
    if (hdr) images["hdr"] = base64_encode(encode_hdr(image));
    if (pfm) images["pfm"] = base64_encode(encode_pfm(image));
    Json j{{"version", kResultSchemaVersion},
           {"kind", "render_image"},
           {"mcplay", mcp_version()},
           {"scene", render_scene_to_json(l)},
           {"estimator", estimator_to_json(est)},
           {"spp", spp},
           {"seconds", num(image.seconds)},
           {"rays_per_second", num(image.seconds > 0 ? double(d.rays) / image.seconds : NAN)},
           {"diagnostics", diag},
           {"warnings", warnings}};
    if (est.pixel_allocation == PixelAllocation::Adaptive)
        j["pixel_allocation"] = pixel_allocation_to_json(image.allocation);
    if (error_png) {
        RenderImage ref;
        Json info;
        std::string err;
        if (!obtain_reference(l, &ref, &info, &err)) return fail(MCP_ERROR_SCENE, err);
        ImageError e = image_error(image, ref);
        images["error_png"] = base64_encode(encode_error_png(image, ref));
        double floor = relative_mse_floor(ref);
        info["relative_mse_floor"] = num(floor);
        j["reference"] = info;
        j["relative_mse"] = num(e.rel_mse);
        j["pixel_coverage95"] = num(e.coverage);
        if (!std::isfinite(e.rel_mse)) j["warnings"].push_back(black_reference_warning());
    }
    j["images"] = images;
    *result_json = copy_out(dump(j));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    return boundary::succeed();
}

int mcp_render_study_plan(const char* scene_json, const char* options_json, char** plan_json) {
    using namespace mcp;
    LoadedRender l;
    Json options;
    if (int st = begin_render_call("mcp_render_study_plan", plan_json, scene_json, options_json, &l,
                                   &options))
        return st;
    const RenderRequest& r = *l.request;
    const RenderStudySettings& s = r.settings;
    std::string err;
    if (!check_render_study(r, &err)) return fail(MCP_ERROR_SCENE, err);
    const int threads = resolve_threads(s.threads);
    const double pixels = double(s.width) * double(s.height);
    // The pilot: each estimator renders one small image (at most 64 x 64 pixels, 1 spp) on one
    // thread; the seconds per sample scale to the study's samples over its threads.
    RenderSettings pilot;
    pilot.width = std::min(s.width, kPlanPilotSide);
    pilot.height = std::min(s.height, kPlanPilotSide);
    pilot.spp = 1;
    pilot.threads = 1;
    pilot.jitter_pixels = s.jitter_pixels;
    pilot.stream = replicate_stream(s.seed, "pilot", 1, -2);
    const double pilot_samples = double(pilot.width) * double(pilot.height);
    auto seconds_per_sample = [&](const RenderEstimator& e) {
        return render_image(l.scene, e, pilot).seconds / pilot_samples;
    };
    Json estimators = Json::array();
    double samples = 0.0, predicted = 0.0;
    const double per_estimator = pixels * study_spp_per_estimator(s);
    for (const RenderEstimator& e : r.estimators) {
        const double cost = seconds_per_sample(e);
        estimators.push_back({{"name", e.name},
                              {"samples", per_estimator},
                              {"seconds_per_sample", num(cost)},
                              {"predicted_seconds", num(per_estimator * cost / threads)}});
        samples += per_estimator;
        predicted += per_estimator * cost / threads;
    }
    // The reference: read from its file, taken from options.reference_data or the cache, or
    // rendered first.
    const std::string cache_file = reference_cache_file(r);
    std::string source = "rendered";
    if (!r.reference.file.empty())
        source = "file";
    else if (!r.supplied_reference.empty() &&
             encoded_reference_key(r.supplied_reference) == reference_key(r))
        source = "supplied"; // its content is checked when the study reads it
    else if (!cache_file.empty() && is_regular_file(cache_file))
        source = "cache"; // its content is checked when the study reads it
    Json reference{{"source", source}, {"spp", r.reference.spp}};
    if (source == "rendered") {
        const double ref_samples = pixels * double(r.reference.spp);
        const double ref_seconds =
            ref_samples * seconds_per_sample(r.reference.estimator) / threads;
        reference["samples"] = ref_samples;
        reference["predicted_seconds"] = num(ref_seconds);
        samples += ref_samples;
        predicted += ref_seconds;
    }
    Json out{{"version", kResultSchemaVersion},
             {"kind", "render"},
             {"samples", samples},
             {"limit_samples", kMaxCallSamples},
             {"predicted_seconds", num(predicted)},
             {"threads", threads},
             {"levels", n_ladder(s.spp_min, s.spp_max)},
             {"reps", s.reps},
             {"pilot_samples", pilot_samples},
             {"reference", reference},
             {"estimators", estimators}};
    *plan_json = copy_out(dump(out));
    if (!*plan_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the plan");
    return boundary::succeed();
}

int mcp_render_study_run(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                         void* user, char** result_json) {
    using namespace mcp;
    LoadedRender l;
    Json options;
    if (int st = begin_render_call("mcp_render_study_run", result_json, scene_json, options_json,
                                   &l, &options))
        return st;
    const RenderRequest& r = *l.request;
    bool previews = wants(options, "previews", false);
    std::string err;
    if (!check_render_study(r, &err)) return fail(MCP_ERROR_SCENE, err);
    RenderImage reference;
    Json ref_info;
    if (int st = obtain_reference_reporting(l, progress, user, &reference, &ref_info, &err))
        return fail(st, err);
    const double floor = relative_mse_floor(reference);
    int threads = resolve_threads(r.settings.threads);
    RenderStudyProgress on_level;
    if (progress) {
        on_level = [&](const RenderStudyResult& partial, size_t level) {
            Json ests = Json::array();
            uint64_t n = 0;
            for (const RenderEstimatorStudy& s : partial.estimators) {
                ests.push_back(estimator_study_to_json(s, previews, r.exposure, &reference, floor,
                                                       false, level));
                if (level < s.levels.size()) n = s.levels[level].n;
            }
            Json p{{"version", kResultSchemaVersion},
                   {"kind", "render"},
                   {"level_index", level},
                   {"n", n},
                   {"estimators", ests}};
            if (previews && level == 0)
                p["reference_png"] = base64_encode(encode_png(reference, r.exposure));
            add_part(&p, r.settings, summarise_reference(reference));
            std::string text = dump(p);
            return progress(text.c_str(), user) == 0;
        };
    }
    RenderStudyResult result =
        run_render_study(l.scene, r.estimators, r.settings, reference, on_level);
    Json scene = render_scene_to_json(l);
    ref_info["mean_luminance"] = num(result.reference_mean_luminance);
    ref_info["relative_mse_floor"] = num(floor);
    scene["reference"] = ref_info;
    if (!std::isfinite(floor)) scene["warnings"].push_back(black_reference_warning());
    scene["exact"] = num(result.reference_mean_luminance);
    scene["quantity"] = "relative_mse";
    Json ests = Json::array();
    for (const RenderEstimatorStudy& s : result.estimators)
        ests.push_back(
            estimator_study_to_json(s, previews, r.exposure, &reference, floor, true, 0));
    Json j{{"version", kResultSchemaVersion},
           {"kind", "render"},
           {"mcplay", mcp_version()},
           {"scene", scene},
           {"settings", render_settings_to_json(r.settings, threads)},
           {"cancelled", result.cancelled},
           {"wall_time_s", num(result.wall_seconds)},
           {"estimators", ests}};
    if (previews) j["reference_png"] = base64_encode(encode_png(reference, r.exposure));
    add_part(&j, r.settings, summarise_reference(reference));
    *result_json = copy_out(dump(j));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    if (result.cancelled) return fail(MCP_ERROR_CANCELLED, "study cancelled by the caller");
    return boundary::succeed();
}

int mcp_render_reference(const char* scene_json, const char* options_json, mcp_progress_fn progress,
                         void* user, char** result_json) {
    using namespace mcp;
    LoadedRender l;
    Json options;
    if (int st = begin_render_call("mcp_render_reference", result_json, scene_json, options_json,
                                   &l, &options))
        return st;
    const RenderRequest& r = *l.request;
    if (!r.reference.file.empty())
        return fail(MCP_ERROR_ARGUMENT, "scene.render.reference.file: this scene's reference is "
                                        "an image file; there is none to render");
    std::string err;
    if (!check_render_work(r, 0.0, 1, true, &err)) return fail(MCP_ERROR_SCENE, err);
    RenderImage reference;
    Json info;
    if (int st = obtain_reference_reporting(l, progress, user, &reference, &info, &err))
        return fail(st, err);
    const RenderStudySettings& s = r.settings;
    info["version"] = kResultSchemaVersion;
    info["kind"] = "render_reference";
    info["mcplay"] = mcp_version();
    info["scene"] = r.name;
    info["width"] = s.width;
    info["height"] = s.height;
    info["mean_luminance"] = num(mean_luminance(reference));
    info["relative_mse_floor"] = num(relative_mse_floor(reference));
    info["reference_data"] = base64_encode(encode_reference(reference, reference_key(r)));
    *result_json = copy_out(dump(info));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the reference");
    return boundary::succeed();
}

int mcp_render_study_merge(const char* parts_json, char** result_json) {
    using namespace mcp;
    if (!result_json)
        return fail(MCP_ERROR_ARGUMENT, "mcp_render_study_merge: the result pointer is NULL");
    *result_json = nullptr;
    Made<Json> in = parse_json(parts_json, "parts");
    if (!in.ok()) return fail(MCP_ERROR_ARGUMENT, in.error);
    Ctx c;
    Json merged;
    if (!merge_render_parts(c, in.value, &merged)) return fail(MCP_ERROR_ARGUMENT, c.error);
    *result_json = copy_out(dump(merged));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    return boundary::succeed();
}

} // extern "C"
