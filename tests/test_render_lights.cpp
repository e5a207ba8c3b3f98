// Area lights: solid angles (octant, quadrature), the distribution of area and spherical
// (solid-angle) light samples against their densities by chi-square on sub-triangles,
// light selection by area and power, sample/pdf agreement in every regime, irradiance
// estimated two ways against Lambert's polygon formula, Lambert's formula against
// quadrature and a closed form, and one-/double-sided emission and degenerate inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/rng.h"
#include "core/special.h"
#include "render/lights.h"
#include "render_scenes.h"
#include "test_support.h"

using namespace mcp;

namespace {

// Chi-square tests in this file: 7 spherical configurations, 3 area ones, 3 selection rules;
// family-wise level 1e-3.
constexpr int kChiSquareTests = 13;
double chi_level() {
    return test::sidak_level(1e-3, kChiSquareTests);
}

Vec2 next_u(Pcg32& rng) {
    double u1 = rng.next_double();
    double u2 = rng.next_double();
    return {u1, u2};
}

/// A scene built by hand: triangles with their own material index.
struct SceneBuilder {
    Scene scene;
    int material(const Vec3& emission, bool double_sided = false) {
        Material m;
        m.emission = emission;
        m.double_sided = double_sided;
        scene.materials.push_back(m);
        return int(scene.materials.size()) - 1;
    }
    uint32_t triangle(const Vec3& p0, const Vec3& p1, const Vec3& p2, int material) {
        uint32_t base = uint32_t(scene.mesh.position.size());
        scene.mesh.position.push_back(p0);
        scene.mesh.position.push_back(p1);
        scene.mesh.position.push_back(p2);
        scene.mesh.index.push_back({base, base + 1, base + 2});
        scene.mesh.material.push_back(uint32_t(material));
        return uint32_t(scene.mesh.index.size()) - 1;
    }
};

struct Tri {
    Vec3 p0, p1, p2;
    Vec3 e1() const { return p1 - p0; }
    Vec3 e2() const { return p2 - p0; }
    Vec3 at(double b1, double b2) const { return p0 + e1() * b1 + e2() * b2; }
    double area() const { return 0.5 * glm::length(glm::cross(e1(), e2())); }
};

/// Barycentric (b1, b2) of p's projection onto the triangle's plane, and its distance to
/// the plane.
Vec2 barycentric(const Tri& t, const Vec3& p, double* plane_distance = nullptr) {
    Vec3 e1 = t.e1(), e2 = t.e2(), d = p - t.p0;
    double d00 = glm::dot(e1, e1), d01 = glm::dot(e1, e2), d11 = glm::dot(e2, e2);
    double d20 = glm::dot(d, e1), d21 = glm::dot(d, e2);
    double den = d00 * d11 - d01 * d01;
    if (plane_distance) {
        Vec3 n = glm::normalize(glm::cross(e1, e2));
        *plane_distance = std::fabs(glm::dot(d, n));
    }
    return {(d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den};
}

/// The K^2 congruent sub-triangles of the regular subdivision of a triangle, in barycentric
/// coordinates, and the cell a barycentric point falls in.
struct Subdivision {
    int k;
    std::vector<std::array<Vec2, 3>> cells;
    std::vector<int> lookup; // (i, j, upper) -> cell or -1

    explicit Subdivision(int k_) : k(k_), lookup(size_t(2 * k_ * k_), -1) {
        double h = 1.0 / k;
        for (int i = 0; i < k; ++i) {
            for (int j = 0; i + j < k; ++j) {
                lookup[size_t(2 * (i * k + j))] = int(cells.size());
                cells.push_back(
                    {Vec2(i * h, j * h), Vec2((i + 1) * h, j * h), Vec2(i * h, (j + 1) * h)});
                if (i + j + 2 <= k) {
                    lookup[size_t(2 * (i * k + j) + 1)] = int(cells.size());
                    cells.push_back({Vec2((i + 1) * h, j * h), Vec2((i + 1) * h, (j + 1) * h),
                                     Vec2(i * h, (j + 1) * h)});
                }
            }
        }
    }
    int cell(Vec2 b) const {
        double x = b.x * k, y = b.y * k;
        int i = std::min(k - 1, std::max(0, int(std::floor(x))));
        int j = std::min(k - 1, std::max(0, int(std::floor(y))));
        bool upper = (x - i) + (y - j) >= 1.0;
        if (i + j > k - 1) j = k - 1 - i, upper = false; // rounding past the far edge
        if (upper && i + j + 2 > k) upper = false;
        return lookup[size_t(2 * (i * k + j) + (upper ? 1 : 0))];
    }
};

/// Light sampling configuration: one triangle light, a reference point, the sampling mode.
struct Config {
    const char* name;
    Tri tri;
    Vec3 ref;
};

const Tri kTri{Vec3(0.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.3, 0.9, 0.0)};

/// LightSet's speed regime for triangle t seen from ref (light_is_small_from), with the
/// centroid and radius computed here.
bool small_from(const Tri& t, const Vec3& ref) {
    const Vec3 c = (t.p0 + t.p1 + t.p2) / 3.0;
    double r2 = 0.0;
    for (const Vec3& v : {t.p0, t.p1, t.p2}) r2 = std::max(r2, glm::dot(v - c, v - c));
    return light_is_small_from(c, r2, ref);
}

/// Chi-square of n light samples of a one-triangle scene, binned into the sub-triangles,
/// against the expected probabilities `expected_prob` of the cells. Also checks that every
/// sample lies on the triangle and carries the density `pdf_expected`. With `map_only`, the
/// samples come from the spherical map itself (sample_spherical_triangle), whatever regime
/// the light sampler would choose.
test::ChiSquareResult sample_chi_square(const Config& cfg, LightSampling mode,
                                        const Subdivision& sub,
                                        const std::vector<double>& expected_prob,
                                        double pdf_expected, int n, uint64_t seed,
                                        bool map_only = false) {
    SceneBuilder sb;
    int m = sb.material(Vec3(1.0));
    sb.triangle(cfg.tri.p0, cfg.tri.p1, cfg.tri.p2, m);
    LightSet lights;
    lights.build(sb.scene, LightSelection::Uniform);
    Pcg32 rng(seed, 7u);
    std::vector<double> observed(sub.cells.size(), 0.0);
    double scale = glm::length(cfg.ref - cfg.tri.p0) + 1.0;
    int off_triangle = 0, wrong_pdf = 0, invalid = 0;
    for (int i = 0; i < n; ++i) {
        double u_select = rng.next_double();
        LightSample s = lights.sample(cfg.ref, u_select, next_u(rng), mode);
        if (map_only) {
            const Vec3 a = cfg.tri.p0 - cfg.ref, n_plane = glm::cross(cfg.tri.e1(), cfg.tri.e2());
            const Vec3 w = sample_spherical_triangle(a, cfg.tri.p1 - cfg.ref, cfg.tri.p2 - cfg.ref,
                                                     next_u(rng), &s.pdf);
            s.point = cfg.ref + w * (glm::dot(a, n_plane) / glm::dot(w, n_plane));
            s.valid = s.pdf > 0.0;
        }
        if (!s.valid) {
            ++invalid;
            continue;
        }
        double dist = 0.0;
        Vec2 b = barycentric(cfg.tri, s.point, &dist);
        const double tol = 1e-9;
        if (b.x < -tol || b.y < -tol || b.x + b.y > 1.0 + tol || dist > tol * scale) ++off_triangle;
        if (std::fabs(s.pdf - pdf_expected) > 1e-9 * pdf_expected) ++wrong_pdf;
        observed[size_t(sub.cell(b))] += 1.0;
    }
    EXPECT_EQ(invalid, 0) << cfg.name;
    EXPECT_EQ(off_triangle, 0) << cfg.name;
    EXPECT_EQ(wrong_pdf, 0) << cfg.name;
    std::vector<double> expected(expected_prob.size());
    for (size_t c = 0; c < expected.size(); ++c) expected[c] = n * expected_prob[c];
    return test::chi_square(observed, expected);
}

/// Solid angles of the sub-triangles seen from ref, and their sum.
std::vector<double> cell_solid_angles(const Tri& t, const Vec3& ref, const Subdivision& sub,
                                      double* total) {
    std::vector<double> w;
    *total = 0.0;
    for (const auto& c : sub.cells) {
        double o = spherical_triangle_area(t.at(c[0].x, c[0].y) - ref, t.at(c[1].x, c[1].y) - ref,
                                           t.at(c[2].x, c[2].y) - ref);
        w.push_back(o);
        *total += o;
    }
    return w;
}

/// Solid angle of a triangle by quadrature of |cos theta_light| / r^2 over its area, on the
/// square mapped onto the triangle collapsed at `apex` (Duffy's transformation, which
/// cancels the 1/r of a near apex): p = apex + s (u + t (v - u)), dA = |u x v| s ds dt.
double solid_angle_quadrature(const Vec3& apex, const Vec3& q1, const Vec3& q2, const Vec3& ref,
                              int panels) {
    Vec3 u = q1 - apex, v = q2 - apex;
    Vec3 n = glm::cross(u, v);
    double jac = glm::length(n);
    n /= jac;
    return test::gauss_legendre(
        [&](double s) {
            return test::gauss_legendre(
                [&](double t) {
                    Vec3 d = apex + (u + (v - u) * t) * s - ref;
                    double r2 = glm::dot(d, d);
                    return std::fabs(glm::dot(d, n)) / (r2 * std::sqrt(r2)) * jac * s;
                },
                0.0, 1.0, panels);
        },
        0.0, 1.0, panels);
}

} // namespace

// --- Solid angle -----------------------------------------------------------------------

TEST(RenderLights, OctantTriangleIsHalfPi) {
    const Vec3 x(1.0, 0.0, 0.0), y(0.0, 1.0, 0.0), z(0.0, 0.0, 1.0);
    EXPECT_NEAR(spherical_triangle_area(x, y, z), kPi / 2.0, 1e-15);
    EXPECT_NEAR(spherical_triangle_area(y, x, z), kPi / 2.0, 1e-15); // either winding
    EXPECT_NEAR(spherical_triangle_area(x * 1e-6, y * 3e5, z * 7.0), kPi / 2.0, 1e-15);
    // The octant triangle's Arvo density is 1 / (pi / 2).
    double pdf = 0.0;
    Vec3 w = sample_spherical_triangle(x, y, z, Vec2(0.3, 0.6), &pdf);
    EXPECT_NEAR(pdf, 2.0 / kPi, 1e-15);
    EXPECT_NEAR(glm::length(w), 1.0, 1e-15);
    EXPECT_TRUE(w.x >= 0.0 && w.y >= 0.0 && w.z >= 0.0);
    // The whole sphere split into 8 octants; 4 triangles around the pole.
    double sum = 0.0;
    for (int sx = -1; sx <= 1; sx += 2)
        for (int sy = -1; sy <= 1; sy += 2)
            for (int sz = -1; sz <= 1; sz += 2)
                sum += spherical_triangle_area(x * double(sx), y * double(sy), z * double(sz));
    EXPECT_NEAR(sum, 4.0 * kPi, 1e-14);
}

TEST(RenderLights, SolidAngleMatchesQuadrature) {
    struct Case {
        Vec3 ref;
        const char* name;
    };
    const Case cases[] = {
        {Vec3(0.4, 0.3, 1.0), "above"},         {Vec3(0.4, 0.3, -0.25), "near, below the interior"},
        {Vec3(3.0, -2.0, 0.05), "grazing"},     {Vec3(20.0, 30.0, 40.0), "far"},
        {Vec3(0.5, 0.0, 0.2), "above an edge"},
    };
    for (const Case& c : cases) {
        double omega = spherical_triangle_area(kTri.p0 - c.ref, kTri.p1 - c.ref, kTri.p2 - c.ref);
        // Split at the foot of the perpendicular when it falls inside, so each piece has the
        // near point at its collapsed apex; otherwise one piece collapsed at p0.
        Vec2 b = barycentric(kTri, c.ref);
        double quad = 0.0;
        if (b.x > 0.0 && b.y > 0.0 && b.x + b.y < 1.0) {
            Vec3 foot = kTri.at(b.x, b.y);
            quad = solid_angle_quadrature(foot, kTri.p0, kTri.p1, c.ref, 60) +
                   solid_angle_quadrature(foot, kTri.p1, kTri.p2, c.ref, 60) +
                   solid_angle_quadrature(foot, kTri.p2, kTri.p0, c.ref, 60);
        } else {
            quad = solid_angle_quadrature(kTri.p0, kTri.p1, kTri.p2, c.ref, 60);
        }
        EXPECT_NEAR(omega, quad, 1e-10 * quad) << c.name;
        // Additivity over a subdivision, which the chi-square tests rely on.
        double total = 0.0;
        cell_solid_angles(kTri, c.ref, Subdivision(9), &total);
        EXPECT_NEAR(total, omega, 1e-12 * omega) << c.name;
    }
}

// --- Distributions of light samples ----------------------------------------------------

TEST(RenderLights, SolidAngleSamplesAreUniformInSolidAngle) {
    const Tri sliver{Vec3(0.0, 0.0, 0.0), Vec3(2.0, 0.05, 0.0), Vec3(1.0, 0.12, 0.3)};
    const Config configs[] = {
        {"moderate", kTri, Vec3(0.2, 0.8, 0.9)},
        {"far", kTri, Vec3(60.0, -80.0, 150.0)},
        {"near the interior", kTri, Vec3(0.45, 0.3, 0.02)},
        {"grazing", kTri, Vec3(2.5, 0.4, 1e-3)},
        {"behind", kTri, Vec3(0.6, 0.2, -0.4)},
        {"above an edge", kTri, Vec3(0.5, 0.0, 1e-3)},
        {"sliver", sliver, Vec3(0.5, 1.0, 0.5)},
    };
    const Subdivision sub(10);
    const int n = 60000;
    uint64_t seed = 11;
    for (const Config& cfg : configs) {
        double omega = 0.0;
        std::vector<double> prob = cell_solid_angles(cfg.tri, cfg.ref, sub, &omega);
        ASSERT_GT(omega, kMinSphericalSolidAngle) << cfg.name;
        ASSERT_LT(omega, kMaxSphericalSolidAngle) << cfg.name;
        for (double& p : prob) p /= omega;
        // Triangles small from the point are sampled by area (AreaSamplesAreUniformInArea);
        // the map is tested on them directly.
        const bool map_only = small_from(cfg.tri, cfg.ref);
        if (std::string(cfg.name) == "far") {
            EXPECT_TRUE(map_only);
        }
        test::ChiSquareResult r = sample_chi_square(cfg, LightSampling::SolidAngle, sub, prob,
                                                    1.0 / omega, n, seed++, map_only);
        EXPECT_GT(r.p_value, chi_level())
            << cfg.name << ": chi2 " << r.statistic << " dof " << r.dof;
        std::printf("  spherical%s %-18s omega %.4g  chi2 %.1f dof %d p %.3g\n",
                    map_only ? " (map)" : "", cfg.name, omega, r.statistic, r.dof, r.p_value);
    }
}

TEST(RenderLights, AreaSamplesAreUniformInArea) {
    // Area mode, and SolidAngle mode in its three area regimes (a triangle small from the
    // point, solid angle below kMinSphericalSolidAngle, reference point within ~1e-14 of the
    // triangle's plane).
    struct Case {
        Config cfg;
        LightSampling mode;
    };
    const Case cases[] = {
        {{"area mode", kTri, Vec3(0.3, 0.2, 0.5)}, LightSampling::Area},
        {{"small from the point", kTri, Vec3(60.0, -80.0, 150.0)}, LightSampling::SolidAngle},
        {{"tiny (fallback)", kTri, Vec3(1.5e6, -1e6, 1.2e6)}, LightSampling::SolidAngle},
        {{"on the plane (fallback)", kTri, Vec3(0.45, 0.3, 1e-14)}, LightSampling::SolidAngle},
    };
    const Subdivision sub(10);
    const int n = 60000;
    uint64_t seed = 101;
    for (const Case& c : cases) {
        double omega = spherical_triangle_area(c.cfg.tri.p0 - c.cfg.ref, c.cfg.tri.p1 - c.cfg.ref,
                                               c.cfg.tri.p2 - c.cfg.ref);
        if (c.mode == LightSampling::SolidAngle) {
            EXPECT_TRUE(small_from(c.cfg.tri, c.cfg.ref) || omega < kMinSphericalSolidAngle ||
                        omega > kMaxSphericalSolidAngle)
                << c.cfg.name << ": omega " << omega;
        }
        std::vector<double> prob(sub.cells.size(), 1.0 / double(sub.cells.size()));
        SceneBuilder sb;
        int m = sb.material(Vec3(1.0));
        sb.triangle(c.cfg.tri.p0, c.cfg.tri.p1, c.cfg.tri.p2, m);
        LightSet lights;
        lights.build(sb.scene, LightSelection::Power);
        Pcg32 rng(seed++, 3u);
        std::vector<double> observed(sub.cells.size(), 0.0);
        int bad_pdf = 0;
        const double inv_area = 1.0 / c.cfg.tri.area();
        for (int i = 0; i < n; ++i) {
            double u_select = rng.next_double();
            LightSample s = lights.sample(c.cfg.ref, u_select, next_u(rng), c.mode);
            if (!s.valid) continue;
            // Expected density: (1 / A) d^2 / |cos theta_light|, computed here from scratch.
            Vec3 d = s.point - c.cfg.ref;
            double cosl = std::fabs(glm::dot(glm::normalize(d), s.normal));
            double expected = inv_area * glm::dot(d, d) / cosl;
            if (std::fabs(s.pdf - expected) > 1e-8 * expected) ++bad_pdf;
            observed[size_t(sub.cell(barycentric(c.cfg.tri, s.point)))] += 1.0;
        }
        EXPECT_EQ(bad_pdf, 0) << c.cfg.name;
        std::vector<double> expected(prob.size());
        for (size_t k = 0; k < prob.size(); ++k) expected[k] = n * prob[k];
        test::ChiSquareResult r = test::chi_square(observed, expected);
        EXPECT_GT(r.p_value, chi_level()) << c.cfg.name << ": chi2 " << r.statistic;
        std::printf("  area %-24s omega %.3g chi2 %.1f dof %d p %.3g\n", c.cfg.name, omega,
                    r.statistic, r.dof, r.p_value);
    }
}

namespace {

/// Six lights of different areas and emissions (two double-sided), between non-emissive
/// triangles and one degenerate emissive triangle.
struct MultiLight {
    SceneBuilder sb;
    std::vector<uint32_t> lights;
    std::vector<double> area, power;
    MultiLight() {
        int dull = sb.material(Vec3(0.0));
        sb.triangle(Vec3(-5, -5, 0), Vec3(5, -5, 0), Vec3(5, 5, 0), dull);
        const Vec3 emission[] = {Vec3(1.0, 1.0, 1.0), Vec3(5.0, 0.5, 0.1), Vec3(0.2, 3.0, 0.2),
                                 Vec3(0.0, 0.0, 8.0), Vec3(2.0, 2.0, 2.0), Vec3(10.0, 9.0, 8.0)};
        const bool two_sided[] = {false, true, false, false, true, false};
        const double size[] = {1.0, 0.5, 2.0, 1.5, 0.3, 0.2};
        for (int i = 0; i < 6; ++i) {
            int m = sb.material(emission[i], two_sided[i]);
            Vec3 o(double(i) - 2.5, 0.5 * double(i % 3), 2.0 + 0.3 * double(i));
            double s = size[i];
            // Facing down (-z): clockwise seen from above.
            uint32_t t = sb.triangle(o, o + Vec3(0.0, s, 0.0), o + Vec3(s, 0.2 * s, 0.1 * s), m);
            lights.push_back(t);
            double a = 0.5 * glm::length(sb.scene.mesh.cross_normal(t));
            area.push_back(a);
            power.push_back(luminance(emission[i]) * a * kPi * (two_sided[i] ? 2.0 : 1.0));
            if (i == 2) { // degenerate emissive triangle and another dull one in between
                sb.triangle(Vec3(0, 0, 7), Vec3(1, 1, 8), Vec3(2, 2, 9), m);
                sb.triangle(Vec3(0, 0, 5), Vec3(1, 0, 5), Vec3(0, 1, 5), dull);
            }
        }
    }
};

} // namespace

TEST(RenderLights, SelectionFollowsUniformAreaAndPower) {
    MultiLight ml;
    const LightSelection rules[] = {LightSelection::Uniform, LightSelection::Area,
                                    LightSelection::Power};
    const char* names[] = {"uniform", "area", "power"};
    double total_power = 0.0;
    for (double p : ml.power) total_power += p;
    const int n = 120000;
    for (int r = 0; r < 3; ++r) {
        LightSet set;
        set.build(ml.sb.scene, rules[r]);
        ASSERT_EQ(set.size(), ml.lights.size());
        EXPECT_NEAR(set.total_power(), total_power, 1e-12 * total_power);
        std::vector<double> weight = r == 0   ? std::vector<double>(6, 1.0)
                                     : r == 1 ? ml.area
                                              : ml.power;
        double sum = 0.0;
        for (double w : weight) sum += w;
        for (size_t i = 0; i < 6; ++i) {
            EXPECT_EQ(set.light_index(ml.lights[i]), int(i));
            EXPECT_NEAR(set.selection_pmf(int(i)), weight[i] / sum, 1e-14);
        }
        Pcg32 rng(500 + uint64_t(r), 9u);
        std::vector<double> observed(6, 0.0), expected(6);
        const Vec3 ref(0.1, 0.2, -1.0);
        for (int k = 0; k < n; ++k) {
            double u_select = rng.next_double();
            LightSample s = set.sample(ref, u_select, next_u(rng), LightSampling::Area);
            ASSERT_TRUE(s.valid);
            int li = set.light_index(s.triangle);
            ASSERT_GE(li, 0);
            observed[size_t(li)] += 1.0;
        }
        for (size_t i = 0; i < 6; ++i) expected[i] = n * weight[i] / sum;
        test::ChiSquareResult c = test::chi_square(observed, expected);
        EXPECT_GT(c.p_value, chi_level()) << names[r] << ": chi2 " << c.statistic;
        std::printf("  selection %-8s chi2 %.2f dof %d p %.3g\n", names[r], c.statistic, c.dof,
                    c.p_value);
    }
}

TEST(RenderLights, SampleAgreesWithPdfInEveryRegime) {
    MultiLight ml;
    // Reference points: ordinary, near and on light planes, far enough for tiny solid angles.
    std::vector<Vec3> refs = {Vec3(0.1, 0.2, -1.0),       Vec3(-2.0, 0.3, 2.0),
                              Vec3(4.0, 5.0, 6.0),        Vec3(0.0, 0.0, 0.0),
                              Vec3(3e6, -2e6, 1e6),       Vec3(-1.7, 0.0, 2.0),
                              Vec3(150.0, -200.0, 100.0), Vec3(1e4, 2e4, -1e4)};
    const Tri light0{ml.sb.scene.mesh.vertex(ml.lights[0], 0),
                     ml.sb.scene.mesh.vertex(ml.lights[0], 1),
                     ml.sb.scene.mesh.vertex(ml.lights[0], 2)};
    const Vec3 n0 = glm::normalize(glm::cross(light0.e1(), light0.e2()));
    refs.push_back(light0.at(0.3, 0.3) + n0 * 1e-14); // within 1e-14 of light 0's plane
    refs.push_back(light0.at(0.3, 0.3) - n0 * 1e-3);  // just below it
    refs.push_back(light0.at(0.5, 0.0) - n0 * 1e-4);  // just off its edge
    refs.push_back(light0.at(1.2, 0.4));              // in its plane, outside
    Pcg32 rng(77, 1u);
    int checked = 0, mismatched = 0, spherical = 0, off_triangle = 0;
    int fallback_small = 0, fallback_large = 0, small_light = 0;
    const LightSelection rules[] = {LightSelection::Uniform, LightSelection::Area,
                                    LightSelection::Power};
    for (LightSelection rule : rules) {
        LightSet set;
        set.build(ml.sb.scene, rule);
        for (const Vec3& ref : refs) {
            for (LightSampling mode : {LightSampling::Area, LightSampling::SolidAngle}) {
                for (int k = 0; k < 300; ++k) {
                    double u_select = rng.next_double();
                    LightSample s = set.sample(ref, u_select, next_u(rng), mode);
                    if (!s.valid) continue;
                    ++checked;
                    double p = set.pdf(ref, s.triangle, s.point, mode);
                    if (!(std::fabs(p - s.pdf) <= 1e-9 * s.pdf)) ++mismatched;
                    const Mesh& mesh = ml.sb.scene.mesh;
                    Tri t{mesh.vertex(s.triangle, 0), mesh.vertex(s.triangle, 1),
                          mesh.vertex(s.triangle, 2)};
                    double dist = 0.0;
                    Vec2 b = barycentric(t, s.point, &dist);
                    double scale = glm::length(s.point) + 1.0;
                    if (b.x < -1e-9 || b.y < -1e-9 || b.x + b.y > 1.0 + 1e-9 || dist > 1e-9 * scale)
                        ++off_triangle;
                    if (mode == LightSampling::SolidAngle) {
                        double omega = spherical_triangle_area(t.p0 - ref, t.p1 - ref, t.p2 - ref);
                        double area_pdf = set.pdf(ref, s.triangle, s.point, LightSampling::Area);
                        const bool small = small_from(t, ref);
                        if (!small && omega >= kMinSphericalSolidAngle &&
                            omega <= kMaxSphericalSolidAngle) {
                            ++spherical;
                            double expect = set.selection_pmf(set.light_index(s.triangle)) / omega;
                            if (std::fabs(s.pdf - expect) > 1e-9 * expect) ++mismatched;
                        } else {
                            if (small && omega >= kMinSphericalSolidAngle)
                                ++small_light;
                            else
                                ++(omega < 1.0 ? fallback_small : fallback_large);
                            if (s.pdf != area_pdf) ++mismatched; // the same rule, bit for bit
                        }
                    }
                }
            }
        }
        // A triangle that does not emit has density 0.
        EXPECT_EQ(set.pdf(Vec3(0.0, 0.0, 1.0), 0u, Vec3(0.0), LightSampling::SolidAngle), 0.0);
        EXPECT_EQ(set.pdf(Vec3(0.0, 0.0, 1.0), 0u, Vec3(0.0), LightSampling::Area), 0.0);
    }
    EXPECT_EQ(mismatched, 0);
    EXPECT_EQ(off_triangle, 0);
    EXPECT_GT(spherical, 1000);
    EXPECT_GT(small_light, 100);    // every area regime is visited: a light small from the
    EXPECT_GT(fallback_small, 100); // point, a tiny solid angle,
    EXPECT_GT(fallback_large, 10);  // and a point within 1e-14 of a light's plane
    EXPECT_GT(checked, 15000);
    std::printf("  agreement: %d samples, %d spherical, %d small lights, %d + %d fallback\n",
                checked, spherical, small_light, fallback_small, fallback_large);
}

// --- Irradiance two ways and Lambert's formula -------------------------------------------

namespace {

struct Estimate {
    double mean = 0.0;
    double stderr_ = 0.0; ///< collapsed-strata (pairs of neighbouring strata) estimate
};

/// Irradiance at x (normal n) from the lights of `set`, by one light sample per stratum of
/// an m x m jittered grid: mean of L cos_x / pdf, and a conservative standard error from
/// the differences of horizontally neighbouring strata.
Estimate irradiance(const LightSet& set, const Vec3& x, const Vec3& n, LightSampling mode, int m,
                    uint64_t seed) {
    Pcg32 rng(seed, 5u);
    std::vector<double> f(size_t(m) * size_t(m));
    for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
            double u1 = (i + rng.next_double()) / m;
            double u2 = (j + rng.next_double()) / m;
            LightSample s = set.sample(x, 0.5, Vec2(u1, u2), mode);
            double v = 0.0;
            if (s.valid) {
                Vec3 w = glm::normalize(s.point - x);
                v = s.radiance.x * std::fmax(0.0, glm::dot(w, n)) / s.pdf;
            }
            f[size_t(j * m + i)] = v;
        }
    }
    Estimate e;
    double sum = 0.0, var = 0.0;
    for (size_t k = 0; k < f.size(); ++k) sum += f[k];
    for (size_t k = 0; k + 1 < f.size(); k += 2) var += (f[k] - f[k + 1]) * (f[k] - f[k + 1]);
    double nn = double(f.size());
    e.mean = sum / nn;
    e.stderr_ = std::sqrt(var) / nn;
    return e;
}

} // namespace

