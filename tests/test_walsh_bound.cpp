// The Walsh error bound of one scrambled Sobol' sequence (core/walsh_bound.h): the transform is
// the discrete Walsh transform, doubling extends it exactly, the bound of a smooth integrand
// holds in (nearly) every randomization while it shrinks faster than K randomizations' error
// bars, and a run through the estimator pipeline reports it as its error bar.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "api/scene.h"
#include "core/qmc.h"
#include "core/rng.h"
#include "core/samplers.h"
#include "core/walsh_bound.h"
#include "estimators/registry.h"
#include "estimators/study.h"

using namespace mcp;

namespace {

int popcount(uint64_t x) {
    int c = 0;
    for (; x; x &= x - 1) ++c;
    return c;
}

// f(x) = prod_j (1 + 0.8 sin(2 pi (x_j - 1/4)) / j), integral exactly 1: smooth and periodic,
// its Walsh coefficients decay steadily (an integrand in the bound's cone).
double smooth(const double* x, int d) {
    double p = 1.0;
    for (int j = 0; j < d; ++j)
        p *= 1.0 + 0.8 * std::sin(6.283185307179586 * (x[j] - 0.25)) / (j + 1);
    return p;
}

// y in natural order: the values of f at the first n points of one lms_shift randomization.
std::vector<double> natural_values(int d, uint64_t n, uint64_t key) {
    std::vector<double> y(n);
    const QmcRandomizer q =
        make_qmc_randomizer(QmcKind::Sobol, QmcRandomization::LmsShift, d, key, n);
    std::vector<double> x(static_cast<size_t>(d));
    for (uint64_t i = 0; i < n; ++i) {
        for (int j = 0; j < d; ++j) x[static_cast<size_t>(j)] = qmc_coordinate(q, i, j);
        y[gray_natural_index(i)] = smooth(x.data(), d);
    }
    return y;
}

} // namespace

// The fast transform is (1/n) sum_i y_i (-1)^<nu,i>, and its coefficient 0 the mean: checked
// against the direct sum through the band sums of an identity-ordered map (m = 5: the map can
// only permute within the levels it reorders, so every band's total over all levels is the sum
// of all |coefficients| but the first).
TEST(WalshBound, TransformIsTheDiscreteWalshTransform) {
    const uint64_t n = 32;
    std::vector<double> y(n);
    Pcg32 rng(7, 1);
    for (double& v : y) v = rng.next_double() - 0.3;
    double direct_abs = 0.0, mean = 0.0;
    for (uint64_t nu = 0; nu < n; ++nu) {
        double c = 0.0;
        for (uint64_t i = 0; i < n; ++i) c += (popcount(nu & i) % 2 ? -1.0 : 1.0) * y[i];
        c /= static_cast<double>(n);
        if (nu == 0)
            mean = c;
        else
            direct_abs += std::fabs(c);
    }
    WalshBound w;
    w.start(y.data(), n);
    EXPECT_NEAR(w.mean(), mean, 1e-15);
    double bands = 0.0;
    for (int l = 1; l <= w.log2_size(); ++l) bands += w.band_sum(l);
    EXPECT_NEAR(bands, direct_abs, 1e-13);
    // The bound reads band m - 4 = 1 (one coefficient) with fudge 5 / 32.
    EXPECT_NEAR(w.bound(), 5.0 / 32.0 * w.band_sum(1), 1e-16);
}

// Doubling keeps every coefficient: the mean and the total of all bands after start(n) and
// one extend equal those of start(2n) on the same values.
TEST(WalshBound, ExtendingEqualsTransformingTheWhole) {
    const std::vector<double> y = natural_values(3, 4096, 11);
    WalshBound doubled, whole;
    doubled.start(y.data(), 2048);
    doubled.extend(y.data() + 2048);
    whole.start(y.data(), 4096);
    EXPECT_EQ(doubled.size(), 4096u);
    EXPECT_NEAR(doubled.mean(), whole.mean(), 1e-15);
    double a = 0.0, b = 0.0;
    for (int l = 1; l <= 12; ++l) {
        a += doubled.band_sum(l);
        b += whole.band_sum(l);
    }
    EXPECT_NEAR(a, b, 1e-12 * b);
    const WalshBound from_helper = walsh_bound_of(y);
    EXPECT_EQ(from_helper.log2_size(), 12);
    EXPECT_GT(from_helper.bound(), 0.0);
}

// On a smooth product in d = 3 (integral exactly 1), the bound holds in at least 95% of 200
// independent randomizations at N = 4096 (it is a bound for integrands in its cone: it should
// hold in nearly all), and it is not vacuous: its median is below the error bar of 16
// randomizations of N/16 points on the same budget.
TEST(WalshBound, HoldsOnASmoothIntegrandAndIsTighterThanRandomizations) {
    const int d = 3;
    const uint64_t n = 4096;
    int held = 0;
    std::vector<double> bounds;
    for (uint64_t key = 1; key <= 200; ++key) {
        const std::vector<double> y = natural_values(d, n, key * 7919);
        const WalshBound w = walsh_bound_of(y);
        held += std::fabs(w.mean() - 1.0) <= w.bound();
        bounds.push_back(w.bound());
    }
    EXPECT_GE(held, 190) << "the bound held in " << held << " of 200";
    std::nth_element(bounds.begin(), bounds.begin() + 100, bounds.end());
    const double median_bound = bounds[100];
    // 16 randomizations of 256 points: t_15 s_b / 4.
    double sum = 0.0, sum_sq = 0.0;
    for (uint64_t k = 0; k < 16; ++k) {
        const std::vector<double> y = natural_values(d, 256, 100000 + k);
        double mean = 0.0;
        for (double v : y) mean += v;
        mean /= 256.0;
        sum += mean;
        sum_sq += mean * mean;
    }
    const double var = (sum_sq - sum * sum / 16.0) / 15.0;
    const double half_width = 2.131 * std::sqrt(var / 16.0);
    EXPECT_LT(median_bound, half_width);
}

