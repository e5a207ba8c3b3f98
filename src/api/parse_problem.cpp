// Scene parsing, the problem: the "domain" object (box, interval, disk, triangle, sphere,
// hemisphere) and the "integrand" object or "f" expression (docs/scene-format.md). Part of the
// scene parsers (api/scene_parsers.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "api/caller_functions.h"
#include "api/scene_parsers.h"
#include "core/special.h"
#include "integrands/expression.h"
#include "integrands/genz.h"

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

} // namespace

/// A number for messages ("1e+200", "0.25", "NaN", "-inf": the same on every platform).
std::string number_text(double x) {
    if (std::isnan(x)) return "NaN";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    std::ostringstream s;
    s.precision(6);
    s << x;
    return s.str();
}

namespace {

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

} // namespace

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

namespace {

// --- integrand ---------------------------------------------------------------------------

constexpr const char* kIntegrandTypes =
    "constant, monomial, exponential, gaussian, indicator_ball, expression, genz_oscillatory, "
    "genz_product_peak, genz_corner_peak, genz_gaussian, genz_continuous, genz_discontinuous, "
    "function (a caller's)";

/// {"type": "function", "name": N, "dim"?}: the caller's function N (api/caller_functions.h).
bool parse_function_integrand(Ctx& c, const Json& j, const std::string& path, int dim,
                              Integrand* out) {
    if (!check_keys(c, j, path, {"type", "name", "dim"})) return false;
    std::shared_ptr<const CallerFunction> fn;
    if (!find_caller_function(c, j, "name", path, &fn)) return false;
    uint64_t given = 0;
    if (!get_count(c, j, "dim", path, &given)) return false;
    if (find(j, "dim") && given != static_cast<uint64_t>(dim))
        return c.fail(sub(path, "dim"), "is " + std::to_string(given) +
                                            ", but the domain's points have " +
                                            std::to_string(dim) + " coordinates");
    *out = make_function_integrand(std::move(fn), dim);
    return true;
}

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

} // namespace

bool find_caller_function(Ctx& c, const Json& j, const char* key, const std::string& path,
                          std::shared_ptr<const CallerFunction>* out) {
    std::string name;
    if (!get_string(c, j, key, path, &name)) return false;
    if (name.empty())
        return c.fail(sub(path, key), "expected the name of a function the caller gave");
    if (!c.functions || c.functions->list.empty())
        return c.fail(sub(path, key),
                      "names the caller's function '" + name_text(name) +
                          "', but this call was given no functions (a caller's function reaches "
                          "mcplay through its library: Python's mcplay.integrate, or "
                          "mcp_study_run_with in C)");
    *out = c.functions->find(name);
    if (!*out)
        return c.fail(sub(path, key), "no function named '" + name_text(name) +
                                          "' was given (given: " + c.functions->names() + ")");
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
    if (type == "function") return parse_function_integrand(c, j, path, dim, out);
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
    if (const Json* type = find(j, "type"); type && *type == "function") {
        uint64_t dim = 1;
        if (!get_count(c, j, "dim", path, &dim)) return false;
        if (dim < 1 || dim > uint64_t(kMaxDim))
            return c.fail(sub(path, "dim"), "expected 1 to " + std::to_string(kMaxDim) + ", got " +
                                                std::to_string(dim));
        *out = static_cast<int>(dim);
        return true;
    }
    int dim = 0;
    bool given = false;
    if (!get_genz_dim(c, j, path, &dim, &given)) return false;
    if (given) *out = dim;
    return true;
}

} // namespace mcp
