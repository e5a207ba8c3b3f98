// Scene parsing. Every value is type-checked before use (the API is built without
// exceptions, so no nlohmann accessor that could throw is called on unchecked data), and
// every error names the JSON path of the offending field and what was expected.
#include "api/scene.h"
#include "api/json_read.h"
#include "estimators/stopping.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>
#include <sstream>

#include "core/special.h"

namespace mcp {

namespace {

bool get_vec2(Ctx& c, const Json& v, const std::string& path, Vec2* out) {
    std::vector<double> xs;
    if (!to_numbers(c, v, path, &xs)) return false;
    if (xs.size() != 2)
        return c.fail(path, "expected [x, y], got " + std::to_string(xs.size()) + " numbers");
    *out = Vec2{xs[0], xs[1]};
    return true;
}

// --- domain ------------------------------------------------------------------------------

/// Most dimensions of any domain, integrand or parameter array.
constexpr int kMaxDim = 64;

/// "1e-400" style order of magnitude of 10^e10 (e10 = log10 of a number outside the double
/// range), for messages about measures that overflow or underflow.
std::string magnitude(double e10) {
    return "about 1e" + std::to_string(static_cast<long long>(std::floor(e10 + 1e-6)));
}

/// A number for messages ("1e+200", "0.25", "NaN", "-inf": the same on every platform).
std::string number_text(double x) {
    if (std::isnan(x)) return "NaN";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    std::ostringstream s;
    s.precision(6);
    s << x;
    return s.str();
}

/// A measure (a width, volume, area) must be a finite, normal positive double: otherwise every
/// density 1/measure, every mean and every exact value built on it is inf or 0, and the study
/// reports 0 +- 0 [Goldberg91]. Returns "" or what is wrong, given log10 of the true value.
std::string check_measure(double measure, double log10_measure) {
    if (std::isfinite(measure) && measure >= std::numeric_limits<double>::min()) return "";
    const bool over = !std::isfinite(measure) || log10_measure > 0.0;
    return std::string(over ? "overflows" : "underflows") + " the double range (" +
           magnitude(log10_measure) +
           "); it must be a finite, normal positive double (2.2e-308 .. 1.8e308): rescale the "
           "problem";
}

/// The fields each domain type reads; any other field is refused, not silently ignored.
bool check_domain_fields(Ctx& c, const Json& j, const std::string& path, const std::string& type,
                         const std::vector<std::string>& fields) {
    for (auto it = j.begin(); it != j.end(); ++it) {
        bool ok = false;
        for (const std::string& k : fields) ok = ok || k == it.key();
        if (!ok)
            return c.fail(sub(path, it.key().c_str()), "does not apply to a " + type +
                                                           " domain (its fields: " + join(fields) +
                                                           ")");
    }
    return true;
}

bool parse_domain(Ctx& c, const Json& j, const std::string& path, int default_dim, Domain* out) {
    std::string type = "box";
    if (!check_keys(c, j, path, {"type", "dim", "lower", "upper", "center", "radius", "vertices"}))
        return false;
    if (!get_string(c, j, "type", path, &type)) return false;
    if (type == "box" || type == "interval") {
        if (!check_domain_fields(c, j, path, type, {"type", "dim", "lower", "upper"})) return false;
        uint64_t dim = static_cast<uint64_t>(default_dim);
        if (!get_count(c, j, "dim", path, &dim)) return false;
        if (dim < 1 || dim > static_cast<uint64_t>(kMaxDim))
            return c.fail(sub(path, "dim"), "must be in 1.." + std::to_string(kMaxDim) + ", got " +
                                                std::to_string(dim));
        // Array lengths are checked before any array is converted.
        for (const char* key : {"lower", "upper"})
            if (const Json* v = find(j, key); v && v->is_array() && v->size() > size_t(kMaxDim))
                return c.fail(sub(path, key), "has " + std::to_string(v->size()) +
                                                  " entries; mcplay integrates in at most " +
                                                  std::to_string(kMaxDim) + " dimensions");
        std::vector<double> lo(dim, 0.0), hi(dim, 1.0);
        if (!get_numbers(c, j, "lower", path, &lo) || !get_numbers(c, j, "upper", path, &hi))
            return false;
        // An explicit "dim" must agree with the bounds it comes with.
        for (const std::vector<double>* bound : {&lo, &hi})
            if (find(j, "dim") && bound->size() != dim)
                return c.fail(sub(path, "dim"), "is " + std::to_string(dim) + ", but \"" +
                                                    (bound == &lo ? "lower" : "upper") + "\" has " +
                                                    std::to_string(bound->size()) + " entries");
        if (find(j, "lower") && !find(j, "dim") && !find(j, "upper")) hi.assign(lo.size(), 1.0);
        if (find(j, "upper") && !find(j, "dim") && !find(j, "lower")) lo.assign(hi.size(), 0.0);
        if (lo.size() != hi.size())
            return c.fail(path, "lower has " + std::to_string(lo.size()) + " entries, upper has " +
                                    std::to_string(hi.size()));
        if (type == "interval" && lo.size() != 1)
            return c.fail(path, "an interval has one dimension");
        Made<Domain> d = make_box(lo, hi);
        if (!d.ok()) return c.fail(path, d.error);
        // Each width, and their product, must be a normal positive double.
        double log10_volume = 0.0;
        for (size_t a = 0; a < lo.size(); ++a) {
            const double w = hi[a] - lo[a];
            // hi - lo overflows only when both are huge: halve first for the magnitude.
            const double lw =
                std::isfinite(w) ? std::log10(w) : std::log10(0.5 * hi[a] - 0.5 * lo[a]) + 0.30103;
            log10_volume += lw;
            std::string bad = check_measure(w, lw);
            if (!bad.empty())
                return c.fail(path, "the width upper - lower of axis " + std::to_string(a) + " (" +
                                        number_text(hi[a]) + " - " + number_text(lo[a]) + ") " +
                                        bad);
        }
        std::string bad = check_measure(d.value.measure(), log10_volume);
        if (!bad.empty())
            return c.fail(path, "the box's volume (the product of its " +
                                    std::to_string(lo.size()) + " widths) " + bad);
        *out = d.value;
        return true;
    }
    if (type == "disk") {
        if (!check_domain_fields(c, j, path, type, {"type", "center", "radius"})) return false;
        Vec2 center{0.0, 0.0};
        double radius = 1.0;
        if (const Json* v = find(j, "center"); v && !get_vec2(c, *v, sub(path, "center"), &center))
            return false;
        if (!get_number(c, j, "radius", path, &radius)) return false;
        Made<Domain> d = make_disk(center, radius);
        if (!d.ok()) return c.fail(path, d.error);
        // pi r^2, and the bounding box centre +- r, must be representable.
        std::string bad =
            check_measure(d.value.measure(), std::log10(kPi) + 2.0 * std::log10(radius));
        if (!bad.empty())
            return c.fail(sub(path, "radius"),
                          "the disk's area pi r^2 with r = " + number_text(radius) + " " + bad);
        if (!std::isfinite(center.x - radius) || !std::isfinite(center.x + radius) ||
            !std::isfinite(center.y - radius) || !std::isfinite(center.y + radius))
            return c.fail(path, "centre +- radius overflows the double range");
        *out = d.value;
        return true;
    }
    if (type == "triangle") {
        if (!check_domain_fields(c, j, path, type, {"type", "vertices"})) return false;
        const Json* v = find(j, "vertices");
        if (!v) return c.fail(path, "a triangle needs \"vertices\": [[x, y], [x, y], [x, y]]");
        if (!v->is_array() || v->size() != 3)
            return c.fail(sub(path, "vertices"), "expected three [x, y] points");
        Vec2 p[3];
        for (size_t i = 0; i < 3; ++i)
            if (!get_vec2(c, (*v)[i], sub(path, "vertices") + "[" + std::to_string(i) + "]", &p[i]))
                return false;
        // The area from edge vectors scaled by their largest component s: |cross| s^2 / 2,
        // so that an area outside the double range is told from a degenerate triangle.
        const Vec2 e1 = p[1] - p[0], e2 = p[2] - p[0];
        const double s = std::max(std::max(std::fabs(e1.x), std::fabs(e1.y)),
                                  std::max(std::fabs(e2.x), std::fabs(e2.y)));
        if (std::isfinite(s) && s > 0.0) {
            const Vec2 a1 = e1 / s, a2 = e2 / s;
            const double cross = std::fabs(a1.x * a2.y - a2.x * a1.y);
            if (cross > 0.0) {
                const double log10_area = std::log10(0.5 * cross) + 2.0 * std::log10(s);
                std::string bad = check_measure(0.5 * cross * s * s, log10_area);
                if (!bad.empty()) return c.fail(path, "the triangle's area " + bad);
            }
        } else if (!std::isfinite(s)) {
            return c.fail(path, "the triangle's edges overflow the double range");
        }
        Made<Domain> d = make_triangle(p[0], p[1], p[2]);
        if (!d.ok()) return c.fail(path, d.error);
        std::string bad = check_measure(d.value.measure(), 0.0);
        if (!bad.empty()) return c.fail(path, "the triangle's area " + bad);
        *out = d.value;
        return true;
    }
    if (type == "sphere" || type == "hemisphere") {
        if (!check_domain_fields(c, j, path, type, {"type"})) return false;
        *out = type == "sphere" ? make_sphere() : make_hemisphere();
        return true;
    }
    return c.fail(sub(path, "type"),
                  "unknown domain '" + type +
                      "' (known: box, interval, disk, triangle, sphere, hemisphere)");
}

// --- integrand ---------------------------------------------------------------------------

constexpr const char* kIntegrandTypes =
    "constant, monomial, exponential, gaussian, indicator_ball, expression, genz_oscillatory, "
    "genz_product_peak, genz_corner_peak, genz_gaussian, genz_continuous, genz_discontinuous";

bool parse_expression(Ctx& c, const Json& text, const std::string& path, int dim, Integrand* out) {
    if (!text.is_string())
        return c.fail(path, "expected an expression string, got " + type_of(text));
    Made<Integrand> f = make_expression_integrand(text.get<std::string>(), dim);
    if (!f.ok()) return c.fail(path, f.error);
    *out = f.value;
    return true;
}

/// Parameter arrays whose length is a dimension.
constexpr const char* kDimensionArrays[] = {"powers", "rates", "center", "a", "u"};

/// Refuses parameter arrays longer than any domain, before they are converted.
bool check_array_lengths(Ctx& c, const Json& j, const std::string& path) {
    for (const char* key : kDimensionArrays)
        if (const Json* v = find(j, key); v && v->is_array() && v->size() > size_t(kMaxDim))
            return c.fail(sub(path, key), "has " + std::to_string(v->size()) +
                                              " entries; mcplay integrates in at most " +
                                              std::to_string(kMaxDim) + " dimensions");
    return true;
}

/// A Genz "dim": a whole number in 1..64 (false with an error otherwise; *given is false when
/// there is none).
bool get_genz_dim(Ctx& c, const Json& j, const std::string& path, int* dim, bool* given) {
    *given = find(j, "dim") != nullptr;
    if (!*given) return true;
    uint64_t d = 0;
    if (!get_count(c, j, "dim", path, &d)) return false;
    if (d < 1 || d > static_cast<uint64_t>(kMaxDim))
        return c.fail(sub(path, "dim"),
                      "must be in 1.." + std::to_string(kMaxDim) + ", got " + std::to_string(d));
    *dim = static_cast<int>(d);
    return true;
}

// Genz families: explicit "a" and "u", or Genz's random normalisation from "seed" and
// "difficulty" (dimension from "dim" or the domain).
bool parse_genz(Ctx& c, const Json& j, const std::string& path, GenzFamily family, int dim,
                Integrand* out) {
    if (!check_keys(c, j, path, {"type", "a", "u", "dim", "seed", "difficulty"})) return false;
    if (!check_array_lengths(c, j, path)) return false;
    // "dim" is never ignored: it must agree with the domain and with "a".
    int given_dim = 0;
    bool has_dim = false;
    if (!get_genz_dim(c, j, path, &given_dim, &has_dim)) return false;
    if (has_dim && given_dim != dim)
        return c.fail(sub(path, "dim"), "is " + std::to_string(given_dim) +
                                            ", but the domain has " + std::to_string(dim) +
                                            (dim == 1 ? " dimension" : " dimensions"));
    std::vector<double> a, u;
    if (!get_numbers(c, j, "a", path, &a) || !get_numbers(c, j, "u", path, &u)) return false;
    if (has_dim && find(j, "a") && a.size() != size_t(given_dim))
        return c.fail(sub(path, "dim"), "is " + std::to_string(given_dim) + ", but \"a\" has " +
                                            std::to_string(a.size()) + " entries");
    GenzParams params;
    if (find(j, "a")) {
        if (!find(j, "u")) u.assign(a.size(), 0.5);
        Made<GenzParams> g = make_genz(family, a, u);
        if (!g.ok()) return c.fail(path, g.error);
        params = g.value;
    } else {
        if (find(j, "u"))
            return c.fail(sub(path, "u"), "give \"a\" with \"u\", or neither (random)");
        uint64_t seed = 1;
        double difficulty = 1.0;
        if (!get_count(c, j, "seed", path, &seed) ||
            !get_number(c, j, "difficulty", path, &difficulty))
            return false;
        if (!(difficulty > 0.0))
            return c.fail(sub(path, "difficulty"), "must be > 0 (1 = Genz's standard difficulty)");
        params = genz_random(family, dim, seed, difficulty);
    }
    // Genz's normalisation can push an integral (and every value of f) below the double range
    // (product_peak at d = 64 is ~1e-340): refuse it rather than estimate 0 against 0.
    int sign = 0;
    const double log_exact = genz_log_exact(params, &sign);
    if (sign != 0 && log_exact < std::log(1e-280))
        return c.fail(
            path, std::string(genz_family_name(family)) +
                      " in d = " + std::to_string(params.dim()) + " has an integral of about 1e" +
                      std::to_string(static_cast<int>(std::floor(log_exact / std::log(10.0)))) +
                      ", outside double precision: lower the difficulty or the dimension");
    if (params.dim() != dim)
        return c.fail(path, std::string(genz_family_name(family)) + " has " +
                                std::to_string(params.dim()) + " dimensions, the domain " +
                                std::to_string(dim));
    *out = make_genz_integrand(params);
    return true;
}

bool parse_integrand(Ctx& c, const Json& j, const std::string& path, int dim, Integrand* out) {
    if (j.is_string()) return parse_expression(c, j, path, dim, out);
    if (!j.is_object())
        return c.fail(path, "expected an integrand object or expression string, got " + type_of(j));
    std::string type;
    if (!get_string(c, j, "type", path, &type)) return false;
    if (type.empty())
        return c.fail(path, std::string("missing \"type\" (") + kIntegrandTypes + ")");
    if (type == "expression") {
        if (!check_keys(c, j, path, {"type", "f"})) return false;
        const Json* text = find(j, "f");
        if (!text) return c.fail(path, "an expression integrand needs \"f\": \"...\"");
        return parse_expression(c, *text, sub(path, "f"), dim, out);
    }
    GenzFamily family;
    if (parse_genz_family(type, &family)) return parse_genz(c, j, path, family, dim, out);
    IntegrandKind kind;
    if (!parse_integrand_kind(type, &kind))
        return c.fail(sub(path, "type"),
                      "unknown integrand '" + type + "' (known: " + kIntegrandTypes + ")");
    if (!check_keys(c, j, path, {"type", "scale", "powers", "rates", "center", "sigma", "radius"}))
        return false;
    if (!check_array_lengths(c, j, path)) return false;
    double scale = 1.0, width = 1.0;
    std::vector<double> coeffs, center;
    if (!get_number(c, j, "scale", path, &scale)) return false;
    if (kind == IntegrandKind::Monomial && !get_numbers(c, j, "powers", path, &coeffs))
        return false;
    if (kind == IntegrandKind::Exponential && !get_numbers(c, j, "rates", path, &coeffs))
        return false;
    if ((kind == IntegrandKind::Monomial || kind == IntegrandKind::Exponential) &&
        coeffs.size() == 1 && dim > 1)
        coeffs.assign(static_cast<size_t>(dim), coeffs[0]);
    if (kind == IntegrandKind::Gaussian || kind == IntegrandKind::IndicatorBall) {
        if (!get_numbers(c, j, "center", path, &center)) return false;
        if (!get_number(c, j, kind == IntegrandKind::Gaussian ? "sigma" : "radius", path, &width))
            return false;
    }
    Made<Integrand> f = make_integrand(kind, dim, scale, coeffs, center, width);
    if (!f.ok()) return c.fail(path, f.error);
    *out = f.value;
    return true;
}

// The dimension an integrand asks for when the scene gives no domain: the length of its
// parameter arrays, a Genz "dim", or the highest variable an expression uses. Errors for
// arrays longer than 64 and for a "dim" outside 1..64.
bool integrand_dimension(Ctx& c, const Json& j, const std::string& path, int* out) {
    *out = 1;
    if (j.is_string() || (j.is_object() && find(j, "f") && find(j, "f")->is_string())) {
        const std::string text =
            j.is_string() ? j.get<std::string>() : find(j, "f")->get<std::string>();
        *out = kMaxDim; // not an expression in any dimension: the full one reports the error
        if (!compile_expression(text, kMaxDim).ok()) return true;
        for (int d = 1; d <= kMaxDim; ++d)
            if (compile_expression(text, d).ok()) {
                *out = d;
                break;
            }
        return true;
    }
    if (!j.is_object()) return true; // parse_integrand reports it
    if (!check_array_lengths(c, j, path)) return false;
    for (const char* key : kDimensionArrays)
        if (const Json* v = find(j, key); v && v->is_array() && !v->empty())
            *out = static_cast<int>(v->size());
    int dim = 0;
    bool given = false;
    if (!get_genz_dim(c, j, path, &dim, &given)) return false;
    if (given) *out = dim;
    return true;
}

// --- pdfs --------------------------------------------------------------------------------

constexpr int kMaxBins = 1 << 20;      // bins of a 1D table
constexpr int kMaxBinsPerAxis = 4096;  // bins per axis of a 2D table
constexpr size_t kMaxCells = 1u << 20; // cells of a 2D table
constexpr int kSubSamples = 4;         // shape evaluations per bin and axis when tabulating
constexpr size_t kMaxTabulationPoints = size_t(1) << 24; // shape evaluations per table
constexpr int kExpressionBins1D = 1024;
constexpr int kExpressionBins2D = 64;

// Tabulation values: explicit "values", or |shape| averaged over kSubSamples^d points per cell.
// Every count is checked before any array is converted or any shape evaluated.
bool table_values(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                  const std::vector<int>& bins, const std::vector<double>& lo,
                  const std::vector<double>& hi, std::vector<double>* values) {
    size_t cells = 1;
    for (int b : bins) cells *= static_cast<size_t>(b); // b <= 2^20, at most two axes
    if (const Json* v = find(j, "values")) {
        const size_t given = v->is_array() ? v->size() : 1;
        if (given != cells)
            return c.fail(sub(path, "values"), "has " + std::to_string(given) +
                                                   " entries, bins ask for " +
                                                   std::to_string(cells));
        if (!to_numbers(c, *v, sub(path, "values"), values)) return false;
        return true;
    }
    const Json* shape = find(j, "shape");
    if (!shape) return c.fail(path, "a tabulated pdf needs \"values\" or \"shape\"");
    const int dim = static_cast<int>(bins.size());
    const size_t sub_count = dim == 1 ? kSubSamples : kSubSamples * kSubSamples;
    const size_t total = cells * sub_count;
    if (total > kMaxTabulationPoints)
        return c.fail(sub(path, "bins"), std::to_string(cells) + " cells of " +
                                             std::to_string(sub_count) + " points each are " +
                                             std::to_string(total) +
                                             " shape evaluations, more "
                                             "than the limit of " +
                                             std::to_string(kMaxTabulationPoints));
    Integrand f;
    // The integrand's shape is tabulated as |f| (the density proportional to |f| is the best one
    // [Owen13, 9.1]); a shape the user gives is a density and must not be negative: silently
    // taking |p| would sample from something else than what was typed.
    const bool from_integrand = shape->is_string() && shape->get<std::string>() == "integrand";
    if (from_integrand) {
        if (problem.integrand.dim != dim)
            return c.fail(sub(path, "shape"), "the integrand has " +
                                                  std::to_string(problem.integrand.dim) +
                                                  " dimensions, the table " + std::to_string(dim));
        f = problem.integrand;
    } else if (!parse_integrand(c, *shape, sub(path, "shape"), dim, &f)) {
        return false;
    }
    values->assign(cells, 0.0);
    // kSubSamples^d points per cell, evaluated a block at a time (cell-major, so each cell's
    // points are summed in order); x fastest over the cells, matching make_tabulated_2d.
    PointBlock block;
    block.reset(dim, kBlockSize);
    std::vector<double> v(kBlockSize);
    size_t bad = 0, negative = 0;
    double bad_x = 0.0, bad_y = 0.0, bad_value = 0.0;
    double neg_x = 0.0, neg_y = 0.0, neg_value = 0.0;
    for (size_t first = 0; first < total; first += kBlockSize) {
        block.n = std::min(kBlockSize, total - first);
        for (size_t i = 0; i < block.n; ++i) {
            const size_t cell = (first + i) / sub_count, sub = (first + i) % sub_count;
            const size_t ix = cell % static_cast<size_t>(bins[0]);
            const size_t iy = dim == 2 ? cell / static_cast<size_t>(bins[0]) : 0;
            const size_t sx = sub % kSubSamples, sy = sub / kSubSamples;
            block.coord(0)[i] = lo[0] + (hi[0] - lo[0]) * (ix + (sx + 0.5) / kSubSamples) / bins[0];
            if (dim == 2)
                block.coord(1)[i] =
                    lo[1] + (hi[1] - lo[1]) * (iy + (sy + 0.5) / kSubSamples) / bins[1];
        }
        evaluate_block(f, block, v.data());
        for (size_t i = 0; i < block.n; ++i) {
            const double a = std::fabs(v[i]);
            if (!std::isfinite(a)) { // counted and reported, never dropped
                if (bad++ == 0) {
                    bad_x = block.coord(0)[i];
                    bad_y = dim == 2 ? block.coord(1)[i] : 0.0;
                    bad_value = v[i];
                }
                continue;
            }
            if (v[i] < 0.0 && !from_integrand && negative++ == 0) {
                neg_x = block.coord(0)[i];
                neg_y = dim == 2 ? block.coord(1)[i] : 0.0;
                neg_value = v[i];
            }
            (*values)[(first + i) / sub_count] += a;
        }
    }
    if (bad > 0) {
        return c.fail(sub(path, "shape"),
                      "the pdf shape is NaN or infinite at " + std::to_string(bad) + " of " +
                          std::to_string(total) + " tabulation points (first " +
                          number_text(bad_value) + " at " +
                          (dim == 2
                               ? "(x, y) = (" + number_text(bad_x) + ", " + number_text(bad_y) + ")"
                               : "x = " + number_text(bad_x)) +
                          "); a pdf shape must be finite on the whole domain");
    }
    auto where = [dim](double x, double y) {
        return dim == 2 ? "(x, y) = (" + number_text(x) + ", " + number_text(y) + ")"
                        : "x = " + number_text(x);
    };
    if (negative > 0)
        return c.fail(sub(path, "shape"),
                      "a density must be >= 0, and this one is negative at " +
                          std::to_string(negative) + " of " + std::to_string(total) +
                          " tabulation points (first " + number_text(neg_value) + " at " +
                          where(neg_x, neg_y) + "); write abs(...) if |p| is meant");
    bool all_zero = true;
    for (double value : *values) all_zero = all_zero && value == 0.0;
    if (all_zero)
        return c.fail(sub(path, "shape"), "the density is 0 at every one of the " +
                                              std::to_string(total) +
                                              " tabulation points: it samples nothing");
    for (double& value : *values) value /= static_cast<double>(sub_count);
    return true;
}

bool parse_pdf_1d(Ctx& c, const Json& j, const std::string& path, const Problem& problem, double a,
                  double b, Distribution1D* out) {
    if (!check_keys(c, j, path,
                    {"type", "k", "rate", "mu", "sigma", "omega", "x0", "bins", "values", "shape"}))
        return false;
    std::string type;
    if (!get_string(c, j, "type", path, &type)) return false;
    Made<Distribution1D> d;
    if (type == "uniform") {
        d = make_uniform(a, b);
    } else if (type == "power" || type == "linear") {
        double k = 1.0;
        if (!get_number(c, j, "k", path, &k)) return false;
        d = make_power(a, b, k);
    } else if (type == "exponential") {
        double rate = 1.0;
        if (!get_number(c, j, "rate", path, &rate)) return false;
        d = make_exponential(a, b, rate);
    } else if (type == "gaussian" || type == "truncated_gaussian") {
        double mu = 0.5 * (a + b), sigma = 0.25 * (b - a);
        if (!get_number(c, j, "mu", path, &mu) || !get_number(c, j, "sigma", path, &sigma))
            return false;
        d = make_truncated_gaussian(a, b, mu, sigma);
    } else if (type == "cosine") {
        double omega = 1.0, x0 = 0.0;
        if (!get_number(c, j, "omega", path, &omega) || !get_number(c, j, "x0", path, &x0))
            return false;
        d = make_cosine(a, b, omega, x0);
    } else if (type == "tabulated") {
        uint64_t bins = 64;
        if (!get_count(c, j, "bins", path, &bins)) return false;
        if (bins < 1 || bins > static_cast<uint64_t>(kMaxBins))
            return c.fail(sub(path, "bins"), "must be in 1.." + std::to_string(kMaxBins) +
                                                 ", got " + std::to_string(bins));
        if (const Json* v = find(j, "values"); v && !find(j, "bins")) {
            // Without "bins", the values set the count: the same limit, checked before reading.
            const size_t given = v->is_array() ? v->size() : 1;
            if (given < 1 || given > static_cast<size_t>(kMaxBins))
                return c.fail(sub(path, "values"), "has " + std::to_string(given) +
                                                       " entries; a tabulated pdf has 1.." +
                                                       std::to_string(kMaxBins) + " bins");
            bins = given;
        }
        std::vector<double> values;
        if (!table_values(c, j, path, problem, {static_cast<int>(bins)}, {a}, {b}, &values))
            return false;
        d = make_tabulated(a, b, values);
    } else {
        return c.fail(sub(path, "type"),
                      "unknown 1D pdf '" + type +
                          "' (known: uniform, power, exponential, gaussian, cosine, tabulated)");
    }
    if (!d.ok()) return c.fail(path, d.error);
    *out = d.value;
    return true;
}

bool parse_pdf(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
               Proposal* out) {
    const Domain& dom = problem.domain;
    // A pdf expression is an unnormalised shape, tabulated into a piecewise-constant density:
    // "pdf": "x^2" or {"type": "expression", "p": "x^2", "bins": 256}.
    if (j.is_string() || (j.is_object() && find(j, "type") && *find(j, "type") == "expression")) {
        if (dom.kind != DomainKind::Box || dom.lo.size() > 2)
            return c.fail(path, "pdf expressions are tabulated on 1- or 2-dimensional boxes; the "
                                "domain is a " +
                                    dom.describe());
        Json table = {{"shape", j.is_string() ? j : Json(nullptr)}};
        if (j.is_object()) {
            if (!check_keys(c, j, path, {"type", "p", "bins"})) return false;
            const Json* p = find(j, "p");
            if (!p) return c.fail(path, "an expression pdf needs \"p\": \"...\"");
            table["shape"] = *p;
            if (const Json* b = find(j, "bins")) table["bins"] = *b;
        }
        if (!table["shape"].is_string())
            return c.fail(sub(path, "p"),
                          "expected an expression string, got " + type_of(table["shape"]));
        const bool one_d = dom.lo.size() == 1;
        table["type"] = one_d ? "tabulated" : "tabulated_2d";
        if (!table.contains("bins"))
            table["bins"] = one_d ? Json(kExpressionBins1D) : Json(kExpressionBins2D);
        return parse_pdf(c, table, path, problem, out);
    }
    std::string type;
    if (!j.is_object())
        return c.fail(path, "expected a pdf object or expression string, got " + type_of(j));
    if (!get_string(c, j, "type", path, &type)) return false;
    if (type.empty()) return c.fail(path, "missing \"type\"");
    out->importance = true;
    if (type == "cosine_hemisphere") {
        if (!check_keys(c, j, path, {"type"})) return false;
        out->kind = ProposalKind::CosineHemisphere;
    } else if (type == "tabulated_2d") {
        if (!check_keys(c, j, path, {"type", "bins", "values", "shape"})) return false;
        if (dom.kind != DomainKind::Box || dom.lo.size() != 2)
            return c.fail(path, "tabulated_2d needs a 2-dimensional box domain");
        std::vector<double> bins{32, 32};
        if (!get_numbers(c, j, "bins", path, &bins)) return false;
        if (bins.size() == 1) bins.push_back(bins[0]);
        if (bins.size() != 2) return c.fail(sub(path, "bins"), "expected [nx, ny]");
        for (double b : bins)
            if (!(b >= 1 && b <= kMaxBinsPerAxis && b == std::floor(b)))
                return c.fail(sub(path, "bins"), "each count must be a whole number in 1.." +
                                                     std::to_string(kMaxBinsPerAxis) + ", got " +
                                                     number_text(b));
        std::vector<int> nb{static_cast<int>(bins[0]), static_cast<int>(bins[1])};
        const size_t cells = size_t(nb[0]) * size_t(nb[1]);
        if (cells > kMaxCells)
            return c.fail(sub(path, "bins"), std::to_string(nb[0]) + " x " + std::to_string(nb[1]) +
                                                 " = " + std::to_string(cells) +
                                                 " cells, more than the limit of " +
                                                 std::to_string(kMaxCells));
        std::vector<double> values;
        if (!table_values(c, j, path, problem, nb, dom.lo, dom.hi, &values)) return false;
        Made<TabulatedDistribution2D> t =
            make_tabulated_2d(dom.lo[0], dom.hi[0], dom.lo[1], dom.hi[1], nb[0], nb[1], values);
        if (!t.ok()) return c.fail(path, t.error);
        out->kind = ProposalKind::Tabulated2D;
        out->table = t.value;
    } else {
        if (dom.kind != DomainKind::Box)
            return c.fail(
                path, "pdf '" + type + "' samples box axes, the domain is a " +
                          domain_kind_name(dom.kind) +
                          (dom.kind == DomainKind::Hemisphere ? " (use cosine_hemisphere)" : ""));
        out->kind = ProposalKind::Product1D;
        out->marginals.clear();
        const size_t dim = dom.lo.size();
        if (type == "product") {
            if (!check_keys(c, j, path, {"type", "factors"})) return false;
            const Json* f = find(j, "factors");
            if (!f || !f->is_array())
                return c.fail(sub(path, "factors"), "expected an array with one 1D pdf per axis");
            if (f->size() != dim)
                return c.fail(sub(path, "factors"), "has " + std::to_string(f->size()) +
                                                        " entries, the box has " +
                                                        std::to_string(dim) + " axes");
            for (size_t a = 0; a < dim; ++a) {
                Distribution1D d;
                if (!parse_pdf_1d(c, (*f)[a], sub(path, "factors") + "[" + std::to_string(a) + "]",
                                  problem, dom.lo[a], dom.hi[a], &d))
                    return false;
                out->marginals.push_back(d);
            }
        } else {
            if (type == "tabulated" && dim != 1)
                return c.fail(path, "tabulated is 1D: use tabulated_2d, or a product of 1D pdfs");
            for (size_t a = 0; a < dim; ++a) {
                Distribution1D d;
                if (!parse_pdf_1d(c, j, path, problem, dom.lo[a], dom.hi[a], &d)) return false;
                out->marginals.push_back(d);
            }
        }
    }
    std::string mismatch = check_proposal(*out, dom);
    if (!mismatch.empty()) return c.fail(path, mismatch);
    return true;
}

// --- estimators --------------------------------------------------------------------------

const EstimatorPreset* find_preset(const std::string& name) {
    for (const EstimatorPreset& p : estimator_presets())
        if (name == p.name) return &p;
    return nullptr;
}

std::vector<std::string> preset_names() {
    std::vector<std::string> names;
    for (const EstimatorPreset& p : estimator_presets()) names.push_back(p.name);
    return names;
}

/// Levenshtein distance (insertions, deletions, substitutions), for "did you mean".
size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t k = 0; k <= b.size(); ++k) row[k] = k;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t k = 1; k <= b.size(); ++k) {
            const size_t up = row[k];
            row[k] =
                std::min({row[k] + 1, row[k - 1] + 1, diagonal + (a[i - 1] == b[k - 1] ? 0 : 1)});
            diagonal = up;
        }
    }
    return row[b.size()];
}

