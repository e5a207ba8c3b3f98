// Area lights: selection tables, area sampling, spherical-triangle sampling [Arvo95] and
// Lambert's polygon form factor [Lambert1760].
#include "render/lights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/points.h"  // u63_to_double
#include "core/special.h" // kPi
#include "core/trig.h"

namespace mcp {

namespace {

/// The spherical triangle of a mesh triangle seen from a reference point, set up for Arvo's
/// map. Everything is derived from the vectors a, b, c from the reference point to the
/// vertices and the edges e1 = p1 - p0, e2 = p2 - p0 taken from the world-space vertices, so
/// that small or distant triangles keep their relative accuracy: the plane normals of the
/// arcs are a x e1 (= a x b) and a x e2 (= a x c), the triple product is a . (e1 x e2), and
/// angles come from atan2 of such products rather than from differences of unit vectors.
/// Filled by fill_spherical and read only after it: no default values, whose zeroing (a
/// memset call in wasm) cost 2% of a light-sampling render there.
struct SphericalTriangle {
    Vec3 A, B;       ///< unit directions to vertices 0 and 1
    Vec3 tangent_ac; ///< unit tangent at A of the arc towards C
    /// Sine and cosine of the interior angle alpha at A, or of pi minus it when obtuse (kept
    /// accurate near pi).
    double sin_alpha, cos_alpha;
    bool obtuse;
    double sin_half_c, cos_half_c; ///< of half the arc length AB
    double sin_half_b, cos_half_b; ///< of half the arc length AC
    double sin_b, cos_b;           ///< of the arc length AC
    double omega;                  ///< solid angle
};

/// The vertex vectors' lengths |a|, |b|, |c|.
struct VertexLengths {
    double a, b, c;
};
VertexLengths vertex_lengths(const Vec3& a, const Vec3& b, const Vec3& c) {
    return {glm::length(a), glm::length(b), glm::length(c)};
}

/// Solid angle of the triangle (a, b, c) seen from the origin, with det = a . (b x c) and
/// the lengths computed by the caller: tan(Omega / 2) = |det| / (|a||b||c| + (a.b)|c| + (a.c)|b| +
/// (b.c)|a|) [VanOosteromStrackee83]. atan2 keeps the branch right past Omega = pi, where the
/// denominator turns negative.
double solid_angle(const Vec3& a, const Vec3& b, const Vec3& c, double det,
                   const VertexLengths& len) {
    const double la = len.a, lb = len.b, lc = len.c;
    double denom = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
    return 2.0 * std::atan2(std::fabs(det), denom);
}

/// Solid angles outside [kMinSphericalSolidAngle, kMaxSphericalSolidAngle] (and reference
/// points on the triangle's plane) are sampled by area instead; see lights.h for why.
bool spherical_applies(double det, double omega) {
    return det != 0.0 && omega >= kMinSphericalSolidAngle && omega <= kMaxSphericalSolidAngle;
}

/// (s, c) / |(s, c)| for s, c >= 0: the sine and cosine of the angle atan2(s, c), (0, 1) when
/// both are 0. Scaled by the larger first, so that the squares neither overflow nor underflow
/// (hypot's guarantee without its cost: one division, one square root and one more division).
inline void unit_pair(double s, double c, double* sin_out, double* cos_out) {
    const double m = fmax_inline(s, c);
    if (!(m > 0.0)) {
        *sin_out = 0.0;
        *cos_out = 1.0;
        return;
    }
    const double inv_m = 1.0 / m;
    const double a = s * inv_m, b = c * inv_m; // the larger is 1 to an ulp
    const double inv_r = 1.0 / std::sqrt(a * a + b * b);
    *sin_out = a * inv_r;
    *cos_out = b * inv_r;
}

/// Sin and cos of half the angle between a and b, from |a x b| (computed accurately by the
/// caller) and a . b, without the cancellation of |a||b| + a.b near antipodal directions:
/// tan(c/2) = |a x b| / (|a||b| + a.b) = (|a||b| - a.b) / |a x b|.
void half_angle(double cross_len, double dot_ab, double len_ab, double* sin_half,
                double* cos_half) {
    double s = dot_ab >= 0.0 ? cross_len : len_ab - dot_ab;
    double c = dot_ab >= 0.0 ? len_ab + dot_ab : cross_len;
    unit_pair(s, c, sin_half, cos_half);
}

/// Fills the map's parameters of the triangle with vertex vectors a, b, c, edges e1 = b - a,
/// e2 = c - a and triple product det = a . (e1 x e2), det != 0.
void fill_spherical(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& e1, const Vec3& e2,
                    double det, const VertexLengths& len, SphericalTriangle* st) {
    Vec3 n_ab = glm::cross(a, e1); // normal of the great circle through A and B
    Vec3 n_ac = glm::cross(a, e2); // ... through A and C
    const double la = len.a, lb = len.b;
    // The angle at A is the angle between the two arc planes; |n_ab x n_ac| = |a| |det|
    // since (a x e1) x (a x e2) = (a . (e1 x e2)) a. Near pi its supplement is kept instead.
    double cos_term = glm::dot(n_ab, n_ac);
    st->obtuse = cos_term < 0.0;
    unit_pair(la * std::fabs(det), std::fabs(cos_term), &st->sin_alpha, &st->cos_alpha);
    half_angle(glm::length(n_ab), glm::dot(a, b), la * lb, &st->sin_half_c, &st->cos_half_c);
    half_angle(glm::length(n_ac), glm::dot(a, c), la * len.c, &st->sin_half_b, &st->cos_half_b);
    st->sin_b = 2.0 * st->sin_half_b * st->cos_half_b;
    st->cos_b = (st->cos_half_b - st->sin_half_b) * (st->cos_half_b + st->sin_half_b);
    st->A = a / la;
    st->B = b / lb;
    st->tangent_ac = glm::normalize(glm::cross(n_ac, st->A)); // (A x C) x A = C - (A.C) A
}

/// Sets up the spherical triangle (cross_normal = e1 x e2); st->omega is always set, the rest
/// only when the triangle is in the spherical regime (return value true).
bool setup_spherical(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& e1, const Vec3& e2,
                     const Vec3& cross_normal, SphericalTriangle* st) {
    double det = glm::dot(a, cross_normal);
    const VertexLengths len = vertex_lengths(a, b, c); // shared by both
    st->omega = solid_angle(a, b, c, det, len);
    if (!spherical_applies(det, st->omega)) return false;
    fill_spherical(a, b, c, e1, e2, det, len, st);
    return true;
}

/// Arvo's area-preserving map from the unit square to the spherical triangle [Arvo95]:
/// u1 picks the sub-triangle A B C' of area u1 Omega (C' on the arc AC), u2 a point on the
/// arc B C' with 1 - cos(theta) uniform. Arvo's closed form for cos |AC'| is rewritten here
/// as
///   tan(|AC'| / 2) = cos(c/2) sin(A'/2) / (sin(c/2) sin(alpha - A'/2)),  A' = u1 Omega,
/// (our derivation: with phi = A' - alpha, Arvo's law-of-cosines step gives the angle beta'
/// of the sub-triangle at B as (sin beta', cos beta') ~ (u, -v), u = cos phi - cos alpha =
/// 2 sin(A'/2) sin(alpha - A'/2), v = sin phi + sin alpha cos c; the four-part formula
/// sin c cot|AC'| = cos c cos alpha + sin alpha cot beta' then simplifies by half-angle
/// identities to tan of a double angle). Its factors are all well conditioned: no
/// cancellation for small sub-triangles and no sqrt(1 - q^2) near q = 1. Likewise the second step,
/// 1 - cos(theta) = u2 (1 - cos |BC'|), is solved as tan(theta/2) = sqrt(u2) s / sqrt((1 - u2) s^2
/// + k^2) with s = |C' - B| / 2 and k = |C' + B| / 2 the sine and cosine of |BC'| / 2.
Vec3 sample_spherical(const SphericalTriangle& st, const Vec2& u) {
    // A'/2 = u1 Omega / 2 in [0, pi], in turns for sincos_turns.
    const SinCos h = sincos_turns(u.x * st.omega * (0.25 / kPi));
    // sin(alpha - A'/2) by the difference formula (for an obtuse angle, stored as pi - alpha,
    // sin(pi - alpha + A'/2) by the sum), clamped at 0 where A'/2 passes alpha: a sub-triangle
    // fits in its lune, and past it the sine turns negative.
    const double sin_rest =
        fmax_inline(0.0, st.obtuse ? st.sin_alpha * h.cos + st.cos_alpha * h.sin
                                   : st.sin_alpha * h.cos - st.cos_alpha * h.sin);
    double num = st.cos_half_c * h.sin;
    double den = st.sin_half_c * sin_rest;
    // |AC'| = 2 atan2(num, den) (num >= 0), clamped to |AC|. Its cosine and sine follow from
    // the half angle's by cos 2x = (d^2 - n^2) / (d^2 + n^2), sin 2x = 2 n d / (d^2 + n^2),
    // and the clamp compares the half angles by a cross product: no trigonometric call.
    double cos_arc = st.cos_b, sin_arc = st.sin_b;
    if (num * st.cos_half_b - den * st.sin_half_b < 0.0) { // |AC'| / 2 < |AC| / 2
        const double m = fmax_inline(num, std::fabs(den));
        const double n = m > 0.0 ? num / m : 0.0, d = m > 0.0 ? den / m : 1.0;
        const double r2 = n * n + d * d;
        cos_arc = (d - n) * (d + n) / r2;
        sin_arc = 2.0 * n * d / r2;
    }
    Vec3 c_hat = st.A * cos_arc + st.tangent_ac * sin_arc;
    double s = 0.5 * glm::length(c_hat - st.B), k = 0.5 * glm::length(c_hat + st.B);
    // theta = 2 atan2(y, x), y = sqrt(u2) s, x = sqrt((1 - u2) s^2 + k^2): again by the
    // half-angle formulas, with x^2 + y^2 = s^2 + k^2.
    const double x2 = (1.0 - u.y) * s * s + k * k, y2 = u.y * s * s, r2 = x2 + y2;
    if (!(r2 > 0.0)) return st.B;
    const double cos_theta = (x2 - y2) / r2;
    const double sin_theta = 2.0 * std::sqrt(x2 * y2) / r2;
    Vec3 t = c_hat - st.B * glm::dot(c_hat, st.B);
    double lt = glm::length(t);
    if (!(lt > 0.0)) return st.B;
    return st.B * cos_theta + t * (sin_theta / lt);
}

/// Solid-angle density of a uniform area sample at `point` seen from ref, per unit (1/A)
/// area density: d^2 / (A |cos theta_light|) = 2 d^3 / |N . (point - ref)| with N the
/// unnormalised cross normal (|N| = 2 A). 0 when the point is at ref or seen edge-on.
double area_to_solid_angle(const Vec3& ref, const Vec3& point, const Vec3& cross_normal) {
    Vec3 w = point - ref;
    double d2 = glm::dot(w, w);
    double cosine = std::fabs(glm::dot(cross_normal, w));
    if (!(d2 > 0.0) || !(cosine > 0.0)) return 0.0;
    return 2.0 * d2 * std::sqrt(d2) / cosine;
}

} // namespace

// --- Light set -------------------------------------------------------------------------

void LightSet::build(const Scene& scene, LightSelection selection) {
    selection_ = selection;
    lights_.clear();
    selection_cdf_.clear();
    selection_pmf_.clear();
    const Mesh& mesh = scene.mesh;
    light_of_triangle_.assign(mesh.triangle_count(), -1);
    degenerate_ = nonfinite_ = 0;
    total_power_ = 0.0;
    // First pass: the lights, their luminance and area, and the largest of each.
    std::vector<double> lum, area, sides;
    double max_lum = 0.0, max_area = 0.0;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        uint32_t m = t < mesh.material.size() ? mesh.material[t] : 0u;
        if (m >= scene.materials.size()) continue;
        const Material& mat = scene.materials[m];
        const Vec3& le = mat.emission;
        bool finite = std::isfinite(le.x) && std::isfinite(le.y) && std::isfinite(le.z);
        if (finite && !mat.is_emissive()) continue;
        double a = 0.5 * glm::length(mesh.cross_normal(t));
        if (!finite || !std::isfinite(a)) { // never silently dropped: counted, and refused
            ++nonfinite_;
            continue;
        }
        if (!(a > 0.0)) { // degenerate: never hit, never sampled
            ++degenerate_;
            continue;
        }
        double l = std::max(0.0, luminance(le));
        light_of_triangle_[t] = int32_t(lights_.size());
        Light light;
        light.p0 = mesh.vertex(t, 0);
        light.p1 = mesh.vertex(t, 1);
        light.p2 = mesh.vertex(t, 2);
        light.e1 = light.p1 - light.p0;
        light.e2 = light.p2 - light.p0;
        light.cross_normal = glm::cross(light.e1, light.e2);
        light.unit_normal = glm::normalize(light.cross_normal);
        light.emission = le;
        light.centroid = (light.p0 + light.p1 + light.p2) / 3.0;
        for (const Vec3* v : {&light.p0, &light.p1, &light.p2}) {
            const Vec3 r = *v - light.centroid;
            light.radius2 = std::max(light.radius2, glm::dot(r, r));
        }
        light.double_sided = mat.double_sided;
        light.triangle = uint32_t(t);
        lights_.push_back(light);
        lum.push_back(l);
        area.push_back(a);
        sides.push_back(mat.double_sided ? 2.0 : 1.0);
        max_lum = std::max(max_lum, l);
        max_area = std::max(max_area, a);
    }
    // Flux of a Lambertian emitter: pi L A per emitting side. The weights are taken relative
    // to the largest radiance and area, each factor in [0, 1], so they stay finite when the
    // power itself overflows a double.
    std::vector<double> weight(lights_.size(), 1.0);
    double relative_power = 0.0;
    for (size_t i = 0; i < lights_.size(); ++i) {
        double p = (max_lum > 0.0 ? lum[i] / max_lum : 0.0) * (area[i] / max_area) * sides[i];
        relative_power += p;
        if (selection == LightSelection::Area) weight[i] = area[i] / max_area;
        if (selection == LightSelection::Power) weight[i] = p;
    }
    total_power_ = relative_power > 0.0 ? max_lum * max_area * kPi * relative_power : 0.0;
    // One light, or uniform choice: no table (index and pmf are arithmetic).
    if (lights_.size() <= 1 || selection == LightSelection::Uniform) return;
    double sum = 0.0;
    for (double w : weight) sum += w;
    if (!(sum > 0.0) || !std::isfinite(sum)) return; // no usable weights: uniform choice
    selection_pmf_.resize(weight.size());
    selection_cdf_.resize(weight.size() + 1);
    selection_cdf_[0] = 0.0;
    double run = 0.0;
    for (size_t i = 0; i < weight.size(); ++i) {
        selection_pmf_[i] = weight[i] / sum;
        run += weight[i];
        selection_cdf_[i + 1] = run / sum;
    }
    selection_cdf_.back() = 1.0;
}

