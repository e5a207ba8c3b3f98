// Render results as JSON (render_json.h): what the core measured, in the keys of
// docs/result-schema.md, with its flags worded as warnings.
#include "render_api/render_json.h"

#include <cmath>
#include <string>

#include "api/report.h"
#include "api/scene.h"
#include "render_api/image_io.h"

namespace mcp {

namespace {

const char* selection_name(LightSelection s) {
    switch (s) {
    case LightSelection::Uniform: return "uniform";
    case LightSelection::Area: return "area";
    case LightSelection::Power: return "power";
    }
    return "?"; // not reached: every selection is a case
}

const char* sampling_name(LightSampling s) {
    switch (s) {
    case LightSampling::Area: return "area";
    case LightSampling::SolidAngle: return "solid_angle";
    }
    return "?"; // not reached: every sampling is a case
}

const char* accel_kind_name(AccelKind k) {
    switch (k) {
    case AccelKind::Auto: return "auto"; // not in AccelStats: it names what was built
    case AccelKind::BruteForce: return "brute_force";
    case AccelKind::Bvh: return "bvh";
    }
    return "?"; // not reached: every kind is a case
}

/// The error concentration of level i (a default, flagless one if the study has none).
const ErrorConcentration& concentration_of(const RenderEstimatorStudy& s, size_t i) {
    static const ErrorConcentration none;
    return i < s.concentration.size() ? s.concentration[i] : none;
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

} // namespace

Json pixel_allocation_to_json(const PixelAllocationInfo& a) {
    if (!a.adaptive) return Json{{"adaptive", false}};
    return Json{{"adaptive", true},
                {"first_pass_spp", a.first_pass_spp},
                {"min_spp", a.min_spp},
                {"max_spp", a.max_spp},
                {"predicted_gain", num(a.predicted_gain)}};
}

Json estimator_to_json(const RenderEstimator& e) {
    Json j{{"name", e.name},
           {"strategy", strategy_name(e.strategy)},
           {"light_selection", selection_name(e.light_selection)},
           {"light_sampling", sampling_name(e.light_sampling)},
           {"pixel_sampler", pixel_sampler_name(e.pixel_sampler)}};
    if (e.strategy == RadianceStrategy::Path) {
        j["max_depth"] = e.max_depth;
        j["rr_depth"] = e.rr_depth;
    }
    if (e.strategy == RadianceStrategy::Ris || e.candidates != 1 || e.candidate_pilot.ran)
        j["candidates"] = e.candidates;
    if (e.light_samples != 1 || e.bsdf_samples != 1 || e.split_pilot.ran) {
        j["light_samples"] = e.light_samples;
        j["bsdf_samples"] = e.bsdf_samples;
    }
    if (e.emission_samples != 1 || e.emission_pilot.ran) j["emission_samples"] = e.emission_samples;
    if (e.pixel_allocation == PixelAllocation::Adaptive) j["pixel_allocation"] = "adaptive";
    const auto pilot_json = [](const SplitPilot& p) {
        return Json{
            {"variance_rest", p.variance_rest},
            {"variance_light", p.variance_light},
            {"seconds_rest", p.seconds_rest},
            {"seconds_light", p.seconds_light},
            {"samples", p.samples},
            {"seconds", p.seconds},
            {"counts", std::vector<int>(p.counts, p.counts + p.tried)},
            {"relative_variance",
             std::vector<double>(p.relative_variance, p.relative_variance + p.tried)},
            {"tail", p.tail},
            {"sample_seconds", std::vector<double>(p.sample_seconds, p.sample_seconds + p.tried)}};
    };
    // light_samples or candidates "auto": what the pilot measured (splitting.h)
    if (e.split_pilot.ran) j["split_pilot"] = pilot_json(e.split_pilot);
    if (e.candidate_pilot.ran) j["candidate_pilot"] = pilot_json(e.candidate_pilot);
    if (e.emission_pilot.ran) j["emission_pilot"] = pilot_json(e.emission_pilot);
    return j;
}

Json render_warnings(const RenderEstimatorStudy& s, double floor) {
    Json w = Json::array();
    const TailWording tail_words{"the samples' reflected radiance values", "samples", "spp",
                                 "the pixel variance", s.bound.reason.c_str()};
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
            if (f.code == FlagCode::HeavyTail && s.bound.infinite_variance &&
                !(f.value < kHeavyTailAlpha))
                w.push_back(flag_warning(
                    f, "the pixel variance is infinite by the scene's construction (" +
                           s.bound.reason + "), though " +
                           (std::isfinite(f.value)
                                ? "the samples' tail index reads " + fmt("%.2f", f.value)
                                : std::string("there are too few samples to estimate a tail")) +
                           " at spp = " + std::to_string(f.n) +
                           ": the rare samples near the contact that make it infinite are "
                           "beyond the tail estimate's view. The error bars are not "
                           "trustworthy"));
            else
                w.push_back(tail_warning(f, s.levels.back().diagnostics.nonzero, tail_words));
            break;
        case FlagCode::SlowConvergence:
            w.push_back(flag_warning(
                f, "relative MSE falls as spp^" + fmt("%.2f", f.value) + " +/- " +
                       fmt("%.2f", f.se) + ", slower than 1/spp: " +
                       (s.bound.bounded
                            ? "the samples are bounded (" + s.bound.reason +
                                  "), so the variance is finite and unbiased samples' expected "
                                  "relative MSE falls as 1/spp; the slower fit comes from rare "
                                  "large errors some levels missed, a reference too noisy for "
                                  "this spp, or a bias (pixel_error_bars judges the pixels "
                                  "against the reference)"
                            : std::string("infinite variance, bias against the reference, or "
                                          "a reference too noisy for this spp"))));
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
                       "image" +
                       (f.severity == Severity::Info
                            ? ". The samples are bounded (" + s.bound.reason +
                                  "), so these terms have a finite variance and their weight "
                                  "fades as spp, images or pixels grow"
                            : std::string())));
            break;
        case FlagCode::PixelErrorBars:
            w.push_back(flag_warning(
                f, "only " + fmt("%.1f", 100.0 * f.value) +
                       "% of the pixels' own 95% error bars cover the reference at "
                       "spp = " +
                       std::to_string(f.n) + ": per-pixel error bars are too small (" +
                       (s.bound.bounded ? "the samples are bounded, so not a heavy tail: "
                                          "rare large values that most pixels have not yet "
                                          "drawn, or a bias"
                                        : "heavy tails or bias") +
                       ")"));
            break;
        // A level's flags (render_level_to_json words them), and the integration studies' flags,
        // which render_flags never raises.
        case FlagCode::BelowReferenceNoise:
        case FlagCode::FewPixelErrors:
        case FlagCode::NoEstimate:
        case FlagCode::NonfiniteEstimate:
        case FlagCode::NonfiniteVariance:
        case FlagCode::ZeroErrorBar:
        case FlagCode::NonfiniteSamples:
        case FlagCode::ZeroPdfSamples:
        case FlagCode::SkewedWeights:
        case FlagCode::LowEss:
        case FlagCode::ExactOutsideCi:
        case FlagCode::PdfSupport:
        case FlagCode::LevelDrift:
        case FlagCode::Float32Accumulator:
        case FlagCode::IterationsDisagree:
        case FlagCode::ErrorBarsUnderstate:
        case FlagCode::ErrorBarsUnstable:
        case FlagCode::BiasDominates:
        case FlagCode::ConservativeErrorBars:
        case FlagCode::ValuesUnderflow:
        case FlagCode::ReplicateFarOff: break;
        }
    }
    sort_by_severity(w);
    return w;
}

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

Json render_scene_to_json(const LoadedRender& l) {
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
                 {{"kind", accel_kind_name(a.kind)},
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

Json render_settings_to_json(const RenderStudySettings& s, int threads) {
    return Json{{"n_min", s.spp_min},
                {"n_max", s.spp_max},
                {"reps", s.reps},
                {"seed", s.seed},
                {"threads", threads},
                {"n_name", "spp"},
                {"error_name", "relative_mse"},
                {"jitter_pixels", s.jitter_pixels}};
}

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
    j["contribution_bound"] = Json{{"bounded", s.bound.bounded},
                                   {"infinite_variance", s.bound.infinite_variance},
                                   {"reason", s.bound.reason}};
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

Json black_reference_warning() {
    return warning("black_reference", Severity::Warning,
                   "the reference image is black (mean luminance 0): relative MSE is undefined "
                   "and reported as null");
}

} // namespace mcp