/// " (did you mean 'stratified'?" or " (" : the closest preset within a third of its length.
std::string did_you_mean(const std::string& name) {
    if (name.size() > 64) return " (";
    const EstimatorPreset* best = nullptr;
    size_t best_d = 0;
    for (const EstimatorPreset& p : estimator_presets()) {
        const size_t d = edit_distance(name, p.name);
        if (!best || d < best_d) {
            best = &p;
            best_d = d;
        }
    }
    const size_t len = std::string(best->name).size();
    if (best_d > 0 && best_d * 3 <= len)
        return " (did you mean '" + std::string(best->name) + "'? ";
    return " (";
}

/// The text of an estimator name for messages: at most 64 characters.
std::string name_text(const std::string& name) {
    return name.size() <= 64 ? name : name.substr(0, 61) + "...";
}

/// The "vegas" object of an estimator: every field optional, each bounded before any work.
bool parse_vegas_options(Ctx& c, const Json& j, const std::string& path, int dim,
                         VegasOptions* out) {
    if (!check_keys(c, j, path,
                    {"increments", "alpha", "train_fraction", "train_iterations", "uniform_share",
                     "report", "iterations", "stratify", "beta"}))
        return false;
    uint64_t increments = 0, iterations = static_cast<uint64_t>(out->train_iterations);
    uint64_t rounds = static_cast<uint64_t>(out->iterations);
    std::string report;
    if (!get_count(c, j, "increments", path, &increments) ||
        !get_number(c, j, "alpha", path, &out->alpha) ||
        !get_number(c, j, "train_fraction", path, &out->train_fraction) ||
        !get_number(c, j, "uniform_share", path, &out->uniform_share) ||
        !get_count(c, j, "train_iterations", path, &iterations) ||
        !get_count(c, j, "iterations", path, &rounds) ||
        !get_string(c, j, "report", path, &report) || !get_number(c, j, "beta", path, &out->beta))
        return false;
    // The map holds dim x increments edges and sums: at most 2^22 of each.
    if (find(j, "increments") &&
        (increments < 1 || increments * static_cast<uint64_t>(dim) > (uint64_t(1) << 22)))
        return c.fail(sub(path, "increments"),
                      "must be >= 1 and at most 4194304 / dimension (" +
                          std::to_string((uint64_t(1) << 22) / static_cast<uint64_t>(dim)) +
                          " here), got " + std::to_string(increments));
    if (!(out->alpha >= 0.0 && out->alpha <= 4.0))
        return c.fail(sub(path, "alpha"), "must be in [0, 4] (vegas uses 0.5, GSL 1.5)");
    if (!(out->train_fraction >= 0.0 && out->train_fraction <= 0.9))
        return c.fail(sub(path, "train_fraction"),
                      "must be in [0, 0.9]: the share of N that trains the map");
    if (!(out->uniform_share >= 0.0 && out->uniform_share <= 1.0))
        return c.fail(sub(path, "uniform_share"), "must be in [0, 1]");
    if (iterations < 1 || iterations > 1000)
        return c.fail(sub(path, "train_iterations"), "must be in [1, 1000]");
    if (report == "iterations")
        out->report = VegasReport::Iterations;
    else if (report == "frozen" || report.empty())
        out->report = VegasReport::Frozen;
    else
        return c.fail(sub(path, "report"), "expected \"frozen\" (train, then estimate with the "
                                           "frozen map) or \"iterations\" (the weighted average "
                                           "of adapting iterations), got \"" +
                                               report.substr(0, 64) + "\"");
    if (const Json* st = find(j, "stratify")) {
        if (!st->is_boolean())
            return c.fail(sub(path, "stratify"), "expected true or false, got " + type_of(*st));
        out->stratify = st->get<bool>();
    }
    if (!(out->beta >= 0.0 && out->beta <= 2.0))
        return c.fail(sub(path, "beta"),
                      "must be in [0, 2] (0: equal points per hypercube; vegas uses 0.75)");
    if (out->stratify && out->report == VegasReport::Iterations)
        return c.fail(sub(path, "report"), "adaptive stratification (\"stratify\") reports the "
                                           "frozen map and allocation only");
    if (rounds < 2 || rounds > 1000) return c.fail(sub(path, "iterations"), "must be in [2, 1000]");
    out->iterations = static_cast<int>(rounds);
    out->increments = static_cast<int>(increments);
    out->train_iterations = static_cast<int>(iterations);
    return true;
}

