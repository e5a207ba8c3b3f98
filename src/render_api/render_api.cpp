// The render C API: scene file -> request -> renders -> JSON. Built without exceptions like
// the integration API; every failure is a status code plus mcp_last_error.
#include "render_api/mcplay_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "api/boundary.h"
#include "api/files.h"
#include "api/scene.h"
#include "render_api/image_io.h"
#include "render_api/render_request.h"

using mcp::boundary::copy_out;
using mcp::boundary::dump;
using mcp::boundary::fail;

namespace mcp {

namespace {

/// Part of every reference's cache key. Bumped whenever the renderer's image for a given seed
/// changes, so that no cache (nor a shipped reference) serves a reference the current build
/// would not render: 4 = stratified strata tables and Sobol' requests prepared per pixel;
/// 5 = solid-angle light sampling takes area samples of lights small from the point.
constexpr int kReferenceCacheVersion = 5;

/// Work and memory bounds, checked before anything is rendered: samples of a whole call
/// (every image of the study and the reference), and bytes of the images held at once
/// (each estimator's preview, the reference and the image being rendered, 48 bytes a pixel).
constexpr double kMaxCallSamples = 4398046511104.0; // 2^42
constexpr double kMaxImageBytes = 1073741824.0;     // 1 GiB
/// A rendered reference needs at least this many times the study's largest spp.
constexpr uint64_t kReferenceSppRatio = 4;
constexpr int kPlanPilotSide = 64; ///< a plan's pilot images are at most this many pixels a side

const char* selection_name(LightSelection s) {
    switch (s) {
    case LightSelection::Area: return "area";
    case LightSelection::Power: return "power";
    default: return "uniform";
    }
}

Json estimator_to_json(const RenderEstimator& e) {
    Json j{{"name", e.name},
           {"strategy", strategy_name(e.strategy)},
           {"light_selection", selection_name(e.light_selection)},
           {"light_sampling", e.light_sampling == LightSampling::Area ? "area" : "solid_angle"},
           {"pixel_sampler", pixel_sampler_name(e.pixel_sampler)}};
    if (e.strategy == RadianceStrategy::Path) {
        j["max_depth"] = e.max_depth;
        j["rr_depth"] = e.rr_depth;
    }
    return j;
}

/// The error concentration of level i (a default, flagless one if the study has none).
const ErrorConcentration& concentration_of(const RenderEstimatorStudy& s, size_t i) {
    static const ErrorConcentration none;
    return i < s.concentration.size() ? s.concentration[i] : none;
}

/// Warnings about an estimator over the whole study (the levels carry their own): the
/// render flags of the core (render_study.h), worded.
Json render_warnings(const RenderEstimatorStudy& s, double floor) {
    Json w = Json::array();
    const TailWording tail_words{"the samples' reflected radiance values", "samples", "spp",
                                 "the pixel variance"};
    for (const Flag& f : render_flags(s, floor)) {
        switch (f.code) {
        case FlagCode::ReferenceNoise:
            w.push_back(
                flag_warning(f, std::to_string(f.count) + " of " + std::to_string(f.of) +
                                    " spp level(s) have a relative MSE below the reference's "
                                    "own noise (floor " +
                                    fmt("%.3e", f.threshold) +
                                    "): those levels are left out of the fit and have no "
                                    "efficiency"));
            break;
        case FlagCode::HeavyTail:
        case FlagCode::HeavyTail4:
            w.push_back(tail_warning(f, s.levels.back().diagnostics.nonzero, tail_words));
            break;
        case FlagCode::SlowConvergence:
            w.push_back(
                flag_warning(f, "relative MSE falls as spp^" + fmt("%.2f", f.value) + " +/- " +
                                    fmt("%.2f", f.se) +
                                    ", slower than 1/spp: infinite variance, bias against the "
                                    "reference, or a reference too noisy for this spp"));
            break;
        case FlagCode::RareLargeErrors:
            w.push_back(flag_warning(
                f, "in " + std::to_string(f.count) + " of " + std::to_string(f.of) +
                       " spp level(s) the relative MSE rests on fewer than " +
                       fmt("%.0f", f.threshold) + " (pixel, image) errors (" +
                       fmt("%.1f", f.value) + " at spp = " + std::to_string(f.n) +
                       "): the error is made by rare large pixel errors (a camera ray that "
                       "hits a light from a dark pixel, a firefly). Levels that saw none "
                       "understate it, so the relative MSE need not fall with spp and the "
                       "fitted order is unreliable; more images per spp or more pixels average "
                       "more of them, and each level's relative_mse_median shows the typical "
                       "image"));
            break;
        case FlagCode::PixelErrorBars:
            w.push_back(
                flag_warning(f, "only " + fmt("%.1f", 100.0 * f.value) +
                                    "% of the pixels' own 95% error bars cover the reference at "
                                    "spp = " +
                                    std::to_string(f.n) +
                                    ": per-pixel error bars are too small (heavy tails or bias)"));
            break;
        default: break;
        }
    }
    sort_by_severity(w);
    return w;
}

/// A level's JSON: relative_mse (null when undefined, see render_study.h), its median over the
/// images and where its largest (pixel, image) term lies, and a flag and a warning when it lies
/// below the reference's relative-MSE floor or one pixel of one image carries most of it.
Json render_level_to_json(const LevelStats& l, const ErrorConcentration& c, double floor) {
    Json j = level_to_json(l);
    j["relative_mse"] = num(l.variance);
    j["relative_mse_median"] = num(c.median_rel_mse);
    j["error_concentration"] = Json{{"effective_terms", num(c.effective_terms)},
                                    {"worst_image", c.worst_image},
                                    {"worst_x", c.worst_x},
                                    {"worst_y", c.worst_y},
                                    {"worst_share", num(c.worst_share)}};
    j["below_reference_noise"] = false;
    for (const Flag& f : render_level_flags(l, c, floor)) {
        if (f.code == FlagCode::BelowReferenceNoise) {
            j["below_reference_noise"] = true;
            j["warnings"].push_back(flag_warning(
                f, "relative MSE " + fmt("%.3e", f.value) + " at spp = " + std::to_string(f.n) +
                       " is " + (f.value < 0.0 ? "negative" : "below") +
                       " the reference's own noise (relative-MSE floor " +
                       fmt("%.3e", f.threshold) +
                       "): it measures the reference, not the estimator; use a reference with "
                       "more spp"));
        } else if (f.code == FlagCode::FewPixelErrors) {
            j["warnings"].push_back(flag_warning(
                f, "the relative MSE at spp = " + std::to_string(f.n) + " rests on about " +
                       fmt("%.1f", f.value) + " (pixel, image) errors: pixel (" +
                       std::to_string(c.worst_x) + ", " + std::to_string(c.worst_y) +
                       ") of image " + std::to_string(c.worst_image + 1) + " of " +
                       std::to_string(c.images) + " alone carries " +
                       fmt("%.0f", 100.0 * c.worst_share) +
                       "% (the median image's relative MSE is " + fmt("%.3e", c.median_rel_mse) +
                       "): this level's number and interval rest on rare events"));
        }
    }
    return j;
}

/// One image's summary for a part of a split study: everything render_level_stats needs.
Json image_summary_to_json(const ImageSummary& im) {
    const ImageError& e = im.error;
    const RenderDiagnostics& d = im.diagnostics;
    Json top = Json::array();
    for (double x : d.top) top.push_back(num(x));
    return Json{{"replicate", im.replicate},
                {"spp", im.spp},
                {"seconds", num(im.seconds)},
                {"rel_mse", num(e.rel_mse)},
                {"rel_mse_raw", num(e.rel_mse_raw)},
                {"coverage", num(e.coverage)},
                {"mean_luminance", num(e.mean_luminance)},
                {"mean_luminance_se", num(e.mean_luminance_se)},
                {"worst_pixel_term", num(e.worst_pixel_term)},
                {"pixel_term_squares", num(e.pixel_term_squares)},
                {"worst_x", e.worst_x},
                {"worst_y", e.worst_y},
                {"samples", d.samples},
                {"discarded_nonfinite", d.discarded_nonfinite},
                {"rays", d.rays},
                {"light_misses", d.light_misses},
                {"dominated_pixels", d.dominated_pixels},
                {"max_sample_share", num(d.max_sample_share)},
                {"top", top}};
}

/// A required number of a part's JSON; null (how num writes NaN) reads as NaN.
bool read_number(Ctx& c, const Json& j, const char* key, const std::string& path, double* out) {
    const Json* v = find(j, key);
    if (!v) return c.fail(sub(path, key), "missing");
    if (v->is_null()) {
        *out = NAN;
        return true;
    }
    if (!v->is_number()) return c.fail(sub(path, key), "expected a number, got " + type_of(*v));
    *out = v->get<double>();
    return true;
}

bool read_count(Ctx& c, const Json& j, const char* key, const std::string& path, uint64_t* out) {
    if (!find(j, key)) return c.fail(sub(path, key), "missing");
    return get_count(c, j, key, path, out);
}

bool read_pixel(Ctx& c, const Json& j, const char* key, const std::string& path, int* out) {
    const Json* v = find(j, key);
    if (!v || !v->is_number_integer() || v->get<int64_t>() < -1 || v->get<int64_t>() >= 4096)
        return c.fail(sub(path, key), "expected an integer in -1..4095");
    *out = int(v->get<int64_t>());
    return true;
}

bool image_summary_from_json(Ctx& c, const Json& j, const std::string& path, ImageSummary* im) {
    if (!j.is_object()) return c.fail(path, "expected an object, got " + type_of(j));
    ImageError& e = im->error;
    RenderDiagnostics& d = im->diagnostics;
    uint64_t replicate = 0;
    if (!read_count(c, j, "replicate", path, &replicate) ||
        !read_count(c, j, "spp", path, &im->spp) ||
        !read_number(c, j, "seconds", path, &im->seconds) ||
        !read_number(c, j, "rel_mse", path, &e.rel_mse) ||
        !read_number(c, j, "rel_mse_raw", path, &e.rel_mse_raw) ||
        !read_number(c, j, "coverage", path, &e.coverage) ||
        !read_number(c, j, "mean_luminance", path, &e.mean_luminance) ||
        !read_number(c, j, "mean_luminance_se", path, &e.mean_luminance_se) ||
        !read_number(c, j, "worst_pixel_term", path, &e.worst_pixel_term) ||
        !read_number(c, j, "pixel_term_squares", path, &e.pixel_term_squares) ||
        !read_pixel(c, j, "worst_x", path, &e.worst_x) ||
        !read_pixel(c, j, "worst_y", path, &e.worst_y) ||
        !read_count(c, j, "samples", path, &d.samples) ||
        !read_count(c, j, "discarded_nonfinite", path, &d.discarded_nonfinite) ||
        !read_count(c, j, "rays", path, &d.rays) ||
        !read_count(c, j, "light_misses", path, &d.light_misses) ||
        !read_count(c, j, "dominated_pixels", path, &d.dominated_pixels) ||
        !read_number(c, j, "max_sample_share", path, &d.max_sample_share))
        return false;
    if (replicate >= 1024) return c.fail(sub(path, "replicate"), "must be in 0..1023");
    if (im->spp < 1) return c.fail(sub(path, "spp"), "must be at least 1");
    if (!(im->seconds >= 0.0)) return c.fail(sub(path, "seconds"), "expected a number >= 0");
    im->replicate = int(replicate);
    const Json* top = find(j, "top");
    if (!top || !top->is_array() || top->size() > kTopWeights)
        return c.fail(sub(path, "top"),
                      "expected an array of at most " + std::to_string(kTopWeights) + " numbers");
    d.top.clear();
    for (size_t i = 0; i < top->size(); ++i) {
        const Json& x = (*top)[i];
        if (!x.is_number() || !(x.get<double>() >= 0.0))
            return c.fail(sub(path, "top") + "[" + std::to_string(i) + "]",
                          "expected a number >= 0");
        d.top.push_back(x.get<double>());
    }
    return true;
}

struct Loaded {
    std::shared_ptr<RenderRequest> request;
    RenderScene scene;
};

int load(const char* scene_json, const char* options_json, Loaded* out, Json* options) {
    Made<Json> scene = parse_json(scene_json, "scene");
    if (!scene.ok()) return fail(MCP_ERROR_SCENE, scene.error);
    *options = Json::object();
    if (options_json && *options_json) {
        Made<Json> o = parse_json(options_json, "options");
        if (!o.ok()) return fail(MCP_ERROR_ARGUMENT, o.error);
        if (!o.value.is_object()) return fail(MCP_ERROR_ARGUMENT, "options: expected an object");
        *options = o.value;
    }
    if (!is_render_scene(scene.value))
        return fail(MCP_ERROR_SCENE, "scene: not a render scene (no \"render\" object)");
    Made<std::shared_ptr<RenderRequest>> req = build_render_request(scene.value, *options);
    if (!req.ok()) return boundary::request_error(req.error);
    out->request = req.value;
    out->scene.build(*out->request->scene, out->request->accel);
    // A light whose emission or area is NaN or infinite cannot be rendered; dropping it would
    // leave a silently darker image.
    if (size_t bad = out->scene.lights_uniform.nonfinite())
        return fail(MCP_ERROR_SCENE, "scene.render.gltf: " + std::to_string(bad) +
                                         " emissive triangle(s) have a non-finite emission or "
                                         "area: expected finite emissiveFactor x "
                                         "emissiveStrength and finite positions");
    return MCP_OK;
}

/// The start of every render call: the out-parameter checked and cleared, the scene loaded.
int begin_call(const char* function, char** out, const char* scene_json, const char* options_json,
               Loaded* loaded, Json* options) {
    if (!out)
        return fail(MCP_ERROR_ARGUMENT, std::string(function) + ": the result pointer is NULL");
    *out = nullptr;
    return load(scene_json, options_json, loaded, options);
}

std::string hex(uint64_t x) {
    char buf[20];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(x));
    return buf;
}

/// The hash of everything a rendered reference depends on: the glTF, the scene's name, the
/// image size, the reference's estimator, spp and seed, and the renderer's version. It names
/// the cache file and is stored in it (and in a supplied reference): nothing of the scene's
/// text reaches a path.
uint64_t reference_key(const RenderRequest& r) {
    const RenderStudySettings& s = r.settings;
    const RenderEstimator& e = r.reference.estimator;
    uint64_t key = hash_combine(r.gltf_hash, uint64_t(kReferenceCacheVersion));
    key = hash_combine(key, hash_string(r.name.c_str()));
    for (uint64_t v :
         {uint64_t(s.width), uint64_t(s.height), uint64_t(s.jitter_pixels), uint64_t(e.strategy),
          uint64_t(e.light_selection), uint64_t(e.light_sampling), uint64_t(e.pixel_sampler),
          uint64_t(e.max_depth), uint64_t(e.rr_depth), r.reference.spp, r.reference.seed})
        key = hash_combine(key, v);
    return key;
}

/// Where a rendered reference is cached ("" without a cache folder).
std::string reference_cache_file(const RenderRequest& r) {
    if (r.cache_dir.empty()) return "";
    return r.cache_dir + "/" + hex(reference_key(r)) + ".mcref";
}

/// Called with the rows of the reference rendered so far and the image's rows; false cancels.
using ReferenceProgress = std::function<bool(int rows_done, int rows)>;

/// The reference image: read from the scene's HDR file, taken from options.reference_data
/// when it was made from the same scene and settings, read from the cache, or rendered (and
/// then cached). `source` says which; a supplied reference that is not used says why.
bool obtain_reference(const Loaded& l, RenderImage* ref, Json* info, std::string* error,
                      const ReferenceProgress& progress = nullptr) {
    const RenderRequest& r = *l.request;
    const RenderStudySettings& s = r.settings;
    if (!r.reference.file.empty()) {
        // The path was resolved and checked to lie inside the scene's folder when the request
        // was built; here it is read only if it is a regular file of bounded size.
        std::string bytes;
        if (!read_regular_file(r.reference.file, kMaxReferenceFileBytes, &bytes, error)) {
            *error = "reference.file: " + *error;
            return false;
        }
        if (!decode_hdr(bytes, ref, error)) {
            *error = "reference.file: " + *error;
            return false;
        }
        if (ref->width != s.width || ref->height != s.height) {
            *error = "reference.file: the image is " + std::to_string(ref->width) + "x" +
                     std::to_string(ref->height) + " but the render is " + std::to_string(s.width) +
                     "x" + std::to_string(s.height);
            return false;
        }
        *info = Json{{"source", "file"}, {"file", r.reference.file}};
        return true;
    }
    const RenderEstimator& e = r.reference.estimator;
    const uint64_t key = reference_key(r);
    *info = Json{
        {"estimator", estimator_to_json(e)}, {"spp", r.reference.spp}, {"seed", r.reference.seed}};
    if (!r.supplied_reference.empty()) {
        if (encoded_reference_key(r.supplied_reference) != key) {
            (*info)["supplied"] = "not used: it was made from another scene, image size, "
                                  "reference estimator, spp or seed, or by another version";
        } else if (!decode_reference(r.supplied_reference, key, ref) || ref->width != s.width ||
                   ref->height != s.height || ref->spp != r.reference.spp) {
            *error = "options.reference_data: a corrupt reference image (its sizes, length or "
                     "values are not what mcplay writes)";
            return false;
        } else {
            (*info)["source"] = "supplied";
            return true;
        }
    }
    const std::string cache_file = reference_cache_file(r);
    if (!cache_file.empty() && read_reference_cache(cache_file, key, ref) &&
        ref->width == s.width && ref->height == s.height && ref->spp == r.reference.spp) {
        (*info)["source"] = "cache";
        (*info)["file"] = cache_file;
        return true;
    }
    RenderSettings rs;
    rs.width = s.width;
    rs.height = s.height;
    rs.spp = r.reference.spp;
    // Its own stream, from its own seed: no study image shares random numbers with it, and a
    // study's seed does not change it.
    rs.stream = replicate_stream(r.reference.seed, "reference", r.reference.spp, -1);
    rs.threads = resolve_threads(s.threads);
    rs.jitter_pixels = s.jitter_pixels;
    rs.progress = progress;
    *ref = render_image(l.scene, e, rs);
    if (ref->cancelled) {
        *error = "cancelled while rendering the reference";
        return false;
    }
    (*info)["source"] = "rendered";
    (*info)["seconds"] = num(ref->seconds);
    if (!cache_file.empty() && write_reference_cache(cache_file, *ref, key))
        (*info)["file"] = cache_file;
    return true;
}

/// The progress lines of a reference being rendered, {"kind": "render_reference", "rows_done",
/// "rows"}, at most one per percent; sets *cancelled when the callback asks to stop.
ReferenceProgress reference_progress(mcp_progress_fn progress, void* user, bool* cancelled) {
    if (!progress) return nullptr;
    return [progress, user, cancelled, last = -1](int rows_done, int rows) mutable {
        const int percent = int(100.0 * rows_done / std::max(1, rows));
        if (percent == last) return true;
        last = percent;
        const std::string text = dump(Json{{"version", kResultSchemaVersion},
                                           {"kind", "render_reference"},
                                           {"rows_done", rows_done},
                                           {"rows", rows}});
        if (progress(text.c_str(), user) == 0) return true;
        *cancelled = true;
        return false;
    };
}

/// obtain_reference for a C API call with a progress callback: MCP_OK, or the status to fail
/// with (MCP_ERROR_CANCELLED when the callback stopped it, else MCP_ERROR_SCENE; `error` says).
int obtain_reference_reporting(const Loaded& l, mcp_progress_fn progress, void* user,
                               RenderImage* ref, Json* info, std::string* error) {
    bool cancelled = false;
    if (obtain_reference(l, ref, info, error, reference_progress(progress, user, &cancelled)))
        return MCP_OK;
    return cancelled ? MCP_ERROR_CANCELLED : MCP_ERROR_SCENE;
}

Json scene_to_json(const Loaded& l) {
    const RenderRequest& r = *l.request;
    const Scene& sc = *r.scene;
    const AccelStats& a = l.scene.accel.stats();
    Json warnings = Json::array();
    for (const std::string& w : r.warnings)
        warnings.push_back(warning("gltf", Severity::Warning, w));
    const LightSet& lights = l.scene.lights_uniform;
    if (size_t n = lights.degenerate())
        warnings.push_back(warning("degenerate_lights", Severity::Info,
                                   std::to_string(n) +
                                       " emissive triangle(s) have zero area: they can neither be "
                                       "hit nor sampled and are left out of the lights"));
    if (lights.empty())
        warnings.push_back(warning("no_lights", Severity::Warning,
                                   "the scene has no emissive surface: every image is black"));
    Json materials = Json::array();
    for (const Material& m : sc.materials)
        materials.push_back(Json{{"name", m.name},
                                 {"base_color", {m.base_color.x, m.base_color.y, m.base_color.z}},
                                 {"metallic", m.metallic},
                                 {"roughness", m.roughness},
                                 {"emission", {m.emission.x, m.emission.y, m.emission.z}},
                                 {"textured", m.base_color_texture >= 0}});
    return Json{{"name", r.name},
                {"description", r.description},
                {"kind", "render"},
                {"gltf", r.gltf_path},
                {"width", r.settings.width},
                {"height", r.settings.height},
                {"triangles", sc.mesh.triangle_count()},
                {"lights", l.scene.lights_uniform.size()},
                {"degenerate_lights", l.scene.lights_uniform.degenerate()},
                {"light_power", num(l.scene.lights_uniform.total_power())},
                {"materials", materials},
                {"textures", sc.textures.size()},
                {"surface_kernel", surface_kernel_name(surface_kernel(sc))},
                {"accel",
                 {{"kind", a.kind == AccelKind::Bvh ? "bvh" : "brute_force"},
                  {"width", Accelerator::kNodeWidth},
                  {"nodes", a.nodes},
                  {"leaves", a.leaves},
                  {"max_depth", a.max_depth},
                  {"build_depth", a.build_depth},
                  {"bytes", a.bytes},
                  {"expected_node_visits", a.expected_node_visits},
                  {"expected_triangle_tests", a.expected_triangle_tests}}},
                {"warnings", warnings}};
}

Json settings_to_json(const RenderStudySettings& s, int threads) {
    return Json{{"n_min", s.spp_min},
                {"n_max", s.spp_max},
                {"reps", s.reps},
                {"seed", s.seed},
                {"threads", threads},
                {"n_name", "spp"},
                {"error_name", "relative_mse"},
                {"jitter_pixels", s.jitter_pixels}};
}

/// Level i's JSON, with its images when the study is a part of a split one.
Json part_level_to_json(const RenderEstimatorStudy& s, size_t i, double floor) {
    Json j = render_level_to_json(s.levels[i], concentration_of(s, i), floor);
    if (i < s.images.size()) {
        Json images = Json::array();
        for (const ImageSummary& im : s.images[i]) images.push_back(image_summary_to_json(im));
        j["images"] = images;
    }
    return j;
}

/// What a part of a split study adds to its result and progress lines.
void add_part(Json* j, const RenderStudySettings& s, const ReferenceSummary& ref) {
    if (s.parts <= 1) return;
    (*j)["part"] = Json{{"index", s.part}, {"of", s.parts}};
    (*j)["reference_summary"] = Json{{"mean_luminance", num(ref.mean_luminance)},
                                     {"mean_luminance_se", num(ref.mean_luminance_se)},
                                     {"relative_mse_floor", num(ref.floor)}};
}

Json estimator_study_to_json(const RenderEstimatorStudy& s, bool previews, double exposure,
                             const RenderImage* reference, double floor, bool all_levels,
                             size_t level) {
    Json j = estimator_to_json(s.estimator);
    j["warnings"] = render_warnings(s, floor);
    if (all_levels) {
        Json levels = Json::array();
        for (size_t i = 0; i < s.levels.size(); ++i)
            levels.push_back(part_level_to_json(s, i, floor));
        j["levels"] = levels;
    } else if (level < s.levels.size()) {
        j["level"] = part_level_to_json(s, level, floor);
    }
    j["fit"] = fit_to_json(s.fit);
    const RenderDiagnostics& d = s.preview.diagnostics;
    j["rays_per_second"] = num(s.preview.seconds > 0 ? double(d.rays) / s.preview.seconds : NAN);
    if (previews && s.preview.pixel_count()) {
        j["preview_png"] = base64_encode(encode_png(s.preview, exposure));
        if (reference) j["error_png"] = base64_encode(encode_error_png(s.preview, *reference));
    }
    return j;
}

/// Checks the work and memory of a call before anything is rendered: `image_spp` per image
/// times `images` images of the estimators (one spp each, or the study's ladder), plus the
/// reference when it is rendered, and `held` images in memory at once.
bool check_work(const RenderRequest& r, double image_samples_per_pixel, size_t held,
                bool reference_rendered, std::string* error) {
    const RenderStudySettings& s = r.settings;
    double pixels = double(s.width) * double(s.height);
    double per_pixel =
        image_samples_per_pixel + (reference_rendered ? double(r.reference.spp) : 0.0);
    double samples = pixels * per_pixel;
    if (!(samples <= kMaxCallSamples)) {
        *error = "scene.render: this needs " + fmt("%.3g", samples) +
                 " samples (width x height x (spp x reps x estimators, summed over the spp "
                 "ladder, plus the reference's spp)), more than the limit of " +
                 fmt("%.3g", kMaxCallSamples) +
                 ": lower spp_max, reps, the image size, the estimators or reference.spp";
        return false;
    }
    double bytes = pixels * 48.0 * double(held);
    if (!(bytes <= kMaxImageBytes)) {
        *error = "scene.render: " + std::to_string(held) + " images of " + std::to_string(s.width) +
                 "x" + std::to_string(s.height) + " pixels held at once need " +
                 fmt("%.0f", bytes / 1048576.0) + " MiB, more than the limit of " +
                 fmt("%.0f", kMaxImageBytes / 1048576.0) +
                 " MiB: lower the image size or the number of estimators";
        return false;
    }
    return true;
}

/// Samples per pixel of one estimator's study images: the spp ladder times the replicates.
double study_spp_per_estimator(const RenderStudySettings& s) {
    double spp = 0.0;
    for (uint64_t n : n_ladder(s.spp_min, s.spp_max)) spp += double(n);
    return spp * double(s.reps);
}

/// The checks of a study before anything is rendered: a rendered reference must have many
/// more samples than the study's images, or its own noise is what the study measures
/// (docs/render-scenes.md, "The reference's noise"); then the work and memory.
bool check_study(const RenderRequest& r, std::string* error) {
    const bool ref_rendered = r.reference.file.empty();
    if (ref_rendered && r.settings.spp_max > r.reference.spp / kReferenceSppRatio) {
        *error = "scene.render.reference.spp: expected at least " +
                 std::to_string(kReferenceSppRatio) +
                 " x spp_max = " + std::to_string(kReferenceSppRatio * r.settings.spp_max) +
                 ", got " + std::to_string(r.reference.spp) +
                 ": a reference with fewer samples is too noisy to judge the images";
        return false;
    }
    return check_work(r, study_spp_per_estimator(r.settings) * double(r.estimators.size()),
                      r.estimators.size() + 2, ref_rendered, error);
}

/// The warning of a result whose reference is black (relative MSE undefined, null).
Json black_reference_warning() {
    return warning("black_reference", Severity::Warning,
                   "the reference image is black (mean luminance 0): relative MSE is undefined "
                   "and reported as null");
}

bool wants(const Json& options, const char* key, bool fallback) {
    auto it = options.find(key);
    return it != options.end() && it->is_boolean() ? it->get<bool>() : fallback;
}

/// Each estimator's levels, fit and warnings merged from the parts of a split study
/// (mcp_render_study_merge): the images of every part at each level, by replicate.
bool merge_estimator(Ctx& c, const std::vector<const Json*>& parts, size_t e,
                     const ReferenceSummary& ref, Json* out) {
    const std::string path = "parts[*].estimators[" + std::to_string(e) + "]";
    size_t levels = SIZE_MAX;
    for (const Json* part : parts) {
        const Json& est = (*part)["estimators"][e];
        const Json* ls = find(est, "levels");
        if (!ls || !ls->is_array() || ls->size() > 64)
            return c.fail(sub(path, "levels"), "expected an array of at most 64 levels");
        levels = std::min(levels, ls->size());
    }
    RenderEstimatorStudy study;
    for (size_t i = 0; i < levels; ++i) {
        const std::string lp = path + ".levels[" + std::to_string(i) + "]";
        std::vector<ImageSummary> images;
        for (const Json* part : parts) {
            const Json& level = (*part)["estimators"][e]["levels"][i];
            const Json* list = level.is_object() ? find(level, "images") : nullptr;
            if (!list || !list->is_array() || list->size() > 1024)
                return c.fail(sub(lp, "images"), "expected an array of at most 1024 images");
            for (size_t k = 0; k < list->size(); ++k) {
                ImageSummary im;
                if (!image_summary_from_json(c, (*list)[k],
                                             lp + ".images[" + std::to_string(k) + "]", &im))
                    return false;
                images.push_back(im);
            }
        }
        if (images.empty() || images.size() > 1024)
            return c.fail(lp, "expected 1..1024 images over the parts");
        std::sort(images.begin(), images.end(), [](const ImageSummary& a, const ImageSummary& b) {
            return a.replicate < b.replicate;
        });
        for (size_t k = 1; k < images.size(); ++k) {
            if (images[k].spp != images[0].spp)
                return c.fail(lp, "the parts' images have different spp");
            if (images[k].replicate == images[k - 1].replicate)
                return c.fail(lp, "replicate " + std::to_string(images[k].replicate) +
                                      " is in two parts");
        }
        ErrorConcentration conc;
        study.levels.push_back(render_level_stats(images, ref, &conc));
        study.concentration.push_back(conc);
    }
    study.fit = fit_render_convergence(study.levels, ref.floor);
    Json levels_json = Json::array();
    for (size_t i = 0; i < study.levels.size(); ++i)
        levels_json.push_back(
            render_level_to_json(study.levels[i], study.concentration[i], ref.floor));
    (*out)["levels"] = levels_json;
    (*out)["fit"] = fit_to_json(study.fit);
    (*out)["warnings"] = study.levels.empty() ? Json::array() : render_warnings(study, ref.floor);
    return true;
}

/// Checks the parts of a split study and merges them into *out.
bool merge_parts(Ctx& c, const Json& in, Json* out) {
    if (!in.is_object()) return c.fail("parts", "expected an object {\"parts\": [...]}");
    if (!check_keys(c, in, "parts", {"parts"})) return false;
    const Json* list = find(in, "parts");
    if (!list || !list->is_array() || list->empty() || list->size() > 1024)
        return c.fail("parts.parts", "expected an array of 1..1024 study results");
    const size_t k = list->size();
    std::vector<const Json*> parts(k, nullptr);
    ReferenceSummary ref;
    for (size_t i = 0; i < k; ++i) {
        const Json& p = (*list)[i];
        const std::string pp = "parts[" + std::to_string(i) + "]";
        if (!p.is_object()) return c.fail(pp, "expected a study result, got " + type_of(p));
        const Json* part = find(p, "part");
        const Json* rs = find(p, "reference_summary");
        const Json* ests = find(p, "estimators");
        if (!part || !part->is_object() || !rs || !rs->is_object())
            return c.fail(pp, "not a part of a split study (no \"part\" and "
                              "\"reference_summary\": run it with options.part and parts)");
        uint64_t index = 0, of = 0;
        if (!read_count(c, *part, "index", sub(pp, "part"), &index) ||
            !read_count(c, *part, "of", sub(pp, "part"), &of))
            return false;
        if (of != k)
            return c.fail(sub(pp, "part.of"), "is " + std::to_string(of) + ", but " +
                                                  std::to_string(k) + " parts were given");
        if (index >= k || parts[index])
            return c.fail(sub(pp, "part.index"),
                          "each index 0.." + std::to_string(k - 1) + " must be given once");
        parts[index] = &p;
        ReferenceSummary r;
        if (!read_number(c, *rs, "mean_luminance", sub(pp, "reference_summary"),
                         &r.mean_luminance) ||
            !read_number(c, *rs, "mean_luminance_se", sub(pp, "reference_summary"),
                         &r.mean_luminance_se) ||
            !read_number(c, *rs, "relative_mse_floor", sub(pp, "reference_summary"), &r.floor))
            return false;
        auto same = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
        if (i == 0)
            ref = r;
        else if (!same(r.mean_luminance, ref.mean_luminance) ||
                 !same(r.mean_luminance_se, ref.mean_luminance_se) || !same(r.floor, ref.floor))
            return c.fail(sub(pp, "reference_summary"),
                          "differs from parts[0]'s: the parts used different references");
        if (!ests || !ests->is_array() || ests->empty() || ests->size() > 64)
            return c.fail(sub(pp, "estimators"), "expected an array of 1..64 estimators");
    }
    const Json& first = *parts[0];
    for (size_t i = 0; i < k; ++i) {
        const Json& ests = (*parts[i])["estimators"];
        if (ests.size() != first["estimators"].size())
            return c.fail("parts", "the parts study different estimators");
        for (size_t e = 0; e < ests.size(); ++e)
            if (!ests[e].is_object() || !ests[e].contains("name") ||
                ests[e]["name"] != first["estimators"][e]["name"])
                return c.fail("parts", "the parts study different estimators");
    }
    *out = first;
    out->erase("part");
    out->erase("reference_summary");
    bool cancelled = false;
    double wall = 0.0;
    uint64_t threads = 0;
    for (const Json* p : parts) {
        const Json* cn = find(*p, "cancelled");
        cancelled = cancelled || (cn && cn->is_boolean() && cn->get<bool>());
        const Json* w = find(*p, "wall_time_s");
        if (w && w->is_number()) wall = std::max(wall, w->get<double>());
        const Json* st = find(*p, "settings");
        const Json* t = st && st->is_object() ? find(*st, "threads") : nullptr;
        threads += t && t->is_number_unsigned() ? std::min<uint64_t>(t->get<uint64_t>(), 256) : 1;
    }
    (*out)["cancelled"] = cancelled;
    (*out)["wall_time_s"] = wall;
    if (out->contains("settings") && (*out)["settings"].is_object())
        (*out)["settings"]["threads"] = threads;
    for (size_t e = 0; e < first["estimators"].size(); ++e)
        if (!merge_estimator(c, parts, e, ref, &(*out)["estimators"][e])) return false;
    return true;
}

} // namespace

} // namespace mcp

