// Warps: round trips, domains, chi-square goodness of fit against the documented densities,
// normalisation of those densities, and the polar/concentric disk maps being different.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "core/rng.h"
#include "core/special.h"
#include "core/trig.h"
#include "core/warps.h"
#include "test_support.h"

using namespace mcp;

namespace {

constexpr double kTwoPi = 2.0 * kPi;
constexpr double kHalfPi = 0.5 * kPi;

// Six chi-square tests below (polar disk, concentric disk, triangle, sphere, hemisphere, cosine
// hemisphere) share a 1% family-wise level.
constexpr int kChiSquareTests = 6;
double chi_level() {
    return test::sidak_level(0.01, kChiSquareTests);
}
constexpr int kChiSamples = 200000;
constexpr int kRoundTrips = 5000;

Vec2 next_u(Pcg32& rng) {
    double u1 = rng.next_double();
    double u2 = rng.next_double();
    return {u1, u2};
}

/// Distance between two azimuth fractions: u = 0 and u = 1 are the same direction.
double azimuth_distance(double a, double b) {
    double d = std::fabs(a - b);
    return std::fmin(d, 1.0 - d);
}

/// Azimuth of (x, y) in [0, 2 pi), computed here independently of the library's inverses.
double azimuth(double x, double y) {
    double phi = std::atan2(y, x);
    return phi < 0.0 ? phi + kTwoPi : phi;
}

/// Composite Simpson rule with `intervals` (even) subintervals.
double simpson(const std::function<double(double)>& f, double lo, double hi, int intervals) {
    const double h = (hi - lo) / intervals;
    double sum = f(lo) + f(hi);
    for (int i = 1; i < intervals; ++i) sum += (i % 2 ? 4.0 : 2.0) * f(lo + i * h);
    return sum * h / 3.0;
}

/// Chi-square of directions binned in (theta, phi) cells, theta equally spaced on
/// [0, theta_max], against the solid-angle density pdf(cos theta): the expected probability of
/// a cell is dphi * integral of pdf(cos theta) sin theta dtheta (fine Simpson rule).
test::ChiSquareResult direction_chi_square(const std::function<Vec3(Vec2)>& sample,
                                           const std::function<double(double)>& pdf,
                                           double theta_max, int n_theta, int n_phi,
                                           uint64_t seed) {
    Pcg32 rng(seed, 1u);
    std::vector<double> observed(size_t(n_theta * n_phi), 0.0);
    for (int i = 0; i < kChiSamples; ++i) {
        Vec3 w = sample(next_u(rng));
        double theta = std::acos(std::fmax(-1.0, std::fmin(1.0, w.z)));
        int it = std::min(n_theta - 1, int(theta / theta_max * n_theta));
        int ip = std::min(n_phi - 1, int(azimuth(w.x, w.y) / kTwoPi * n_phi));
        observed[size_t(it * n_phi + ip)] += 1.0;
    }
    std::vector<double> expected(observed.size());
    const double dtheta = theta_max / n_theta, dphi = kTwoPi / n_phi;
    for (int it = 0; it < n_theta; ++it) {
        double p = dphi * simpson([&](double t) { return pdf(std::cos(t)) * std::sin(t); },
                                  it * dtheta, (it + 1) * dtheta, 64);
        for (int ip = 0; ip < n_phi; ++ip) expected[size_t(it * n_phi + ip)] = kChiSamples * p;
    }
    return test::chi_square(observed, expected);
}

/// Chi-square of disk points binned in polar cells: n_r rings equally spaced in r (not in
/// r^2, so the cells do not line up with the polar map's strata), n_phi sectors; expected
/// count = n * pdf * area of the annular sector.
test::ChiSquareResult disk_chi_square(Vec2 (*sample)(Vec2), uint64_t seed) {
    const int n_r = 10, n_phi = 16;
    Pcg32 rng(seed, 2u);
    std::vector<double> observed(n_r * n_phi, 0.0), expected(n_r * n_phi);
    for (int i = 0; i < kChiSamples; ++i) {
        Vec2 p = sample(next_u(rng));
        double r = std::sqrt(p.x * p.x + p.y * p.y);
        int ir = std::min(n_r - 1, int(r * n_r));
        int ip = std::min(n_phi - 1, int(azimuth(p.x, p.y) / kTwoPi * n_phi));
        observed[size_t(ir * n_phi + ip)] += 1.0;
    }
    for (int ir = 0; ir < n_r; ++ir) {
        double r0 = double(ir) / n_r, r1 = double(ir + 1) / n_r;
        double area = 0.5 * (r1 * r1 - r0 * r0) * (kTwoPi / n_phi);
        for (int ip = 0; ip < n_phi; ++ip)
            expected[size_t(ir * n_phi + ip)] = kChiSamples * disk_pdf() * area;
    }
    return test::chi_square(observed, expected);
}

} // namespace

