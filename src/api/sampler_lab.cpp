// The sampler lab's C functions: a sampler's points, the analysis of a point set (discrepancies,
// minimum distance, power spectrum), discrepancy against N, and a problem integrated with point
// sets given whole. JSON in and out; the computations live in the core (core/point_analysis.h,
// core/draw_points.h, estimators/point_rule.h).
#include <cmath>
#include <string>
#include <vector>

#include "api/boundary.h"
#include "api/json_read.h"
#include "api/mcplay.h"
#include "api/point_input.h"
#include "api/report.h"
#include "api/scene.h"
#include "core/draw_points.h"
#include "core/point_analysis.h"
#include "estimators/point_rule.h"

using mcp::boundary::copy_out;
using mcp::boundary::dump;
using mcp::boundary::fail;

namespace mcp {
namespace {

/// At most this many numbers in one mcp_points answer (about 90 MB of JSON).
constexpr uint64_t kMaxPointsOut = uint64_t(1) << 22;
/// The spectrum's frequency grid: size x size, size even in [2, kMaxSpectrumSize].
constexpr int kMaxSpectrumSize = 1024;
constexpr int kDefaultSpectrumSize = 256;
/// The spectra of one analysis: at most this many complex multiply-adds over all its sets (4,096
/// points on 256 x 256 frequencies take 1.4e8, about 0.1 s natively).
constexpr double kMaxSpectrumOperations = 4294967296.0; // 2^32
/// Discrepancy curves: at most this many samplers, levels, replicates.
constexpr size_t kMaxCurveSamplers = 16;
constexpr uint64_t kMaxCurveReps = 64;

/// A JSON double, or null when it is not finite (JSON has no NaN).
Json number_or_null(double v) {
    return std::isfinite(v) ? Json(v) : Json(nullptr);
}

/// Parses a sampler name for point sets: parse_sampler's names, and "uniform" for independent.
bool parse_point_sampler(const std::string& name, SamplerKind* kind) {
    if (name == "uniform") {
        *kind = SamplerKind::Independent;
        return true;
    }
    return parse_sampler(name, kind);
}

/// {"sampler", "n", "dim", "seed", "randomization"} into a request (set 0).
bool read_point_set_request(Ctx& c, const Json& j, const std::string& path,
                            const std::vector<std::string>& extra_keys, PointSetRequest* out) {
    if (!j.is_object()) return c.fail(path, "expected an object, got " + type_of(j));
    std::vector<std::string> keys{"sampler", "n", "dim", "seed", "randomization"};
    keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
    if (!check_keys(c, j, path, keys)) return false;
    std::string sampler = "independent", randomization;
    uint64_t dim = static_cast<uint64_t>(out->dim);
    if (!get_string(c, j, "sampler", path, &sampler) || !get_count(c, j, "n", path, &out->n) ||
        !get_count(c, j, "dim", path, &dim) || !get_count(c, j, "seed", path, &out->seed) ||
        !get_string(c, j, "randomization", path, &randomization))
        return false;
    if (!parse_point_sampler(sampler, &out->kind))
        return c.fail(sub(path, "sampler"), "unknown sampler '" + sampler +
                                                "' (expected uniform, " + sampler_names() + ")");
    if (dim < 1 || dim > static_cast<uint64_t>(kMaxAnalysisDim))
        return c.fail(sub(path, "dim"), "expected 1 to " + std::to_string(kMaxAnalysisDim) +
                                            ", got " + std::to_string(dim));
    out->dim = static_cast<int>(dim);
    if (is_qmc(out->kind)) {
        out->randomization = default_randomization(qmc_kind_of(out->kind));
        if (!randomization.empty() && !parse_randomization(randomization, &out->randomization))
            return c.fail(sub(path, "randomization"),
                          "unknown randomization '" + randomization + "'");
    } else if (!randomization.empty()) {
        return c.fail(sub(path, "randomization"),
                      "applies to the quasi-Monte Carlo samplers (sobol, halton, lattice) only");
    }
    const std::string why = check_point_set_request(*out);
    if (!why.empty()) return c.fail(path, why);
    return true;
}

Json points_to_rows(const PointSet& set) {
    Json rows = Json::array();
    for (uint64_t i = 0; i < set.n; ++i) {
        Json row = Json::array();
        for (int k = 0; k < set.dim; ++k) row.push_back(set.at(i, k));
        rows.push_back(std::move(row));
    }
    return rows;
}

/// The point sets of an analysis or integration request: "points" (JSON rows, or an array of
/// sets), "csv" (text), or "sampler" (an object as mcp_points takes, with "sets": K).
bool read_point_sets(Ctx& c, const Json& request, UserPointSets* out, Json* source) {
    const Json* points = find(request, "points");
    const Json* csv = find(request, "csv");
    const Json* sampler = find(request, "sampler");
    if ((points ? 1 : 0) + (csv ? 1 : 0) + (sampler ? 1 : 0) != 1)
        return c.fail("request", "give exactly one of \"points\", \"csv\" or \"sampler\"");
    if (points) {
        Made<UserPointSets> m = parse_points_json(*points, "request.points");
        if (!m.ok()) {
            c.error = m.error; // already "request.points[i]...: why"
            return false;
        }
        *out = std::move(m.value);
        *source = {{"kind", "points"}};
        return true;
    }
    if (csv) {
        if (!csv->is_string())
            return c.fail("request.csv", "expected the CSV text as a string, got " + type_of(*csv));
        Made<UserPointSets> m = parse_points_csv(csv->get<std::string>());
        if (!m.ok()) return c.fail("request.csv", m.error);
        *out = std::move(m.value);
        *source = {{"kind", "csv"}};
        return true;
    }
    PointSetRequest r;
    if (!read_point_set_request(c, *sampler, "request.sampler", {"sets"}, &r)) return false;
    uint64_t sets = 1;
    if (!get_count(c, *sampler, "sets", "request.sampler", &sets)) return false;
    if (sets < 1 || sets > kMaxUserSets)
        return c.fail("request.sampler.sets", "expected 1 to " + std::to_string(kMaxUserSets) +
                                                  ", got " + std::to_string(sets));
    if (sets * r.n > kMaxAnalysisPoints)
        return c.fail("request.sampler", std::to_string(sets) + " sets of " + std::to_string(r.n) +
                                             " points exceed " +
                                             std::to_string(kMaxAnalysisPoints) + " points");
    for (uint64_t s = 0; s < sets; ++s) {
        r.set_index = s;
        out->sets.push_back(draw_point_set(r));
        out->set_names.push_back(std::to_string(s));
    }
    *source = {{"kind", "sampler"},
               {"sampler", sampler_name(r.kind)},
               {"randomization",
                is_qmc(r.kind) ? Json(randomization_name(r.randomization)) : Json(nullptr)},
               {"seed", r.seed}};
    return true;
}

/// The mean over sets of a measure, and each set's value.
struct SetMeasure {
    double mean = 0.0;
    std::vector<double> per_set;
};

template <class F> SetMeasure measure_sets(const UserPointSets& sets, F f) {
    SetMeasure m;
    for (const PointSet& s : sets.sets) m.per_set.push_back(f(s));
    double sum = 0.0;
    for (double v : m.per_set) sum += v;
    m.mean = sum / static_cast<double>(m.per_set.size());
    return m;
}

} // namespace
} // namespace mcp

