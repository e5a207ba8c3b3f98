// Merging the parts of a split render study (render_merge.h): the images each part wrote
// (render_json.cpp, image_summary_to_json) read back with every field checked, then the levels
// recomputed from the images of all the parts.
#include "render_api/render_merge.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "api/report.h"
#include "api/scene.h"
#include "render/render_study.h"
#include "render_api/render_json.h"

namespace mcp {

namespace {

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

} // namespace

bool merge_render_parts(Ctx& c, const Json& in, Json* out) {
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

} // namespace mcp