// --- Exact values (from the formulas in warps.h) -------------------------------------------

TEST(Warps, KnownPoints) {
    const double tol = 1e-15;
    // Concentric map: the midpoints of the square's sides go to the axis points.
    Vec2 p = sample_disk_concentric({1.0, 0.5});
    EXPECT_NEAR(p.x, 1.0, tol);
    EXPECT_NEAR(p.y, 0.0, tol);
    p = sample_disk_concentric({0.5, 1.0});
    EXPECT_NEAR(p.x, 0.0, tol);
    EXPECT_NEAR(p.y, 1.0, tol);
    p = sample_disk_concentric({0.0, 0.5});
    EXPECT_NEAR(p.x, -1.0, tol);
    EXPECT_NEAR(p.y, 0.0, tol);
    p = sample_disk_concentric({0.5, 0.5});
    EXPECT_EQ(p.x, 0.0);
    EXPECT_EQ(p.y, 0.0);
    // A corner of the square goes to the diagonal direction on the unit circle.
    p = sample_disk_concentric({1.0, 1.0});
    EXPECT_NEAR(p.x, std::sqrt(0.5), tol);
    EXPECT_NEAR(p.y, std::sqrt(0.5), tol);
    Vec2 u = invert_disk_concentric({0.0, 0.0});
    EXPECT_EQ(u.x, 0.5);
    EXPECT_EQ(u.y, 0.5);

    // Polar map: r = sqrt(u1), phi = 2 pi u2.
    p = sample_disk_polar({0.25, 0.25});
    EXPECT_NEAR(p.x, 0.0, tol);
    EXPECT_NEAR(p.y, 0.5, tol);

    // Triangle: u1 = 1 gives the edge b0 = 0; u2 = 0 the edge b1 = 0.
    Vec2 b = sample_triangle_barycentric({1.0, 0.0});
    EXPECT_EQ(b.x, 0.0);
    EXPECT_EQ(b.y, 0.0);
    b = sample_triangle_barycentric({1.0, 1.0});
    EXPECT_EQ(b.x, 0.0);
    EXPECT_EQ(b.y, 1.0);
    b = sample_triangle_barycentric({0.25, 0.5});
    EXPECT_EQ(b.x, 0.5);
    EXPECT_EQ(b.y, 0.25);

    // Sphere: u1 = 0 is the north pole, u1 = 1/2 the equator.
    Vec3 w = sample_uniform_sphere({0.0, 0.3});
    EXPECT_EQ(w.z, 1.0);
    EXPECT_NEAR(std::hypot(w.x, w.y), 0.0, tol);
    w = sample_uniform_sphere({0.5, 0.0});
    EXPECT_NEAR(w.x, 1.0, tol);
    EXPECT_NEAR(w.z, 0.0, tol);
    w = sample_uniform_hemisphere({0.0, 0.25});
    EXPECT_NEAR(w.x, 0.0, tol);
    EXPECT_NEAR(w.y, 1.0, tol);
    EXPECT_EQ(w.z, 0.0);
    w = sample_cosine_hemisphere({0.5, 0.5});
    EXPECT_EQ(w.z, 1.0);

    // Inverses land in [0, 1)^2 even for the direction of azimuth 2 pi - tiny.
    u = invert_uniform_sphere({1.0, -1e-300, 0.0});
    EXPECT_GE(u.y, 0.0);
    EXPECT_LT(u.y, 1.0);
    u = invert_disk_polar({1.0, -0.0});
    EXPECT_EQ(u.y, 0.0);
    EXPECT_FALSE(std::signbit(u.y));
}

// --- Round trips ---------------------------------------------------------------------------

TEST(Warps, DiskPolarRoundTrip) {
    Pcg32 rng(1u, 10u);
    for (int i = 0; i < kRoundTrips; ++i) {
        Vec2 u = next_u(rng);
        Vec2 v = invert_disk_polar(sample_disk_polar(u));
        ASSERT_NEAR(v.x, u.x, 1e-9) << "u=" << u.x << "," << u.y;
        ASSERT_LE(azimuth_distance(v.y, u.y), 1e-9) << "u=" << u.x << "," << u.y;
        ASSERT_GE(v.x, 0.0);
        ASSERT_LT(v.x, 1.0);
        ASSERT_GE(v.y, 0.0);
        ASSERT_LT(v.y, 1.0);
    }
}