int LightSet::light_index(uint32_t triangle) const {
    return triangle < light_of_triangle_.size() ? light_of_triangle_[triangle] : -1;
}

double LightSet::total_power() const {
    return total_power_;
}

double LightSet::selection_pmf(int light) const {
    if (light < 0 || size_t(light) >= lights_.size()) return 0.0;
    if (selection_pmf_.empty()) return 1.0 / u63_to_double(lights_.size());
    return selection_pmf_[size_t(light)];
}

int LightSet::select(double u_select, double* pmf) const {
    size_t n = lights_.size();
    size_t i;
    if (selection_cdf_.empty()) {
        i = std::min(n - 1, size_t(fmax_inline(0.0, u_select) * u63_to_double(n)));
        *pmf = 1.0 / u63_to_double(n);
    } else {
        // cdf[i] <= u < cdf[i + 1]: lights of zero weight span an empty interval.
        auto it = std::upper_bound(selection_cdf_.begin(), selection_cdf_.end(), u_select);
        i = size_t(std::max<std::ptrdiff_t>(0, it - selection_cdf_.begin() - 1));
        i = std::min(i, n - 1);
        *pmf = selection_pmf_[i];
    }
    return int(i);
}

LightSample LightSet::sample(const Vec3& ref, double u_select, const Vec2& u,
                             LightSampling mode) const {
    LightSample s;
    if (lights_.empty()) return s;
    double pmf = 0.0;
    const Light& light = lights_[size_t(select(u_select, &pmf))];
    const Vec3 &p0 = light.p0, &p1 = light.p1, &p2 = light.p2;
    const Vec3& n = light.cross_normal;
    double pdf = 0.0;
    Vec3 point;
    SphericalTriangle st;
    if (mode == LightSampling::SolidAngle &&
        !light_is_small_from(light.centroid, light.radius2, ref) &&
        setup_spherical(p0 - ref, p1 - ref, p2 - ref, light.e1, light.e2, n, &st)) {
        Vec3 w = sample_spherical(st, u);
        // Where the direction meets the triangle's plane: (ref + t w - p0) . N = 0.
        double t = glm::dot(p0 - ref, n) / glm::dot(w, n);
        if (!(t > 0.0) || !std::isfinite(t)) return s;
        point = ref + w * t;
        pdf = pmf / st.omega;
    } else {
        Vec2 b = sample_triangle_barycentric(u); // [Turk90]
        point = p0 * b.x + p1 * b.y + p2 * (1.0 - b.x - b.y);
        pdf = pmf * area_to_solid_angle(ref, point, n);
    }
    if (!(pdf > 0.0) || !std::isfinite(pdf)) return s;
    s.point = point;
    s.normal = light.unit_normal;
    s.radiance = emitted_by(light, ref - point);
    s.pdf = pdf;
    s.triangle = light.triangle;
    s.valid = true;
    return s;
}

