// Render scene JSON -> RenderRequest (render_request.h): every field checked with a message
// naming its path, the glTF loaded from inside the scene's folder, and the settings taken from
// the glTF's extras.mcplay, the scene and the options, each over the one before.
#include "render_api/render_request.h"

#include <cmath>

#include "api/files.h"
#include "api/report.h" // fmt
#include "api/scene.h"  // parse_json
#include "core/rng.h"
#include "estimators/study.h" // n_ladder
#include "render_api/gltf_scene.h"
#include "render_api/image_io.h"

namespace mcp {

namespace {

constexpr int kMaxImageSide = 4096;
constexpr uint64_t kMaxPixels = uint64_t(1) << 22;
constexpr uint64_t kMaxSpp = uint64_t(1) << 20;

std::string dirname_of(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

bool parse_enum(Ctx& c, const Json& obj, const char* key, const std::string& path,
                const std::vector<std::string>& names, int* out) {
    std::string s;
    if (!get_string(c, obj, key, path, &s)) return false;
    if (!find(obj, key)) return true;
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == s) {
            *out = int(i);
            return true;
        }
    return c.fail(sub(path, key), "unknown value '" + s + "' (known: " + join(names) + ")");
}

std::vector<std::string> strategy_names() {
    std::vector<std::string> names;
    for (int s = 0; s <= int(RadianceStrategy::Ris); ++s)
        names.push_back(strategy_name(RadianceStrategy(s)));
    return names;
}

/// ris draws its candidates cheaply by default (a light chosen uniformly, a point uniform in
/// its area) and leaves the importance to its target [Talbot05]; both can be set.
void use_ris_defaults(RenderEstimator* e) {
    e->light_selection = LightSelection::Uniform;
    e->light_sampling = LightSampling::Area;
    e->candidates = 8;
}

/// light_samples and bsdf_samples (splitting, integrator.h): whole numbers in
/// 1..kMaxSplitSamples, on the strategies that draw such samples; light_samples may be "auto"
/// (0: a timed pilot chooses it, splitting.h). emission_samples (camera rays per sample for
/// the emission seen directly) is taken by every strategy, in the same range or "auto".
bool parse_split_counts(Ctx& c, const Json& j, const std::string& path, RenderEstimator* e) {
    const RadianceStrategy s = e->strategy;
    const bool mis = s == RadianceStrategy::MisBalance || s == RadianceStrategy::MisPower ||
                     s == RadianceStrategy::Path;
    const bool samples_lights = mis || s == RadianceStrategy::LightArea ||
                                s == RadianceStrategy::LightSolidAngle ||
                                s == RadianceStrategy::Ris;
    const bool samples_bsdf = mis || s == RadianceStrategy::Bsdf;
    const std::string range = "must be a whole number in 1.." + std::to_string(kMaxSplitSamples);
    struct Count {
        const char* key;
        bool allowed;
        const char* who;
        int* out;
        bool automatic; ///< takes "auto" (0: a timed pilot chooses it, splitting.h)
    };
    const Count counts[] = {{"light_samples", samples_lights,
                             "strategies that sample lights (light_area, "
                             "light_solid_angle, mis_balance, mis_power, path, ris)",
                             &e->light_samples, true},
                            {"bsdf_samples", samples_bsdf,
                             "strategies that sample the BSDF (bsdf, mis_balance, "
                             "mis_power, path)",
                             &e->bsdf_samples, false},
                            {"emission_samples", true, "", &e->emission_samples, true}};
    for (const Count& k : counts) {
        const Json* v = find(j, k.key);
        if (!v) continue;
        if (!k.allowed)
            return c.fail(sub(path, k.key), std::string("only the ") + k.who + " take it, not '" +
                                                strategy_name(s) + "'");
        const bool automatic = k.automatic;
        if (v->is_string() && v->get<std::string>() == "auto" && automatic) {
            *k.out = 0;
            continue;
        }
        const bool whole = v->is_number_integer() || v->is_number_unsigned();
        if (!whole || v->get<int64_t>() < 1 || v->get<int64_t>() > kMaxSplitSamples)
            return c.fail(sub(path, k.key),
                          range + (automatic ? " or \"auto\"" : "") + ", got " + v->dump());
        *k.out = int(v->get<int64_t>());
    }
    return true;
}

/// candidates (RIS, integrator.h): a whole number in kMinRisCandidates..kMaxRisCandidates or
/// "auto" (0: a timed pilot chooses it, splitting.h), on the strategies that sample lights
/// beside or instead of the BSDF by one light sample (ris, mis_*, path).
bool parse_candidates(Ctx& c, const Json& j, const std::string& path, RenderEstimator* e) {
    const Json* v = find(j, "candidates");
    if (!v) return true;
    const RadianceStrategy s = e->strategy;
    if (s != RadianceStrategy::Ris && s != RadianceStrategy::MisBalance &&
        s != RadianceStrategy::MisPower && s != RadianceStrategy::Path)
        return c.fail(sub(path, "candidates"), std::string("only ris, mis_balance, mis_power and "
                                                           "path resample candidates, not '") +
                                                   strategy_name(s) + "'");
    if (v->is_string() && v->get<std::string>() == "auto") {
        e->candidates = 0;
        return true;
    }
    const bool whole = v->is_number_integer() || v->is_number_unsigned();
    if (!whole || v->get<int64_t>() < kMinRisCandidates || v->get<int64_t>() > kMaxRisCandidates)
        return c.fail(sub(path, "candidates"),
                      "must be a whole number in " + std::to_string(kMinRisCandidates) + ".." +
                          std::to_string(kMaxRisCandidates) + " or \"auto\", got " + v->dump());
    e->candidates = int(v->get<int64_t>());
    return true;
}

bool parse_estimator(Ctx& c, const Json& j, const std::string& path, RenderEstimator* out) {
    RenderEstimator e;
    if (j.is_string()) {
        std::string name = j.get<std::string>();
        if (!parse_strategy(name, &e.strategy))
            return c.fail(path, "unknown estimator '" + name +
                                    "' (known: " + join(strategy_names()) + ")");
        e.name = name;
        if (e.strategy == RadianceStrategy::Ris) use_ris_defaults(&e);
        *out = e;
        return true;
    }
    if (!check_keys(c, j, path,
                    {"name", "strategy", "light_selection", "light_sampling", "pixel_sampler",
                     "max_depth", "rr_depth", "candidates", "light_samples", "bsdf_samples",
                     "emission_samples", "pixel_allocation"}))
        return false;
    std::string strategy;
    if (!get_string(c, j, "strategy", path, &strategy)) return false;
    if (strategy.empty())
        return c.fail(sub(path, "strategy"), "missing (known: " + join(strategy_names()) + ")");
    if (!parse_strategy(strategy, &e.strategy))
        return c.fail(sub(path, "strategy"), "unknown strategy '" + strategy +
                                                 "' (known: " + join(strategy_names()) + ")");
    e.name = strategy;
    if (e.strategy == RadianceStrategy::Ris) use_ris_defaults(&e);
    if (!get_string(c, j, "name", path, &e.name)) return false;
    if (e.name.empty()) return c.fail(sub(path, "name"), "must not be empty");
    int v = int(e.light_selection);
    if (!parse_enum(c, j, "light_selection", path, {"uniform", "area", "power"}, &v)) return false;
    e.light_selection = LightSelection(v);
    v = int(e.light_sampling);
    if (!parse_enum(c, j, "light_sampling", path, {"area", "solid_angle"}, &v)) return false;
    e.light_sampling = LightSampling(v);
    v = int(e.pixel_sampler);
    if (!parse_enum(c, j, "pixel_sampler", path, pixel_sampler_names(), &v)) return false;
    e.pixel_sampler = PixelSamplerKind(v);
    v = int(e.pixel_allocation);
    if (!parse_enum(c, j, "pixel_allocation", path, {"uniform", "adaptive"}, &v)) return false;
    e.pixel_allocation = PixelAllocation(v);
    if (std::string why = check_pixel_allocation(e); !why.empty())
        return c.fail(sub(path, "pixel_allocation"), why);
    uint64_t depth = uint64_t(e.max_depth), rr = uint64_t(e.rr_depth);
    if (!get_count(c, j, "max_depth", path, &depth) || !get_count(c, j, "rr_depth", path, &rr))
        return false;
    if (depth < 1 || depth > 1024) return c.fail(sub(path, "max_depth"), "must be in 1..1024");
    if (rr < 1 || rr > 1024) return c.fail(sub(path, "rr_depth"), "must be in 1..1024");
    if (find(j, "max_depth") && e.strategy != RadianceStrategy::Path)
        return c.fail(sub(path, "max_depth"), "only the 'path' strategy has bounces");
    e.max_depth = int(depth);
    e.rr_depth = int(rr);
    if (!parse_candidates(c, j, path, &e)) return false;
    if (!parse_split_counts(c, j, path, &e)) return false;
    *out = e;
    return true;
}

} // namespace

std::string check_pixel_allocation(const RenderEstimator& e) {
    if (e.pixel_allocation != PixelAllocation::Adaptive || sampler_extends(e.pixel_sampler))
        return "";
    return std::string("'adaptive' adds samples to the pixels that need them after a first "
                       "pass, and the '") +
           pixel_sampler_name(e.pixel_sampler) +
           "' pixel sampler cannot add samples to a pixel (its samples depend on the final "
           "spp): use 'padded_sobol' or 'independent'";
}

namespace {

/// The quantity an estimator estimates: direct lighting, or paths up to a depth. Estimators
/// of one study must agree, or their errors against one reference mean nothing.
std::string quantity_of(const RenderEstimator& e) {
    if (e.strategy != RadianceStrategy::Path) return "direct lighting";
    return "paths of up to " + std::to_string(e.max_depth) + " bounce(s)";
}

/// A file a scene names: relative to `from` (a folder inside `root`), resolving to a regular
/// file inside `root`, the scene's folder. With no root, any path (the caller's choice).
bool resolve_scene_file(Ctx& c, const std::string& field, const std::string& root,
                        const std::string& from, const std::string& name, std::string* out) {
    if (root.empty()) { // a path the caller chose: anywhere, relative to `from`
        if (name.empty()) return c.fail(field, "is empty");
        *out = name[0] == '/' ? name : from + "/" + name;
        return true;
    }
    std::string relative = name, error;
    if (from != root && from.compare(0, root.size() + 1, root + "/") == 0 && !name.empty() &&
        name[0] != '/')
        relative = from.substr(root.size() + 1) + "/" + name;
    if (!resolve_inside(root, relative, out, &error)) return c.fail(field, error);
    return true;
}

bool parse_reference(Ctx& c, const Json& j, const std::string& path, const std::string& root,
                     const std::string& from, ReferenceSpec* out) {
    if (!check_keys(c, j, path, {"estimator", "spp", "seed", "file"})) return false;
    if (const Json* e = find(j, "estimator"))
        if (!parse_estimator(c, *e, sub(path, "estimator"), &out->estimator)) return false;
    if (out->estimator.light_samples == 0) // a pilot's timing would make it differ run to run
        return c.fail(sub(sub(path, "estimator"), "light_samples"),
                      "\"auto\" depends on timing; a reference takes a fixed count");
    if (out->estimator.candidates == 0)
        return c.fail(sub(sub(path, "estimator"), "candidates"),
                      "\"auto\" depends on timing; a reference takes a fixed count");
    if (out->estimator.emission_samples == 0)
        return c.fail(sub(sub(path, "estimator"), "emission_samples"),
                      "\"auto\" depends on timing; a reference takes a fixed count");
    if (!get_count(c, j, "spp", path, &out->spp) || !get_count(c, j, "seed", path, &out->seed))
        return false;
    if (out->spp < 1 || out->spp > kMaxSpp)
        return c.fail(sub(path, "spp"), "must be in 1.." + std::to_string(kMaxSpp));
    std::string file;
    if (!get_string(c, j, "file", path, &file)) return false;
    if (find(j, "file") && !resolve_scene_file(c, sub(path, "file"), root, from, file, &out->file))
        return false;
    return true;
}

bool parse_settings(Ctx& c, const Json& j, const std::string& path, RenderRequest* r) {
    uint64_t w = uint64_t(r->settings.width), h = uint64_t(r->settings.height);
    uint64_t reps = uint64_t(r->settings.reps), threads = uint64_t(r->settings.threads);
    if (!get_count(c, j, "width", path, &w) || !get_count(c, j, "height", path, &h) ||
        !get_count(c, j, "spp_min", path, &r->settings.spp_min) ||
        !get_count(c, j, "spp_max", path, &r->settings.spp_max) ||
        !get_count(c, j, "reps", path, &reps) ||
        !get_count(c, j, "seed", path, &r->settings.seed) ||
        !get_count(c, j, "threads", path, &threads) ||
        !get_number(c, j, "exposure", path, &r->exposure))
        return false;
    if (w < 1 || w > kMaxImageSide) return c.fail(sub(path, "width"), "must be in 1..4096");
    if (h < 1 || h > kMaxImageSide) return c.fail(sub(path, "height"), "must be in 1..4096");
    // Every image holds 6 doubles per pixel (means and variances), and a study a few images.
    if (w * h > kMaxPixels)
        return c.fail(path, "width x height = " + std::to_string(w * h) + " pixels; at most " +
                                std::to_string(kMaxPixels) + " (2048 x 2048) are allowed");
    if (r->settings.spp_min < 1 || r->settings.spp_min > kMaxSpp)
        return c.fail(sub(path, "spp_min"), "must be in 1.." + std::to_string(kMaxSpp));
    if (r->settings.spp_max < r->settings.spp_min || r->settings.spp_max > kMaxSpp)
        return c.fail(sub(path, "spp_max"), "must be in spp_min.." + std::to_string(kMaxSpp));
    if (reps < 2 || reps > 1024) return c.fail(sub(path, "reps"), "must be in 2..1024");
    if (threads > 256) return c.fail(sub(path, "threads"), "must be in 0..256");
    if (const Json* v = find(j, "jitter_pixels")) {
        if (!v->is_boolean()) return c.fail(sub(path, "jitter_pixels"), "expected true or false");
        r->settings.jitter_pixels = v->get<bool>();
    }
    if (const Json* v = find(j, "accel")) {
        int k = int(r->accel);
        if (!parse_enum(c, j, "accel", path, {"auto", "brute_force", "bvh"}, &k)) return false;
        (void)v;
        r->accel = AccelKind(k);
    }
    r->settings.width = int(w);
    r->settings.height = int(h);
    r->settings.reps = int(reps);
    r->settings.threads = int(threads);
    return true;
}

bool parse_estimator_list(Ctx& c, const Json& list, const std::string& path,
                          std::vector<RenderEstimator>* out) {
    if (!list.is_array() || list.empty())
        return c.fail(path, "expected a non-empty array of estimator names or objects");
    out->clear();
    for (size_t i = 0; i < list.size(); ++i) {
        RenderEstimator e;
        if (!parse_estimator(c, list[i], path + "[" + std::to_string(i) + "]", &e)) return false;
        for (const RenderEstimator& o : *out)
            if (o.name == e.name)
                return c.fail(path + "[" + std::to_string(i) + "]",
                              "duplicate estimator name '" + e.name + "'");
        out->push_back(e);
    }
    return true;
}

} // namespace

bool live_image_size(const Camera& camera, int scene_width, int scene_height, int long_side,
                     int* width, int* height, std::string* error) {
    const bool from_camera = camera.aspect_ratio > 0.0;
    const double aspect =
        from_camera ? camera.aspect_ratio
                    : double(std::max(scene_width, 1)) / double(std::max(scene_height, 1));
    if (!(aspect <= kLiveMaxAspect && aspect >= 1.0 / kLiveMaxAspect)) {
        *error = std::string(from_camera ? "the glTF camera's aspectRatio"
                                         : "the scene's width / height") +
                 " is " + fmt("%.4g", aspect) +
                 ", beyond the live view's 8:1 either way: give "
                 "options.width and options.height";
        return false;
    }
    const auto shorter = [&](double ratio) {
        return std::max(1, int(std::lround(double(long_side) * ratio)));
    };
    *width = aspect >= 1.0 ? long_side : shorter(aspect);
    *height = aspect >= 1.0 ? shorter(1.0 / aspect) : long_side;
    return true;
}

bool is_render_scene(const Json& scene) {
    return scene.is_object() && scene.contains("render");
}

Made<RenderEstimator> parse_render_estimator(const Json& j, const std::string& path) {
    Ctx c;
    RenderEstimator e;
    if (!parse_estimator(c, j, path, &e)) return made_error<RenderEstimator>(c.error);
    return Made<RenderEstimator>{e, ""};
}

Made<std::shared_ptr<RenderRequest>> build_render_request(const Json& scene, const Json& options) {
    using Result = Made<std::shared_ptr<RenderRequest>>;
    Ctx c;
    auto r = std::make_shared<RenderRequest>();
    auto error = [&]() { return made_error<std::shared_ptr<RenderRequest>>(c.error); };
    if (!check_keys(c, scene, "scene", {"name", "description", "render"})) return error();
    if (!get_string(c, scene, "name", "scene", &r->name) ||
        !get_string(c, scene, "description", "scene", &r->description))
        return error();
    const Json& render = scene["render"];
    const std::string rp = "scene.render";
    if (!check_keys(c, render, rp,
                    {"gltf", "width", "height", "spp_min", "spp_max", "reps", "seed", "threads",
                     "estimators", "reference", "jitter_pixels", "exposure", "accel"}))
        return error();
    Json opts = options.is_null() ? Json::object() : options;
    if (!check_keys(c, opts, "options",
                    {"base_dir",  "cache_dir",     "width",    "height",        "spp_min",
                     "spp_max",   "reps",          "seed",     "threads",       "estimators",
                     "reference", "jitter_pixels", "exposure", "accel",         "estimator",
                     "spp",       "outputs",       "previews", "pixel_sampler", "reference_data",
                     "part",      "parts",         "live",     "long_side"}))
        return error();
    bool live = false;
    if (const Json* v = find(opts, "live")) {
        if (!v->is_boolean()) {
            c.fail("options.live", "expected true or false");
            return error();
        }
        live = v->get<bool>();
    }
    if (find(opts, "long_side") && (!live || find(opts, "width") || find(opts, "height")))
        return made_error<std::shared_ptr<RenderRequest>>(
            "options.long_side: sizes the live view's image (with live: true), without width "
            "and height");
    std::string base_dir = ".", reference_data;
    if (!get_string(c, opts, "base_dir", "options", &base_dir) ||
        !get_string(c, opts, "cache_dir", "options", &r->cache_dir) ||
        !get_string(c, opts, "reference_data", "options", &reference_data))
        return error();
    if (!reference_data.empty()) {
        // Bounded before it is decoded: at most a cache file's size, in base64.
        if (reference_data.size() > (kMaxCacheFileBytes + 2) / 3 * 4)
            return made_error<std::shared_ptr<RenderRequest>>(
                "options.reference_data: longer than a reference of at most " +
                std::to_string(kMaxCacheFileBytes >> 20) + " MiB");
        if (!base64_decode(reference_data, &r->supplied_reference) ||
            !is_encoded_reference(r->supplied_reference))
            return made_error<std::shared_ptr<RenderRequest>>(
                "options.reference_data: not a reference image made by mcplay (base64 of what "
                "`mcplay reference` writes)");
    }

    // The glTF: a path relative to the scene file, or the glTF JSON itself inline.
    const Json* gltf = find(render, "gltf");
    if (!gltf) return made_error<std::shared_ptr<RenderRequest>>(rp + ".gltf: missing");
    GltfLoadResult loaded;
    std::string text;
    // Every file the scene names lies inside the scene's folder (base_dir).
    const std::string root = real_folder(base_dir);
    if (root.empty())
        return made_error<std::shared_ptr<RenderRequest>>("options.base_dir: the scene's folder '" +
                                                          base_dir + "' does not exist");
    if (gltf->is_string()) {
        std::string why;
        if (!resolve_scene_file(c, rp + ".gltf", root, root, gltf->get<std::string>(),
                                &r->gltf_path))
            return error();
        if (!read_regular_file(r->gltf_path, kGltfMaxInputBytes, &text, &why))
            return made_error<std::shared_ptr<RenderRequest>>(rp + ".gltf: " + why);
        loaded = load_gltf_memory(text, dirname_of(r->gltf_path), root);
    } else if (gltf->is_object()) {
        text = gltf->dump();
        loaded = load_gltf_memory(text, root, root);
    } else {
        return made_error<std::shared_ptr<RenderRequest>>(
            rp + ".gltf: expected a file name or a glTF object, got " + type_of(*gltf));
    }
    if (!loaded.ok)
        return made_error<std::shared_ptr<RenderRequest>>(rp + ".gltf: " + loaded.error);
    r->gltf_hash = hash_string(text.c_str());
    r->scene = std::make_unique<Scene>(std::move(loaded.scene));
    r->warnings = loaded.warnings;
    if (!loaded.has_camera)
        return made_error<std::shared_ptr<RenderRequest>>(
            rp + ".gltf: the scene has no perspective camera (add a camera node)");

    // A glTF may carry its own study settings in extras.mcplay (same keys as "render"); the
    // scene file's and then the options' values take precedence.
    Json extras;
    if (!loaded.extras_json.empty()) {
        Made<Json> e = parse_json(loaded.extras_json.c_str(), "glTF extras");
        if (e.ok() && e.value.is_object() && e.value.contains("mcplay")) extras = e.value["mcplay"];
    }
    const std::string ep = rp + ".gltf: extras.mcplay";
    if (!extras.is_null()) {
        if (!check_keys(c, extras, ep,
                        {"width", "height", "spp_min", "spp_max", "reps", "seed", "threads",
                         "estimators", "reference", "jitter_pixels", "exposure", "accel"}) ||
            !parse_settings(c, extras, ep, r.get()))
            return error();
    }
    if (!parse_settings(c, render, rp, r.get())) return error();
    const uint64_t scene_spp_max = r->settings.spp_max;
    const int scene_width = r->settings.width, scene_height = r->settings.height;
    if (!parse_settings(c, opts, "options", r.get())) return error();
    // The live view's size: the longer side given (or the default), the other from the
    // camera's aspect, unless width and height are given.
    if (live && !find(opts, "width") && !find(opts, "height")) {
        uint64_t long_side = kLiveDefaultLongSide;
        if (!get_count(c, opts, "long_side", "options", &long_side)) return error();
        if (long_side < uint64_t(kLiveMinLongSide) || long_side > uint64_t(kLiveMaxLongSide))
            return made_error<std::shared_ptr<RenderRequest>>(
                "options.long_side: " + std::to_string(long_side) + " is not in " +
                std::to_string(kLiveMinLongSide) + ".." + std::to_string(kLiveMaxLongSide));
        std::string why;
        if (!live_image_size(r->scene->camera, scene_width, scene_height, int(long_side),
                             &r->settings.width, &r->settings.height, &why))
            return made_error<std::shared_ptr<RenderRequest>>(why);
    }
    // The spp ladder: powers of two in spp_min..spp_max; none is a study of no level.
    if (n_ladder(r->settings.spp_min, r->settings.spp_max).empty()) {
        const bool from_options = find(opts, "spp_min") || find(opts, "spp_max");
        c.fail(from_options ? std::string("options.spp_max") : sub(rp, "spp_max"),
               "no power of two lies between spp_min = " + std::to_string(r->settings.spp_min) +
                   " and spp_max = " + std::to_string(r->settings.spp_max) +
                   ": the spp ladder has no level");
        return error();
    }
    // A part of a study split over processes (mcp_render_study_merge).
    uint64_t part = 0, parts = 1;
    if (!get_count(c, opts, "part", "options", &part) ||
        !get_count(c, opts, "parts", "options", &parts))
        return error();
    if (parts < 1 || parts > uint64_t(r->settings.reps)) {
        c.fail("options.parts", "must be in 1..reps = " + std::to_string(r->settings.reps) +
                                    ", got " + std::to_string(parts));
        return error();
    }
    if (part >= parts) {
        c.fail("options.part", "must be in 0..parts - 1 = " + std::to_string(parts - 1) + ", got " +
                                   std::to_string(part));
        return error();
    }
    r->settings.part = int(part);
    r->settings.parts = int(parts);

    // Estimators: the scene's list (or the glTF's, or every direct-lighting strategy), then
    // the options'.
    const Json* scene_list = find(render, "estimators");
    if (!scene_list) scene_list = find(extras, "estimators");
    if (const Json* list = scene_list) {
        std::string lp =
            list == find(render, "estimators") ? rp + ".estimators" : ep + ".estimators";
        if (!parse_estimator_list(c, *list, lp, &r->estimators)) return error();
    } else {
        for (int s = 0; s < int(RadianceStrategy::Path); ++s) {
            RenderEstimator e;
            e.strategy = RadianceStrategy(s);
            e.name = strategy_name(e.strategy);
            r->estimators.push_back(e);
        }
    }
    if (const Json* list = find(opts, "estimators")) {
        // Names pick from the scene's estimators; anything else must be a full estimator.
        if (!list->is_array() || list->empty())
            return made_error<std::shared_ptr<RenderRequest>>(
                "options.estimators: expected a non-empty array");
        // A name given twice is refused (as the CLI's --estimators refuses it): the same
        // estimator twice is one study, not a comparison.
        std::vector<RenderEstimator> chosen;
        for (size_t i = 0; i < list->size(); ++i) {
            const Json& item = (*list)[i];
            const std::string at = "options.estimators[" + std::to_string(i) + "]";
            RenderEstimator e;
            bool found = false;
            if (item.is_string())
                for (const RenderEstimator& s : r->estimators)
                    if (s.name == item.get<std::string>()) {
                        e = s;
                        found = true;
                        break;
                    }
            if (!found && !parse_estimator(c, item, at, &e)) return error();
            for (const RenderEstimator& o : chosen)
                if (o.name == e.name) {
                    c.fail(at, "'" + e.name + "' is named twice");
                    return error();
                }
            chosen.push_back(e);
        }
        r->estimators = chosen;
    }
    for (const RenderEstimator& e : r->estimators)
        if ((e.light_samples == 0 || e.candidates == 0 || e.emission_samples == 0) && parts > 1) {
            c.fail("options.parts", "estimator '" + e.name + "' has " +
                                        (e.light_samples == 0 ? "light_samples"
                                         : e.candidates == 0  ? "candidates"
                                                              : "emission_samples") +
                                        " \"auto\", which each part's timed pilot would choose "
                                        "on its own: give a count");
            return error();
        }
    // options.pixel_sampler (mcplay's --pixel-sampler): every estimator's pixel sampler, not
    // the reference's (the reference is the study's fixed target).
    if (find(opts, "pixel_sampler")) {
        int v = 0;
        if (!parse_enum(c, opts, "pixel_sampler", "options", pixel_sampler_names(), &v))
            return error();
        for (RenderEstimator& e : r->estimators) {
            e.pixel_sampler = PixelSamplerKind(v);
            if (std::string why = check_pixel_allocation(e); !why.empty()) {
                c.fail("options.pixel_sampler", "estimator '" + e.name + "': " + why);
                return error();
            }
        }
    }

    // The reference: by default the power-heuristic MIS estimator of the same quantity.
    const RenderEstimator& first = r->estimators.front();
    r->reference.estimator.name = "reference";
    r->reference.estimator.strategy = first.strategy == RadianceStrategy::Path
                                          ? RadianceStrategy::Path
                                          : RadianceStrategy::MisPower;
    r->reference.estimator.max_depth = first.max_depth;
    r->reference.estimator.rr_depth = first.rr_depth;
    // Its spp: 16 x the scene's spp_max (at least 256), so that a study of fewer spp keeps the
    // scene's reference (cached, or shipped by the site); a study that asks more than a quarter
    // of that (kReferenceSppRatio) gets 16 x its own spp_max.
    r->reference.spp = std::max<uint64_t>(256, 16 * scene_spp_max);
    if (r->settings.spp_max > r->reference.spp / 4)
        r->reference.spp = std::max<uint64_t>(256, 16 * r->settings.spp_max);
    // Reference files: the glTF's extras name them relative to the glTF, the scene and the
    // options relative to the scene's folder.
    const std::string gltf_dir = r->gltf_path.empty() ? root : dirname_of(r->gltf_path);
    // Where the reference's spp was last set, for the Sobol' sampler's power-of-two check.
    std::string ref_spp_field;
    if (const Json* ref = find(extras, "reference")) {
        if (!parse_reference(c, *ref, ep + ".reference", root, gltf_dir, &r->reference))
            return error();
        if (find(*ref, "spp")) ref_spp_field = ep + ".reference.spp";
    }
    if (const Json* ref = find(render, "reference")) {
        if (!parse_reference(c, *ref, rp + ".reference", root, root, &r->reference)) return error();
        if (find(*ref, "spp")) ref_spp_field = rp + ".reference.spp";
    }
    // The caller's options are not scene text: their file may lie anywhere.
    if (const Json* ref = find(opts, "reference")) {
        if (!parse_reference(c, *ref, "options.reference", "", root, &r->reference)) return error();
        if (find(*ref, "spp")) ref_spp_field = "options.reference.spp";
    }
    // The live view's reference: at most kLiveReferenceSpp, unless the options give its spp.
    if (live && ref_spp_field != "options.reference.spp")
        r->reference.spp = std::min(r->reference.spp, kLiveReferenceSpp);
    if (r->reference.file.empty()) {
        std::string why =
            check_pixel_sampler_spp(r->reference.estimator.pixel_sampler, r->reference.spp);
        if (!why.empty())
            return made_error<std::shared_ptr<RenderRequest>>(
                (ref_spp_field.empty() ? rp + ".reference.spp" : ref_spp_field) + ": " + why +
                (ref_spp_field.empty() ? " (the default, max(256, 16 x spp_max))" : "") +
                " for the reference's estimator");
    }
    for (const RenderEstimator& e : r->estimators)
        if (quantity_of(e) != quantity_of(r->estimators.front()))
            return made_error<std::shared_ptr<RenderRequest>>(
                "estimators: '" + e.name + "' estimates " + quantity_of(e) + " but '" +
                r->estimators.front().name + "' estimates " + quantity_of(r->estimators.front()) +
                "; one study compares estimators of one quantity");
    if (r->reference.file.empty() &&
        quantity_of(r->reference.estimator) != quantity_of(r->estimators.front()))
        return made_error<std::shared_ptr<RenderRequest>>(
            "reference: estimates " + quantity_of(r->reference.estimator) +
            " but the estimators estimate " + quantity_of(r->estimators.front()));
    r->reference.estimator.name = "reference";
    return Result{r, ""};
}

} // namespace mcp
