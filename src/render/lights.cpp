// Area lights: selection tables, area sampling, spherical-triangle sampling [Arvo95] and
// Lambert's polygon form factor [Lambert1760].
#include "render/lights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/points.h"  // u63_to_double
#include "core/special.h" // kPi
#include "core/spherical_triangle.h"
#include "core/trig.h"

namespace mcp {

namespace {

/// Solid angles outside [kMinSphericalSolidAngle, kMaxSphericalSolidAngle] (and reference
/// points on the triangle's plane) are sampled by area instead; see lights.h for why.
bool spherical_applies(double det, double omega) {
    return det != 0.0 && omega >= kMinSphericalSolidAngle && omega <= kMaxSphericalSolidAngle;
}

/// Sets up the spherical triangle (cross_normal = e1 x e2); st->omega is always set, the rest
/// only when the triangle is in the spherical regime (return value true).
bool setup_spherical(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& e1, const Vec3& e2,
                     const Vec3& cross_normal, SphericalTriangle* st) {
    double det = glm::dot(a, cross_normal);
    const TriangleVertexLengths len = triangle_vertex_lengths(a, b, c); // shared by both
    st->omega = spherical_triangle_solid_angle(a, b, c, det, len);
    if (!spherical_applies(det, st->omega)) return false;
    fill_spherical_triangle(a, b, c, e1, e2, det, len, st);
    return true;
}

/// Solid-angle density of a uniform area sample at `point` seen from ref, per unit (1/A)
/// area density: d^2 / (A |cos theta_light|) = 2 d^3 / |N . (point - ref)| with N the
/// unnormalised cross normal (|N| = 2 A). 0 when the point is at ref or seen edge-on.
double area_to_spherical_triangle_solid_angle(const Vec3& ref, const Vec3& point,
                                              const Vec3& cross_normal) {
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
        Vec3 w = sample_spherical_triangle(st, u);
        // Where the direction meets the triangle's plane: (ref + t w - p0) . N = 0.
        double t = glm::dot(p0 - ref, n) / glm::dot(w, n);
        if (!(t > 0.0) || !std::isfinite(t)) return s;
        point = ref + w * t;
        pdf = pmf / st.omega;
    } else {
        Vec2 b = sample_triangle_barycentric(u); // [Turk90]
        point = p0 * b.x + p1 * b.y + p2 * (1.0 - b.x - b.y);
        pdf = pmf * area_to_spherical_triangle_solid_angle(ref, point, n);
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
        double omega =
            spherical_triangle_solid_angle(a, b, c, det, triangle_vertex_lengths(a, b, c));
        if (spherical_applies(det, omega)) return pmf / omega;
    }
    return pmf * area_to_spherical_triangle_solid_angle(ref, point, n);
}

Vec3 LightSet::emitted(uint32_t triangle, const Vec3& w) const {
    const int light = light_index(triangle);
    return light < 0 ? Vec3(0.0) : emitted_by(lights_[size_t(light)], w);
}

// --- Spherical triangles and polygons ------------------------------------------------------

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
