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
    bool touching = false; ///< within `tight`: the two meet
    Vec3 point{0.0};       ///< a point where they meet (the mean of those found)
};

/// Contact of a receiver triangle r with a light triangle l (neither degenerate): within `tol`
/// of each other, and whether within `tight` (the rounding of vertices) of the light's inside.
/// Their distance is 0 where an edge of one crosses the other, else that of a vertex of one
/// from the other or of two edges (the closest points of two convex polygons). Where they
/// meet, `point` is the mean of the meeting points found (vertices on the other triangle,
/// edges through it): inside the convex set where they meet.
PairContact triangle_contact(const Triangle& l, const Triangle& r, double tol, double tight) {
    PairContact c;
    const Vec3 nl = glm::normalize(glm::cross(l[1] - l[0], l[2] - l[0]));
    const Vec3 nr = glm::normalize(glm::cross(r[1] - r[0], r[2] - r[0]));
    // A surface in the light's plane: cos theta' = 0 at every receiving point, nothing arrives.
    const bool in_plane = std::all_of(r.begin(), r.end(), [&](const Vec3& v) {
        return std::fabs(glm::dot(v - l[0], nl)) <= tight;
    });
    if (in_plane && glm::length(glm::cross(nl, nr)) <= kCoplanarSine) return c;
    Vec3 met(0.0);
    int meetings = 0;
    auto meet = [&](const Vec3& x) {
        met += x;
        ++meetings;
    };
    double d = std::numeric_limits<double>::infinity();
    for (const Vec3& v : r) {
        const double dv = point_triangle_distance(v, l);
        d = std::min(d, dv);
        if (dv <= tight) meet(v);
        if (dv <= tight && projects_inside(v, l, kInteriorMargin)) c.interior = true;
    }
    int light_vertices_on = 0;
    for (const Vec3& v : l) {
        const double dv = point_triangle_distance(v, r);
        d = std::min(d, dv);
        light_vertices_on += dv <= tight;
        if (dv <= tight) meet(v);
    }
    int light_edges_through = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3 &a = r[i], &b = r[(i + 1) % 3];
        const Vec3 &p = l[i], &q = l[(i + 1) % 3];
        for (int j = 0; j < 3; ++j) d = std::min(d, segment_distance(a, b, l[j], l[(j + 1) % 3]));
        Vec3 x;
        if (crosses_plane(a, b, l, tight, &x) && projects_inside(x, l, 0.0)) {
            d = 0.0;
            meet(x);
            if (projects_inside(x, l, kInteriorMargin)) c.interior = true;
        }
        if (crosses_plane(p, q, r, tight, &x) && projects_inside(x, r, 0.0)) {
            d = 0.0;
            meet(x);
            ++light_edges_through;
        }
    }
    // Two edges of the light through the receiver (their chord crosses the light's inside), or
    // the light's face lying on the receiver's.
    if (light_edges_through >= 2 || light_vertices_on == 3) c.interior = true;
    c.contact = d <= tol;
    c.touching = d <= tight && meetings > 0;
    if (c.touching) c.point = met / double(meetings);
    return c;
}

/// The camera's view: the pyramid of the image's rays (jittered rays stay inside it).
struct View {
    Vec3 eye, right, up, forward;
    double tx = 0.0, ty = 0.0; ///< tan of the half-angles across and up

    View(const Camera& c, double aspect)
        : eye(c.position), right(c.right), up(c.up), forward(c.forward),
          tx(std::tan(0.5 * c.yfov) * aspect), ty(std::tan(0.5 * c.yfov)) {}

