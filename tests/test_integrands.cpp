// Closed forms against independent quadrature: the built-in families' exact integrals over
// boxes, and the exact values written into the 1D and 2D scenes of scenes/.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include "api/scene.h"
#include "core/quadrature.h"
#include "core/rng.h"
#include "core/special.h"

using namespace mcp;

namespace {

// Nested adaptive Gauss-Kronrod over a box of dimension 1 or 2, split at the given interior
// points of the first axis (discontinuities, singularities).
// Endpoint singularities: x = a + L q(s) with the quintic q(s) = 6s^5 - 15s^4 + 10s^3,
// q'(s) = 30 s^2 (1-s)^2, turns |x - a|^-alpha into the milder s^(2 - 3 alpha).
double quad_piece(const std::function<double(double)>& g, double a, double b, bool singular) {
    if (!singular) return integrate_adaptive(g, a, b, 1e-11).value;
    const double len = b - a;
    auto h = [&](double t) {
        const double q = t * t * t * (10.0 + t * (-15.0 + 6.0 * t));
        const double dq = 30.0 * t * t * (1.0 - t) * (1.0 - t);
        return g(a + len * q) * len * dq;
    };
    return integrate_adaptive(h, 0.0, 1.0, 1e-11, 0.0, 20000).value;
}

double quad_box(const Integrand& f, const std::vector<double>& lo, const std::vector<double>& hi,
                std::vector<double> splits = {}, bool singular = false) {
    std::vector<double> edges{lo[0]};
    for (double s : splits) edges.push_back(s);
    edges.push_back(hi[0]);
    double total = 0.0;
    for (size_t k = 0; k + 1 < edges.size(); ++k) {
        auto outer = [&](double x) {
            if (f.dim == 1) return evaluate_point(f, &x);
            auto inner = [&](double y) {
                const double p[2] = {x, y};
                return evaluate_point(f, p);
            };
            return integrate_adaptive(inner, lo[1], hi[1], 1e-12).value;
        };
        total += quad_piece(outer, edges[k], edges[k + 1], singular);
    }
    return total;
}

SceneRequest load(const std::string& name) {
    std::ifstream in(std::string(MCPLAY_SOURCE_DIR) + "/scenes/" + name + ".json");
    std::stringstream ss;
    ss << in.rdbuf();
    Made<Json> j = parse_json(ss.str().c_str(), name.c_str());
    EXPECT_TRUE(j.ok()) << j.error;
    Made<SceneRequest> r = build_request(j.value, Json());
    EXPECT_TRUE(r.ok()) << r.error;
    return r.value;
}

} // namespace

