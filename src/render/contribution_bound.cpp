// Bounded per-sample contributions of the render estimators (contribution_bound.h); the
// derivation is in docs/render-scenes.md, "Bounded contributions".
#include "render/contribution_bound.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace mcp {

namespace {

using Triangle = std::array<Vec3, 3>;

double point_segment_distance(const Vec3& x, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(x - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(x - (a + ab * t));
}

/// min |a + s (b - a) - c - t (d - c)| over s, t in [0, 1]: a convex quadratic, so the minimum
/// is its critical point when that lies in the square, else on the square's edges (an endpoint
/// against the other segment).
double segment_distance(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    double best = std::min({point_segment_distance(a, c, d), point_segment_distance(b, c, d),
                            point_segment_distance(c, a, b), point_segment_distance(d, a, b)});
    const Vec3 u = b - a, v = d - c, w = a - c;
    const double A = glm::dot(u, u), B = glm::dot(u, v), C = glm::dot(v, v);
    const double D = glm::dot(u, w), E = glm::dot(v, w), den = A * C - B * B;
    if (den > 1e-12 * A * C) {
        const double s = (B * E - C * D) / den, t = (A * E - B * D) / den;
        if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0)
            best = std::min(best, glm::length(w + u * s - v * t));
    }
    return best;
}

/// Whether x's projection on the triangle's plane has every barycentric coordinate >= margin.
bool projects_inside(const Vec3& x, const Triangle& t, double margin) {
    const Vec3 n = glm::cross(t[1] - t[0], t[2] - t[0]);
    const double n2 = glm::dot(n, n);
    if (!(n2 > 0.0)) return false;
    for (int k = 0; k < 3; ++k) {
        const Vec3& p = t[(k + 1) % 3];
        const Vec3& q = t[(k + 2) % 3];
        if (glm::dot(glm::cross(q - p, x - p), n) / n2 < margin) return false;
    }
    return true;
}

double point_triangle_distance(const Vec3& x, const Triangle& t) {
    const Vec3 n = glm::normalize(glm::cross(t[1] - t[0], t[2] - t[0]));
    if (projects_inside(x, t, 0.0)) return std::fabs(glm::dot(x - t[0], n));
    return std::min({point_segment_distance(x, t[0], t[1]), point_segment_distance(x, t[1], t[2]),
                     point_segment_distance(x, t[2], t[0])});
}

/// Where the segment a b crosses the triangle's plane strictly (its ends more than `tol` on
/// either side), if it does.
bool crosses_plane(const Vec3& a, const Vec3& b, const Triangle& t, double tol, Vec3* x) {
    const Vec3 n = glm::normalize(glm::cross(t[1] - t[0], t[2] - t[0]));
    const double sa = glm::dot(a - t[0], n), sb = glm::dot(b - t[0], n);
    if (!((sa > tol && sb < -tol) || (sa < -tol && sb > tol))) return false;
    *x = a + (b - a) * (sa / (sa - sb));
    return true;
}

/// A barycentric margin that keeps a contact point off the light's edges.
constexpr double kInteriorMargin = 1e-6;

struct PairContact {
    bool contact = false, interior = false;
};

/// Contact of a receiver triangle r with a light triangle l (neither degenerate): within `tol`
/// of each other, and whether within `tight` (the rounding of vertices) of the light's inside.
/// Their distance is 0 where an edge of one crosses the other, else that of a vertex of one
/// from the other or of two edges (the closest points of two convex polygons).
PairContact triangle_contact(const Triangle& l, const Triangle& r, double tol, double tight) {
    PairContact c;
    const Vec3 nl = glm::normalize(glm::cross(l[1] - l[0], l[2] - l[0]));
    const Vec3 nr = glm::normalize(glm::cross(r[1] - r[0], r[2] - r[0]));
    // A surface in the light's plane: cos theta' = 0 at every receiving point, nothing arrives.
    const bool in_plane = std::all_of(r.begin(), r.end(), [&](const Vec3& v) {
        return std::fabs(glm::dot(v - l[0], nl)) <= tight;
    });
    if (in_plane && glm::length(glm::cross(nl, nr)) <= kCoplanarSine) return c;
    double d = std::numeric_limits<double>::infinity();
    for (const Vec3& v : r) {
        const double dv = point_triangle_distance(v, l);
        d = std::min(d, dv);
        if (dv <= tight && projects_inside(v, l, kInteriorMargin)) c.interior = true;
    }
    int light_vertices_on = 0;
    for (const Vec3& v : l) {
        const double dv = point_triangle_distance(v, r);
        d = std::min(d, dv);
        light_vertices_on += dv <= tight;
    }
    int light_edges_through = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3 &a = r[i], &b = r[(i + 1) % 3];
        const Vec3 &p = l[i], &q = l[(i + 1) % 3];
        for (int j = 0; j < 3; ++j) d = std::min(d, segment_distance(a, b, l[j], l[(j + 1) % 3]));
        Vec3 x;
        if (crosses_plane(a, b, l, tight, &x) && projects_inside(x, l, 0.0)) {
            d = 0.0;
            if (projects_inside(x, l, kInteriorMargin)) c.interior = true;
        }
        if (crosses_plane(p, q, r, tight, &x) && projects_inside(x, r, 0.0)) {
            d = 0.0;
            ++light_edges_through;
        }
    }
    // Two edges of the light through the receiver (their chord crosses the light's inside), or
    // the light's face lying on the receiver's.
    if (light_edges_through >= 2 || light_vertices_on == 3) c.interior = true;
    c.contact = d <= tol;
    return c;
}