    /// The bounding planes' outward functions at x (inside: every one <= 0).
    std::array<double, 5> sides(const Vec3& x) const {
        const Vec3 v = x - eye;
        const double z = glm::dot(v, forward), h = glm::dot(v, right), u = glm::dot(v, up);
        return {h - tx * z, -h - tx * z, u - ty * z, -u - ty * z, -z};
    }
    bool sees_point(const Vec3& x) const {
        const auto s = sides(x);
        return std::all_of(s.begin(), s.end(), [](double g) { return g < 0.0; });
    }
    /// false only when the box lies outside one bounding plane (then no ray meets it).
    bool may_see_box(const Vec3& lo, const Vec3& hi) const {
        std::array<bool, 5> outside;
        outside.fill(true);
        for (int k = 0; k < 8; ++k) {
            const Vec3 x(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
            const auto s = sides(x);
            for (size_t i = 0; i < 5; ++i) outside[i] = outside[i] && s[i] > 0.0;
        }
        return std::none_of(outside.begin(), outside.end(), [](bool o) { return o; });
    }
};

/// Whether a surface reflects anything: glTF's BRDF is zero only for a black base colour with
/// metallic 0 and specular factor 0 (f0 = 0.04 s, f90 = s, c_diff = base).
bool reflects(const Material& m) {
    const bool black = m.base_color.x <= 0.0 && m.base_color.y <= 0.0 && m.base_color.z <= 0.0;
    return !(black && m.metallic <= 0.0 && m.specular <= 0.0);
}

Triangle triangle_of(const Mesh& mesh, size_t t) {
    return {mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2)};
}

bool degenerate(const Triangle& t) {
    const double a = glm::length(glm::cross(t[1] - t[0], t[2] - t[0]));
    return !(a > 0.0) || !std::isfinite(a);
}

/// Whether the light l and the receiver t, touching at x, face each other there (the light
/// emits towards the receiver's side near x, and the receiver faces the light from the
/// camera's side) and camera rays reach the receiver 1e-3 and 1e-6 of the extent from x,
/// towards its inside: the pixels there see points arbitrarily close to the contact.
bool seen_touching(const RenderScene& rs, const View& view, const Triangle& tl, const Triangle& tr,
                   size_t l, size_t t, const Vec3& x, double extent) {
    const Vec3 cl = (tl[0] + tl[1] + tl[2]) / 3.0, cr = (tr[0] + tr[1] + tr[2]) / 3.0;
    if (!(glm::length(cl - x) > 0.0) || !(glm::length(cr - x) > 0.0)) return false;
    const Vec3 to_r = glm::normalize(cr - x), to_l = glm::normalize(cl - x);
    const Vec3 nl = glm::normalize(glm::cross(tl[1] - tl[0], tl[2] - tl[0]));
    const Vec3 nr = glm::normalize(glm::cross(tr[1] - tr[0], tr[2] - tr[0]));
    const Mesh& mesh = rs.scene->mesh;
    const bool two_sided = rs.scene->materials[mesh.material[l]].double_sided;
    const double emits = glm::dot(to_r, nl), eye_side = glm::dot(view.eye - x, nr);
    const double light_side = glm::dot(to_l, nr);
    if (!(std::fabs(emits) > kCoplanarSine) || (!two_sided && emits < 0.0)) return false;
    if (!(std::fabs(light_side) > kCoplanarSine) || eye_side * light_side <= 0.0) return false;
    for (double step : {1e-3, 1e-6}) {
        const Vec3 q = x + to_r * (step * extent);
        if (!view.sees_point(q)) return false;
        Ray ray;
        ray.origin = view.eye;
        ray.direction = glm::normalize(q - view.eye);
        Hit hit;
        if (!rs.accel.intersect(ray, &hit) || hit.triangle != t) return false;
    }
    return true;
}

} // namespace

LightContacts light_contacts(const RenderScene& rs, double aspect) {
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
    const View view(rs.scene->camera, aspect);
    size_t seen_checks = 0;
    for (const auto& [l, t] : candidates) {
        const Triangle tl = triangle_of(mesh, l), tr = triangle_of(mesh, t);
        if (degenerate(tl) || degenerate(tr)) continue;
        const PairContact c = triangle_contact(tl, tr, tol, tight);
        if (!c.contact) continue;
        // The receiver's points within tol of the light lie in this box: out of view, the
        // surfaces the camera sees keep a distance from this light.
        const Box near_light = box_of(l, tol), receiver = box_of(t, 0.0);
        const Vec3 box_lo = glm::max(near_light.lo, receiver.lo);
        const Vec3 box_hi = glm::min(near_light.hi, receiver.hi);
        if (!reflects(rs.scene->materials[mesh.material[t]]) || !view.may_see_box(box_lo, box_hi)) {
            ++out.ignored;
            continue;
        }
        out.contact = true;
        out.interior_contact = out.interior_contact || c.interior;
        if (c.touching && !out.seen_contact && seen_checks < kMaxSeenChecks) {
            ++seen_checks;
            out.seen_contact = seen_touching(rs, view, tl, tr, l, t, c.point, extent);
        }
    }
    return out;
}