TEST(RenderLights, IrradianceByAreaAndSolidAngleMatchesLambert) {
    // A one-sided triangle light of radiance 3 facing down (-z) at height 1.
    const double radiance = 3.0;
    const Tri light{Vec3(-0.5, -0.4, 1.0), Vec3(0.2, 0.8, 1.0), Vec3(0.7, -0.3, 1.0)};
    SceneBuilder sb;
    int m = sb.material(Vec3(radiance));
    sb.triangle(light.p0, light.p1, light.p2, m);
    LightSet set;
    set.build(sb.scene, LightSelection::Power);
    ASSERT_LT(glm::cross(light.e1(), light.e2()).z, 0.0); // faces down
    struct Case {
        Vec3 x, n;
        const char* name;
    };
    const Case cases[] = {
        {Vec3(0.1, 0.0, 0.0), Vec3(0.0, 0.0, 1.0), "below"},
        {Vec3(1.5, 0.5, 0.2), glm::normalize(Vec3(-0.5, 0.1, 1.0)), "aside, tilted"},
        {Vec3(0.0, 0.1, 0.85), Vec3(0.0, 0.0, 1.0), "close below"},
        {Vec3(0.3, -0.2, 0.6), glm::normalize(Vec3(1.0, 0.2, 0.3)), "partly below horizon"},
    };
    const Vec3 verts[3] = {light.p0, light.p1, light.p2};
    uint64_t seed = 900;
    for (const Case& c : cases) {
        double lambert = kPi * radiance * lambert_polygon_form_factor(c.x, c.n, verts, 3);
        Estimate ea = irradiance(set, c.x, c.n, LightSampling::Area, 256, seed++);
        Estimate es = irradiance(set, c.x, c.n, LightSampling::SolidAngle, 256, seed++);
        EXPECT_NEAR(ea.mean, es.mean, 1e-3 * lambert) << c.name;
        EXPECT_NEAR(ea.mean, lambert, 5.0 * ea.stderr_) << c.name;
        EXPECT_NEAR(es.mean, lambert, 5.0 * es.stderr_) << c.name;
        std::printf("  E %-20s lambert %.8f area %.8f (+-%.1e) solid angle %.8f (+-%.1e)\n", c.name,
                    lambert, ea.mean, ea.stderr_, es.mean, es.stderr_);
    }
}