/// The "miser" object of an estimator: every field optional, each bounded.
bool parse_miser_options(Ctx& c, const Json& j, const std::string& path, MiserOptions* out) {
    if (!check_keys(
            c, j, path,
            {"estimate_fraction", "min_calls", "min_calls_per_bisection", "alpha", "dither"}))
        return false;
    if (!get_number(c, j, "estimate_fraction", path, &out->estimate_fraction) ||
        !get_count(c, j, "min_calls", path, &out->min_calls) ||
        !get_count(c, j, "min_calls_per_bisection", path, &out->min_calls_per_bisection) ||
        !get_number(c, j, "alpha", path, &out->alpha) ||
        !get_number(c, j, "dither", path, &out->dither))
        return false;
    if (!(out->estimate_fraction > 0.0 && out->estimate_fraction <= 0.5))
        return c.fail(sub(path, "estimate_fraction"),
                      "must be in (0, 0.5]: the share of a region's calls that probe it");
    if (find(j, "min_calls") && (out->min_calls < 2 || out->min_calls > (uint64_t(1) << 30)))
        return c.fail(sub(path, "min_calls"), "must be in [2, 2^30]");
    if (out->min_calls_per_bisection > (uint64_t(1) << 40))
        return c.fail(sub(path, "min_calls_per_bisection"), "must be at most 2^40");
    if (!(out->alpha >= 0.0 && out->alpha <= 10.0))
        return c.fail(sub(path, "alpha"), "must be in [0, 10] (GSL uses 2)");
    if (!(out->dither >= 0.0 && out->dither <= 0.25))
        return c.fail(sub(path, "dither"), "must be in [0, 0.25] (typical: 0.05 to 0.1)");
    return true;
}

