#include "estimators/problem.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/special.h"
#include "estimators/estimator_kind.h"
#include "estimators/named_warps.h"
#include "estimators/registry.h"
#include "estimators/warp_test.h" // kWarpDomainTolerance

namespace mcp {

const char* domain_kind_name(DomainKind kind) {
    switch (kind) {
    case DomainKind::Box: return "box";
    case DomainKind::Disk: return "disk";
    case DomainKind::Triangle: return "triangle";
    case DomainKind::Sphere: return "sphere";
    case DomainKind::Hemisphere: return "hemisphere";
    }
    return "?";
}

int Domain::point_dim() const {
    switch (kind) {
    case DomainKind::Box: return static_cast<int>(lo.size());
    case DomainKind::Disk:
    case DomainKind::Triangle: return 2;
    case DomainKind::Sphere:
    case DomainKind::Hemisphere: return 3;
    }
    return 0;
}

int Domain::sample_dim() const {
    return kind == DomainKind::Box ? static_cast<int>(lo.size()) : 2;
}

double Domain::measure() const {
    switch (kind) {
    case DomainKind::Box: {
        double v = 1.0;
        for (size_t j = 0; j < lo.size(); ++j) v *= hi[j] - lo[j];
        return v;
    }
    case DomainKind::Disk: return kPi * radius * radius;
    case DomainKind::Triangle:
        return 0.5 * std::fabs((v1.x - v0.x) * (v2.y - v0.y) - (v2.x - v0.x) * (v1.y - v0.y));
    case DomainKind::Sphere: return 4.0 * kPi;
    case DomainKind::Hemisphere: return 2.0 * kPi;
    }
    return 0.0;
}

std::string Domain::describe() const {
    std::ostringstream s;
    s.precision(6);
    switch (kind) {
    case DomainKind::Box:
        for (size_t j = 0; j < lo.size(); ++j)
            s << (j ? " x " : "") << "[" << lo[j] << ", " << hi[j] << "]";
        break;
    case DomainKind::Disk:
        s << "disk centre (" << center.x << ", " << center.y << ") radius " << radius;
        break;
    case DomainKind::Triangle:
        s << "triangle (" << v0.x << ", " << v0.y << ") (" << v1.x << ", " << v1.y << ") (" << v2.x
          << ", " << v2.y << ")";
        break;
    case DomainKind::Sphere: s << "unit sphere of directions"; break;
    case DomainKind::Hemisphere: s << "hemisphere of directions z >= 0"; break;
    }
    return s.str();
}

Made<Domain> make_box(std::vector<double> lo, std::vector<double> hi) {
    if (lo.empty() || lo.size() != hi.size())
        return made_error<Domain>("box: lower and upper must be non-empty and of equal length");
    if (lo.size() > 64)
        return made_error<Domain>("box: at most 64 dimensions, got " + std::to_string(lo.size()));
    for (size_t j = 0; j < lo.size(); ++j) {
        if (!std::isfinite(lo[j]) || !std::isfinite(hi[j]) || !(lo[j] < hi[j]))
            return made_error<Domain>("box: axis " + std::to_string(j) +
                                      " needs finite lower < upper");
    }
    Domain d;
    d.kind = DomainKind::Box;
    d.lo = std::move(lo);
    d.hi = std::move(hi);
    return {d, {}};
}

Made<Domain> make_disk(Vec2 center, double radius) {
    if (!std::isfinite(center.x) || !std::isfinite(center.y))
        return made_error<Domain>("disk: center must be finite");
    if (!(radius > 0.0) || !std::isfinite(radius))
        return made_error<Domain>("disk: radius must be a finite number > 0");
    Domain d;
    d.kind = DomainKind::Disk;
    d.center = center;
    d.radius = radius;
    d.lo = {center.x - radius, center.y - radius};
    d.hi = {center.x + radius, center.y + radius};
    return {d, {}};
}

Made<Domain> make_triangle(Vec2 a, Vec2 b, Vec2 c) {
    for (Vec2 v : {a, b, c})
        if (!std::isfinite(v.x) || !std::isfinite(v.y))
            return made_error<Domain>("triangle: vertices must be finite");
    Domain d;
    d.kind = DomainKind::Triangle;
    d.v0 = a;
    d.v1 = b;
    d.v2 = c;
    if (!(d.measure() > 0.0))
        return made_error<Domain>("triangle: vertices are collinear (zero area)");
    return {d, {}};
}

Domain make_sphere() {
    Domain d;
    d.kind = DomainKind::Sphere;
    return d;
}

Domain make_hemisphere() {
    Domain d;
    d.kind = DomainKind::Hemisphere;
    return d;
}

const char* proposal_kind_name(ProposalKind kind) {
    switch (kind) {
    case ProposalKind::UniformBox: return "uniform";
    case ProposalKind::DiskPolar: return "uniform_polar";
    case ProposalKind::DiskConcentric: return "uniform_concentric";
    case ProposalKind::Triangle: return "uniform";
    case ProposalKind::Sphere: return "uniform";
    case ProposalKind::Hemisphere: return "uniform";
    case ProposalKind::CosineHemisphere: return "cosine_hemisphere";
    case ProposalKind::Product1D: return "product";
    case ProposalKind::Tabulated2D: return "tabulated_2d";
    case ProposalKind::Warp: return "warp";
    }
    return "?";
}

std::string Proposal::describe() const {
    switch (kind) {
    case ProposalKind::UniformBox: return "uniform";
    case ProposalKind::DiskPolar: return "uniform (polar map r = sqrt(u1))";
    case ProposalKind::DiskConcentric: return "uniform (concentric map)";
    case ProposalKind::Triangle: return "uniform (barycentric sqrt map)";
    case ProposalKind::Sphere:
    case ProposalKind::Hemisphere: return "uniform";
    case ProposalKind::CosineHemisphere: return "cos(theta)/pi";
    case ProposalKind::Product1D: {
        std::string s;
        for (size_t j = 0; j < marginals.size(); ++j)
            s += (j ? " x " : "") + marginals[j].describe();
        return s;
    }
    case ProposalKind::Tabulated2D:
        return "tabulated_2d(" + std::to_string(table.nx()) + " x " + std::to_string(table.ny()) +
               ")";
    case ProposalKind::Warp: return "warp '" + (warp ? warp->name : std::string("?")) + "'";
    }
    return "?";
}

namespace {

std::string point_text(Vec2 p) {
    return "(" + shortest_number_text(p.x) + ", " + shortest_number_text(p.y) + ")";
}

std::string interval_words(double a, double b) {
    return "[" + shortest_number_text(a) + ", " + shortest_number_text(b) + "]";
}

// A domain in words: "[0, 1]^2", "[0, 1] x [0, 2]", "the disk of radius 1 centred at (0, 0)".
std::string domain_words(const Domain& d) {
    switch (d.kind) {
    case DomainKind::Box: {
        bool cube = d.lo.size() > 1;
        for (size_t j = 1; cube && j < d.lo.size(); ++j)
            cube = d.lo[j] == d.lo[0] && d.hi[j] == d.hi[0];
        if (cube) return interval_words(d.lo[0], d.hi[0]) + "^" + std::to_string(d.lo.size());
        std::string s;
        for (size_t j = 0; j < d.lo.size(); ++j)
            s += (j ? " x " : "") + interval_words(d.lo[j], d.hi[j]);
        return s;
    }
    case DomainKind::Disk:
        return "the disk of radius " + shortest_number_text(d.radius) + " centred at " +
               point_text(d.center);
    case DomainKind::Triangle:
        return "the triangle with corners " + point_text(d.v0) + ", " + point_text(d.v1) + ", " +
               point_text(d.v2);
    case DomainKind::Sphere: return "the sphere of directions";
    case DomainKind::Hemisphere: return "the upper hemisphere of directions";
    }
    return "the domain";
}

// A named warp's density in words (named_warp_infos); another name with its underscores as
// spaces.
std::string warp_words(const Warp* warp, const Domain& d) {
    const std::string name = warp ? warp->name : std::string();
    const std::string on = domain_words(d);
    if (name == "uniform" || name == "uniform_sphere" || name == "uniform_hemisphere" ||
        name == "triangle")
        return "uniform on " + on;
    if (name == "polar_disk") return "uniform on " + on + ", by the polar map";
    if (name == "concentric_disk") return "uniform on " + on + ", by the concentric map";
    if (name == "cosine_hemisphere")
        return "cosine-weighted density cos(theta) / pi on the upper hemisphere of directions";
    if (name == "tabulated_1d" || name == "tabulated_2d")
        return "piecewise-constant density from a table on " + on;
    if (name == "ggx_visible_normals")
        return "density of the GGX microfacet normals visible from a direction of view";
    if (name == "spherical_triangle") return "uniform over the solid angle of a triangle";
    if (name == "expression") return "the density of a warp given by expressions, on " + on;
    if (name == "typed") return "the density of a warp given by the caller, on " + on;
    std::string words = name.empty() ? std::string("a warp") : "the warp " + name;
    std::replace(words.begin(), words.end(), '_', ' ');
    return words + "'s density on " + on;
}

} // namespace

std::string Proposal::describe_text(const Domain& domain) const {
    switch (kind) {
    case ProposalKind::UniformBox:
    case ProposalKind::Triangle:
    case ProposalKind::Sphere:
    case ProposalKind::Hemisphere: return "uniform on " + domain_words(domain);
    case ProposalKind::DiskPolar:
        return "uniform on " + domain_words(domain) + ", by the polar map";
    case ProposalKind::DiskConcentric:
        return "uniform on " + domain_words(domain) + ", by the concentric map";
    case ProposalKind::CosineHemisphere:
        return "cosine-weighted density cos(theta) / pi on the upper hemisphere of directions";
    case ProposalKind::Product1D: {
        if (marginals.size() == 1) return marginals[0].describe_text("x");
        bool uniform = true;
        for (const Distribution1D& m : marginals)
            uniform = uniform && m.kind() == Dist1DKind::Uniform;
        if (uniform) {
            Domain box;
            box.lo.clear();
            box.hi.clear();
            for (const Distribution1D& m : marginals) {
                box.lo.push_back(m.lower());
                box.hi.push_back(m.upper());
            }
            return "uniform on " + domain_words(box);
        }
        std::string s = "a product of one density per axis: ";
        for (size_t j = 0; j < marginals.size(); ++j) {
            const std::string x = "x" + std::to_string(j + 1);
            s += (j ? "; " : "") + x + ": " + marginals[j].describe_text(x);
        }
        return s;
    }
    case ProposalKind::Tabulated2D: return table.describe_text();
    case ProposalKind::Warp: return warp_words(warp.get(), warp_domain);
    }
    return "a density on " + domain_words(domain);
}

Proposal uniform_proposal(const Domain& domain, bool disk_polar) {
    Proposal p;
    switch (domain.kind) {
    case DomainKind::Box: p.kind = ProposalKind::UniformBox; break;
    case DomainKind::Disk:
        p.kind = disk_polar ? ProposalKind::DiskPolar : ProposalKind::DiskConcentric;
        break;
    case DomainKind::Triangle: p.kind = ProposalKind::Triangle; break;
    case DomainKind::Sphere: p.kind = ProposalKind::Sphere; break;
    case DomainKind::Hemisphere: p.kind = ProposalKind::Hemisphere; break;
    }
    return p;
}

namespace {
// The same domain: kind and parameters equal.
bool same_domain(const Domain& a, const Domain& b) {
    if (a.kind != b.kind) return false;
    switch (a.kind) {
    case DomainKind::Box: return a.lo == b.lo && a.hi == b.hi;
    case DomainKind::Disk: return a.center == b.center && a.radius == b.radius;
    case DomainKind::Triangle: return a.v0 == b.v0 && a.v1 == b.v1 && a.v2 == b.v2;
    case DomainKind::Sphere:
    case DomainKind::Hemisphere: return true;
    }
    return false;
}
} // namespace

std::string check_proposal(const Proposal& p, const Domain& d) {
    auto need = [&](DomainKind k) -> std::string {
        if (d.kind == k) return "";
        return std::string("pdf '") + proposal_kind_name(p.kind) + "' samples a " +
               domain_kind_name(k) + ", the domain is a " + domain_kind_name(d.kind);
    };
    switch (p.kind) {
    case ProposalKind::UniformBox: return need(DomainKind::Box);
    case ProposalKind::DiskPolar:
    case ProposalKind::DiskConcentric: return need(DomainKind::Disk);
    case ProposalKind::Triangle: return need(DomainKind::Triangle);
    case ProposalKind::Sphere: return need(DomainKind::Sphere);
    case ProposalKind::Hemisphere:
    case ProposalKind::CosineHemisphere: return need(DomainKind::Hemisphere);
    case ProposalKind::Product1D: {
        if (auto e = need(DomainKind::Box); !e.empty()) return e;
        if (p.marginals.size() != d.lo.size())
            return "pdf has " + std::to_string(p.marginals.size()) + " factors, the box has " +
                   std::to_string(d.lo.size()) + " axes";
        for (size_t j = 0; j < d.lo.size(); ++j)
            if (p.marginals[j].lower() != d.lo[j] || p.marginals[j].upper() != d.hi[j])
                return "pdf factor " + std::to_string(j) + " does not span the box axis";
        return "";
    }
    case ProposalKind::Tabulated2D: {
        if (auto e = need(DomainKind::Box); !e.empty()) return e;
        if (d.lo.size() != 2) return "tabulated_2d needs a 2-dimensional box";
        if (p.table.x0() != d.lo[0] || p.table.x1() != d.hi[0] || p.table.y0() != d.lo[1] ||
            p.table.y1() != d.hi[1])
            return "tabulated_2d table does not span the box";
        return "";
    }
    case ProposalKind::Warp: {
        if (!p.warp || !p.warp->map || !p.warp->pdf) return "pdf 'warp' has no map or density";
        if (!same_domain(p.warp_domain, d))
            return "warp '" + p.warp->name + "' maps onto " + p.warp_domain.describe() +
                   ", the domain is " + d.describe();
        if (p.warp->sample_dim != d.sample_dim())
            return "warp '" + p.warp->name + "' reads " + std::to_string(p.warp->sample_dim) +
                   " unit-cube coordinates, the domain's samplers give " +
                   std::to_string(d.sample_dim());
        return "";
    }
    }
    return "unknown pdf";
}

void warp_block(const Proposal& p, const Domain& d, const PointBlock& u, PointBlock& x,
                double* pdf) {
    const size_t n = u.n;
    x.n = n;
    switch (p.kind) {
    case ProposalKind::UniformBox: {
        const double density = 1.0 / d.measure();
        for (size_t j = 0; j < d.lo.size(); ++j) {
            const double a = d.lo[j], w = d.hi[j] - d.lo[j];
            const double* uj = u.coord(static_cast<int>(j));
            double* xj = x.coord(static_cast<int>(j));
            for (size_t i = 0; i < n; ++i) xj[i] = a + w * uj[i];
        }
        for (size_t i = 0; i < n; ++i) pdf[i] = density;
        break;
    }
    case ProposalKind::DiskPolar:
    case ProposalKind::DiskConcentric: {
        const double density = 1.0 / d.measure();
        // One loop per map, each with the map inlined (no per-point choice of map).
        auto warp_disk = [&](auto map) {
            for (size_t i = 0; i < n; ++i) {
                const Vec2 q = map(Vec2{u.coord(0)[i], u.coord(1)[i]});
                x.coord(0)[i] = d.center.x + d.radius * q.x;
                x.coord(1)[i] = d.center.y + d.radius * q.y;
                pdf[i] = density;
            }
        };
        if (p.kind == ProposalKind::DiskPolar)
            warp_disk([](Vec2 v) { return sample_disk_polar(v); });
        else
            warp_disk([](Vec2 v) { return sample_disk_concentric(v); });
        break;
    }
    case ProposalKind::Triangle: {
        const double density = 1.0 / d.measure();
        for (size_t i = 0; i < n; ++i) {
            Vec2 b = sample_triangle_barycentric(Vec2{u.coord(0)[i], u.coord(1)[i]});
            Vec2 q = b.x * d.v0 + b.y * d.v1 + (1.0 - b.x - b.y) * d.v2;
            x.coord(0)[i] = q.x;
            x.coord(1)[i] = q.y;
            pdf[i] = density;
        }
        break;
    }
    case ProposalKind::Sphere:
    case ProposalKind::Hemisphere:
    case ProposalKind::CosineHemisphere: {
        auto warp_sphere = [&](auto map, auto density) {
            for (size_t i = 0; i < n; ++i) {
                const Vec3 w = map(Vec2{u.coord(0)[i], u.coord(1)[i]});
                x.coord(0)[i] = w.x;
                x.coord(1)[i] = w.y;
                x.coord(2)[i] = w.z;
                pdf[i] = density(w.z);
            }
        };
        if (p.kind == ProposalKind::Sphere)
            warp_sphere([](Vec2 v) { return sample_uniform_sphere(v); },
                        [](double) { return uniform_sphere_pdf(); });
        else if (p.kind == ProposalKind::Hemisphere)
            warp_sphere([](Vec2 v) { return sample_uniform_hemisphere(v); },
                        [](double) { return uniform_hemisphere_pdf(); });
        else
            warp_sphere([](Vec2 v) { return sample_cosine_hemisphere(v); },
                        [](double z) { return cosine_hemisphere_pdf(z); });
        break;
    }
    case ProposalKind::Product1D: {
        // The first axis writes the density, the others multiply theirs in.
        for (size_t j = 0; j < p.marginals.size(); ++j) {
            const int jj = static_cast<int>(j);
            if (j == 0) {
                p.marginals[0].sample_block(u.coord(0), x.coord(0), pdf, n);
            } else {
                double density[kBlockSize];
                for (size_t start = 0; start < n; start += kBlockSize) {
                    const size_t m = n - start < kBlockSize ? n - start : kBlockSize;
                    p.marginals[j].sample_block(u.coord(jj) + start, x.coord(jj) + start, density,
                                                m);
                    for (size_t i = 0; i < m; ++i) pdf[start + i] *= density[i];
                }
            }
        }
        break;
    }
    case ProposalKind::Tabulated2D:
        p.table.sample_block(u.coord(0), u.coord(1), x.coord(0), x.coord(1), pdf, n);
        break;
    case ProposalKind::Warp:
        p.warp->map(u, x);
        x.n = n;
        // A typed warp's every block is checked (a few comparisons per point beside its
        // expression's evaluation): one point outside the domain makes the study fail, as
        // warp-test does, rather than average f where it is not defined.
        if (p.warp->escape && !p.warp->escape->seen()) {
            const size_t i = first_outside(p.warp_domain, x);
            if (i < n) p.warp->escape->record(u, x, i);
        }
        p.warp->pdf(x, pdf);
        break;
    }
}

size_t first_outside(const Domain& d, const PointBlock& x) {
    constexpr double tol = kWarpDomainTolerance;
    const size_t n = x.n;
    switch (d.kind) {
    case DomainKind::Box:
        for (size_t i = 0; i < n; ++i)
            for (size_t j = 0; j < d.lo.size(); ++j) {
                const double t = (x.coord(int(j))[i] - d.lo[j]) / (d.hi[j] - d.lo[j]);
                if (!(t >= -tol && t <= 1.0 + tol)) return i;
            }
        return n;
    case DomainKind::Disk: {
        const double limit = (1.0 + tol) * (1.0 + tol) * d.radius * d.radius;
        for (size_t i = 0; i < n; ++i) {
            const double dx = x.coord(0)[i] - d.center.x, dy = x.coord(1)[i] - d.center.y;
            if (!(dx * dx + dy * dy <= limit)) return i;
        }
        return n;
    }
    case DomainKind::Triangle: {
        // Barycentrics of (x, y) in (v0, v1, v2), each >= -tol.
        const Vec2 e0 = d.v0 - d.v2, e1 = d.v1 - d.v2;
        const double inv_det = 1.0 / (e0.x * e1.y - e1.x * e0.y);
        for (size_t i = 0; i < n; ++i) {
            const double px = x.coord(0)[i] - d.v2.x, py = x.coord(1)[i] - d.v2.y;
            const double b0 = (px * e1.y - e1.x * py) * inv_det;
            const double b1 = (e0.x * py - px * e0.y) * inv_det;
            if (!(b0 >= -tol && b1 >= -tol && 1.0 - b0 - b1 >= -tol)) return i;
        }
        return n;
    }
    case DomainKind::Sphere:
    case DomainKind::Hemisphere:
        for (size_t i = 0; i < n; ++i) {
            const double a = x.coord(0)[i], b = x.coord(1)[i], z = x.coord(2)[i];
            if (!(std::fabs(a * a + b * b + z * z - 1.0) <= 2.0 * tol)) return i;
            if (d.kind == DomainKind::Hemisphere && !(z >= -tol)) return i;
        }
        return n;
    }
    return n;
}

void proposal_pdf_block(const Proposal& p, const Domain& d, const PointBlock& x, double* pdf) {
    const size_t n = x.n;
    switch (p.kind) {
    case ProposalKind::UniformBox:
    case ProposalKind::DiskPolar:
    case ProposalKind::DiskConcentric:
    case ProposalKind::Triangle:
    case ProposalKind::Sphere:
    case ProposalKind::Hemisphere: {
        // Uniform proposals: 1/measure wherever the warp can land, which is the whole domain.
        const double density = 1.0 / d.measure();
        for (size_t i = 0; i < n; ++i) pdf[i] = density;
        break;
    }
    case ProposalKind::CosineHemisphere:
        for (size_t i = 0; i < n; ++i) pdf[i] = cosine_hemisphere_pdf(x.coord(2)[i]);
        break;
    case ProposalKind::Product1D:
        for (size_t i = 0; i < n; ++i) pdf[i] = 1.0;
        for (size_t j = 0; j < p.marginals.size(); ++j)
            p.marginals[j].multiply_pdf_block(x.coord(static_cast<int>(j)), pdf, n);
        break;
    case ProposalKind::Tabulated2D:
        for (size_t i = 0; i < n; ++i) pdf[i] = p.table.pdf(x.coord(0)[i], x.coord(1)[i]);
        break;
    case ProposalKind::Warp: p.warp->pdf(x, pdf); break;
    }
}

namespace {
// A density bounded below on its domain: the uniform ones (the cosine-weighted hemisphere
// vanishes at the horizon; importance densities, warps' included, may vanish anywhere).
bool density_bounded_below(const Proposal& p) {
    return !p.importance && p.kind != ProposalKind::CosineHemisphere &&
           p.kind != ProposalKind::Product1D && p.kind != ProposalKind::Tabulated2D &&
           p.kind != ProposalKind::Warp;
}
} // namespace

bool weights_bounded(const Problem& problem, const EstimatorSpec& spec) {
    if (!integrand_bounded(problem.integrand) || !spec.control_variate_options.variates.empty())
        return false;
    for (const Proposal* p : proposals_of(spec))
        if (density_bounded_below(*p)) return true; // MIS: the mixture is at least c_k p_k
    return false;
}

bool variance_follows_integrand(const EstimatorSpec& spec) {
    if (spec.has_techniques() || !spec.control_variate_options.variates.empty()) return false;
    const std::string kind = kind_of(spec).name;
    const bool kept = kind == "fixed" || kind == "vegas" || kind == "vegas_plus" || kind == "miser";
    return kept && density_bounded_below(spec.proposal); // uniform: bounded above too
}

std::vector<const Proposal*> proposals_of(const EstimatorSpec& spec) {
    std::vector<const Proposal*> out;
    if (!spec.has_techniques()) {
        // RIS with a pdf as its target keeps points only where the target is positive.
        out.push_back(spec.ris_options.target_pdf ? &spec.ris_options.target : &spec.proposal);
        return out;
    }
    for (const Proposal& p : spec.mis_options.proposals) out.push_back(&p);
    return out;
}

void sampling_density_block(const EstimatorSpec& spec, const Domain& domain, const PointBlock& x,
                            double* pdf) {
    if (!spec.has_techniques()) {
        proposal_pdf_block(*proposals_of(spec)[0], domain, x, pdf);
        return;
    }
    std::vector<double> one(x.n);
    std::fill(pdf, pdf + x.n, 0.0);
    const MisOptions& m = spec.mis_options;
    for (size_t k = 0; k < m.proposals.size(); ++k) {
        proposal_pdf_block(m.proposals[k], domain, x, one.data());
        for (size_t i = 0; i < x.n; ++i) pdf[i] += m.fractions[k] * one[i];
    }
}

std::string describe_sampling_text(const EstimatorSpec& spec, const Domain& domain) {
    std::string s;
    if (!spec.has_techniques()) {
        s = spec.proposal.describe_text(domain);
    } else {
        const MisOptions& m = spec.mis_options;
        s = "a mixture of " + std::to_string(m.proposals.size()) +
            " densities (multiple importance sampling, " +
            (m.optimal ? std::string("optimal weights")
                       : std::string(mis_heuristic_name(m.weighting.heuristic)) + " heuristic") +
            (m.one_sample ? ", each point from one density drawn at random" : "") + "): ";
        for (size_t k = 0; k < m.proposals.size(); ++k) {
            char share[32];
            std::snprintf(share, sizeof share, "%.3g%% from (", 100.0 * m.fractions[k]);
            s += (k ? "; " : "") + std::string(share) + m.proposals[k].describe_text(domain) + ")";
        }
    }
    // The adaptive kinds reshape it during a run.
    const std::string kind = spec.kind ? spec.kind->name : "";
    if (kind == "vegas" || kind == "vegas_plus")
        s += ", reshaped by the VEGAS map the run learns";
    else if (kind == "miser")
        s += ", within the boxes MISER's recursive bisection makes";
    else if (kind == "ris")
        s += ": " + std::to_string(spec.ris_options.candidates) +
             " candidates per point, one kept with probability proportional to g / p, where g "
             "is " +
             (spec.ris_options.target_pdf ? "the " + spec.ris_options.target.describe_text(domain)
                                          : std::string("|f|"));
    return s;
}

std::string describe_sampling(const EstimatorSpec& spec) {
    if (!spec.has_techniques()) return spec.proposal.describe();
    const MisOptions& m = spec.mis_options;
    std::string s = std::string("mis(") +
                    (m.optimal ? "optimal" : mis_heuristic_name(m.weighting.heuristic)) +
                    (m.one_sample ? ", one-sample" : "") + ": ";
    for (size_t k = 0; k < m.proposals.size(); ++k) {
        char share[32];
        std::snprintf(share, sizeof share, " %.3g", m.fractions[k]);
        s += (k ? ", " : "") + m.proposals[k].describe() + share;
    }
    return s + ")";
}

} // namespace mcp