// Through a scene: sobol_walsh runs a study with the Walsh bound as its error bar and the
// error method named; its intervals cover the exact value of a smooth Genz integrand.
TEST(WalshBound, TheSobolWalshPresetReportsItsBound) {
    Json scene{{"name", "osc"},
               {"domain", {{"type", "box"}, {"dim", 3}}},
               {"integrand",
                {{"type", "genz_oscillatory"}, {"a", {3.0, 2.0, 4.0}}, {"u", {0.3, 0.2, 0.5}}}},
               {"estimators", {"sobol_walsh"}},
               {"n_min", 1024},
               {"n_max", 4096},
               {"reps", 20}};
    Made<SceneRequest> r = build_request(scene, Json::object());
    ASSERT_TRUE(r.ok()) << r.error;
    const EstimatorSpec& spec = r.value.estimators.front();
    EXPECT_TRUE(spec.walsh_bound);
    EXPECT_EQ(spec.randomization, QmcRandomization::LmsShift);
    EXPECT_EQ(spec.randomizations, 1);
    EXPECT_EQ(error_method_for(spec), ErrorMethod::WalshBound);
    EXPECT_STREQ(estimator_method(spec), "rqmc_walsh");
    const double exact = *r.value.problem.exact;
    Workspace ws;
    int covered = 0;
    for (int rep = 0; rep < 20; ++rep) {
        Pcg32 rng = replicate_rng(5, spec.name, 4096, rep);
        const RunResult run = run_estimate(r.value.problem, spec, 4096, rng, ws);
        ASSERT_GT(run.std_error, 0.0);
        EXPECT_EQ(run.n, 4096u);
        covered += std::fabs(run.estimate - exact) <= kNormal975 * run.std_error;
    }
    EXPECT_GE(covered, 18);
    // Below 2^10 points the cone's bands have not begun: no error bar, and a level of such runs
    // is neither "deterministic" nor covered.
    std::vector<RunResult> small;
    for (int rep = 0; rep < 4; ++rep) {
        Pcg32 rng = replicate_rng(5, spec.name, 512, rep);
        small.push_back(run_estimate(r.value.problem, spec, 512, rng, ws));
        EXPECT_TRUE(std::isnan(small.back().std_error));
        EXPECT_EQ(small.back().dof, 0);
    }
    const LevelStats level = summarise_level(small, r.value.problem);
    EXPECT_FALSE(level.deterministic);
    EXPECT_TRUE(std::isnan(level.coverage));
}

// What the Walsh bound needs is checked up front, each message naming the field.
TEST(WalshBound, ItsRequirementsAreCheckedWithAMessage) {
    auto error_of = [](Json estimator, uint64_t n_min, uint64_t n_max) {
        Json scene{{"name", "x"},
                   {"integrand", {{"type", "expression"}, {"f", "x*x"}}},
                   {"estimators", Json::array({estimator})},
                   {"n_min", n_min},
                   {"n_max", n_max}};
        Made<SceneRequest> r = build_request(scene, Json::object());
        return r.ok() ? std::string() : r.error;
    };
    const Json ok{{"name", "w"}, {"sampler", "sobol"}, {"error_bar", "walsh"}};
    EXPECT_EQ(error_of(ok, 1024, 65536), "");
    EXPECT_EQ(error_of("sobol_walsh", 1024, 65536), "");
    EXPECT_NE(
        error_of(Json{{"name", "w"}, {"sampler", "halton"}, {"error_bar", "walsh"}}, 1024, 65536)
            .find("error_bar: the Walsh bound is for the sobol sampler"),
        std::string::npos);
    EXPECT_NE(error_of(Json{{"name", "w"},
                            {"sampler", "sobol"},
                            {"error_bar", "walsh"},
                            {"randomization", "owen"}},
                       1024, 65536)
                  .find("randomization: the Walsh bound needs points that stay a digital net"),
              std::string::npos);
    EXPECT_NE(error_of(Json{{"name", "w"},
                            {"sampler", "sobol"},
                            {"error_bar", "walsh"},
                            {"randomizations", 4}},
                       1024, 65536)
                  .find("randomizations must be 1, got 4"),
              std::string::npos);
    EXPECT_NE(
        error_of(Json{{"name", "w"}, {"sampler", "sobol"}, {"error_bar", "spread"}}, 1024, 65536)
            .find("error_bar: expected \"randomizations\""),
        std::string::npos);
    EXPECT_NE(error_of(Json{{"name", "w"}, {"sampler", "independent"}, {"error_bar", "walsh"}},
                       1024, 65536)
                  .find("error_bar: applies to the quasi-Monte Carlo samplers only"),
              std::string::npos);
    EXPECT_NE(error_of(Json{{"name", "sobol_walsh"}, {"error_bar", "randomizations"}}, 1024, 65536)
                  .find("'sobol_walsh' is the preset with the Walsh error bar"),
              std::string::npos);
    EXPECT_EQ(error_of("sobol_walsh", 16, 65536), ""); // N < 1024: runs without an error bar
    EXPECT_NE(error_of("sobol_walsh", 16, 512).find("n_max must be at least 1024, got 512"),
              std::string::npos);
    EXPECT_NE(error_of("sobol_walsh", 1024, uint64_t(1) << 25).find("n_max must be at most 2^24"),
              std::string::npos);
}