/// Multiple importance sampling fields of an estimator object: "proposals" (pdfs, or "uniform"
/// for the domain's uniform density), "fractions", "heuristic" (with "beta" or "cutoff"),
/// "one_sample" and "defensive" (Hesterberg's mixture: the uniform density joins with that
/// share). A lone "pdf" with "defensive" is the first proposal.
bool parse_mis_options(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                       const Json* pdf, MisOptions* out) {
    const Json* proposals = find(j, "proposals");
    std::vector<Json> entries;
    if (proposals) {
        if (pdf)
            return c.fail(sub(path, "pdf"), "an estimator has \"pdf\" or \"proposals\", not both");
        if (!proposals->is_array() || proposals->empty())
            return c.fail(sub(path, "proposals"),
                          "expected an array of pdfs (or \"uniform\"), got " + type_of(*proposals));
        if (proposals->size() > static_cast<size_t>(kMaxMisTechniques))
            return c.fail(sub(path, "proposals"),
                          "has " + std::to_string(proposals->size()) + " entries; at most " +
                              std::to_string(kMaxMisTechniques) + " techniques are combined");
        for (const Json& e : *proposals) entries.push_back(e);
    } else if (pdf) {
        entries.push_back(*pdf);
    } else {
        entries.push_back("uniform");
    }
    for (size_t k = 0; k < entries.size(); ++k) {
        const std::string at =
            (proposals ? sub(path, "proposals") + "[" + std::to_string(k) + "]" : sub(path, "pdf"));
        Proposal prop = uniform_proposal(problem.domain);
        if (!(entries[k].is_string() && entries[k] == "uniform") &&
            !parse_pdf(c, entries[k], at, problem, &prop))
            return false;
        out->proposals.push_back(prop);
    }
    const size_t k_count = out->proposals.size();
    out->fractions.assign(k_count, 1.0 / static_cast<double>(k_count));
    if (find(j, "fractions")) {
        std::vector<double> f;
        if (!get_numbers(c, j, "fractions", path, &f)) return false;
        if (f.size() != k_count)
            return c.fail(sub(path, "fractions"), "has " + std::to_string(f.size()) +
                                                      " entries for " + std::to_string(k_count) +
                                                      " proposals");
        double total = 0.0;
        for (double x : f) {
            if (!(x > 0.0 && x <= 1e6))
                return c.fail(sub(path, "fractions"),
                              "each share must be positive (and at most 1e6), got " +
                                  number_text(x));
            total += x;
        }
        for (size_t k = 0; k < k_count; ++k) out->fractions[k] = f[k] / total;
    }
    double defensive = 0.0;
    if (!get_number(c, j, "defensive", path, &defensive)) return false;
    if (find(j, "defensive")) {
        if (!(defensive > 0.0 && defensive < 1.0))
            return c.fail(sub(path, "defensive"),
                          "must be in (0, 1): the uniform density's share of the mixture "
                          "(Hesterberg suggests 0.1 to 0.5), got " +
                              number_text(defensive));
        if (k_count + 1 > static_cast<size_t>(kMaxMisTechniques))
            return c.fail(sub(path, "defensive"), "the uniform density would be technique " +
                                                      std::to_string(k_count + 1) + "; at most " +
                                                      std::to_string(kMaxMisTechniques));
        for (double& f : out->fractions) f *= 1.0 - defensive;
        out->proposals.push_back(uniform_proposal(problem.domain));
        out->fractions.push_back(defensive);
    }
    std::string heuristic = "balance";
    if (!get_string(c, j, "heuristic", path, &heuristic)) return false;
    if (heuristic == "balance")
        out->weighting.heuristic = MisHeuristic::Balance;
    else if (heuristic == "power")
        out->weighting.heuristic = MisHeuristic::Power;
    else if (heuristic == "maximum")
        out->weighting.heuristic = MisHeuristic::Maximum;
    else if (heuristic == "cutoff")
        out->weighting.heuristic = MisHeuristic::Cutoff;
    else if (heuristic == "optimal")
        out->optimal = true;
    else
        return c.fail(sub(path, "heuristic"),
                      "unknown heuristic '" + heuristic.substr(0, 64) +
                          "' (known: balance, power, maximum, cutoff, optimal)");
    if (find(j, "beta")) {
        if (out->weighting.heuristic != MisHeuristic::Power || out->optimal)
            return c.fail(sub(path, "beta"), "applies to the power heuristic only");
        if (!get_number(c, j, "beta", path, &out->weighting.beta)) return false;
        if (!(out->weighting.beta >= 1.0 && out->weighting.beta <= 16.0))
            return c.fail(sub(path, "beta"), "must be in [1, 16] (Veach uses 2), got " +
                                                 number_text(out->weighting.beta));
    }
    if (find(j, "cutoff")) {
        if (out->weighting.heuristic != MisHeuristic::Cutoff || out->optimal)
            return c.fail(sub(path, "cutoff"), "applies to the cutoff heuristic only");
        if (!get_number(c, j, "cutoff", path, &out->weighting.cutoff)) return false;
        if (!(out->weighting.cutoff >= 0.0 && out->weighting.cutoff <= 1.0))
            return c.fail(sub(path, "cutoff"), "must be in [0, 1] (Veach uses 0.1), got " +
                                                   number_text(out->weighting.cutoff));
    }
    if (const Json* one = find(j, "one_sample")) {
        if (!one->is_boolean())
            return c.fail(sub(path, "one_sample"), "expected true or false, got " + type_of(*one));
        out->one_sample = one->get<bool>();
    }
    return true;
}