double LightSet::pdf(const Vec3& ref, uint32_t triangle, const Vec3& point,
                     LightSampling mode) const {
    int light = light_index(triangle);
    if (light < 0) return 0.0;
    double pmf = selection_pmf(light);
    const Light& l = lights_[size_t(light)];
    const Vec3& n = l.cross_normal;
    if (mode == LightSampling::SolidAngle && !light_is_small_from(l.centroid, l.radius2, ref)) {
        // The same rule as sample: the same solid angle and the same regime tests.
        Vec3 a = l.p0 - ref;
        double det = glm::dot(a, n);
        const Vec3 b = l.p1 - ref, c = l.p2 - ref;
        double omega = solid_angle(a, b, c, det, vertex_lengths(a, b, c));
        if (spherical_applies(det, omega)) return pmf / omega;
    }
    return pmf * area_to_solid_angle(ref, point, n);
}

Vec3 LightSet::emitted(uint32_t triangle, const Vec3& w) const {
    const int light = light_index(triangle);
    return light < 0 ? Vec3(0.0) : emitted_by(lights_[size_t(light)], w);
}

// --- Spherical triangles and polygons ------------------------------------------------------

double spherical_triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
    return solid_angle(a, b, c, glm::dot(a, glm::cross(b - a, c - a)), vertex_lengths(a, b, c));
}