TEST(RenderLights, LambertFormulaMatchesQuadratureAndClosedForm) {
    // Rectangle [0, a] x [0, b] at height h, facing down; point x on the floor.
    const double a = 1.3, b = 0.8, h = 0.9;
    const Vec3 rect[4] = {Vec3(0, 0, h), Vec3(0, b, h), Vec3(a, b, h), Vec3(a, 0, h)};
    // Form factor by quadrature of cos_x cos_l / (pi r^2) over the rectangle (cos_x clipped).
    auto quadrature = [&](const Vec3& x, const Vec3& n, int panels) {
        return test::gauss_legendre(
            [&](double px) {
                return test::gauss_legendre(
                    [&](double py) {
                        Vec3 d = Vec3(px, py, h) - x;
                        double r2 = glm::dot(d, d);
                        double cosx = std::fmax(0.0, glm::dot(d, n)) / std::sqrt(r2);
                        double cosl = std::fabs(d.z) / std::sqrt(r2);
                        return cosx * cosl / (kPi * r2);
                    },
                    0.0, b, panels);
            },
            0.0, a, panels);
    };
    // Under a corner, parallel planes: the classical closed form with X = a/h, Y = b/h,
    // F = (1/2pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))].
    const double X = a / h, Y = b / h;
    const double corner = (X / std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) +
                           Y / std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y))) /
                          (2.0 * kPi);
    const Vec3 up(0.0, 0.0, 1.0);
    EXPECT_NEAR(lambert_polygon_form_factor(Vec3(0.0), up, rect, 4), corner, 1e-14);
    // Reversed winding gives the same value.
    const Vec3 rev[4] = {rect[3], rect[2], rect[1], rect[0]};
    EXPECT_NEAR(lambert_polygon_form_factor(Vec3(0.0), up, rev, 4), corner, 1e-14);
    // The centre by superposition of four corner rectangles of half size.
    {
        const double x2 = 0.5 * a / h, y2 = 0.5 * b / h;
        double quarter = (x2 / std::sqrt(1 + x2 * x2) * std::atan(y2 / std::sqrt(1 + x2 * x2)) +
                          y2 / std::sqrt(1 + y2 * y2) * std::atan(x2 / std::sqrt(1 + y2 * y2))) /
                         (2.0 * kPi);
        EXPECT_NEAR(lambert_polygon_form_factor(Vec3(0.5 * a, 0.5 * b, 0.0), up, rect, 4),
                    4.0 * quarter, 1e-14);
    }
    struct Case {
        Vec3 x, n;
        double tol;
        const char* name;
    };
    const Case cases[] = {
        {Vec3(0.3, 0.2, 0.0), up, 1e-12, "below, parallel"},
        {Vec3(2.0, -0.5, 0.3), glm::normalize(Vec3(-1.0, 0.4, 0.8)), 1e-12, "aside, tilted"},
        {Vec3(0.6, 0.4, 0.5), glm::normalize(Vec3(1.0, 0.0, 0.2)), 2e-7, "clipped by horizon"},
    };
    for (const Case& c : cases) {
        double f = lambert_polygon_form_factor(c.x, c.n, rect, 4);
        double q = quadrature(c.x, c.n, c.tol < 1e-9 ? 40 : 400);
        EXPECT_NEAR(f, q, c.tol) << c.name;
        std::printf("  F %-20s lambert %.12f quadrature %.12f\n", c.name, f, q);
    }
    // Out-of-range vertex counts are refused.
    EXPECT_TRUE(std::isnan(lambert_polygon_form_factor(Vec3(0.0), up, rect, 2)));
}