/// Control-variate fields: "control_variates": [{"g": integrand, "integral": G}, ...] and the
/// optional "coefficients" (one per variate; fitted when absent).
bool parse_control_variates(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                            ControlVariateOptions* out) {
    const Json* list = find(j, "control_variates");
    const std::string at = sub(path, "control_variates");
    if (!list->is_array() || list->empty())
        return c.fail(at, "expected an array of {\"g\": ..., \"integral\": ...}, got " +
                              type_of(*list));
    if (list->size() > static_cast<size_t>(kMaxControlVariates))
        return c.fail(at, "has " + std::to_string(list->size()) + " entries; at most " +
                              std::to_string(kMaxControlVariates));
    for (size_t k = 0; k < list->size(); ++k) {
        const std::string here = at + "[" + std::to_string(k) + "]";
        const Json& e = (*list)[k];
        if (!e.is_object())
            return c.fail(here, "expected {\"g\": ..., \"integral\": ...}, got " + type_of(e));
        if (!check_keys(c, e, here, {"g", "integral"})) return false;
        const Json* g = find(e, "g");
        if (!g) return c.fail(here, "a control variate needs \"g\": an expression or integrand");
        ControlVariate cv;
        if (!parse_integrand(c, *g, sub(here, "g"), problem.domain.point_dim(), &cv.g))
            return false;
        cv.text = g->is_string() ? g->get<std::string>().substr(0, 200) : g->dump().substr(0, 200);
        if (find(e, "integral")) {
            if (!get_number(c, e, "integral", here, &cv.integral)) return false;
            if (!std::isfinite(cv.integral))
                return c.fail(sub(here, "integral"), "must be a finite number");
        } else {
            std::optional<double> known =
                problem.domain.kind == DomainKind::Box
                    ? exact_integral_over_box(cv.g, problem.domain.lo, problem.domain.hi)
                    : std::nullopt;
            if (!known)
                return c.fail(here, "needs \"integral\": the integral of g over the domain (known "
                                    "in closed form only for built-in integrands on boxes)");
            cv.integral = *known;
        }
        out->variates.push_back(cv);
    }
    if (find(j, "coefficients")) {
        if (!get_numbers(c, j, "coefficients", path, &out->coefficients)) return false;
        if (out->coefficients.size() != out->variates.size())
            return c.fail(sub(path, "coefficients"),
                          "has " + std::to_string(out->coefficients.size()) + " entries for " +
                              std::to_string(out->variates.size()) + " control variates");
        for (double x : out->coefficients)
            if (!std::isfinite(x))
                return c.fail(sub(path, "coefficients"), "must be finite numbers");
    }
    return true;
}

