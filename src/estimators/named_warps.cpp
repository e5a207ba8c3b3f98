// Named and expression warps: see named_warps.h. Each named warp is a block loop around one
// core routine; the loops run per block, the routines are inline or called once per point.
#include "estimators/named_warps.h"

#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>

#include "core/distributions.h"
#include "core/microfacet.h"
#include "core/spherical_triangle.h"
#include "integrands/expression.h"

namespace mcp {
namespace {

constexpr int kDefaultExpressionBins1D = 64;
constexpr int kDefaultExpressionCells2D = 16;
/// Most entries of a table (tabulated_1d bins, tabulated_2d cells), and most cells per axis.
constexpr size_t kMaxTableEntries = size_t(1) << 20;
constexpr int kMaxTableAxis = 4096;

const std::vector<NamedWarpInfo> kInfos = {
    {"uniform", "x = lo + (hi - lo) u on a box of 1 to 3 axes; density 1 / volume"},
    {"polar_disk", "r = R sqrt(u1), phi = 2 pi u2 (the course notes' polar map); density "
                   "1 / (pi R^2)"},
    {"concentric_disk", "Shirley and Chiu's concentric map of the square onto the disk "
                        "[ShirleyChiu97]; density 1 / (pi R^2)"},
    {"uniform_sphere", "z = 1 - 2 u1, phi = 2 pi u2; density 1 / (4 pi)"},
    {"uniform_hemisphere", "z = u1, phi = 2 pi u2; density 1 / (2 pi)"},
    {"cosine_hemisphere", "a concentric disk sample lifted to the hemisphere (Malley's method); "
                          "density cos(theta) / pi"},
    {"triangle", "barycentrics b0 = 1 - sqrt(u1), b1 = u2 sqrt(u1) [Turk90]; density 1 / area"},
    {"tabulated_1d", "inverse CDF of a piecewise-constant density on equal bins of [a, b] "
                     "(values, or an expression at the bins' centres)"},
    {"tabulated_2d", "marginal in y then conditional in x of a piecewise-constant table "
                     "[PBR4, A.5.6]"},
    {"ggx_visible_normals", "GGX normals visible from wo [Heitz18]; density G1(wo) max(0, "
                            "wo.h) D(h) / wo.z"},
    {"spherical_triangle", "Arvo's area-preserving map onto a triangle's solid angle "
                           "[Arvo95]; density 1 / Omega inside it"},
};

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

bool finite3(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// x[j][i] = lo[j] + (hi[j] - lo[j]) u[j][i]; density 1 / volume.
NamedWarp uniform_box(const Domain& d) {
    NamedWarp w;
    w.domain = d;
    w.warp.name = "uniform";
    w.warp.sample_dim = d.sample_dim();
    const std::vector<double> lo = d.lo, hi = d.hi;
    w.warp.map = [lo, hi](const PointBlock& u, PointBlock& x) {
        for (size_t j = 0; j < lo.size(); ++j) {
            const double a = lo[j], width = hi[j] - lo[j];
            const double* uj = u.coord(static_cast<int>(j));
            double* xj = x.coord(static_cast<int>(j));
            for (size_t i = 0; i < u.n; ++i) xj[i] = a + width * uj[i];
        }
    };
    const double density = 1.0 / d.measure();
    w.warp.pdf = [density](const PointBlock& x, double* pdf) {
        for (size_t i = 0; i < x.n; ++i) pdf[i] = density;
    };
    return w;
}

/// A 2D map of the unit square onto the domain's points (2 or 3 coordinates) with a constant
/// density.
template <class Map>
NamedWarp constant_density(const char* name, const Domain& d, double density, Map m) {
    NamedWarp w;
    w.domain = d;
    w.warp.name = name;
    w.warp.sample_dim = 2;
    w.warp.map = [m](const PointBlock& u, PointBlock& x) {
        for (size_t i = 0; i < u.n; ++i) m(Vec2{u.coord(0)[i], u.coord(1)[i]}, x, i);
    };
    w.warp.pdf = [density](const PointBlock& x, double* pdf) {
        for (size_t i = 0; i < x.n; ++i) pdf[i] = density;
    };
    return w;
}

void put3(PointBlock& x, size_t i, const Vec3& v) {
    x.coord(0)[i] = v.x;
    x.coord(1)[i] = v.y;
    x.coord(2)[i] = v.z;
}

Made<NamedWarp> disk_warp(const char* name, bool polar, const NamedWarpParams& p) {
    Made<Domain> d = make_disk(p.center, p.radius);
    if (!d.ok()) return made_error<NamedWarp>(std::string(name) + ": " + d.error);
    const Vec2 c = p.center;
    const double r = p.radius, density = disk_pdf() / (r * r);
    if (polar)
        return {constant_density(name, d.value, density,
                                 [c, r](Vec2 u, PointBlock& x, size_t i) {
                                     const Vec2 q = c + r * sample_disk_polar(u);
                                     x.coord(0)[i] = q.x;
                                     x.coord(1)[i] = q.y;
                                 }),
                {}};
    return {constant_density(name, d.value, density,
                             [c, r](Vec2 u, PointBlock& x, size_t i) {
                                 const Vec2 q = c + r * sample_disk_concentric(u);
                                 x.coord(0)[i] = q.x;
                                 x.coord(1)[i] = q.y;
                             }),
            {}};
}

Made<NamedWarp> triangle_warp(const NamedWarpParams& p) {
    Made<Domain> d = make_triangle(p.v0, p.v1, p.v2);
    if (!d.ok()) return made_error<NamedWarp>("triangle: " + d.error);
    const Vec2 a = p.v0, b = p.v1, c = p.v2;
    return {constant_density("triangle", d.value, 1.0 / d.value.measure(),
                             [a, b, c](Vec2 u, PointBlock& x, size_t i) {
                                 const Vec2 w = sample_triangle_barycentric(u);
                                 const Vec2 q = w.x * a + w.y * b + (1.0 - w.x - w.y) * c;
                                 x.coord(0)[i] = q.x;
                                 x.coord(1)[i] = q.y;
                             }),
            {}};
}

NamedWarp cosine_hemisphere_warp() {
    NamedWarp w;
    w.domain = make_hemisphere();
    w.warp.name = "cosine_hemisphere";
    w.warp.sample_dim = 2;
    w.warp.map = [](const PointBlock& u, PointBlock& x) {
        for (size_t i = 0; i < u.n; ++i)
            put3(x, i, sample_cosine_hemisphere(Vec2{u.coord(0)[i], u.coord(1)[i]}));
    };
    w.warp.pdf = [](const PointBlock& x, double* pdf) {
        for (size_t i = 0; i < x.n; ++i) pdf[i] = cosine_hemisphere_pdf(x.coord(2)[i]);
    };
    return w;
}

/// The box [lo[0], hi[0]] (tabulated_1d) or [lo, hi] (tabulated_2d), defaults the unit ones.
Made<Domain> table_box(const char* name, const NamedWarpParams& p, size_t axes) {
    std::vector<double> lo = p.lo, hi = p.hi;
    if (lo.empty() && hi.empty()) {
        lo.assign(axes, 0.0);
        hi.assign(axes, 1.0);
    }
    if (lo.size() < axes || hi.size() < axes)
        return made_error<Domain>(std::string(name) + ": lo and hi need " + std::to_string(axes) +
                                  " bounds each");
    lo.resize(axes);
    hi.resize(axes);
    Made<Domain> d = make_box(lo, hi);
    if (!d.ok()) d.error = std::string(name) + ": " + d.error;
    return d;
}

Made<NamedWarp> tabulated_1d_warp(const NamedWarpParams& p) {
    Made<Domain> d = table_box("tabulated_1d", p, 1);
    if (!d.ok()) return made_error<NamedWarp>(d.error);
    const double a = d.value.lo[0], b = d.value.hi[0];
    std::vector<double> values = p.values;
    if (values.empty() && !p.expression.empty()) {
        const int bins = p.nx > 0 ? p.nx : kDefaultExpressionBins1D;
        if (static_cast<size_t>(bins) > kMaxTableEntries)
            return made_error<NamedWarp>("tabulated_1d: at most " +
                                         std::to_string(kMaxTableEntries) + " bins, got " +
                                         std::to_string(bins));
        auto f = compile_expression(p.expression, 1);
        if (!f.ok()) return made_error<NamedWarp>("tabulated_1d: expression: " + f.error);
        values.resize(static_cast<size_t>(bins));
        for (int k = 0; k < bins; ++k) {
            const double x = a + (b - a) * (k + 0.5) / bins;
            values[static_cast<size_t>(k)] = f.value->evaluate_point(&x);
        }
    } else if (values.empty()) {
        values = {1.0, 4.0, 0.0, 2.0, 3.0}; // a zero bin and steps inside the test's bins
    }
    if (values.size() > kMaxTableEntries)
        return made_error<NamedWarp>("tabulated_1d: at most " + std::to_string(kMaxTableEntries) +
                                     " values, got " + std::to_string(values.size()));
    Made<Distribution1D> dist = make_tabulated(a, b, values);
    if (!dist.ok()) return made_error<NamedWarp>("tabulated_1d: " + dist.error);
    auto shared = std::make_shared<const Distribution1D>(std::move(dist.value));
    NamedWarp w;
    w.domain = d.value;
    w.warp.name = "tabulated_1d";
    w.warp.sample_dim = 1;
    w.warp.map = [shared](const PointBlock& u, PointBlock& x) {
        double pdf[kBlockSize];
        for (size_t start = 0; start < u.n; start += kBlockSize) {
            const size_t m = u.n - start < kBlockSize ? u.n - start : kBlockSize;
            shared->sample_block(u.coord(0) + start, x.coord(0) + start, pdf, m);
        }
    };
    w.warp.pdf = [shared](const PointBlock& x, double* pdf) {
        for (size_t i = 0; i < x.n; ++i) pdf[i] = 1.0;
        shared->multiply_pdf_block(x.coord(0), pdf, x.n);
    };
    return {w, {}};
}

Made<NamedWarp> tabulated_2d_warp(const NamedWarpParams& p) {
    Made<Domain> d = table_box("tabulated_2d", p, 2);
    if (!d.ok()) return made_error<NamedWarp>(d.error);
    const Domain& box = d.value;
    std::vector<double> values = p.values;
    int nx = p.nx, ny = p.ny;
    if (values.empty() && !p.expression.empty()) {
        nx = nx > 0 ? nx : kDefaultExpressionCells2D;
        ny = ny > 0 ? ny : kDefaultExpressionCells2D;
        if (nx > kMaxTableAxis || ny > kMaxTableAxis ||
            static_cast<size_t>(nx) * static_cast<size_t>(ny) > kMaxTableEntries)
            return made_error<NamedWarp>("tabulated_2d: at most " + std::to_string(kMaxTableAxis) +
                                         " cells per axis and " + std::to_string(kMaxTableEntries) +
                                         " in all");
        auto f = compile_expression(p.expression, 2);
        if (!f.ok()) return made_error<NamedWarp>("tabulated_2d: expression: " + f.error);
        values.resize(static_cast<size_t>(nx) * static_cast<size_t>(ny));
        for (int iy = 0; iy < ny; ++iy)
            for (int ix = 0; ix < nx; ++ix) {
                const double q[2] = {box.lo[0] + (box.hi[0] - box.lo[0]) * (ix + 0.5) / nx,
                                     box.lo[1] + (box.hi[1] - box.lo[1]) * (iy + 0.5) / ny};
                values[static_cast<size_t>(iy) * static_cast<size_t>(nx) +
                       static_cast<size_t>(ix)] = f.value->evaluate_point(q);
            }
    } else if (values.empty()) {
        nx = 3;
        ny = 2;
        values = {1.0, 2.0, 0.5, 3.0, 0.0, 1.0}; // a zero cell; steps inside the test's bins
    }
    if (nx <= 0 || ny <= 0 || nx > kMaxTableAxis || ny > kMaxTableAxis ||
        static_cast<size_t>(nx) * static_cast<size_t>(ny) != values.size())
        return made_error<NamedWarp>("tabulated_2d: nx x ny (" + std::to_string(nx) + " x " +
                                     std::to_string(ny) + ") must equal the number of values (" +
                                     std::to_string(values.size()) + "), each at most " +
                                     std::to_string(kMaxTableAxis));
    Made<TabulatedDistribution2D> table =
        make_tabulated_2d(box.lo[0], box.hi[0], box.lo[1], box.hi[1], nx, ny, values);
    if (!table.ok()) return made_error<NamedWarp>("tabulated_2d: " + table.error);
    auto shared = std::make_shared<const TabulatedDistribution2D>(std::move(table.value));
    NamedWarp w;
    w.domain = box;
    w.warp.name = "tabulated_2d";
    w.warp.sample_dim = 2;
    w.warp.map = [shared](const PointBlock& u, PointBlock& x) {
        double pdf[kBlockSize];
        for (size_t start = 0; start < u.n; start += kBlockSize) {
            const size_t m = u.n - start < kBlockSize ? u.n - start : kBlockSize;
            shared->sample_block(u.coord(0) + start, u.coord(1) + start, x.coord(0) + start,
                                 x.coord(1) + start, pdf, m);
        }
    };
    w.warp.pdf = [shared](const PointBlock& x, double* pdf) {
        for (size_t i = 0; i < x.n; ++i) pdf[i] = shared->pdf(x.coord(0)[i], x.coord(1)[i]);
    };
    return {w, {}};
}

Made<NamedWarp> ggx_warp(const NamedWarpParams& p) {
    if (!(p.alpha >= 1e-3 && p.alpha <= 10.0))
        return made_error<NamedWarp>("ggx_visible_normals: alpha must be in [0.001, 10], got " +
                                     number(p.alpha));
    Vec3 wo;
    if (!finite3(p.wo) || !safe_normalize(p.wo, &wo) || !(wo.z > 0.0))
        return made_error<NamedWarp>("ggx_visible_normals: wo must be a finite direction above "
                                     "the surface (wo.z > 0), got (" +
                                     number(p.wo.x) + ", " + number(p.wo.y) + ", " +
                                     number(p.wo.z) + ")");
    const double alpha = p.alpha;
    NamedWarp w;
    w.domain = make_hemisphere();
    w.warp.name = "ggx_visible_normals";
    w.warp.sample_dim = 2;
    w.warp.map = [alpha, wo](const PointBlock& u, PointBlock& x) {
        for (size_t i = 0; i < u.n; ++i)
            put3(x, i, ggx_sample_visible_normal(alpha, wo, Vec2{u.coord(0)[i], u.coord(1)[i]}));
    };
    w.warp.pdf = [alpha, wo](const PointBlock& x, double* pdf) {
        for (size_t i = 0; i < x.n; ++i)
            pdf[i] = ggx_visible_normal_pdf(alpha, wo,
                                            Vec3{x.coord(0)[i], x.coord(1)[i], x.coord(2)[i]});
    };
    return {w, {}};
}

Made<NamedWarp> spherical_triangle_warp(const NamedWarpParams& p) {
    if (!finite3(p.a) || !finite3(p.b) || !finite3(p.c) || !finite3(p.viewpoint))
        return made_error<NamedWarp>("spherical_triangle: vertices and viewpoint must be finite");
    const Vec3 a = p.a - p.viewpoint, b = p.b - p.viewpoint, c = p.c - p.viewpoint;
    const Vec3 e1 = b - a, e2 = c - a;
    const double det = glm::dot(a, glm::cross(e1, e2));
    const TriangleVertexLengths len = triangle_vertex_lengths(a, b, c);
    SphericalTriangle st;
    st.omega = spherical_triangle_solid_angle(a, b, c, det, len);
    if (det == 0.0 || !(st.omega > 0.0) || !std::isfinite(st.omega))
        return made_error<NamedWarp>("spherical_triangle: the triangle has zero solid angle "
                                     "from the viewpoint (degenerate, or seen edge-on)");
    fill_spherical_triangle(a, b, c, e1, e2, det, len, &st);
    // Inside: on the triangle's side of each of its three great circles (the side the third
    // vertex is on), by the signs of triple products.
    const double s = det > 0.0 ? 1.0 : -1.0;
    const Vec3 nab = s * glm::cross(a, b), nbc = s * glm::cross(b, c), nca = s * glm::cross(c, a);
    const double density = 1.0 / st.omega;
    NamedWarp w;
    w.domain = make_sphere();
    w.warp.name = "spherical_triangle";
    w.warp.sample_dim = 2;
    w.warp.map = [st](const PointBlock& u, PointBlock& x) {
        for (size_t i = 0; i < u.n; ++i)
            put3(x, i, sample_spherical_triangle(st, Vec2{u.coord(0)[i], u.coord(1)[i]}));
    };
    w.warp.pdf = [nab, nbc, nca, density](const PointBlock& x, double* pdf) {
        for (size_t i = 0; i < x.n; ++i) {
            const Vec3 v{x.coord(0)[i], x.coord(1)[i], x.coord(2)[i]};
            const bool inside =
                glm::dot(v, nab) >= 0.0 && glm::dot(v, nbc) >= 0.0 && glm::dot(v, nca) >= 0.0;
            pdf[i] = inside ? density : 0.0;
        }
    };
    return {w, {}};
}

} // namespace

const std::vector<NamedWarpInfo>& named_warp_infos() {
    return kInfos;
}

std::string named_warp_names() {
    std::string s;
    for (const NamedWarpInfo& info : kInfos) s += (s.empty() ? "" : ", ") + std::string(info.name);
    return s;
}

Made<NamedWarp> make_named_warp(const std::string& name, const NamedWarpParams& p) {
    if (name == "uniform") {
        std::vector<double> lo = p.lo, hi = p.hi;
        if (lo.empty() && hi.empty()) {
            lo = {0.0, 0.0};
            hi = {1.0, 1.0};
        }
        if (lo.size() > static_cast<size_t>(kMaxWarpDim))
            return made_error<NamedWarp>("uniform: at most " + std::to_string(kMaxWarpDim) +
                                         " axes, got " + std::to_string(lo.size()));
        Made<Domain> d = make_box(lo, hi);
        if (!d.ok()) return made_error<NamedWarp>("uniform: " + d.error);
        return {uniform_box(d.value), {}};
    }
    if (name == "polar_disk") return disk_warp("polar_disk", true, p);
    if (name == "concentric_disk") return disk_warp("concentric_disk", false, p);
    if (name == "uniform_sphere")
        return {constant_density(
                    "uniform_sphere", make_sphere(), uniform_sphere_pdf(),
                    [](Vec2 u, PointBlock& x, size_t i) { put3(x, i, sample_uniform_sphere(u)); }),
                {}};
    if (name == "uniform_hemisphere")
        return {constant_density("uniform_hemisphere", make_hemisphere(), uniform_hemisphere_pdf(),
                                 [](Vec2 u, PointBlock& x, size_t i) {
                                     put3(x, i, sample_uniform_hemisphere(u));
                                 }),
                {}};
    if (name == "cosine_hemisphere") return {cosine_hemisphere_warp(), {}};
    if (name == "triangle") return triangle_warp(p);
    if (name == "tabulated_1d") return tabulated_1d_warp(p);
    if (name == "tabulated_2d") return tabulated_2d_warp(p);
    if (name == "ggx_visible_normals") return ggx_warp(p);
    if (name == "spherical_triangle") return spherical_triangle_warp(p);
    return made_error<NamedWarp>("unknown warp '" + name + "' (warps: " + named_warp_names() + ")");
}

Made<Warp> make_expression_warp(const Domain& domain, const std::vector<std::string>& g,
                                const std::string& p) {
    return make_typed_warp(domain, g, nullptr, p, nullptr);
}

Made<Warp> make_typed_warp(const Domain& domain, const std::vector<std::string>& g_texts,
                           std::shared_ptr<const CallerFunction> g_function,
                           const std::string& p_text,
                           std::shared_ptr<const CallerFunction> p_function) {
    const int point_dim = domain.point_dim(), sample_dim = domain.sample_dim();
    const char* what = g_function || p_function ? "typed warp" : "expression warp";
    if (point_dim < 1 || point_dim > kMaxWarpDim)
        return made_error<Warp>(std::string(what) + ": the domain has " +
                                std::to_string(point_dim) + " coordinates; at most " +
                                std::to_string(kMaxWarpDim));
    if (!g_function && g_texts.size() != static_cast<size_t>(point_dim))
        return made_error<Warp>(std::string(what) + ": the domain's points have " +
                                std::to_string(point_dim) + " coordinates, got " +
                                std::to_string(g_texts.size()) + " expressions for g");
    Warp w;
    w.name = g_function || p_function ? "typed" : "expression";
    w.sample_dim = sample_dim;
    if (g_function) {
        w.map = [g_function, point_dim](const PointBlock& u, PointBlock& x) {
            g_function->evaluate(u, point_dim, x.coord(0), x.capacity);
        };
    } else {
        std::vector<std::shared_ptr<const ExprProgram>> maps;
        for (size_t k = 0; k < g_texts.size(); ++k) {
            auto made = compile_expression(g_texts[k], sample_dim, ExprVariables::Unit);
            if (!made.ok())
                return made_error<Warp>("g" + std::to_string(k + 1) + ": " + made.error);
            maps.push_back(made.value);
        }
        w.map = [maps, sample_dim](const PointBlock& u, PointBlock& x) {
            const double* vars[kMaxWarpDim];
            for (int j = 0; j < sample_dim; ++j) vars[j] = u.coord(j);
            for (size_t k = 0; k < maps.size(); ++k)
                maps[k]->evaluate(vars, u.n, x.coord(static_cast<int>(k)));
        };
    }
    if (p_function) {
        w.pdf = [p_function](const PointBlock& x, double* out) {
            p_function->evaluate(x, 1, out, x.n);
        };
    } else {
        auto density = compile_expression(p_text, point_dim);
        if (!density.ok()) return made_error<Warp>("p: " + density.error);
        const std::shared_ptr<const ExprProgram> pdf = density.value;
        w.pdf = [pdf, point_dim](const PointBlock& x, double* out) {
            const double* vars[kMaxWarpDim];
            for (int j = 0; j < point_dim; ++j) vars[j] = x.coord(j);
            pdf->evaluate(vars, x.n, out);
        };
    }
    w.escape = std::make_shared<WarpEscape>();
    return {w, {}};
}

void WarpEscape::record(const PointBlock& u, const PointBlock& x, size_t i) {
    if (seen()) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (seen_.load(std::memory_order_relaxed)) return;
    for (int j = 0; j < u.dim; ++j) u_.push_back(u.coord(j)[i]);
    for (int j = 0; j < x.dim; ++j) x_.push_back(x.coord(j)[i]);
    seen_.store(true, std::memory_order_release);
}

std::string WarpEscape::describe(const Domain& domain) const {
    if (!seen()) return "";
    std::lock_guard<std::mutex> lock(mutex_);
    auto tuple = [](const std::vector<double>& v) {
        std::string t = "(";
        char buf[32];
        for (size_t j = 0; j < v.size(); ++j) {
            std::snprintf(buf, sizeof buf, "%.6g", v[j]);
            t += (j ? ", " : "") + std::string(buf);
        }
        return t + ")";
    };
    return "u = " + tuple(u_) + " gave x = " + tuple(x_) + ", outside its domain, the " +
           domain.describe();
}

Proposal warp_proposal(std::shared_ptr<const Warp> warp, const Domain& domain) {
    Proposal p;
    p.kind = ProposalKind::Warp;
    p.warp = std::move(warp);
    p.warp_domain = domain;
    p.importance = true;
    return p;
}

} // namespace mcp