extern "C" {

int mcp_render_scene_info(const char* scene_json, const char* options_json, char** info_json) {
    using namespace mcp;
    Loaded l;
    Json options;
    if (int st =
            begin_call("mcp_render_scene_info", info_json, scene_json, options_json, &l, &options))
        return st;
    Json j = scene_to_json(l);
    Json ests = Json::array();
    for (const RenderEstimator& e : l.request->estimators) ests.push_back(estimator_to_json(e));
    j["estimators"] = ests;
    j["settings"] =
        settings_to_json(l.request->settings, resolve_threads(l.request->settings.threads));
    j["reference"] = Json{{"estimator", estimator_to_json(l.request->reference.estimator)},
                          {"spp", l.request->reference.spp},
                          {"file", l.request->reference.file}};
    *info_json = copy_out(dump(j));
    if (!*info_json) return fail(MCP_ERROR_INTERNAL, "out of memory");
    return boundary::succeed();
}

int mcp_render_image(const char* scene_json, const char* options_json, char** result_json) {
    using namespace mcp;
    Loaded l;
    Json options;
    if (int st =
            begin_call("mcp_render_image", result_json, scene_json, options_json, &l, &options))
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
        if (!check_work(r, 0.0, 1, r.reference.file.empty(), &err))
            return fail(MCP_ERROR_SCENE, err);
        RenderImage ref;
        Json info;
        if (!obtain_reference(l, &ref, &info, &err)) return fail(MCP_ERROR_SCENE, err);
        Json images = Json::object();
        if (reference_png) images["reference_png"] = base64_encode(encode_png(ref, r.exposure));
        if (reference_hdr) images["reference_hdr"] = base64_encode(encode_hdr(ref));
        Json j{
            {"version", kResultSchemaVersion}, {"kind", "render_image"}, {"mcplay", mcp_version()},
            {"scene", scene_to_json(l)},       {"reference", info},      {"images", images}};
        *result_json = copy_out(dump(j));
        if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
        return boundary::succeed();
    }
    {
        std::string err;
        bool ref_rendered = error_png && r.reference.file.empty();
        if (!check_work(r, double(spp), 2, ref_rendered, &err)) return fail(MCP_ERROR_SCENE, err);
    }
    RenderSettings rs;
    rs.width = r.settings.width;
    rs.height = r.settings.height;
    rs.spp = spp;
    rs.stream = replicate_stream(r.settings.seed, est.name, spp, 0);
    rs.threads = resolve_threads(r.settings.threads);
    rs.jitter_pixels = r.settings.jitter_pixels;
    RenderImage image = render_image(l.scene, est, rs);
    const RenderDiagnostics& d = image.diagnostics;
    Json diag{{"samples", d.samples},
              {"discarded_nonfinite", d.discarded_nonfinite},
              {"rays", d.rays},
              {"light_misses", d.light_misses},
              {"dominated_pixels", d.dominated_pixels},
              {"max_sample_share", num(d.max_sample_share)}};
    Json warnings = Json::array();
    if (d.discarded_nonfinite)
        warnings.push_back(warning("nonfinite", Severity::Error,
                                   std::to_string(d.discarded_nonfinite) +
                                       " sample(s) with NaN/Inf radiance were "
                                       "discarded: the image is biased there"));
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
           {"scene", scene_to_json(l)},
           {"estimator", estimator_to_json(est)},
           {"spp", spp},
           {"seconds", num(image.seconds)},
           {"rays_per_second", num(image.seconds > 0 ? double(d.rays) / image.seconds : NAN)},
           {"diagnostics", diag},
           {"warnings", warnings}};
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
    Loaded l;
    Json options;
    if (int st =
            begin_call("mcp_render_study_plan", plan_json, scene_json, options_json, &l, &options))
        return st;
    const RenderRequest& r = *l.request;
    const RenderStudySettings& s = r.settings;
    std::string err;
    if (!check_study(r, &err)) return fail(MCP_ERROR_SCENE, err);
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
    // The reference: read from a file or the cache, or rendered first.
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
    Loaded l;
    Json options;
    if (int st =
            begin_call("mcp_render_study_run", result_json, scene_json, options_json, &l, &options))
        return st;
    const RenderRequest& r = *l.request;
    bool previews = wants(options, "previews", false);
    std::string err;
    if (!check_study(r, &err)) return fail(MCP_ERROR_SCENE, err);
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
    Json scene = scene_to_json(l);
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
           {"settings", settings_to_json(r.settings, threads)},
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
    Loaded l;
    Json options;
    if (int st =
            begin_call("mcp_render_reference", result_json, scene_json, options_json, &l, &options))
        return st;
    const RenderRequest& r = *l.request;
    if (!r.reference.file.empty())
        return fail(MCP_ERROR_ARGUMENT, "scene.render.reference.file: this scene's reference is "
                                        "an image file; there is none to render");
    std::string err;
    if (!check_work(r, 0.0, 1, true, &err)) return fail(MCP_ERROR_SCENE, err);
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
    if (!merge_parts(c, in.value, &merged)) return fail(MCP_ERROR_ARGUMENT, c.error);
    *result_json = copy_out(dump(merged));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    return boundary::succeed();
}

} // extern "C"