// --- Emission sides and degenerate inputs ----------------------------------------------

TEST(RenderLights, OneSidedAndDoubleSidedEmission) {
    SceneBuilder sb;
    int one = sb.material(Vec3(2.0, 1.0, 0.5), false);
    int two = sb.material(Vec3(0.5, 0.5, 0.5), true);
    // Counter-clockwise seen from +z: front side faces +z.
    uint32_t t1 = sb.triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), one);
    uint32_t t2 = sb.triangle(Vec3(0, 0, 2), Vec3(1, 0, 2), Vec3(0, 1, 2), two);
    LightSet set;
    set.build(sb.scene, LightSelection::Power);
    ASSERT_EQ(set.size(), 2u);
    const Vec3 up(0, 0, 1), down(0, 0, -1);
    EXPECT_EQ(set.emitted(t1, up), Vec3(2.0, 1.0, 0.5));
    EXPECT_EQ(set.emitted(t1, down), Vec3(0.0));
    EXPECT_EQ(set.emitted(t1, Vec3(1, 0, 0)), Vec3(0.0)); // edge-on: not the front side
    EXPECT_EQ(set.emitted(t2, up), Vec3(0.5));
    EXPECT_EQ(set.emitted(t2, down), Vec3(0.5));
    // Total power: pi L A per emitting side.
    double expect = kPi * 0.5 * (luminance(Vec3(2.0, 1.0, 0.5)) + 2.0 * 0.5);
    EXPECT_NEAR(set.total_power(), expect, 1e-14);
    // Samples seen from below the one-sided light carry radiance 0 but are valid; from
    // above they carry its emission. Both modes.
    for (LightSampling mode : {LightSampling::Area, LightSampling::SolidAngle}) {
        Pcg32 rng(3, 3u);
        for (int k = 0; k < 200; ++k) {
            Vec2 u = next_u(rng);
            // u_select small picks the first light (t1), large the second (t2).
            LightSample below = set.sample(Vec3(0.2, 0.2, -1.0), 0.01, u, mode);
            ASSERT_TRUE(below.valid);
            ASSERT_EQ(below.triangle, t1);
            EXPECT_EQ(below.radiance, Vec3(0.0));
            EXPECT_GT(below.pdf, 0.0);
            EXPECT_EQ(below.normal, up);
            LightSample above = set.sample(Vec3(0.2, 0.2, 1.0), 0.01, u, mode);
            ASSERT_TRUE(above.valid);
            EXPECT_EQ(above.radiance, Vec3(2.0, 1.0, 0.5));
            LightSample two_below = set.sample(Vec3(0.2, 0.2, 1.0), 0.999, u, mode);
            ASSERT_EQ(two_below.triangle, t2);
            EXPECT_EQ(two_below.radiance, Vec3(0.5));
        }
    }
}