extern "C" {

int mcp_points(const char* request_json, char** points_json) {
    if (!points_json) return fail(MCP_ERROR_ARGUMENT, "mcp_points: points_json is NULL");
    *points_json = nullptr;
    mcp::Made<mcp::Json> request = mcp::parse_json(request_json, "request");
    if (!request.ok()) return fail(MCP_ERROR_ARGUMENT, request.error);
    mcp::Ctx c;
    mcp::PointSetRequest r;
    if (!mcp::read_point_set_request(c, request.value, "request", {}, &r))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    if (r.n * static_cast<uint64_t>(r.dim) > mcp::kMaxPointsOut)
        return fail(MCP_ERROR_ARGUMENT, "request: " + std::to_string(r.n) + " points of " +
                                            std::to_string(r.dim) + " coordinates exceed " +
                                            std::to_string(mcp::kMaxPointsOut) +
                                            " numbers in one answer");
    const mcp::PointSet set = mcp::draw_point_set(r);
    mcp::Json out{{"version", mcp::kResultSchemaVersion},
                  {"sampler", mcp::sampler_name(r.kind)},
                  {"randomization", mcp::is_qmc(r.kind)
                                        ? mcp::Json(mcp::randomization_name(r.randomization))
                                        : mcp::Json(nullptr)},
                  {"n", r.n},
                  {"dim", r.dim},
                  {"seed", r.seed},
                  {"points", mcp::points_to_rows(set)}};
    *points_json = copy_out(dump(out));
    if (!*points_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the points");
    return mcp::boundary::succeed();
}

int mcp_points_analyze(const char* request_json, char** analysis_json) {
    if (!analysis_json)
        return fail(MCP_ERROR_ARGUMENT, "mcp_points_analyze: analysis_json is NULL");
    *analysis_json = nullptr;
    mcp::Made<mcp::Json> request = mcp::parse_json(request_json, "request");
    if (!request.ok()) return fail(MCP_ERROR_ARGUMENT, request.error);
    const mcp::Json& j = request.value;
    mcp::Ctx c;
    if (!j.is_object()) return fail(MCP_ERROR_ARGUMENT, "request: expected an object");
    if (!mcp::check_keys(c, j, "request", {"points", "csv", "sampler", "spectrum", "pairwise"}))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    // The spectrum's options: false, or {"axes": [a, b], "size": S}.
    bool want_spectrum = true, pairwise = true;
    int axis_a = 0, axis_b = 1, size = mcp::kDefaultSpectrumSize;
    if (const mcp::Json* s = mcp::find(j, "spectrum")) {
        if (s->is_boolean()) {
            want_spectrum = s->get<bool>();
        } else if (s->is_object()) {
            if (!mcp::check_keys(c, *s, "request.spectrum", {"axes", "size"}))
                return fail(MCP_ERROR_ARGUMENT, c.error);
            uint64_t sz = static_cast<uint64_t>(size);
            if (!mcp::get_count(c, *s, "size", "request.spectrum", &sz))
                return fail(MCP_ERROR_ARGUMENT, c.error);
            if (sz < 2 || sz > static_cast<uint64_t>(mcp::kMaxSpectrumSize) || sz % 2)
                return fail(MCP_ERROR_ARGUMENT, "request.spectrum.size: expected an even number "
                                                "from 2 to " +
                                                    std::to_string(mcp::kMaxSpectrumSize) +
                                                    ", got " + std::to_string(sz));
            size = static_cast<int>(sz);
            std::vector<double> axes;
            if (!mcp::get_numbers(c, *s, "axes", "request.spectrum", &axes))
                return fail(MCP_ERROR_ARGUMENT, c.error);
            if (!axes.empty()) {
                if (axes.size() != 2 || axes[0] != std::floor(axes[0]) ||
                    axes[1] != std::floor(axes[1]) || axes[0] < 0 || axes[1] < 0 || axes[0] > 63 ||
                    axes[1] > 63 || axes[0] == axes[1])
                    return fail(MCP_ERROR_ARGUMENT,
                                "request.spectrum.axes: expected two different axes (0-based), "
                                "e.g. [0, 1]");
                axis_a = static_cast<int>(axes[0]);
                axis_b = static_cast<int>(axes[1]);
            }
        } else {
            return fail(MCP_ERROR_ARGUMENT,
                        "request.spectrum: expected false or {\"axes\", \"size\"}, got " +
                            mcp::type_of(*s));
        }
    }
    if (const mcp::Json* p = mcp::find(j, "pairwise")) {
        if (!p->is_boolean())
            return fail(MCP_ERROR_ARGUMENT, "request.pairwise: expected true or false");
        pairwise = p->get<bool>();
    }
    mcp::UserPointSets sets;
    mcp::Json source;
    if (!mcp::read_point_sets(c, j, &sets, &source)) return fail(MCP_ERROR_ARGUMENT, c.error);
    const mcp::PointSet& first = sets.sets[0];
    const int dim = first.dim;
    if (want_spectrum && dim >= 2 && (axis_a >= dim || axis_b >= dim))
        return fail(MCP_ERROR_ARGUMENT, "request.spectrum.axes: the points have " +
                                            std::to_string(dim) + " coordinates (axes 0 to " +
                                            std::to_string(dim - 1) + ")");

    mcp::Json out{{"version", mcp::kResultSchemaVersion},
                  {"source", source},
                  {"n", first.n},
                  {"dim", dim},
                  {"sets", sets.sets.size()},
                  {"set_names", sets.set_names}};
    mcp::Json skipped = mcp::Json::object(), per_set = mcp::Json::object();
    out["expected_iid"] = {
        {"l2_star_discrepancy", std::sqrt(mcp::expected_l2_star_squared_iid(first.n, dim))},
        {"centered_l2_discrepancy", std::sqrt(mcp::expected_centered_squared_iid(first.n, dim))},
        {"wraparound_l2_discrepancy",
         std::sqrt(mcp::expected_wraparound_squared_iid(first.n, dim))}};
    const char* pair_names[] = {"l2_star_discrepancy", "centered_l2_discrepancy",
                                "wraparound_l2_discrepancy", "min_distance",
                                "min_distance_toroidal"};
    // The pair sums of all the sets together within the bound of one set's.
    const double set_count = static_cast<double>(sets.sets.size());
    const bool affordable =
        set_count * mcp::pair_coordinates(first.n, dim) <= mcp::kMaxPairCoordinates;
    if (pairwise && affordable) {
        const mcp::SetMeasure measures[] = {
            mcp::measure_sets(sets,
                              [](const mcp::PointSet& s) { return mcp::l2_star_discrepancy(s); }),
            mcp::measure_sets(
                sets, [](const mcp::PointSet& s) { return mcp::centered_l2_discrepancy(s); }),
            mcp::measure_sets(
                sets, [](const mcp::PointSet& s) { return mcp::wraparound_l2_discrepancy(s); }),
            mcp::measure_sets(sets,
                              [](const mcp::PointSet& s) { return mcp::min_distance(s, false); }),
            mcp::measure_sets(sets,
                              [](const mcp::PointSet& s) { return mcp::min_distance(s, true); })};
        for (size_t m = 0; m < 5; ++m) {
            out[pair_names[m]] = mcp::number_or_null(measures[m].mean);
            if (sets.sets.size() > 1) per_set[pair_names[m]] = measures[m].per_set;
        }
    } else {
        const std::string why =
            !pairwise ? "not asked for (pairwise: false)"
                      : "the O(N^2 d) sums over pairs of " + std::to_string(sets.sets.size()) +
                            " set(s) of " + std::to_string(first.n) + " points in " +
                            std::to_string(dim) + " dimensions exceed the limit of " +
                            std::to_string(static_cast<uint64_t>(mcp::kMaxPairCoordinates)) +
                            " pair-coordinates; analyse fewer points";
        for (const char* name : pair_names) {
            out[name] = nullptr;
            skipped[name] = why;
        }
    }
    if (sets.sets.size() > 1) out["per_set"] = per_set;
    const double spectrum_cost = set_count * mcp::spectrum_operations(first.n, size);
    if (want_spectrum && spectrum_cost > mcp::kMaxSpectrumOperations) {
        want_spectrum = false;
        skipped["spectrum"] = "the periodogram of " + std::to_string(sets.sets.size()) +
                              " set(s) of " + std::to_string(first.n) + " points on " +
                              std::to_string(size) + " x " + std::to_string(size) +
                              " frequencies would take " +
                              std::to_string(static_cast<uint64_t>(spectrum_cost)) +
                              " operations, above the limit of " +
                              std::to_string(static_cast<uint64_t>(mcp::kMaxSpectrumOperations)) +
                              "; choose a smaller size or fewer points";
    } else if (want_spectrum) {
        // Averaged over the sets: the expected periodogram of the randomized rule.
        const int b = dim >= 2 ? axis_b : -1;
        mcp::PowerSpectrum mean;
        for (const mcp::PointSet& s : sets.sets) {
            mcp::PowerSpectrum ps = mcp::power_spectrum(s, axis_a, b, size);
            if (mean.power.empty()) {
                mean = std::move(ps);
            } else {
                for (size_t i = 0; i < mean.power.size(); ++i) mean.power[i] += ps.power[i];
            }
        }
        const double scale = 1.0 / static_cast<double>(sets.sets.size());
        for (double& v : mean.power) v *= scale;
        const mcp::RadialSpectrum radial = mcp::radial_average(mean);
        out["spectrum"] = {
            {"size", size},
            {"axes", {axis_a, b}},
            {"power", mean.power},
            {"radial",
             {{"frequency", radial.frequency}, {"power", radial.power}, {"count", radial.count}}}};
    } else if (!skipped.contains("spectrum")) {
        skipped["spectrum"] = "not asked for (spectrum: false)";
    }
    out["skipped"] = skipped;
    *analysis_json = copy_out(dump(out));
    if (!*analysis_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the analysis");
    return mcp::boundary::succeed();
}

int mcp_discrepancy_curve(const char* request_json, char** curve_json) {
    if (!curve_json) return fail(MCP_ERROR_ARGUMENT, "mcp_discrepancy_curve: curve_json is NULL");
    *curve_json = nullptr;
    mcp::Made<mcp::Json> request = mcp::parse_json(request_json, "request");
    if (!request.ok()) return fail(MCP_ERROR_ARGUMENT, request.error);
    const mcp::Json& j = request.value;
    mcp::Ctx c;
    if (!j.is_object()) return fail(MCP_ERROR_ARGUMENT, "request: expected an object");
    if (!mcp::check_keys(c, j, "request",
                         {"samplers", "dim", "n_min", "n_max", "seed", "reps", "scene"}))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    uint64_t dim = 2, n_min = 16, n_max = 4096, seed = 1, reps = 8;
    if (!mcp::get_count(c, j, "dim", "request", &dim) ||
        !mcp::get_count(c, j, "n_min", "request", &n_min) ||
        !mcp::get_count(c, j, "n_max", "request", &n_max) ||
        !mcp::get_count(c, j, "seed", "request", &seed) ||
        !mcp::get_count(c, j, "reps", "request", &reps))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    if (n_min < 1 || n_max < n_min || n_max > 65536)
        return fail(MCP_ERROR_ARGUMENT, "request: expected 1 <= n_min <= n_max <= 65536, got " +
                                            std::to_string(n_min) + " and " +
                                            std::to_string(n_max));
    if (reps < 1 || reps > mcp::kMaxCurveReps)
        return fail(MCP_ERROR_ARGUMENT,
                    "request.reps: expected 1 to " + std::to_string(mcp::kMaxCurveReps));
    std::vector<std::string> names{"independent", "stratified", "latin_hypercube",
                                   "sobol",       "halton",     "lattice"};
    if (const mcp::Json* s = mcp::find(j, "samplers")) {
        if (!s->is_array() || s->empty() || s->size() > mcp::kMaxCurveSamplers)
            return fail(MCP_ERROR_ARGUMENT, "request.samplers: expected 1 to " +
                                                std::to_string(mcp::kMaxCurveSamplers) +
                                                " sampler names");
        names.clear();
        for (const mcp::Json& v : *s) {
            if (!v.is_string())
                return fail(MCP_ERROR_ARGUMENT,
                            "request.samplers: expected names, got " + mcp::type_of(v));
            names.push_back(v.get<std::string>());
        }
    }
    // The integration error beside the discrepancy: a problem with an exact value (optional).
    mcp::Problem problem;
    bool with_problem = false;
    if (const mcp::Json* scene = mcp::find(j, "scene")) {
        mcp::Made<mcp::SceneRequest> req = mcp::build_request(*scene, mcp::Json());
        if (!req.ok()) return mcp::boundary::request_error("request.scene: " + req.error);
        problem = req.value.problem;
        if (!problem.exact)
            return fail(MCP_ERROR_SCENE, "request.scene: the problem has no exact value, so the "
                                         "integration error cannot be measured");
        if (problem.domain.sample_dim() != static_cast<int>(dim))
            return fail(MCP_ERROR_SCENE, "request.scene: its domain is sampled in " +
                                             std::to_string(problem.domain.sample_dim()) +
                                             " dimensions, the curve's points have " +
                                             std::to_string(dim));
        with_problem = true;
    }
    // The ladder: powers of two from n_min (rounded up) to n_max.
    std::vector<uint64_t> ladder;
    for (uint64_t n = 1; n <= n_max; n *= 2)
        if (n >= n_min) ladder.push_back(n);
    if (ladder.empty()) ladder.push_back(n_min);
    // Bound the work before it starts: the pair sums cost about reps * sum N^2 d / 2.
    double cost = 0.0;
    for (uint64_t n : ladder) cost += 0.5 * double(n) * double(n) * double(dim);
    cost *= double(reps) * double(names.size());
    if (cost > mcp::kMaxPairCoordinates)
        return fail(MCP_ERROR_ARGUMENT,
                    "request: the curve would sum " + std::to_string(static_cast<uint64_t>(cost)) +
                        " pair-coordinates, above the limit of " +
                        std::to_string(static_cast<uint64_t>(mcp::kMaxPairCoordinates)) +
                        "; lower n_max, reps or the number of samplers");
    mcp::Json curves = mcp::Json::array();
    for (const std::string& name : names) {
        mcp::PointSetRequest r;
        r.dim = static_cast<int>(dim);
        r.seed = seed;
        if (!mcp::parse_point_sampler(name, &r.kind))
            return fail(MCP_ERROR_ARGUMENT, "request.samplers: unknown sampler '" + name + "'");
        if (mcp::is_qmc(r.kind))
            r.randomization = mcp::default_randomization(mcp::qmc_kind_of(r.kind));
        mcp::Json n_out = mcp::Json::array(), l2 = mcp::Json::array(), wrap = mcp::Json::array(),
                  err = mcp::Json::array();
        for (uint64_t n : ladder) {
            r.n = n;
            const std::string why = mcp::check_point_set_request(r);
            if (!why.empty()) return fail(MCP_ERROR_ARGUMENT, "request (" + name + "): " + why);
            // Root mean square over the replicates: discrepancies and errors of random sets.
            double l2_sq = 0.0, wrap_sq = 0.0, err_sq = 0.0;
            for (uint64_t rep = 0; rep < reps; ++rep) {
                r.set_index = rep;
                const mcp::PointSet s = mcp::draw_point_set(r);
                const double d = mcp::l2_star_discrepancy(s), w = mcp::wraparound_l2_discrepancy(s);
                l2_sq += d * d;
                wrap_sq += w * w;
                if (with_problem) {
                    const double e =
                        mcp::integrate_with_point_sets(problem, {s}).estimate - *problem.exact;
                    err_sq += e * e;
                }
            }
            n_out.push_back(n);
            l2.push_back(std::sqrt(l2_sq / double(reps)));
            wrap.push_back(std::sqrt(wrap_sq / double(reps)));
            if (with_problem) err.push_back(mcp::number_or_null(std::sqrt(err_sq / double(reps))));
        }
        mcp::Json curve{{"sampler", mcp::sampler_name(r.kind)},
                        {"n", n_out},
                        {"l2_star_discrepancy", l2},
                        {"wraparound_l2_discrepancy", wrap}};
        if (with_problem) curve["rms_error"] = err;
        curves.push_back(curve);
    }
    mcp::Json out{{"version", mcp::kResultSchemaVersion},
                  {"dim", dim},
                  {"reps", reps},
                  {"seed", seed},
                  {"statistic", "root mean square over reps independent point sets"},
                  {"curves", curves}};
    if (with_problem) {
        out["problem"] = problem.name;
        out["exact"] = *problem.exact;
    }
    *curve_json = copy_out(dump(out));
    if (!*curve_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the curve");
    return mcp::boundary::succeed();
}

int mcp_points_integrate(const char* scene_json, const char* request_json, char** result_json) {
    if (!result_json) return fail(MCP_ERROR_ARGUMENT, "mcp_points_integrate: result_json is NULL");
    *result_json = nullptr;
    mcp::Made<mcp::Json> scene = mcp::parse_json(scene_json, "scene");
    if (!scene.ok()) return fail(MCP_ERROR_SCENE, scene.error);
    mcp::Made<mcp::Json> request = mcp::parse_json(request_json, "request");
    if (!request.ok()) return fail(MCP_ERROR_ARGUMENT, request.error);
    mcp::Ctx c;
    if (!request.value.is_object()) return fail(MCP_ERROR_ARGUMENT, "request: expected an object");
    if (!mcp::check_keys(c, request.value, "request", {"points", "csv", "sampler"}))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    mcp::Made<mcp::SceneRequest> req = mcp::build_request(scene.value, mcp::Json());
    if (!req.ok()) return mcp::boundary::request_error(req.error);
    mcp::UserPointSets sets;
    mcp::Json source;
    if (!mcp::read_point_sets(c, request.value, &sets, &source))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    const mcp::Problem& problem = req.value.problem;
    const std::string why = mcp::check_point_rule(problem, sets.sets);
    if (!why.empty()) return fail(MCP_ERROR_ARGUMENT, "request: " + why);
    const mcp::PointRuleEstimate e = mcp::integrate_with_point_sets(problem, sets.sets);
    mcp::Json out{{"version", mcp::kResultSchemaVersion},
                  {"problem", problem.name},
                  {"source", source},
                  {"n", sets.sets[0].n},
                  {"sets", sets.sets.size()},
                  {"estimate", mcp::number_or_null(e.estimate)},
                  {"per_set", e.per_set},
                  {"evaluations", e.evaluations},
                  {"exact", problem.exact ? mcp::Json(*problem.exact) : mcp::Json(nullptr)}};
    if (problem.exact) out["error"] = mcp::number_or_null(e.estimate - *problem.exact);
    if (e.has_error_bar) {
        out["error_bar"] = {{"standard_error", mcp::number_or_null(e.standard_error)},
                            {"half_width_95", mcp::number_or_null(e.half_width_95)},
                            {"degrees_of_freedom", e.degrees_of_freedom},
                            {"method", "t interval over the sets as independent randomizations"}};
    } else {
        out["error_bar"] = nullptr;
        out["note"] = e.no_error_bar;
    }
    *result_json = copy_out(dump(out));
    if (!*result_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the result");
    return mcp::boundary::succeed();
}

} // extern "C"