TEST(Warps, DiskConcentricRoundTrip) {
    Pcg32 rng(2u, 10u);
    for (int i = 0; i < kRoundTrips; ++i) {
        Vec2 u = next_u(rng);
        Vec2 v = invert_disk_concentric(sample_disk_concentric(u));
        ASSERT_NEAR(v.x, u.x, 1e-9) << "u=" << u.x << "," << u.y;
        ASSERT_NEAR(v.y, u.y, 1e-9) << "u=" << u.x << "," << u.y;
    }
    // The wedge boundaries |a| = |b| (the square's diagonals), where the forward and inverse
    // maps may pick different branches.
    for (int i = 1; i < 100; ++i) {
        double t = i / 100.0;
        for (Vec2 u : {Vec2{t, t}, Vec2{t, 1.0 - t}}) {
            Vec2 v = invert_disk_concentric(sample_disk_concentric(u));
            ASSERT_NEAR(v.x, u.x, 1e-9) << "u=" << u.x << "," << u.y;
            ASSERT_NEAR(v.y, u.y, 1e-9) << "u=" << u.x << "," << u.y;
        }
    }
}

TEST(Warps, TriangleRoundTrip) {
    Pcg32 rng(3u, 10u);
    int checked = 0;
    for (int i = 0; i < kRoundTrips; ++i) {
        Vec2 u = next_u(rng);
        // Near u1 = 0 the point approaches the vertex b0 = 1, where u2 is undetermined: the
        // inverse's u2 = b1 / (1 - b0) has error ~ 1e-16 / sqrt(u1).
        if (u.x < 1e-8) continue;
        Vec2 v = invert_triangle_barycentric(sample_triangle_barycentric(u));
        ASSERT_NEAR(v.x, u.x, 1e-9) << "u=" << u.x << "," << u.y;
        ASSERT_NEAR(v.y, u.y, 1e-9) << "u=" << u.x << "," << u.y;
        ++checked;
    }
    EXPECT_GT(checked, kRoundTrips - 10);
}

TEST(Warps, SphereRoundTrip) {
    Pcg32 rng(4u, 10u);
    for (int i = 0; i < kRoundTrips; ++i) {
        Vec2 u = next_u(rng);
        Vec2 v = invert_uniform_sphere(sample_uniform_sphere(u));
        ASSERT_NEAR(v.x, u.x, 1e-9) << "u=" << u.x << "," << u.y;
        ASSERT_LE(azimuth_distance(v.y, u.y), 1e-9) << "u=" << u.x << "," << u.y;
    }
}

TEST(Warps, HemisphereRoundTrip) {
    Pcg32 rng(5u, 10u);
    for (int i = 0; i < kRoundTrips; ++i) {
        Vec2 u = next_u(rng);
        Vec2 v = invert_uniform_hemisphere(sample_uniform_hemisphere(u));
        ASSERT_NEAR(v.x, u.x, 1e-9) << "u=" << u.x << "," << u.y;
        ASSERT_LE(azimuth_distance(v.y, u.y), 1e-9) << "u=" << u.x << "," << u.y;
    }
}

TEST(Warps, CosineHemisphereRoundTrip) {
    Pcg32 rng(6u, 10u);
    for (int i = 0; i < kRoundTrips; ++i) {
        Vec2 u = next_u(rng);
        Vec2 v = invert_cosine_hemisphere(sample_cosine_hemisphere(u));
        ASSERT_NEAR(v.x, u.x, 1e-9) << "u=" << u.x << "," << u.y;
        ASSERT_NEAR(v.y, u.y, 1e-9) << "u=" << u.x << "," << u.y;
    }
}

// --- Domains -------------------------------------------------------------------------------