TEST(RenderLights, EmptyAndDegenerateLightSets) {
    // No emissive material: empty, and sampling is invalid without crashing.
    SceneBuilder dull;
    int m = dull.material(Vec3(0.0));
    dull.triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), m);
    LightSet set;
    set.build(dull.scene, LightSelection::Power);
    EXPECT_TRUE(set.empty());
    EXPECT_EQ(set.total_power(), 0.0);
    EXPECT_EQ(set.light_index(0), -1);
    EXPECT_EQ(set.light_index(12345), -1);
    for (LightSampling mode : {LightSampling::Area, LightSampling::SolidAngle}) {
        LightSample s = set.sample(Vec3(0, 0, 1), 0.5, Vec2(0.5, 0.5), mode);
        EXPECT_FALSE(s.valid);
        EXPECT_EQ(set.pdf(Vec3(0, 0, 1), 0, Vec3(0.1, 0.1, 0.0), mode), 0.0);
    }
    EXPECT_EQ(set.emitted(0, Vec3(0, 0, 1)), Vec3(0.0));
    // An empty scene too.
    Scene empty;
    LightSet none;
    none.build(empty, LightSelection::Area);
    EXPECT_TRUE(none.empty());
    EXPECT_FALSE(none.sample(Vec3(0.0), 0.3, Vec2(0.2, 0.7), LightSampling::SolidAngle).valid);

    // Zero-area emissive triangles (collinear, coincident) are skipped; one real light
    // remains, selected with probability 1 and no table.
    SceneBuilder sb;
    int e = sb.material(Vec3(1.0));
    sb.triangle(Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), e);
    sb.triangle(Vec3(3, 0, 0), Vec3(3, 0, 0), Vec3(3, 0, 0), e);
    uint32_t real = sb.triangle(Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1), e);
    LightSet one;
    one.build(sb.scene, LightSelection::Power);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_EQ(one.light_index(0), -1);
    EXPECT_EQ(one.light_index(1), -1);
    EXPECT_EQ(one.light_index(real), 0);
    EXPECT_EQ(one.selection_pmf(0), 1.0);
    for (double u_select : {0.0, 0.5, 0.999999}) {
        LightSample s =
            one.sample(Vec3(0.2, 0.2, 2.0), u_select, Vec2(0.3, 0.3), LightSampling::SolidAngle);
        ASSERT_TRUE(s.valid);
        EXPECT_EQ(s.triangle, real);
    }
    // A reference point on the light's vertex: the area sample lands on it (u = 0 gives
    // vertex 0), or the solid-angle mode falls back to area samples seen edge-on: nothing
    // to sample, no crash.
    EXPECT_FALSE(one.sample(Vec3(0.0, 0.0, 1.0), 0.5, Vec2(0.0, 0.0), LightSampling::Area).valid);
    EXPECT_FALSE(
        one.sample(Vec3(0.0, 0.0, 1.0), 0.5, Vec2(0.4, 0.6), LightSampling::SolidAngle).valid);
}