bool parse_estimator(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                     EstimatorSpec* out) {
    std::string name, sampler_name_str, warp, randomization;
    int randomizations = 0; // 0: not given
    const Json* pdf = nullptr;
    const Json* vegas = nullptr;
    const Json* miser = nullptr;
    bool mis = false, control = false;
    if (j.is_string()) {
        name = j.get<std::string>();
    } else if (j.is_object()) {
        if (!check_keys(c, j, path,
                        {"name", "sampler", "pdf", "warp", "samples_per_stratum", "randomization",
                         "randomizations", "vegas", "miser", "proposals", "fractions", "heuristic",
                         "beta", "cutoff", "one_sample", "defensive", "control_variates",
                         "coefficients"}))
            return false;
        uint64_t m = 1;
        if (!get_count(c, j, "samples_per_stratum", path, &m)) return false;
        if (m != 1 && m != 2)
            return c.fail(
                sub(path, "samples_per_stratum"),
                "must be 1 (one jittered point per cell) or 2 (unbiased error bars), got " +
                    std::to_string(m));
        out->per_stratum = m;
        if (!get_string(c, j, "name", path, &name) ||
            !get_string(c, j, "sampler", path, &sampler_name_str) ||
            !get_string(c, j, "warp", path, &warp) ||
            !get_string(c, j, "randomization", path, &randomization))
            return false;
        if (find(j, "randomizations")) {
            uint64_t k = 0;
            if (!get_count(c, j, "randomizations", path, &k)) return false;
            randomizations = static_cast<int>(std::min<uint64_t>(k, 1u << 30));
        }
        pdf = find(j, "pdf");
        vegas = find(j, "vegas");
        miser = find(j, "miser");
        for (const char* key :
             {"proposals", "fractions", "heuristic", "beta", "cutoff", "one_sample", "defensive"})
            mis = mis || find(j, key);
        control = find(j, "control_variates") != nullptr;
        if (!control && find(j, "coefficients"))
            return c.fail(sub(path, "coefficients"), "applies with \"control_variates\" only");
    } else {
        return c.fail(path, "expected an estimator name or object, got " + type_of(j));
    }
    if (name.empty()) return c.fail(path, "an estimator needs a \"name\"");
    const EstimatorPreset* preset = find_preset(name);
    out->name = name;
    out->sampler = preset ? preset->sampler : SamplerKind::Independent;
    if (!sampler_name_str.empty() && !parse_sampler(sampler_name_str, &out->sampler))
        return c.fail(sub(path, "sampler"), "unknown sampler '" + sampler_name_str +
                                                "' (known: " + sampler_names() + ")");
    if (out->per_stratum != 1 && out->sampler != SamplerKind::Stratified)
        return c.fail(sub(path, "samples_per_stratum"), "applies to the stratified sampler only");
    if (is_qmc(out->sampler)) {
        const QmcKind q = qmc_kind_of(out->sampler);
        out->randomization = default_randomization(q);
        if (!randomization.empty() && !parse_randomization(randomization, &out->randomization))
            return c.fail(sub(path, "randomization"),
                          "unknown randomization '" + randomization +
                              "' (known: owen, lms_shift, digital_shift, permutation, "
                              "random_shift, none)");
        out->randomizations =
            out->randomization == QmcRandomization::None ? 1 : kDefaultRandomizations;
        if (randomizations > 0) out->randomizations = randomizations;
        const std::string bad = check_sampler_options(out->sampler, out->sampler_options(),
                                                      problem.domain.sample_dim());
        if (!bad.empty()) {
            const size_t colon = bad.find(": ");
            const std::string field = bad.substr(0, colon);
            if (field == "randomization" || field == "randomizations")
                return c.fail(sub(path, field.c_str()), bad.substr(colon + 2));
            return c.fail(path, bad);
        }
    } else if (!randomization.empty() || randomizations > 0) {
        return c.fail(sub(path, randomization.empty() ? "randomizations" : "randomization"),
                      "applies to the quasi-Monte Carlo samplers only (sobol, halton, lattice)");
    }
    if (!warp.empty() && warp != "polar" && warp != "concentric")
        return c.fail(sub(path, "warp"), "unknown warp '" + warp + "' (known: polar, concentric)");
    if (!warp.empty() && problem.domain.kind != DomainKind::Disk)
        return c.fail(sub(path, "warp"), "only disk domains have a choice of warp");
    // A name runs what it says: a bare name must be a preset, and a preset is not redefined.
    if (!preset && sampler_name_str.empty() && !pdf && !vegas && !miser && !mis && !control)
        return c.fail(path, "unknown estimator '" + name_text(name) + "'" + did_you_mean(name) +
                                "presets: " + join(preset_names()) +
                                "; a new name needs \"sampler\", \"pdf\", \"vegas\", \"miser\", "
                                "\"proposals\" or \"control_variates\")");
    if (preset && !sampler_name_str.empty() && out->sampler != preset->sampler)
        return c.fail(sub(path, "sampler"),
                      "'" + name + "' is the preset with the " + sampler_name(preset->sampler) +
                          " sampler; give the estimator another name to use " + sampler_name_str);
    if (preset && pdf && !preset->needs_pdf)
        return c.fail(sub(path, "pdf"), "'" + name +
                                            "' is a preset with the uniform density; give the "
                                            "estimator another name to sample a pdf");
    out->vegas = preset && preset->vegas;
    out->vegas_options.stratify = preset && std::string(preset->name) == "vegas_plus";
    if (vegas) {
        out->vegas = true;
        if (!parse_vegas_options(c, *vegas, sub(path, "vegas"), problem.domain.sample_dim(),
                                 &out->vegas_options))
            return false;
    }
    out->miser = (preset && std::string(preset->name) == "miser") || miser;
    if (miser && !parse_miser_options(c, *miser, sub(path, "miser"), &out->miser_options))
        return false;
    if (out->miser && out->vegas) return c.fail(path, "an estimator is VEGAS or MISER, not both");
    if (out->miser && out->sampler != SamplerKind::Independent)
        return c.fail(sub(path, "sampler"), "MISER draws its own points in its regions: the "
                                            "sampler must be independent");
    if (out->vegas && out->vegas_options.stratify && out->sampler != SamplerKind::Independent)
        return c.fail(sub(path, "sampler"), "VEGAS+ (\"stratify\": true) draws its own points in "
                                            "its hypercubes: the sampler must be independent");
    if (mis || control) {
        const char* what = mis ? "multiple importance sampling" : "control variates";
        if (out->vegas || out->miser)
            return c.fail(path, std::string(what) + " does not combine with VEGAS or MISER");
        if (out->sampler != SamplerKind::Independent)
            return c.fail(sub(path, "sampler"), std::string(what) +
                                                    " needs the independent sampler (its error "
                                                    "bar is that of independent points)");
        if (mis && control)
            return c.fail(sub(path, "control_variates"),
                          "not with multiple importance sampling (\"heuristic\": \"optimal\" "
                          "is MIS with the densities as control variates)");
    }
    if (control && !parse_control_variates(c, j, path, problem, &out->control_variate_options))
        return false;
    out->control_variates = control;
    if (mis) {
        if (preset)
            return c.fail(path, "'" + name + "' is a preset; give the MIS estimator another name");
        if (!parse_mis_options(c, j, path, problem, pdf, &out->mis_options)) return false;
        out->mis = true;
        out->proposal = out->mis_options.proposals[0];
        return true;
    }
    out->proposal = uniform_proposal(problem.domain, warp == "polar");
    if (pdf) {
        if (!parse_pdf(c, *pdf, sub(path, "pdf"), problem, &out->proposal)) return false;
    } else if (preset && preset->needs_pdf) {
        return c.fail(path, "estimator '" + name + "' needs a pdf: give \"pdf\": {\"type\": ...}");
    }
    return true;
}