TEST(Warps, SamplesLieInTheirDomains) {
    Pcg32 rng(7u, 11u);
    const double slack = 4e-16;
    for (int i = 0; i < 20000; ++i) {
        Vec2 u = next_u(rng);
        Vec2 p = sample_disk_polar(u);
        ASSERT_LE(p.x * p.x + p.y * p.y, 1.0 + slack);
        p = sample_disk_concentric(u);
        ASSERT_LE(p.x * p.x + p.y * p.y, 1.0 + slack);

        Vec2 b = sample_triangle_barycentric(u);
        ASSERT_GE(b.x, 0.0);
        ASSERT_GE(b.y, 0.0);
        ASSERT_LE(b.x + b.y, 1.0 + slack);

        Vec3 w = sample_uniform_sphere(u);
        ASSERT_NEAR(w.x * w.x + w.y * w.y + w.z * w.z, 1.0, 1e-15);
        w = sample_uniform_hemisphere(u);
        ASSERT_NEAR(w.x * w.x + w.y * w.y + w.z * w.z, 1.0, 1e-15);
        ASSERT_GE(w.z, 0.0);
        w = sample_cosine_hemisphere(u);
        ASSERT_NEAR(w.x * w.x + w.y * w.y + w.z * w.z, 1.0, 1e-15);
        ASSERT_GE(w.z, 0.0);
        ASSERT_GE(cosine_hemisphere_pdf(w.z), 0.0);
    }
}

// --- Chi-square goodness of fit ------------------------------------------------------------

TEST(Warps, DiskPolarChiSquare) {
    auto r = disk_chi_square(sample_disk_polar, 21u);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    EXPECT_GT(r.cells, 100);
}

TEST(Warps, DiskConcentricChiSquare) {
    auto r = disk_chi_square(sample_disk_concentric, 22u);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    EXPECT_GT(r.cells, 100);
}

// Barycentrics (b0, b1) -> the point (b1, b2) of the unit right triangle (0,0), (1,0), (0,1),
// where the uniform density is 2. On a k x k grid the cells wholly below the diagonal have
// area 1/k^2, those it cuts through (i + j = k - 1) half of that, the others none.
TEST(Warps, TriangleChiSquare) {
    const int k = 16;
    Pcg32 rng(23u, 3u);
    std::vector<double> observed(k * k, 0.0), expected(k * k, 0.0);
    int outside = 0;
    for (int n = 0; n < kChiSamples; ++n) {
        Vec2 b = sample_triangle_barycentric(next_u(rng));
        double x = b.y, y = 1.0 - b.x - b.y;
        int i = std::min(k - 1, int(x * k)), j = std::min(k - 1, int(std::fmax(y, 0.0) * k));
        if (i + j > k - 1) {
            // Only a point on the diagonal itself can round into the next cell.
            if (x + y > 1.0 + 1e-15) ++outside;
            j = k - 1 - i;
        }
        observed[size_t(j * k + i)] += 1.0;
    }
    EXPECT_EQ(outside, 0);
    for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
            double area = i + j < k - 1 ? 1.0 / (k * k) : (i + j == k - 1 ? 0.5 / (k * k) : 0.0);
            expected[size_t(j * k + i)] = kChiSamples * 2.0 * area;
        }
    auto r = test::chi_square(observed, expected);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    EXPECT_GT(r.cells, 100);
}

TEST(Warps, UniformSphereChiSquare) {
    auto r = direction_chi_square(
        sample_uniform_sphere, [](double) { return uniform_sphere_pdf(); }, kPi, 16, 16, 24u);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    EXPECT_GT(r.cells, 200);
}

TEST(Warps, UniformHemisphereChiSquare) {
    auto r = direction_chi_square(
        sample_uniform_hemisphere, [](double) { return uniform_hemisphere_pdf(); }, kHalfPi, 12, 16,
        25u);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    EXPECT_GT(r.cells, 150);
}

TEST(Warps, CosineHemisphereChiSquare) {
    auto r =
        direction_chi_square(sample_cosine_hemisphere, cosine_hemisphere_pdf, kHalfPi, 12, 16, 26u);
    EXPECT_GT(r.p_value, chi_level()) << "chi2=" << r.statistic << " dof=" << r.dof;
    EXPECT_GT(r.cells, 150);
}

// A warp into the wrong density must fail the same test: the uniform hemisphere's samples
// judged against the cosine density.
TEST(Warps, ChiSquareRejectsWrongDensity) {
    auto r = direction_chi_square(sample_uniform_hemisphere, cosine_hemisphere_pdf, kHalfPi, 12, 16,
                                  27u);
    EXPECT_LT(r.p_value, 1e-12);
}

// --- Densities integrate to one ------------------------------------------------------------

