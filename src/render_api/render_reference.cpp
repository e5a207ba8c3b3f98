// The reference image of a render study (render_reference.h): its cache key, its cache file,
// and where each call gets it from.
#include "render_api/render_reference.h"

#include <algorithm>
#include <cstdio>

#include "api/boundary.h"
#include "api/files.h"
#include "api/report.h"
#include "api/scene.h"
#include "core/rng.h"
#include "estimators/study.h"
#include "render_api/image_io.h"
#include "render_api/render_json.h"

namespace mcp {

using boundary::dump;

namespace {

/// Part of every reference's cache key. Bumped whenever the renderer's image for a given seed
/// changes, so that no cache (nor a shipped reference) serves a reference the current build
/// would not render: 4 = stratified strata tables and Sobol' requests prepared per pixel;
/// 5 = solid-angle light sampling takes area samples of lights small from the point.
constexpr int kReferenceCacheVersion = 5;

std::string hex(uint64_t x) {
    char buf[20];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(x));
    return buf;
}

} // namespace

ReferenceProgress rows_progress(mcp_progress_fn progress, void* user, const char* kind,
                                bool* cancelled) {
    if (!progress) return nullptr;
    return [progress, user, kind, cancelled, last = -1](int rows_done, int rows) mutable {
        const int percent = int(100.0 * rows_done / std::max(1, rows));
        if (percent == last) return true;
        last = percent;
        const std::string text = dump(Json{{"version", kResultSchemaVersion},
                                           {"kind", kind},
                                           {"rows_done", rows_done},
                                           {"rows", rows}});
        if (progress(text.c_str(), user) == 0) return true;
        *cancelled = true;
        return false;
    };
}

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
    if (e.strategy == RadianceStrategy::Ris || e.candidates != 1)
        key = hash_combine(key, uint64_t(e.candidates));
    if (e.light_samples != 1 || e.bsdf_samples != 1) // splitting (keys of 1, 1 unchanged)
        key = hash_combine(hash_combine(key, uint64_t(e.light_samples)), uint64_t(e.bsdf_samples));
    if (e.emission_samples != 1) key = hash_combine(key, uint64_t(e.emission_samples) << 32);
    if (e.pixel_allocation == PixelAllocation::Adaptive) key = hash_combine(key, 0xada9u);
    return key;
}

std::string reference_cache_file(const RenderRequest& r) {
    if (r.cache_dir.empty()) return "";
    return r.cache_dir + "/" + hex(reference_key(r)) + ".mcref";
}

bool obtain_reference(const LoadedRender& l, RenderImage* ref, Json* info, std::string* error,
                      const ReferenceProgress& progress, bool may_render) {
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
        } else if (std::string why; !decode_reference(r.supplied_reference, key, ref, &why) ||
                                    ref->width != s.width || ref->height != s.height ||
                                    ref->spp != r.reference.spp) {
            *error = why.empty() ? "options.reference_data: a corrupt reference image (its sizes, "
                                   "length or values are not what mcplay writes)"
                                 : "options.reference_data: a corrupt reference image: " + why;
            return false;
        } else {
            (*info)["source"] = "supplied";
            return true;
        }
    }
    const std::string cache_file = reference_cache_file(r);
    std::string cache_why;
    if (!cache_file.empty() && read_reference_cache(cache_file, key, ref, &cache_why) &&
        ref->width == s.width && ref->height == s.height && ref->spp == r.reference.spp) {
        (*info)["source"] = "cache";
        (*info)["file"] = cache_file;
        return true;
    }
    // A cache file with a bad pixel value is not used (the reference is rendered again, and the
    // new one replaces it); the info says which file and pixel.
    if (!cache_why.empty()) (*info)["cache"] = "not used: " + cache_file + ": " + cache_why;
    if (!may_render) {
        *ref = RenderImage();
        (*info)["source"] = "none";
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

int obtain_reference_reporting(const LoadedRender& l, mcp_progress_fn progress, void* user,
                               RenderImage* ref, Json* info, std::string* error, bool may_render) {
    bool cancelled = false;
    if (obtain_reference(l, ref, info, error,
                         rows_progress(progress, user, "render_reference", &cancelled), may_render))
        return MCP_OK;
    return cancelled ? MCP_ERROR_CANCELLED : MCP_ERROR_SCENE;
}

} // namespace mcp
