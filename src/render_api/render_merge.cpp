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
#include "estimators/study.h" // n_ladder
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
    if (!std::isfinite(*out)) return c.fail(sub(path, key), "expected a finite number");
    return true;
}

/// A number read by read_number in lo..hi (null, NaN, passes: no value, e.g. a black reference).
bool check_range(Ctx& c, const std::string& path, const char* key, double x, double lo, double hi) {
    if (std::isnan(x) || (x >= lo && x <= hi)) return true;
    return c.fail(sub(path, key), "out of range: expected " + fmt("%.17g", lo) + ".." +
                                      fmt("%.17g", hi) + ", got " + fmt("%.17g", x));
}

/// The replicates of part `index` of `of`: r = index, index + of, ... below reps.
size_t part_replicate_count(uint64_t reps, uint64_t index, uint64_t of) {
    return index < reps ? size_t((reps - 1 - index) / of + 1) : 0;
}

/// A part's value at a path found by first_difference, for the message ("missing" if none).
std::string value_text(const Json& root, const std::string& path, const std::string& prefix) {
    if (path.compare(0, prefix.size(), prefix) != 0) return "?";
    std::string rest = path.substr(prefix.size()), key;
    const Json* at = &root;
    for (size_t i = 0; i <= rest.size(); ++i) {
        if (i == rest.size() || rest[i] == '.' || rest[i] == '[') {
            if (!key.empty()) {
                if (!at->is_object() || !at->contains(key)) return "missing";
                at = &(*at)[key];
            }
            key.clear();
            if (i < rest.size() && rest[i] == '[') {
                const size_t close = rest.find(']', i);
                if (close == std::string::npos) return "?";
                const size_t k = std::stoul(rest.substr(i + 1, close - i - 1));
                if (!at->is_array() || k >= at->size()) return "missing";
                at = &(*at)[k];
                i = close;
            }
        } else {
            key += rest[i];
        }
    }
    const std::string text = at->dump();
    return text.size() > 60 ? text.substr(0, 57) + "..." : text;
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

/// The image size of the parts (their scene's width and height), for checking the images.
struct ImageShape {
    uint64_t width = 4096, height = 4096;
};

/// `ref_floor`: the reference's relative MSE floor (reference_summary.relative_mse_floor).
bool image_summary_from_json(Ctx& c, const Json& j, const std::string& path,
                             const ImageShape& shape, double ref_floor, ImageSummary* im) {
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
    // Every number in its range: raw relative errors, sums of squares and standard errors are
    // >= 0, a coverage and a share lie in 0..1, pixels in the image, counts within counts. The
    // relative MSE is the raw one less the reference's noise pixel by pixel (render_study.cpp,
    // image_error): it lies in -floor..rel_mse_raw, negative once the image is closer to the
    // truth than the reference can tell (docs/render-scenes.md), up to rounding.
    const double pixels = double(shape.width) * double(shape.height);
    const double floor = std::isfinite(ref_floor) && ref_floor > 0.0 ? ref_floor : 0.0;
    const double rounding = 1e-9 * (floor + std::fabs(e.rel_mse_raw));
    if (!check_range(c, path, "rel_mse_raw", e.rel_mse_raw, 0.0, INFINITY) ||
        !check_range(c, path, "rel_mse", e.rel_mse, -floor - rounding,
                     std::isnan(e.rel_mse_raw) ? INFINITY : e.rel_mse_raw + rounding) ||
        !check_range(c, path, "coverage", e.coverage, 0.0, 1.0) ||
        !check_range(c, path, "mean_luminance_se", e.mean_luminance_se, 0.0, INFINITY) ||
        !check_range(c, path, "worst_pixel_term", e.worst_pixel_term, 0.0, INFINITY) ||
        !check_range(c, path, "pixel_term_squares", e.pixel_term_squares, 0.0, INFINITY) ||
        !check_range(c, path, "max_sample_share", d.max_sample_share, 0.0, 1.0) ||
        !check_range(c, path, "worst_x", e.worst_x, -1.0, double(shape.width) - 1.0) ||
        !check_range(c, path, "worst_y", e.worst_y, -1.0, double(shape.height) - 1.0) ||
        !check_range(c, path, "samples", double(d.samples), 0.0, double(im->spp) * pixels) ||
        !check_range(c, path, "discarded_nonfinite", double(d.discarded_nonfinite), 0.0,
                     double(d.samples)) ||
        !check_range(c, path, "light_misses", double(d.light_misses), 0.0, double(d.rays)) ||
        !check_range(c, path, "dominated_pixels", double(d.dominated_pixels), 0.0, pixels))
        return false;
    im->replicate = int(replicate);
    const Json* top = find(j, "top");
    if (!top || !top->is_array() || top->size() > kTopWeights)
        return c.fail(sub(path, "top"),
                      "expected an array of at most " + std::to_string(kTopWeights) + " numbers");
    d.top.clear();
    for (size_t i = 0; i < top->size(); ++i) {
        const Json& x = (*top)[i];
        if (!x.is_number() || !(x.get<double>() >= 0.0) || !std::isfinite(x.get<double>()) ||
            (i > 0 && x.get<double>() > d.top.back()))
            return c.fail(sub(path, "top") + "[" + std::to_string(i) + "]",
                          "expected a number >= 0 (finite, in decreasing order)");
        d.top.push_back(x.get<double>());
    }
    return true;
}

/// Each estimator's levels, fit and warnings merged from the parts of a split study
/// (mcp_render_study_merge): the images of every part at each level, by replicate.
bool merge_estimator(Ctx& c, const std::vector<const Json*>& parts, size_t e,
                     const ReferenceSummary& ref, const ImageShape& shape,
                     const std::vector<uint64_t>& ladder, uint64_t reps, Json* out) {
    const std::string path = "parts[*].estimators[" + std::to_string(e) + "]";
    size_t levels = SIZE_MAX;
    for (const Json* part : parts) {
        const Json& est = (*part)["estimators"][e];
        const Json* ls = find(est, "levels");
        const size_t most = ladder.empty() ? 64 : ladder.size();
        if (!ls || !ls->is_array() || ls->size() > most)
            return c.fail(sub(path, "levels"), "expected an array of at most " +
                                                   std::to_string(most) +
                                                   " levels (the spp ladder)");
        levels = std::min(levels, ls->size());
    }
    RenderEstimatorStudy study;
    // Whether the contributions are bounded: the parts agree on it (one study), and a part
    // without it (from before the field) leaves the tail estimate's verdict.
    if (const Json* b = find((*parts[0])["estimators"][e], "contribution_bound")) {
        const Json* bounded = b->is_object() ? find(*b, "bounded") : nullptr;
        const Json* reason = b->is_object() ? find(*b, "reason") : nullptr;
        // infinite_variance: absent in parts from before the field (false then).
        const Json* infinite = b->is_object() ? find(*b, "infinite_variance") : nullptr;
        const bool infinite_ok =
            !infinite ||
            (infinite->is_boolean() &&
             !(infinite->get<bool>() && bounded && bounded->is_boolean() && bounded->get<bool>()));
        if (!bounded || !bounded->is_boolean() || !reason || !reason->is_string() ||
            reason->get<std::string>().size() > 1000 || !infinite_ok)
            return c.fail("part 0.estimators[" + std::to_string(e) + "].contribution_bound",
                          "expected {\"bounded\": true or false, \"infinite_variance\": true "
                          "or false (not both true), \"reason\": a string}");
        study.bound = {bounded->get<bool>(), infinite && infinite->get<bool>(),
                       reason->get<std::string>()};
    }
    for (size_t i = 0; i < levels; ++i) {
        const std::string lp = path + ".levels[" + std::to_string(i) + "]";
        std::vector<ImageSummary> images;
        const uint64_t of = parts.size();
        // The level's image lists; their total is the replicate count when the parts carry no
        // settings (the progress lines the page merges level by level).
        std::vector<const Json*> lists(of, nullptr);
        uint64_t total = 0;
        for (uint64_t index = 0; index < of; ++index) {
            const Json& level = (*parts[index])["estimators"][e]["levels"][i];
            const Json* list = level.is_object() ? find(level, "images") : nullptr;
            if (!list || !list->is_array() || list->size() > 1024)
                return c.fail("part " + std::to_string(index) + ".estimators[" + std::to_string(e) +
                                  "].levels[" + std::to_string(i) + "].images",
                              "expected an array of at most 1024 images");
            lists[index] = list;
            total += list->size();
        }
        const uint64_t level_reps = reps ? reps : total;
        if (level_reps < 2 || level_reps > 1024 || of > level_reps)
            return c.fail(lp, std::to_string(total) + " images over " + std::to_string(of) +
                                  " parts: expected reps (2..1024, at least one per part)");
        for (uint64_t index = 0; index < of; ++index) {
            const Json* list = lists[index];
            const std::string pl = "part " + std::to_string(index) + ".estimators[" +
                                   std::to_string(e) + "].levels[" + std::to_string(i) + "]";
            // Part index of K holds exactly the replicates r < reps with r % K == index.
            const size_t want = part_replicate_count(level_reps, index, of);
            if (list->size() != want)
                return c.fail(sub(pl, "images"),
                              "expected the " + std::to_string(want) +
                                  " images of replicates r with r % " + std::to_string(of) + " = " +
                                  std::to_string(index) + ", got " + std::to_string(list->size()));
            for (size_t k = 0; k < list->size(); ++k) {
                ImageSummary im;
                const std::string ip = pl + ".images[" + std::to_string(k) + "]";
                if (!image_summary_from_json(c, (*list)[k], ip, shape, ref.floor, &im))
                    return false;
                if (uint64_t(im.replicate) != index + k * of)
                    return c.fail(sub(ip, "replicate"),
                                  "expected replicate " + std::to_string(index + k * of));
                if (!ladder.empty() && im.spp != ladder[i])
                    return c.fail(sub(ip, "spp"),
                                  "expected the level's " + std::to_string(ladder[i]) + " spp");
                images.push_back(im);
            }
        }
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
    // One study's parts: the same scene (image size, reference), settings (seed, spp range,
    // reps; threads aside) and estimators (their settings; levels, fits and timings aside).
    auto study_of = [](const Json& p) {
        Json j = Json::object();
        for (const char* key : {"version", "kind", "mcplay", "scene", "settings"})
            if (p.contains(key)) j[key] = p[key];
        if (j.contains("settings") && j["settings"].is_object()) j["settings"].erase("threads");
        // The reference's timing and where it came from (rendered, a cache file) may differ;
        // its numbers may not (reference_summary, above, and the rest of its description).
        if (j.contains("scene") && j["scene"].is_object() && j["scene"].contains("reference") &&
            j["scene"]["reference"].is_object()) {
            j["scene"]["reference"].erase("seconds");
            j["scene"]["reference"].erase("source");
            j["scene"]["reference"].erase("file");
        }
        Json ests = Json::array();
        for (const Json& e : p["estimators"]) {
            Json x = e;
            if (x.is_object())
                for (const char* key :
                     {"levels", "warnings", "fit", "rays_per_second", "preview_png", "error_png"})
                    x.erase(key);
            ests.push_back(x);
        }
        j["estimators"] = ests;
        return j;
    };
    const Json study0 = study_of(first);
    auto names_of = [](const Json& p) {
        std::string names;
        for (const Json& e : p["estimators"])
            names += (names.empty() ? "" : ", ") +
                     (e.is_object() && e.contains("name") ? e["name"].dump() : std::string("?"));
        return names;
    };
    for (size_t i = 1; i < k; ++i) {
        const std::string pp = "part " + std::to_string(i);
        if (names_of(*parts[i]) != names_of(first))
            return c.fail(pp + ".estimators", "are " + names_of(*parts[i]) + ", part 0's are " +
                                                  names_of(first) +
                                                  ": the parts are not of one study");
        const Json study = study_of(*parts[i]);
        const std::string d = first_difference(study, study0, pp);
        if (!d.empty())
            return c.fail(d, "is " + value_text(study, d, pp) + ", part 0's is " +
                                 value_text(study0, d, pp) +
                                 ": the parts are not of one study (same scene and settings)");
    }
    // A result carries its settings and scene; a progress line (the page merges them level by
    // level) neither: then the replicates are counted from the images, and the spp and pixel
    // bounds are the widest.
    const Json* settings = find(first, "settings");
    const Json* scene = find(first, "scene");
    uint64_t reps = 0, spp_min = 0, spp_max = 0;
    ImageShape shape;
    std::vector<uint64_t> ladder;
    if (settings) {
        if (!settings->is_object()) return c.fail("part 0.settings", "expected an object");
        if (!read_count(c, *settings, "reps", "part 0.settings", &reps) ||
            !read_count(c, *settings, "n_min", "part 0.settings", &spp_min) ||
            !read_count(c, *settings, "n_max", "part 0.settings", &spp_max))
            return false;
        if (reps < 2 || reps > 1024) return c.fail("part 0.settings.reps", "must be in 2..1024");
        if (k > reps) return c.fail("parts", "more parts than reps = " + std::to_string(reps));
        if (spp_min < 1 || spp_max < spp_min || spp_max > (uint64_t(1) << 40))
            return c.fail("part 0.settings.n_max", "expected 1 <= n_min <= n_max <= 2^40");
        ladder = n_ladder(spp_min, spp_max);
        if (ladder.empty())
            return c.fail("part 0.settings.n_max", "no power of two between n_min and n_max");
    }
    if (scene) {
        if (!scene->is_object()) return c.fail("part 0.scene", "expected an object");
        if (!read_count(c, *scene, "width", "part 0.scene", &shape.width) ||
            !read_count(c, *scene, "height", "part 0.scene", &shape.height))
            return false;
        if (shape.width < 1 || shape.width > 4096 || shape.height < 1 || shape.height > 4096)
            return c.fail("part 0.scene", "width and height must be in 1..4096");
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
        if (!merge_estimator(c, parts, e, ref, shape, ladder, reps, &(*out)["estimators"][e]))
            return false;
    return true;
}

} // namespace mcp
