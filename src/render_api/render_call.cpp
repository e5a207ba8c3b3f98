// What every render C API call does first (render_call.h): the scene loaded, or the work it
// asks for refused before anything is rendered.
#include "render_api/render_call.h"

#include "api/boundary.h"
#include "api/mcplay.h"
#include "api/report.h"
#include "api/scene.h"
#include "estimators/study.h"

namespace mcp {

using boundary::fail;

namespace {

int load(const char* scene_json, const char* options_json, LoadedRender* out, Json* options) {
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

} // namespace

int begin_render_call(const char* function, char** out, const char* scene_json,
                      const char* options_json, LoadedRender* loaded, Json* options) {
    if (!out)
        return fail(MCP_ERROR_ARGUMENT, std::string(function) + ": the result pointer is NULL");
    *out = nullptr;
    return load(scene_json, options_json, loaded, options);
}

bool check_render_work(const RenderRequest& r, double image_samples_per_pixel, size_t held,
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

double study_spp_per_estimator(const RenderStudySettings& s) {
    double spp = 0.0;
    for (uint64_t n : n_ladder(s.spp_min, s.spp_max)) spp += double(n);
    return spp * double(s.reps);
}

bool check_render_study(const RenderRequest& r, std::string* error) {
    const bool ref_rendered = r.reference.file.empty();
    if (ref_rendered && r.settings.spp_max > r.reference.spp / kReferenceSppRatio) {
        *error = "scene.render.reference.spp: expected at least " +
                 std::to_string(kReferenceSppRatio) +
                 " x spp_max = " + std::to_string(kReferenceSppRatio * r.settings.spp_max) +
                 ", got " + std::to_string(r.reference.spp) +
                 ": a reference with fewer samples is too noisy to judge the images";
        return false;
    }
    return check_render_work(r, study_spp_per_estimator(r.settings) * double(r.estimators.size()),
                             r.estimators.size() + 2, ref_rendered, error);
}

} // namespace mcp