TEST(ClosedForms, BuiltInFamiliesMatchQuadrature) {
    Pcg32 rng(12, 34);
    for (int trial = 0; trial < 6; ++trial) {
        for (int dim = 1; dim <= 2; ++dim) {
            std::vector<double> lo, hi, powers, rates, center;
            for (int j = 0; j < dim; ++j) {
                lo.push_back(-0.5 + rng.next_double());
                hi.push_back(lo.back() + 0.2 + 2.0 * rng.next_double());
                powers.push_back(std::floor(4.0 * rng.next_double()));
                rates.push_back(-3.0 + 6.0 * rng.next_double());
                center.push_back(lo.back() + (hi.back() - lo.back()) * rng.next_double());
            }
            const double sigma = 0.05 + 0.5 * rng.next_double();
            std::vector<Made<Integrand>> fs = {
                make_integrand(IntegrandKind::Constant, dim, 2.5, {}, {}, 1.0),
                make_integrand(IntegrandKind::Monomial, dim, 1.5, powers, {}, 1.0),
                make_integrand(IntegrandKind::Exponential, dim, 0.7, rates, {}, 1.0),
                make_integrand(IntegrandKind::Gaussian, dim, 1.0, {}, center, sigma)};
            for (auto& f : fs) {
                ASSERT_TRUE(f.ok()) << f.error;
                std::optional<double> exact = exact_integral_over_box(f.value, lo, hi);
                ASSERT_TRUE(exact.has_value());
                const double q = quad_box(f.value, lo, hi);
                EXPECT_NEAR(*exact, q, 1e-9 * std::fabs(q) + 1e-13)
                    << integrand_kind_name(f.value.kind) << " dim " << dim << " trial " << trial;
            }
        }
    }
    // Non-integer power on [0, b] (singular derivative at 0) and a ball inside a box.
    Made<Integrand> root = make_integrand(IntegrandKind::Monomial, 1, 1.0, {-0.5}, {}, 1.0);
    ASSERT_TRUE(root.ok());
    EXPECT_NEAR(*exact_integral_over_box(root.value, {0.0}, {3.0}), 2.0 * std::sqrt(3.0), 1e-15);
    Made<Integrand> ball =
        make_integrand(IntegrandKind::IndicatorBall, 2, 1.0, {}, {0.5, 0.5}, 0.3);
    ASSERT_TRUE(ball.ok());
    EXPECT_NEAR(*exact_integral_over_box(ball.value, {0, 0}, {1, 1}), kPi * 0.09, 1e-15);
    EXPECT_FALSE(exact_integral_over_box(ball.value, {0, 0}, {0.7, 1}).has_value()); // sticks out
}

TEST(ClosedForms, SceneExactValuesMatchQuadrature) {
    struct Case {
        const char* scene;
        std::vector<double> splits; // interior points where f is not smooth
        double tolerance;           // relative
        bool singular = false;      // f has integrable singularities at the piece ends
    };
    const Case cases[] = {
        {"exp_1d", {}, 1e-12},
        {"gaussian_peak_1d", {0.5}, 1e-10},
        {"expectation_4xy", {}, 1e-12},
        {"gaussian_2d", {0.3}, 1e-9},
        {"sin_product_2d", {}, 1e-11},
        {"oscillatory_cos1000", {}, 1e-8},
        {"offset_1e8_sin", {}, 1e-14},
        {"step_1d", {0.3}, 1e-12},
        {"singular_power_0.3", {}, 1e-10, true},
        {"singular_power_0.5", {}, 1e-10, true},
        {"singular_power_0.9", {}, 1e-6, true},
        {"heavy_tail_abs", {0.5}, 1e-8, true},
    };
    for (const Case& c : cases) {
        SceneRequest req = load(c.scene);
        ASSERT_TRUE(req.problem.exact.has_value()) << c.scene;
        const Domain& d = req.problem.domain;
        ASSERT_EQ(d.kind, DomainKind::Box);
        double q = quad_box(req.problem.integrand, d.lo, d.hi, c.splits, c.singular);
        if (req.problem.quantity == Quantity::Mean) q /= d.measure();
        EXPECT_NEAR(*req.problem.exact, q, c.tolerance * std::fabs(q)) << c.scene;
    }
}

TEST(ClosedForms, NonBoxSceneExactValues) {
    // Hemisphere: int cos^2(theta) d omega = 2 pi int_0^1 z^2 dz.
    SceneRequest h = load("hemisphere_cos2");
    EXPECT_NEAR(*h.problem.exact,
                2 * kPi * integrate_adaptive([](double z) { return z * z; }, 0, 1).value, 1e-14);
    // Triangle (0,0) (1,0) (0,1): int x dA = int_0^1 x (1 - x) dx.
    SceneRequest t = load("triangle_moment");
    EXPECT_NEAR(*t.problem.exact,
                integrate_adaptive([](double x) { return x * (1 - x); }, 0, 1).value, 1e-15);
    // Disks: P(r < a) = a^2 for a uniform point of the unit disk.
    EXPECT_NEAR(*load("disk_quarter").problem.exact, 0.25, 1e-15);
    EXPECT_NEAR(*load("disk_third").problem.exact, 1.0 / 9.0, 1e-15);
}