ContributionBound contribution_bound(const RenderEstimator& e, const LightContacts& contacts) {
    // The bounds of docs/render-scenes.md, "Bounded contributions", with Le the largest
    // emission (finite: the loader refuses more than 3.4e38).
    const ContributionBound unchecked{false, false,
                                      "too many light-surface pairs to check contacts"};
    const bool nee_strategy = e.strategy == RadianceStrategy::MisBalance ||
                              e.strategy == RadianceStrategy::MisPower ||
                              e.strategy == RadianceStrategy::Path;
    if (nee_strategy && e.candidates != 1) {
        // The MIS weight is taken at the kept candidate, while the mean of the weights may be
        // ruled by another: bounded where resampled light sampling (ris) is.
        RenderEstimator ris = e;
        ris.strategy = RadianceStrategy::Ris;
        ContributionBound b = contribution_bound(ris, contacts);
        b.reason = "the light sample resampled from candidates (MIS weight at the kept one, "
                   "not at the candidate that rules the weights' mean): " +
                   b.reason;
        return b;
    }
    switch (e.strategy) {
    case RadianceStrategy::UniformHemisphere:
    case RadianceStrategy::CosineHemisphere:
        return {true, false, "f cos / p <= 2 pi max f cos, and f is bounded (alpha >= 1e-3)"};
    case RadianceStrategy::Bsdf:
        return {true, false,
                "f cos / p <= 1/q_spec + 1/q_diff <= 21.05 (lobe choice clamped to [0.05, 0.95])"};
    case RadianceStrategy::MisBalance:
    case RadianceStrategy::MisPower:
        return {true, false,
                "multiple importance sampling with BSDF sampling, whose f cos / p is bounded: "
                "each weighted term is at most f cos / p_bsdf"};
    case RadianceStrategy::Path:
        return {true, false,
                "at most max_depth bounces, each a bounded BSDF weight (Russian roulette divides "
                "by at least min(0.95, the throughput)) and a bounded multiple-importance term"};
    case RadianceStrategy::LightSolidAngle:
        if (!contacts.checked) return unchecked;
        if (contacts.interior_contact)
            return {false, false,
                    "a surface touches a light inside its edges, where solid-angle sampling "
                    "falls back to area sampling"};
        return {true, false,
                "f cos Le / p <= f cos Le (solid angle) / P(light), the solid angle at most 2 pi"};
    case RadianceStrategy::LightArea:
        if (!contacts.checked) return unchecked;
        if (contacts.seen_contact)
            return {false, true,
                    "a light touches a surface it lights where the camera sees: at distance a "
                    "from the contact the second moment of cos cos' / r^2 grows as 1 / a^2, "
                    "whose integral over the pixel diverges"};
        if (contacts.contact)
            return {false, false,
                    "a light comes within 1e-4 of the scene's extent of a surface it lights, in "
                    "the camera's view, though not seen touching it face to face: "
                    "cos cos' / r^2 is not known to be bounded there"};
        return {true, false,
                contacts.ignored > 0
                    ? "the lights touch only surfaces that reflect nothing or that the camera "
                      "does not see there: cos cos' / r^2 <= 1 / d^2 on the surfaces seen, for "
                      "d their smallest distance from a light"
                    : "every light is away from the surfaces: cos cos' / r^2 <= 1 / d^2 for "
                      "d the smallest distance"};
    case RadianceStrategy::Ris: {
        // f Le cos V / target(y) * (1/M) sum_j w_j: the first factor is at most
        // max_c(rgb_c) / lum(rgb) <= 1 / 0.0722 per channel, the mean at most the largest
        // w_j = lum(f Le cos) / p, light sampling's weight. Bounded exactly where that is.
        RenderEstimator light = e;
        const bool area = e.light_sampling == LightSampling::Area;
        light.strategy = area ? RadianceStrategy::LightArea : RadianceStrategy::LightSolidAngle;
        ContributionBound b = contribution_bound(light, contacts);
        b.reason = "resampled light samples: f Le cos / target <= 1 / 0.0722 times the mean "
                   "of light sampling's weights, so bounded where light sampling is: " +
                   b.reason;
        return b;
    }
    }
    return {false, false, "unknown strategy"};
}

} // namespace mcp