TEST(Warps, DensitiesIntegrateToOne) {
    const double tol = 1e-12;
    // Disk: integral over r of pdf * 2 pi r.
    double disk =
        test::gauss_legendre([](double r) { return disk_pdf() * kTwoPi * r; }, 0.0, 1.0, 16);
    EXPECT_NEAR(disk, 1.0, tol);
    // Directions: integral over theta of pdf(cos theta) * 2 pi sin theta.
    auto over_theta = [](double (*pdf)(double), double theta_max) {
        return test::gauss_legendre(
            [pdf](double t) { return pdf(std::cos(t)) * kTwoPi * std::sin(t); }, 0.0, theta_max,
            64);
    };
    EXPECT_NEAR(over_theta([](double) { return uniform_sphere_pdf(); }, kPi), 1.0, tol);
    EXPECT_NEAR(over_theta([](double) { return uniform_hemisphere_pdf(); }, kHalfPi), 1.0, tol);
    EXPECT_NEAR(over_theta(cosine_hemisphere_pdf, kHalfPi), 1.0, tol);
    // The cosine density vanishes below the horizon, so over the whole sphere it is still 1.
    EXPECT_NEAR(over_theta(cosine_hemisphere_pdf, kPi), 1.0, 1e-9);
    EXPECT_EQ(cosine_hemisphere_pdf(-0.5), 0.0);
    EXPECT_EQ(cosine_hemisphere_pdf(0.0), 0.0);
}

// --- Polar versus concentric ---------------------------------------------------------------

// Both maps are uniform (chi-square above) but they are different maps: the lower-left
// quarter [0, 1/2)^2 of the square goes to the upper half of the disk of radius sqrt(1/2)
// under the polar map (r < sqrt(1/2), phi in [0, pi)) and to the lower-left quadrant of the
// unit disk under the concentric map ((a, b) = 2u - 1 both negative).
TEST(Warps, PolarAndConcentricDiskMapsDiffer) {
    Pcg32 rng(8u, 12u);
    int far_from_centre = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec2 u = 0.5 * next_u(rng);
        Vec2 p = sample_disk_polar(u);
        ASSERT_GE(p.y, 0.0);
        ASSERT_LT(p.x * p.x + p.y * p.y, 0.5 + 1e-15);
        Vec2 q = sample_disk_concentric(u);
        ASSERT_LE(q.x, 1e-15);
        ASSERT_LE(q.y, 1e-15);
        far_from_centre += q.x * q.x + q.y * q.y > 0.5;
    }
    // The concentric quadrant reaches radius 1: (1 - 1/2) of its area lies beyond sqrt(1/2).
    EXPECT_GT(far_from_centre, 800);
    EXPECT_LT(far_from_centre, 1200);
    // And the maps disagree pointwise almost everywhere.
    Vec2 a = sample_disk_polar({0.3, 0.7}), c = sample_disk_concentric({0.3, 0.7});
    EXPECT_GT(std::hypot(a.x - c.x, a.y - c.y), 0.1);
}

// The warps' sine and cosine against long double references: within 2 ulp of the reference
// value (the evaluation's rounding; the Taylor truncation is below 1e-19), quarter-turn
// rotations and the ends included.
TEST(Trig, WithinTwoUlpOfLongDouble) {
    auto ulps = [](double got, long double ref) {
        const double r = static_cast<double>(ref);
        const double ulp = std::nextafter(std::fabs(r), 1.0 / 0.0) - std::fabs(r);
        // Below 2^-60 the long double reference's own error (of pi) is what remains.
        return static_cast<double>(std::fabs(static_cast<long double>(got) - ref)) /
               std::max(ulp, 0x1p-60);
    };
    const long double pi = 3.141592653589793238462643383279502884L;
    Pcg32 rng(2024, 12);
    double worst_quarter = 0.0, worst_turns = 0.0;
    std::vector<double> us = {0.0,  0.125, 0.25,    0.375,          0.5,           0.625,
                              0.75, 0.875, 0x1p-40, 0.25 - 0x1p-54, 0.5 + 0x1p-53, 1.0 - 0x1p-53};
    for (int i = 0; i < 100000; ++i) us.push_back(rng.next_double());
    for (double u : us) {
        const double t = (u - 0.5) * 0.5 * kPi; // [-pi/4, pi/4)
        const SinCos a = sincos_quarter(t);
        worst_quarter = std::max({worst_quarter, ulps(a.sin, std::sin(static_cast<long double>(t))),
                                  ulps(a.cos, std::cos(static_cast<long double>(t)))});
        const SinCos b = sincos_turns(u);
        const long double phi = 2.0L * pi * static_cast<long double>(u);
        worst_turns =
            std::max({worst_turns, ulps(b.sin, std::sin(phi)), ulps(b.cos, std::cos(phi))});
    }
    EXPECT_LE(worst_quarter, 2.0);
    EXPECT_LE(worst_turns, 2.0);
}
