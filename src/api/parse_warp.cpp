// A scene's "warp" (docs/scene-format.md, "Warps"): a named warp ("concentric_disk", or
// {"name": ..., its parameters}) or one typed as expressions ({"domain", "g", "p"}).
#include <algorithm>
#include <cmath>

#include "api/scene_parsers.h"
#include "estimators/named_warps.h"

namespace mcp {
namespace {

bool get_vec3(Ctx& c, const Json& j, const char* key, const std::string& path, Vec3* out) {
    const Json* v = find(j, key);
    if (!v) return true;
    std::vector<double> xs;
    if (!to_numbers(c, *v, sub(path, key), &xs)) return false;
    if (xs.size() != 3) return c.fail(sub(path, key), "expected [x, y, z]");
    *out = Vec3(xs[0], xs[1], xs[2]);
    return true;
}

bool get_point2(Ctx& c, const Json& v, const std::string& path, Vec2* out) {
    std::vector<double> xs;
    if (!to_numbers(c, v, path, &xs)) return false;
    if (xs.size() != 2) return c.fail(path, "expected [x, y]");
    *out = Vec2(xs[0], xs[1]);
    return true;
}

/// The parameters each named warp reads (docs/scene-format.md, "Warps"); null for a name that
/// is none of them.
const std::vector<std::string>* named_warp_fields(const std::string& name) {
    static const std::vector<std::pair<std::string, std::vector<std::string>>> fields = {
        {"uniform", {"lower", "upper"}},
        {"polar_disk", {"center", "radius"}},
        {"concentric_disk", {"center", "radius"}},
        {"uniform_sphere", {}},
        {"uniform_hemisphere", {}},
        {"cosine_hemisphere", {}},
        {"triangle", {"vertices"}},
        {"tabulated_1d", {"lower", "upper", "values", "f", "bins"}},
        {"tabulated_2d", {"lower", "upper", "values", "f", "nx", "ny"}},
        {"ggx_visible_normals", {"alpha", "wo"}},
        {"spherical_triangle", {"a", "b", "c", "viewpoint"}},
    };
    for (const auto& [n, f] : fields)
        if (n == name) return &f;
    return nullptr;
}

/// The parameters of a named warp from its object: only those the warp reads, so that a
/// parameter of another warp is refused rather than ignored.
bool parse_named_params(Ctx& c, const Json& j, const std::string& path, const std::string& name,
                        const std::vector<std::string>& known, NamedWarpParams* p) {
    for (auto it = j.begin(); it != j.end(); ++it) {
        if (it.key() == "name" || std::find(known.begin(), known.end(), it.key()) != known.end())
            continue;
        return c.fail(path, "unknown parameter '" + it.key() + "' of the warp '" + name + "' (" +
                                (known.empty() ? std::string("it takes none")
                                               : "its parameters: " + join(known)) +
                                ")");
    }
    if (!get_numbers(c, j, "lower", path, &p->lo) || !get_numbers(c, j, "upper", path, &p->hi) ||
        !get_number(c, j, "radius", path, &p->radius) ||
        !get_number(c, j, "alpha", path, &p->alpha) || !get_vec3(c, j, "wo", path, &p->wo) ||
        !get_vec3(c, j, "a", path, &p->a) || !get_vec3(c, j, "b", path, &p->b) ||
        !get_vec3(c, j, "c", path, &p->c) || !get_vec3(c, j, "viewpoint", path, &p->viewpoint) ||
        !get_string(c, j, "f", path, &p->expression))
        return false;
    if (const Json* center = find(j, "center"))
        if (!get_point2(c, *center, sub(path, "center"), &p->center)) return false;
    if (const Json* v = find(j, "vertices")) {
        if (!v->is_array() || v->size() != 3)
            return c.fail(sub(path, "vertices"), "expected three [x, y] points");
        Vec2* corners[] = {&p->v0, &p->v1, &p->v2};
        for (size_t i = 0; i < 3; ++i)
            if (!get_point2(c, (*v)[i], sub(path, "vertices") + "[" + std::to_string(i) + "]",
                            corners[i]))
                return false;
    }
    if (const Json* v = find(j, "values"); v && v->is_array() && v->size() > (size_t(1) << 20))
        return c.fail(sub(path, "values"), "at most 2^20 values");
    if (!get_numbers(c, j, "values", path, &p->values)) return false;
    // Left out, a count takes the warp's default; given, it is 1..4096 (a 0 is not the default).
    uint64_t counts[3] = {0, 0, 0};
    const char* count_keys[3] = {"bins", "nx", "ny"};
    for (int k = 0; k < 3; ++k) {
        if (!get_count(c, j, count_keys[k], path, &counts[k])) return false;
        if (find(j, count_keys[k]) && (counts[k] < 1 || counts[k] > 4096))
            return c.fail(sub(path, count_keys[k]), "must be in 1..4096, got " +
                                                        std::to_string(counts[k]) +
                                                        " (leave it out for the default)");
    }
    p->nx = static_cast<int>(counts[0] ? counts[0] : counts[1]);
    p->ny = static_cast<int>(counts[2]);
    return true;
}

} // namespace

bool parse_warp(Ctx& c, const Json& j, const std::string& path, NamedWarp* out) {
    if (j.is_string()) {
        Made<NamedWarp> w = make_named_warp(j.get<std::string>());
        if (!w.ok()) return c.fail(path, w.error);
        *out = std::move(w.value);
        return true;
    }
    if (!j.is_object()) return c.fail(path, "expected a warp name or object, got " + type_of(j));
    if (find(j, "name")) {
        std::string name;
        if (!get_string(c, j, "name", path, &name)) return false;
        const std::vector<std::string>* known = named_warp_fields(name);
        NamedWarpParams params;
        if (known && !parse_named_params(c, j, path, name, *known, &params)) return false;
        Made<NamedWarp> w = make_named_warp(name, params);
        if (!w.ok()) return c.fail(path, w.error);
        *out = std::move(w.value);
        return true;
    }
    // Typed: {"domain", "g": [one expression per coordinate of x] (a string in 1-D), "p"}; g or
    // p may instead name a caller's function ({"function": N}; g also "sample_dim").
    if (!check_keys(c, j, path, {"domain", "g", "p"})) return false;
    const Json* g = find(j, "g");
    const Json* p = find(j, "p");
    if (!g || !p)
        return c.fail(path, "a typed warp needs \"g\" (x as expressions in u1, u2, ...) and \"p\" "
                            "(its density in x, y, z), or \"name\": one of " +
                                named_warp_names());
    std::vector<std::string> g_texts;
    std::shared_ptr<const CallerFunction> g_function, p_function;
    uint64_t g_sample_dim = 0;
    if (g->is_object()) {
        if (!check_keys(c, *g, sub(path, "g"), {"function", "sample_dim"}) ||
            !find_caller_function(c, *g, "function", sub(path, "g"), &g_function) ||
            !get_count(c, *g, "sample_dim", sub(path, "g"), &g_sample_dim))
            return false;
        if (!find(j, "domain"))
            return c.fail(path, "a warp whose g is a function needs \"domain\" (where g's points "
                                "land)");
    } else if (g->is_string()) {
        g_texts.push_back(g->get<std::string>());
    } else if (g->is_array() && !g->empty() && g->size() <= size_t(kMaxWarpDim)) {
        for (size_t i = 0; i < g->size(); ++i) {
            if (!(*g)[i].is_string())
                return c.fail(sub(path, "g") + "[" + std::to_string(i) + "]",
                              "expected an expression string, got " + type_of((*g)[i]));
            g_texts.push_back((*g)[i].get<std::string>());
        }
    } else {
        return c.fail(sub(path, "g"), "expected 1 to " + std::to_string(kMaxWarpDim) +
                                          " expressions, one per coordinate of x, or "
                                          "{\"function\": name}");
    }
    if (p->is_object()) {
        if (!check_keys(c, *p, sub(path, "p"), {"function"}) ||
            !find_caller_function(c, *p, "function", sub(path, "p"), &p_function))
            return false;
    } else if (!p->is_string()) {
        return c.fail(sub(path, "p"),
                      "expected an expression string or {\"function\": name}, got " + type_of(*p));
    }
    Domain domain;
    if (const Json* d = find(j, "domain")) {
        if (!parse_domain(c, *d, sub(path, "domain"), static_cast<int>(g_texts.size()), &domain))
            return false;
    } else {
        Made<Domain> unit = make_box(std::vector<double>(g_texts.size(), 0.0),
                                     std::vector<double>(g_texts.size(), 1.0));
        if (!unit.ok()) return c.fail(path, unit.error);
        domain = unit.value;
    }
    if (g_function && g_sample_dim != 0 && g_sample_dim != uint64_t(domain.sample_dim()))
        return c.fail(sub(sub(path, "g"), "sample_dim"),
                      "is " + std::to_string(g_sample_dim) + ", but warps onto the " +
                          domain.describe() + " read " + std::to_string(domain.sample_dim()) +
                          " unit-cube coordinates");
    if (!g_function && static_cast<int>(g_texts.size()) != domain.point_dim())
        return c.fail(sub(path, "g"), "has " + std::to_string(g_texts.size()) +
                                          " expressions, but points of the " + domain.describe() +
                                          " have " + std::to_string(domain.point_dim()) +
                                          " coordinates");
    Made<Warp> w = make_typed_warp(domain, g_texts, g_function,
                                   p_function ? std::string() : p->get<std::string>(), p_function);
    if (!w.ok()) return c.fail(path, w.error);
    out->warp = std::move(w.value);
    out->domain = domain;
    return true;
}

} // namespace mcp