bool parse_accumulator(Ctx& c, const Json& obj, const std::string& path, Accumulator* out) {
    std::string name;
    if (!get_string(c, obj, "accumulator", path, &name)) return false;
    if (name.empty()) return true;
    if (name == "compensated")
        *out = Accumulator::Compensated;
    else if (name == "float32")
        *out = Accumulator::Float32;
    else
        return c.fail(sub(path, "accumulator"),
                      "expected \"compensated\" or \"float32\", got \"" + name + "\"");
    return true;
}

} // namespace

const std::vector<EstimatorPreset>& estimator_presets() {
    static const std::vector<EstimatorPreset> presets = {
        {"uniform", SamplerKind::Independent, false,
         "independent uniform points, f / p with p uniform"},
        {"stratified", SamplerKind::Stratified, false,
         "one jittered point per cell of an N-cell grid"},
        {"latin_hypercube", SamplerKind::LatinHypercube, false,
         "N-rooks: one point per slab of every axis"},
        {"importance", SamplerKind::Independent, true,
         "independent points drawn from the given pdf"},
        {"stratified_importance", SamplerKind::Stratified, true,
         "jittered unit-cube points warped by the pdf's inverse CDF"},
        {"sobol", SamplerKind::Sobol, false,
         "Owen-scrambled Sobol' points: 16 randomizations of N/16 points"},
        {"halton", SamplerKind::Halton, false,
         "Owen-scrambled Halton points: 16 randomizations of N/16 points"},
        {"lattice", SamplerKind::Lattice, false,
         "randomly shifted rank-1 lattice: 16 shifts of N/16 points"},
        {"vegas", SamplerKind::Independent, false,
         "VEGAS: a map trained on a quarter of N, then frozen for independent points", true},
        {"vegas_sobol", SamplerKind::Sobol, false,
         "VEGAS map trained, then frozen for 16 Owen-scrambled Sobol' nets", true},
        {"miser", SamplerKind::Independent, false,
         "MISER: recursive bisection, calls to the halves by their spread (GSL's defaults)"},
        {"vegas_plus", SamplerKind::Independent, false,
         "VEGAS+: the map and hypercubes with points allocated by sigma^0.75, trained then "
         "frozen",
         true},
    };
    return presets;
}

Made<EstimatorSpec> preset_estimator(const Problem& problem, const std::string& name) {
    Ctx c;
    EstimatorSpec spec;
    if (!parse_estimator(c, Json(name), "estimator", problem, &spec))
        return made_error<EstimatorSpec>(c.error);
    return Made<EstimatorSpec>{spec, ""};
}