Vec3 sample_spherical_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec2& u,
                               double* pdf) {
    // The same map as the light sampler, without its fallback regimes: only a triangle of
    // zero solid angle (or one that contains the origin in its plane) is refused.
    Vec3 e1 = b - a, e2 = c - a;
    double det = glm::dot(a, glm::cross(e1, e2));
    SphericalTriangle st;
    const VertexLengths len = vertex_lengths(a, b, c);
    st.omega = solid_angle(a, b, c, det, len);
    if (det == 0.0 || !(st.omega > 0.0) || !std::isfinite(st.omega)) {
        if (pdf) *pdf = 0.0;
        return Vec3(0.0);
    }
    fill_spherical(a, b, c, e1, e2, det, len, &st);
    if (pdf) *pdf = 1.0 / st.omega;
    return sample_spherical(st, u);
}

double lambert_polygon_form_factor(const Vec3& x, const Vec3& n, const Vec3* vertices, int count) {
    constexpr int kMaxClipped = 2 * kMaxFormFactorVertices;
    if (count < 3 || count > kMaxFormFactorVertices)
        return std::numeric_limits<double>::quiet_NaN();
    // Clip to the half-space n . (v - x) >= 0 (Sutherland-Hodgman): the part below the
    // tangent plane receives no cos-weighted light.
    Vec3 clipped[kMaxClipped];
    int m = 0;
    for (int i = 0; i < count; ++i) {
        Vec3 p = vertices[i] - x, q = vertices[(i + 1) % count] - x;
        double dp = glm::dot(n, p), dq = glm::dot(n, q);
        if (dp >= 0.0) clipped[m++] = p;
        if ((dp >= 0.0) != (dq >= 0.0)) clipped[m++] = p + (q - p) * (dp / (dp - dq));
    }
    // F = (1 / 2 pi) sum_i beta_i n . (v_i x v_i+1) / |v_i x v_i+1| [Lambert1760]: each edge
    // contributes the angle it subtends times the cosine of its arc plane's normal.
    double sum = 0.0;
    for (int i = 0; i < m; ++i) {
        double li = glm::length(clipped[i]), lj = glm::length(clipped[(i + 1) % m]);
        if (!(li > 0.0) || !(lj > 0.0)) continue;
        Vec3 vi = clipped[i] / li, vj = clipped[(i + 1) % m] / lj;
        Vec3 cr = glm::cross(vi, vj);
        double s = glm::length(cr);
        if (!(s > 0.0)) continue;
        sum += std::atan2(s, glm::dot(vi, vj)) * glm::dot(n, cr) / s;
    }
    // The sign follows the winding as seen from x; the form factor is its magnitude.
    return std::fabs(sum) / (2.0 * kPi);
}

} // namespace mcp