Triangle triangle_of(const Mesh& mesh, size_t t) {
    return {mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2)};
}

bool degenerate(const Triangle& t) {
    const double a = glm::length(glm::cross(t[1] - t[0], t[2] - t[0]));
    return !(a > 0.0) || !std::isfinite(a);
}

} // namespace

LightContacts light_contacts(const RenderScene& rs) {
    LightContacts out;
    const Mesh& mesh = rs.scene->mesh;
    const LightSet& lights = rs.lights_uniform;
    Vec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    for (const Vec3& p : mesh.position) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const double extent = glm::length(hi - lo);
    const double tol = kContactDistance * extent, tight = kPlaneDistance * extent;
    std::vector<size_t> light_triangles;
    for (size_t t = 0; t < mesh.triangle_count(); ++t)
        if (lights.light_index(uint32_t(t)) >= 0) light_triangles.push_back(t);
    // Boxes first (each light's widened by tol), the exact test where they overlap.
    struct Box {
        Vec3 lo, hi;
    };
    auto box_of = [&](size_t t, double widen) {
        const Triangle tri = triangle_of(mesh, t);
        Box b{glm::min(tri[0], glm::min(tri[1], tri[2])),
              glm::max(tri[0], glm::max(tri[1], tri[2]))};
        b.lo -= Vec3(widen);
        b.hi += Vec3(widen);
        return b;
    };
    auto overlap = [](const Box& a, const Box& b) {
        return !(a.lo.x > b.hi.x || a.lo.y > b.hi.y || a.lo.z > b.hi.z || a.hi.x < b.lo.x ||
                 a.hi.y < b.lo.y || a.hi.z < b.lo.z);
    };
    // The triangles near some light (one pass over the scene), then each light against them.
    Box near_lights{Vec3(std::numeric_limits<double>::infinity()),
                    Vec3(-std::numeric_limits<double>::infinity())};
    for (size_t l : light_triangles) {
        const Box b = box_of(l, tol);
        near_lights.lo = glm::min(near_lights.lo, b.lo);
        near_lights.hi = glm::max(near_lights.hi, b.hi);
    }
    std::vector<size_t> near;
    for (size_t t = 0; t < mesh.triangle_count() && !light_triangles.empty(); ++t)
        if (overlap(box_of(t, 0.0), near_lights)) near.push_back(t);
    if (light_triangles.size() * near.size() > kMaxContactBoxTests) return out; // not checked
    std::vector<std::pair<size_t, size_t>> candidates;
    for (size_t l : light_triangles) {
        const Box bl = box_of(l, tol);
        for (size_t t : near) {
            if (t == l || !overlap(box_of(t, 0.0), bl)) continue;
            if (candidates.size() >= kMaxContactPairs) return out; // not checked
            candidates.emplace_back(l, t);
        }
    }
    out.checked = true;
    out.pairs = candidates.size();
    for (const auto& [l, t] : candidates) {
        const Triangle tl = triangle_of(mesh, l), tr = triangle_of(mesh, t);
        if (degenerate(tl) || degenerate(tr)) continue;
        const PairContact c = triangle_contact(tl, tr, tol, tight);
        out.contact = out.contact || c.contact;
        out.interior_contact = out.interior_contact || c.interior;
    }
    return out;
}

ContributionBound contribution_bound(const RenderEstimator& e, const LightContacts& contacts) {
    // The bounds of docs/render-scenes.md, "Bounded contributions", with Le the largest
    // emission (finite: the loader refuses more than 3.4e38).
    switch (e.strategy) {
    case RadianceStrategy::UniformHemisphere:
    case RadianceStrategy::CosineHemisphere:
        return {true, "f cos / p <= 2 pi max f cos, and f is bounded (alpha >= 1e-3)"};
    case RadianceStrategy::Bsdf:
        return {true, "f cos / p <= 1/q_spec + 1/q_diff <= 21.05 (lobe choice clamped to "
                      "[0.05, 0.95])"};
    case RadianceStrategy::MisBalance:
    case RadianceStrategy::MisPower:
        return {true, "multiple importance sampling with BSDF sampling, whose f cos / p is "
                      "bounded: each weighted term is at most f cos / p_bsdf"};
    case RadianceStrategy::Path:
        return {true, "at most max_depth bounces, each a bounded BSDF weight (Russian roulette "
                      "divides by at least min(0.95, the throughput)) and a bounded "
                      "multiple-importance term"};
    case RadianceStrategy::LightSolidAngle:
        if (!contacts.checked) return {false, "too many light-surface pairs to check contacts"};
        if (contacts.interior_contact)
            return {false, "a surface touches a light inside its edges, where solid-angle "
                           "sampling falls back to area sampling"};
        return {true, "f cos Le / p <= f cos Le (solid angle) / P(light), the solid angle at "
                      "most 2 pi"};
    case RadianceStrategy::LightArea:
        if (!contacts.checked) return {false, "too many light-surface pairs to check contacts"};
        if (contacts.contact)
            return {false, "a light touches a surface it lights: cos cos' / r^2 is unbounded "
                           "at the contact"};
        return {true, "every light is away from the surfaces: cos cos' / r^2 <= 1 / d^2 for "
                      "d the smallest distance"};
    }
    return {false, "unknown strategy"};
}

} // namespace mcp