Made<SceneRequest> build_request(const Json& scene, const Json& options) {
    Ctx c;
    SceneRequest req;
    const std::string path = "scene";
    if (!check_keys(c, scene, path,
                    {"name", "description", "domain", "integrand", "f", "quantity", "exact",
                     "estimators", "n_min", "n_max", "reps", "seed", "threads", "accumulator",
                     "rel_tol", "abs_tol", "max_seconds", "notes"}))
        return made_error<SceneRequest>(c.error);
    Problem& pr = req.problem;
    pr.name = "scene";
    if (!get_string(c, scene, "name", path, &pr.name) ||
        !get_string(c, scene, "description", path, &pr.description))
        return made_error<SceneRequest>(c.error);

    // "f": "expression" is shorthand for "integrand": "expression".
    const Json* integrand = find(scene, "integrand");
    const char* integrand_path = "scene.integrand";
    if (const Json* f = find(scene, "f")) {
        if (integrand)
            return made_error<SceneRequest>("scene: give \"integrand\" or \"f\", not both");
        integrand = f;
        integrand_path = "scene.f";
    }
    if (!integrand)
        return made_error<SceneRequest>("scene: missing \"integrand\" (or \"f\": an expression)");
    int default_dim = 1;
    if (!integrand_dimension(c, *integrand, integrand_path, &default_dim))
        return made_error<SceneRequest>(c.error);
    if (const Json* d = find(scene, "domain")) {
        if (!parse_domain(c, *d, "scene.domain", default_dim, &pr.domain))
            return made_error<SceneRequest>(c.error);
    } else {
        Made<Domain> unit = make_box(std::vector<double>(static_cast<size_t>(default_dim), 0.0),
                                     std::vector<double>(static_cast<size_t>(default_dim), 1.0));
        if (!unit.ok())
            return made_error<SceneRequest>(std::string(integrand_path) + ": " + unit.error);
        pr.domain = unit.value;
    }
    if (!parse_integrand(c, *integrand, integrand_path, pr.domain.point_dim(), &pr.integrand))
        return made_error<SceneRequest>(c.error);

    std::string quantity = "integral";
    if (!get_string(c, scene, "quantity", path, &quantity))
        return made_error<SceneRequest>(c.error);
    if (quantity == "integral")
        pr.quantity = Quantity::Integral;
    else if (quantity == "mean")
        pr.quantity = Quantity::Mean;
    else
        return made_error<SceneRequest>(
            "scene.quantity: expected \"integral\" or \"mean\", got \"" + quantity + "\"");

    if (const Json* e = find(scene, "exact"); e && !e->is_null()) {
        double exact = 0.0;
        if (!get_number(c, scene, "exact", path, &exact)) return made_error<SceneRequest>(c.error);
        pr.exact = exact;
    } else if (pr.domain.kind == DomainKind::Box) {
        std::optional<double> v = exact_integral_over_box(pr.integrand, pr.domain.lo, pr.domain.hi);
        if (v && pr.quantity == Quantity::Mean) *v /= pr.domain.measure();
        // A closed form outside the double range would be compared with estimates as inf or
        // NaN: refuse the scene rather than report a meaningless error.
        if (v && !std::isfinite(*v))
            return made_error<SceneRequest>(
                std::string(integrand_path) + ": the exact " +
                (pr.quantity == Quantity::Mean ? "mean" : "integral") + " over " +
                pr.domain.describe() + " is " + number_text(*v) +
                ", outside double precision: rescale the integrand or the domain");
        pr.exact = v;
    }

    // Estimators: the scene's list, or the three uniform-density presets.
    std::vector<EstimatorSpec> all;
    std::set<std::string> names;
    if (const Json* list = find(scene, "estimators")) {
        if (!list->is_array() || list->empty())
            return made_error<SceneRequest>("scene.estimators: expected a non-empty array");
        for (size_t i = 0; i < list->size(); ++i) {
            EstimatorSpec spec;
            if (!parse_estimator(c, (*list)[i], "scene.estimators[" + std::to_string(i) + "]", pr,
                                 &spec))
                return made_error<SceneRequest>(c.error);
            if (!names.insert(spec.name).second)
                return made_error<SceneRequest>("scene.estimators[" + std::to_string(i) +
                                                "]: duplicate estimator name '" + spec.name + "'");
            all.push_back(spec);
        }
    } else {
        for (const char* n : {"uniform", "stratified", "latin_hypercube"}) {
            EstimatorSpec spec;
            parse_estimator(c, Json(n), "scene.estimators", pr, &spec);
            all.push_back(spec);
        }
    }

    // Settings: defaults, then the scene, then the options.
    StudySettings& s = req.settings;
    uint64_t reps = static_cast<uint64_t>(s.reps), threads = 0;
    if (!get_count(c, scene, "n_min", path, &s.n_min) ||
        !get_count(c, scene, "n_max", path, &s.n_max) ||
        !get_count(c, scene, "reps", path, &reps) || !get_count(c, scene, "seed", path, &s.seed) ||
        !get_count(c, scene, "threads", path, &threads) ||
        !parse_accumulator(c, scene, path, &s.accumulator) ||
        !get_number(c, scene, "rel_tol", path, &s.rel_tol) ||
        !get_number(c, scene, "abs_tol", path, &s.abs_tol) ||
        !get_number(c, scene, "max_seconds", path, &s.max_seconds))
        return made_error<SceneRequest>(c.error);

    req.estimators = all;
    if (!options.is_null()) {
        if (!check_keys(c, options, "options",
                        {"estimators", "n_min", "n_max", "reps", "seed", "threads", "rel_tol",
                         "abs_tol", "max_seconds"}) ||
            !get_number(c, options, "rel_tol", "options", &s.rel_tol) ||
            !get_number(c, options, "abs_tol", "options", &s.abs_tol) ||
            !get_number(c, options, "max_seconds", "options", &s.max_seconds) ||
            !get_count(c, options, "n_min", "options", &s.n_min) ||
            !get_count(c, options, "n_max", "options", &s.n_max) ||
            !get_count(c, options, "reps", "options", &reps) ||
            !get_count(c, options, "seed", "options", &s.seed) ||
            !get_count(c, options, "threads", "options", &threads))
            return made_error<SceneRequest>(c.error);
        if (const Json* sel = find(options, "estimators")) {
            if (!sel->is_array() || sel->empty())
                return made_error<SceneRequest>(
                    "options.estimators: expected a non-empty array of names");
            req.estimators.clear();
            std::set<std::string> chosen;
            for (size_t i = 0; i < sel->size(); ++i) {
                const Json& item = (*sel)[i];
                if (!item.is_string())
                    return made_error<SceneRequest>("options.estimators[" + std::to_string(i) +
                                                    "]: expected a name");
                const std::string name = item.get<std::string>();
                if (!chosen.insert(name).second) continue;
                bool found = false;
                for (const EstimatorSpec& e : all)
                    if (e.name == name) {
                        req.estimators.push_back(e);
                        found = true;
                    }
                if (found) continue;
                const EstimatorPreset* preset = find_preset(name);
                if (preset && !preset->needs_pdf) {
                    EstimatorSpec spec;
                    parse_estimator(c, item, "options.estimators", pr, &spec);
                    req.estimators.push_back(spec);
                    continue;
                }
                std::vector<std::string> have;
                for (const EstimatorSpec& e : all) have.push_back(e.name);
                std::string hint = did_you_mean(name);
                for (const EstimatorSpec& e : all) // a scene's own name may be the near miss
                    if (hint == " (" && edit_distance(name, e.name) > 0 &&
                        edit_distance(name, e.name) * 3 <= e.name.size() && name.size() <= 64)
                        hint = " (did you mean '" + name_text(e.name) + "'? ";
                return made_error<SceneRequest>(
                    "options.estimators[" + std::to_string(i) + "]: unknown estimator '" +
                    name_text(name) + "'" + hint + "this scene has: " + join(have) +
                    (preset ? "; '" + name + "' needs a pdf, which only a scene can give)"
                            : "; presets: " + join(preset_names()) + ")"));
            }
        }
    }
    // check_settings takes ints: a count beyond int is passed as INT_MAX (beyond every limit)
    // and the message then names the count actually given.
    constexpr uint64_t kIntMax = static_cast<uint64_t>(std::numeric_limits<int>::max());
    s.reps = static_cast<int>(std::min(reps, kIntMax));
    s.threads = static_cast<int>(std::min(threads, kIntMax));
    std::string bad = check_settings(s);
    if (!bad.empty()) {
        for (auto [given, passed] :
             {std::pair<uint64_t, int>{reps, s.reps}, {threads, s.threads}}) {
            const std::string tail = "got " + std::to_string(passed);
            if (given != static_cast<uint64_t>(passed) && bad.size() >= tail.size() &&
                bad.compare(bad.size() - tail.size(), tail.size(), tail) == 0) {
                bad = bad.substr(0, bad.size() - tail.size()) + "got " + std::to_string(given);
                break;
            }
        }
        // Whose value is it: the options' (a bad argument) when they set a field the message
        // is about, else the scene's.
        bool from_options = false;
        for (const char* key : {"n_min", "n_max", "reps", "threads"})
            from_options = from_options || (options.is_object() && find(options, key) &&
                                            bad.find(key) != std::string::npos);
        return made_error<SceneRequest>((from_options ? "options: " : "scene: ") + bad);
    }
    // Stopping at a requested accuracy: the tolerances and the time budget. N may double to
    // 2^24 (or the scene's n_max, if larger: a scene's n_max is its ladder's) unless the options
    // set n_max.
    if (s.stopping() && !(options.is_object() && find(options, "n_max")))
        s.n_max = std::max(s.n_max, kStoppingDefaultNMax);
    if (s.stopping() || s.abs_tol != 0.0 || s.rel_tol != 0.0 || s.max_seconds != 0.0) {
        const bool from_options =
            options.is_object() &&
            (find(options, "rel_tol") || find(options, "abs_tol") || find(options, "max_seconds"));
        const char* who = from_options ? "options: " : "scene: ";
        if (!(s.max_seconds >= 0.0) || !std::isfinite(s.max_seconds))
            return made_error<SceneRequest>(std::string(who) +
                                            "max_seconds: must be a finite number >= 0");
        if (!s.stopping() && s.max_seconds > 0.0)
            return made_error<SceneRequest>(std::string(who) +
                                            "max_seconds: applies with rel_tol or abs_tol only");
        const std::string bad_tol = check_stopping(tolerance_of(s), budget_of(s));
        if (!bad_tol.empty()) return made_error<SceneRequest>(who + bad_tol);
    }
    // The whole study's size, before any work (a run of 2^36 points is refused, not begun).
    const std::string too_big = check_study_size(s, req.estimators.size());
    if (!too_big.empty()) {
        bool from_options = false;
        for (const char* key : {"n_min", "n_max", "reps", "estimators"})
            from_options = from_options || (options.is_object() && find(options, key));
        return made_error<SceneRequest>((from_options ? "options: " : "scene: ") + too_big);
    }
    for (const EstimatorSpec& e : req.estimators) {
        if (e.per_stratum > 1 && s.n_min < e.per_stratum)
            return made_error<SceneRequest>("estimator '" + e.name + "': samples_per_stratum = " +
                                            std::to_string(e.per_stratum) +
                                            " needs n_min >= " + std::to_string(e.per_stratum));
        if (!is_qmc(e.sampler)) continue;
        const uint64_t k = static_cast<uint64_t>(e.randomizations);
        const std::string who =
            (options.is_object() && (find(options, "n_min") || find(options, "n_max"))
                 ? "options: estimator '"
                 : "scene: estimator '") +
            name_text(e.name) + "': ";
        const std::vector<uint64_t> ladder = n_ladder(s.n_min, s.n_max);
        if (!ladder.empty() && ladder.front() < k)
            return made_error<SceneRequest>(
                who + std::to_string(k) + " randomizations need n_min >= " + std::to_string(k) +
                " (each run is " + std::to_string(k) + " randomizations of N/" + std::to_string(k) +
                " points), got n_min = " + std::to_string(s.n_min));
        const uint64_t most = qmc_max_points(qmc_kind_of(e.sampler));
        if (s.n_max / k > most)
            return made_error<SceneRequest>(
                who + "n_max = " + std::to_string(s.n_max) + " would give " +
                std::to_string(s.n_max / k) + " points per randomization, beyond the " +
                std::to_string(most) + " the " + sampler_name(e.sampler) +
                " points are built for; lower n_max or raise randomizations");
    }
    return {req, {}};
}

} // namespace mcp