// Issue 10: a light as bright as the largest doubles keeps a valid selection distribution
// (its power overflows, its selection weights do not), so light samples still find it; a
// zero-area emissive triangle and a non-finite emission are counted, never silently dropped.
TEST(LightSet, HugeRadianceKeepsAValidSelection) {
    Scene s = test::quad_light_scene(1e308);
    for (LightSelection sel :
         {LightSelection::Uniform, LightSelection::Area, LightSelection::Power}) {
        LightSet lights;
        lights.build(s, sel);
        ASSERT_EQ(lights.size(), 2u);
        EXPECT_EQ(lights.nonfinite(), 0u);
        EXPECT_DOUBLE_EQ(lights.selection_pmf(0) + lights.selection_pmf(1), 1.0);
        EXPECT_NEAR(lights.selection_pmf(0), 0.5, 1e-15); // the two halves of the quad
        for (double u : {0.1, 0.6}) {
            LightSample ls = lights.sample(Vec3(0.0), u, Vec2(0.3, 0.4), LightSampling::Area);
            EXPECT_TRUE(ls.valid);
            EXPECT_TRUE(std::isfinite(ls.pdf) && ls.pdf > 0.0);
            EXPECT_EQ(ls.radiance.x, 1e308);
        }
    }
    LightSet lights;
    lights.build(s, LightSelection::Power);
    EXPECT_TRUE(std::isinf(lights.total_power())); // pi x 1e308 x 1 m^2: not a number to trust
}

TEST(LightSet, DegenerateAndNonFiniteLightsAreCounted) {
    Scene s = test::quad_light_scene(5.0);
    Material nan_light = test::diffuse(0.0);
    nan_light.emission = Vec3(NAN, 1.0, 1.0);
    s.materials.push_back(nan_light);
    Material inf_light = test::diffuse(0.0);
    inf_light.emission = Vec3(INFINITY);
    s.materials.push_back(inf_light);
    uint32_t base = uint32_t(s.mesh.position.size());
    for (Vec3 p : {Vec3(0, 2, 0), Vec3(1, 2, 0), Vec3(2, 2, 0)}) s.mesh.position.push_back(p);
    s.mesh.index.push_back({base, base + 1, base + 2}); // collinear: zero area
    s.mesh.material.push_back(1);
    test::add_quad(s, {0, 3, 0}, {1, 3, 0}, {1, 3, 1}, {0, 3, 1}, 2); // NaN emission
    test::add_quad(s, {0, 4, 0}, {1, 4, 0}, {1, 4, 1}, {0, 4, 1}, 3); // infinite emission
    LightSet lights;
    lights.build(s, LightSelection::Power);
    EXPECT_EQ(lights.size(), 2u);
    EXPECT_EQ(lights.degenerate(), 1u);
    EXPECT_EQ(lights.nonfinite(), 4u);
    EXPECT_NEAR(lights.total_power(), 5.0 * kPi, 1e-12 * 5.0 * kPi);
}
