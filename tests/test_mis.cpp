// Multiple importance sampling [Veach97, ch. 9] and its optimal weights [Kondapaneni19]: the
// shared weight functions, each combination's variance against the value its formula gives
// (computed by quadrature), calibrated error bars, the balance heuristic never above the worst
// single technique, optimal weights at or below the balance heuristic, and a narrow and a wide
// pdf that each fail where their combination does not.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "api/scene.h"
#include "core/mis.h"
#include "core/regression.h"
#include "estimators/block_driver.h"
#include "independent_runs.h"
#include "test_support.h"

using namespace mcp;

namespace {

const char* kPeak = R"({"type": "gaussian", "mu": 0.3, "sigma": 0.08})";

/// f = 1 + x + a Gaussian bump (sigma 0.05 at 0.3) on [0, 1]; techniques: a Gaussian pdf
/// (sigma 0.08 at 0.3, truncated to [0, 1]) and the uniform density.
/// Its integral: 1.5 + Phi(14) - Phi(-6).
const double kExact =
    2.5 - 0.5 * std::erfc(6.0 / std::sqrt(2.0)) - 0.5 * std::erfc(14.0 / std::sqrt(2.0));

Made<SceneRequest> request(const std::string& estimators, const std::string& f = "",
                           double exact = kExact) {
    const std::string integrand =
        f.empty() ? "1 + x + exp(-0.5 * ((x - 0.3) / 0.05)^2) / (0.05 * sqrt(2 * pi))" : f;
    char exact_text[64];
    std::snprintf(exact_text, sizeof exact_text, "%.17g", exact);
    const std::string scene = R"({"name": "m", "domain": {"type": "interval", "lower": 0,
        "upper": 1}, "integrand": ")" +
                              integrand + R"(", "exact": )" + exact_text + R"(, "estimators": )" +
                              estimators + "}";
    Made<Json> j = parse_json(scene.c_str(), "scene");
    EXPECT_TRUE(j.ok()) << j.error;
    return build_request(j.value, Json());
}

std::string mis(const std::string& name, const std::string& fields, const char* peak = kPeak) {
    return R"({"name": ")" + name + R"(", "proposals": [)" + peak + R"(, "uniform"])" + fields +
           "}";
}

double density(const Proposal& p, const Domain& d, double x) {
    PointBlock b;
    b.reset(1, 1);
    b.n = 1;
    b.coord(0)[0] = x;
    double pdf = 0.0;
    proposal_pdf_block(p, d, b, &pdf);
    return pdf;
}

double value(const Integrand& f, double x) {
    PointBlock b;
    b.reset(1, 1);
    b.n = 1;
    b.coord(0)[0] = x;
    double v = 0.0;
    evaluate_block(f, b, &v);
    return v;
}

/// The variance of an MIS estimate with N points, from its formula by quadrature:
/// multi-sample (1/N^2) sum_k n_k Var_k(y_k), one-sample (1/N) Var(y) under the mixture, with
/// y_k = w_k f / (a_k p_k) [Veach97, 9.2].
double mis_variance(const Problem& problem, const MisOptions& m, uint64_t n, bool one_sample) {
    const Domain& d = problem.domain;
    const size_t k_count = m.proposals.size();
    std::vector<double> a(k_count);
    std::vector<uint64_t> counts(k_count, n >= 2 * k_count ? 2 : 0);
    if (!one_sample) allocate_largest_remainders(n - counts[0] * k_count, m.fractions, &counts);
    for (size_t k = 0; k < k_count; ++k)
        a[k] = one_sample ? m.fractions[k] : static_cast<double>(counts[k]) / n;
    auto y_of = [&](size_t k, double x) {
        std::vector<double> q(k_count);
        for (size_t j = 0; j < k_count; ++j) q[j] = a[j] * density(m.proposals[j], d, x);
        const double w =
            mis_weight(m.weighting, q.data(), static_cast<int>(k_count), static_cast<int>(k));
        return q[k] > 0.0 ? w * value(problem.integrand, x) / q[k] : 0.0;
    };
    const double exact = *problem.exact;
    double total = 0.0;
    for (size_t k = 0; k < k_count; ++k) {
        const double p2 = test::gauss_legendre(
            [&](double x) {
                const double y = y_of(k, x);
                return y * y * density(m.proposals[k], d, x);
            },
            0.0, 1.0, 400);
        const double p1 = test::gauss_legendre(
            [&](double x) { return y_of(k, x) * density(m.proposals[k], d, x); }, 0.0, 1.0, 400);
        total += one_sample ? a[k] * p2 : static_cast<double>(counts[k]) * (p2 - p1 * p1);
    }
    const double nn = static_cast<double>(n);
    return one_sample ? (total - exact * exact) / nn : total / (nn * nn);
}

} // namespace

TEST(MisWeights, HeuristicsSumToOneAndFollowTheirFormulas) {
    const double q[3] = {0.2, 1.0, 3.0};
    for (MisHeuristic h : {MisHeuristic::Balance, MisHeuristic::Power, MisHeuristic::Maximum,
                           MisHeuristic::Cutoff}) {
        MisWeighting w{h, 2.0, 0.1};
        double sum = 0.0;
        for (int i = 0; i < 3; ++i) sum += mis_weight(w, q, 3, i);
        EXPECT_NEAR(sum, 1.0, 1e-15) << mis_heuristic_name(h);
    }
    EXPECT_NEAR(mis_weight({MisHeuristic::Balance}, q, 3, 1), 1.0 / 4.2, 1e-15);
    EXPECT_NEAR(mis_weight({MisHeuristic::Power, 2.0}, q, 3, 1), 1.0 / (0.04 + 1.0 + 9.0), 1e-15);
    EXPECT_NEAR(mis_weight({MisHeuristic::Power, 3.0}, q, 3, 2), 27.0 / (0.008 + 1.0 + 27.0),
                1e-15);
    EXPECT_EQ(mis_weight({MisHeuristic::Maximum}, q, 3, 2), 1.0);
    EXPECT_EQ(mis_weight({MisHeuristic::Maximum}, q, 3, 1), 0.0);
    // Cutoff 0.1 of q_max = 3 drops 0.2: the rest share by balance.
    EXPECT_EQ(mis_weight({MisHeuristic::Cutoff, 2.0, 0.1}, q, 3, 0), 0.0);
    EXPECT_NEAR(mis_weight({MisHeuristic::Cutoff, 2.0, 0.1}, q, 3, 2), 0.75, 1e-15);
    // Ties under the maximum heuristic go to the lowest index: still one weight of 1.
    const double tie[2] = {2.0, 2.0};
    EXPECT_EQ(mis_weight({MisHeuristic::Maximum}, tie, 2, 0), 1.0);
    EXPECT_EQ(mis_weight({MisHeuristic::Maximum}, tie, 2, 1), 0.0);
}

TEST(MisWeights, ExtremeDensitiesNeitherOverflowNorGiveNaN) {
    const MisWeighting power{MisHeuristic::Power, 2.0};
    EXPECT_NEAR(mis_weight(power, 1e300, 1e-300), 1.0, 1e-15);
    EXPECT_NEAR(mis_weight(power, 1e-300, 1e300), 0.0, 1e-15);
    EXPECT_EQ(mis_weight(power, 0.0, 1.0), 0.0);
    EXPECT_EQ(mis_weight(power, 1.0, 0.0), 1.0);
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(mis_weight(power, inf, 1.0), 1.0); // a delta density takes the point
    EXPECT_EQ(mis_weight(power, 1.0, inf), 0.0);
    EXPECT_EQ(mis_weight(power, inf, inf), 0.5);
    EXPECT_EQ(mis_weight({MisHeuristic::Balance}, inf, inf), 0.5);
    EXPECT_EQ(mis_weight(power, std::nan(""), 1.0), 0.0);
    EXPECT_EQ(mis_weight(power, 1.0, std::nan("")), 1.0);
}

TEST(Regression, CovarianceMatchesTwoPassAndSolveDropsDependentColumns) {
    // z = (t, 2t + 1, t^2) for t = 0..999, added in uneven blocks.
    std::vector<double> t(1000), u(1000), v(1000);
    for (int i = 0; i < 1000; ++i) {
        t[i] = 1e6 + i * 0.001; // a large offset: centring must not lose the spread
        u[i] = 2.0 * t[i] + 1.0;
        v[i] = (i * 0.001) * (i * 0.001);
    }
    RunningCovariance c;
    c.reset(3);
    for (size_t first = 0; first < 1000; first += 97) {
        const size_t n = std::min<size_t>(97, 1000 - first);
        const double* cols[3] = {t.data() + first, u.data() + first, v.data() + first};
        c.add_block(cols, n);
    }
    double mt = 0, mv = 0;
    for (int i = 0; i < 1000; ++i) mt += t[i], mv += v[i];
    mt /= 1000, mv /= 1000;
    double ctt = 0, ctv = 0;
    for (int i = 0; i < 1000; ++i)
        ctt += (t[i] - mt) * (t[i] - mt), ctv += (t[i] - mt) * (v[i] - mv);
    EXPECT_NEAR(c.mean(0), mt, 1e-9);
    EXPECT_NEAR(c.comoment(0, 0), ctt, 1e-8 * ctt);
    EXPECT_NEAR(c.comoment(0, 2), ctv, 1e-8 * std::fabs(ctv));
    // Columns (t, 2t + 1): the second is the first's double plus a constant after centring, so
    // on centred co-moments it is dependent and dropped.
    std::vector<double> a = {c.comoment(0, 0), c.comoment(0, 1), c.comoment(1, 0),
                             c.comoment(1, 1)};
    std::vector<double> b = {c.comoment(0, 2), c.comoment(1, 2)}, x;
    EXPECT_EQ(solve_psd(a, b, 2, &x), 1);
    EXPECT_EQ(x[1], 0.0);
    EXPECT_NEAR(x[0], ctv / ctt, 1e-9 * std::fabs(ctv / ctt));
}

// R = 400 runs at N = 1024 of each combination: the variance of the estimates matches the
// formula's (R - 1) s^2 / V ~ chi^2(399): inside [0.80, 1.23] V (two-sided p = 0.002), the mean
// within 4 standard errors of the exact value, and the 95% intervals cover 90-99% of the time.
TEST(Mis, EveryCombinationHasTheVarianceItsFormulaGivesAndHonestIntervals) {
    Made<SceneRequest> r = request("[" + mis("balance", R"(, "heuristic": "balance")") + "," +
                                   mis("power", R"(, "heuristic": "power")") + "," +
                                   mis("power3", R"(, "heuristic": "power", "beta": 3)") + "," +
                                   mis("maximum", R"(, "heuristic": "maximum")") + "," +
                                   mis("cutoff", R"(, "heuristic": "cutoff", "cutoff": 0.3)") +
                                   "," + mis("uneven", R"(, "fractions": [3, 1])") + "," +
                                   mis("one_sample", R"(, "one_sample": true)") + "]");
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const double exact = *problem.exact;
    const uint64_t n = 1024;
    const int runs = 400;
    for (size_t e = 0; e < r.value.estimators.size(); ++e) {
        const EstimatorSpec& spec = r.value.estimators[e];
        const double v = mis_variance(problem, spec.mis_options, n, spec.mis_options.one_sample);
        const test::IndependentRuns s =
            test::independent_runs(problem, spec, n, runs, 17, e, exact);
        EXPECT_TRUE(s.every_n_reported) << spec.name;
        EXPECT_GT(s.variance, 0.80 * v) << spec.name;
        EXPECT_LT(s.variance, 1.23 * v) << spec.name;
        EXPECT_LE(std::fabs(s.mean - exact), 4.0 * std::sqrt(v / runs)) << spec.name;
        EXPECT_GE(s.covered, static_cast<int>(0.90 * runs)) << spec.name;
        EXPECT_LE(s.covered, static_cast<int>(0.99 * runs)) << spec.name;
    }
}

// Veach's theorem 9.2: the balance heuristic's variance is never much above that of any other
// combination of the same samples, and so not above the worse technique used alone (each
// alone with all N points). Here both single techniques are finite-variance; the formula's
// variances are compared, and the measured ones agree with them (previous test).
TEST(Mis, BalanceIsNeverAboveTheWorstSingleTechnique) {
    const char* wide = R"({"type": "gaussian", "mu": 0.3, "sigma": 0.3})";
    Made<SceneRequest> r = request("[" + mis("balance", "", wide) +
                                   R"(, {"name": "peak", "pdf": )" + wide + R"(}, "uniform"])");
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const uint64_t n = 1024;
    const double balance = mis_variance(problem, r.value.estimators[0].mis_options, n, false);
    double worst = 0.0;
    for (size_t e = 1; e < 3; ++e) {
        MisOptions alone;
        alone.proposals = {r.value.estimators[e].proposal};
        alone.fractions = {1.0};
        worst = std::max(worst, mis_variance(problem, alone, n, false));
        // and measured: the single technique's runs agree with its formula
        const test::IndependentRuns s =
            test::independent_runs(problem, r.value.estimators[e], n, 400, 23, e, *problem.exact);
        EXPECT_GT(s.variance, 0.80 * mis_variance(problem, alone, n, false)) << e;
        EXPECT_LT(s.variance, 1.23 * mis_variance(problem, alone, n, false)) << e;
    }
    EXPECT_LE(balance, worst);
}

// Optimal MIS [Kondapaneni19]: R = 400 runs each: its variance is at or below the balance
// heuristic's (s_opt^2 / s_bal^2 below F(399, 399) at p = 0.001, about 1.36), its intervals
// cover, and where f is a combination of the densities it is exact.
TEST(Mis, OptimalWeightsAreAtOrBelowBalanceAndExactOnACombinationOfTheDensities) {
    Made<SceneRequest> r =
        request("[" + mis("balance", "") + "," + mis("optimal", R"(, "heuristic": "optimal")") +
                "," + mis("optimal_one", R"(, "heuristic": "optimal", "one_sample": true)") + "]");
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const double exact = *problem.exact;
    const int runs = 400;
    double variance[3];
    for (size_t e = 0; e < 3; ++e) {
        const test::IndependentRuns s =
            test::independent_runs(problem, r.value.estimators[e], 1024, runs, 31, e, exact);
        variance[e] = s.variance;
        EXPECT_LE(std::fabs(s.mean - exact), 4.0 * std::sqrt(s.variance / runs)) << e;
        EXPECT_GE(s.covered, static_cast<int>(0.90 * runs)) << e;
        EXPECT_LE(s.covered, static_cast<int>(0.99 * runs)) << e;
    }
    EXPECT_LT(variance[1], 1.36 * variance[0]);
    EXPECT_LT(variance[2], 1.36 * variance[0]);

    // f = 3 p_uniform + 2 Z p_peak, with Z = Phi(8.75) - Phi(-3.75) the truncated Gaussian's
    // mass on [0, 1]: the regression fits it exactly, so every run returns 3 + 2 Z.
    Made<SceneRequest> c =
        request("[" + mis("optimal", R"(, "heuristic": "optimal")") + "]",
                "3 + 2 * exp(-0.5 * ((x - 0.3) / 0.08)^2) / (0.08 * sqrt(2 * pi))", 5.0);
    ASSERT_TRUE(c.ok()) << c.error;
    Workspace ws;
    Pcg32 rng(5u, 5u);
    const RunResult one = run_estimate(c.value.problem, c.value.estimators[0], 4096, rng, ws);
    PointBlock mid;
    mid.reset(1, 1);
    mid.n = 1;
    mid.coord(0)[0] = 0.3;
    // The truncated pdf's normaliser, from the code's own density at the mode.
    double p_mode = 0.0;
    proposal_pdf_block(c.value.estimators[0].mis_options.proposals[0], c.value.problem.domain, mid,
                       &p_mode);
    const double z = 1.0 / (0.08 * std::sqrt(2.0 * M_PI) * p_mode);
    EXPECT_NEAR(z, 0.5 * (std::erf(8.75 / std::sqrt(2.0)) + std::erf(3.75 / std::sqrt(2.0))),
                1e-12);
    EXPECT_NEAR(one.estimate, 3.0 + 2.0 * z, 1e-9);
    EXPECT_LT(one.std_error, 1e-9);
}

// A narrow pdf that never sees the plateau and a uniform one that rarely sees the peak: the
// narrow one alone is flagged (heavy tail / biased: it is zero where f is not), the uniform one
// has 50x the variance of their balance-heuristic combination, which is unbiased.
TEST(Mis, ANarrowAndAWidePdfEachFailWhereTheirCombinationDoesNot) {
    const char* narrow = R"({"type": "gaussian", "mu": 0.3, "sigma": 0.012})";
    const std::string f = "1 + x + exp(-0.5 * ((x - 0.3) / 0.01)^2) / (0.01 * sqrt(2 * pi))";
    Made<SceneRequest> r = request(std::string(R"([{"name": "narrow", "pdf": )") + narrow +
                                       R"(}, "uniform", {"name": "mis", "proposals": [)" + narrow +
                                       R"(, "uniform"]}])",
                                   f, 2.5);
    ASSERT_TRUE(r.ok()) << r.error;
    const Problem& problem = r.value.problem;
    const double exact = 2.5; // 1.5 + the whole bump (its mass outside [0, 1] is below 1e-190)
    const int runs = 200;
    const test::IndependentRuns narrow_runs =
        test::independent_runs(problem, r.value.estimators[0], 4096, runs, 41, 0, exact);
    const test::IndependentRuns uniform_runs =
        test::independent_runs(problem, r.value.estimators[1], 4096, runs, 41, 1, exact);
    const test::IndependentRuns mis_runs =
        test::independent_runs(problem, r.value.estimators[2], 4096, runs, 41, 2, exact);
    // The narrow pdf's density underflows beyond |x - 0.3| ~ 0.45: its mean misses f there.
    EXPECT_GT(std::fabs(narrow_runs.mean - exact), 10.0 * std::sqrt(narrow_runs.variance / runs));
    EXPECT_GT(uniform_runs.variance, 50.0 * mis_runs.variance);
    EXPECT_LE(std::fabs(mis_runs.mean - exact), 4.0 * std::sqrt(mis_runs.variance / runs));
    EXPECT_GE(mis_runs.covered, static_cast<int>(0.90 * runs));
}

// Small budgets: every run finishes with N reported, down to fewer points than techniques.
TEST(Mis, RunsOfOneToFortyPointsFinish) {
    Made<SceneRequest> r =
        request("[" + mis("balance", "") + "," + mis("optimal", R"(, "heuristic": "optimal")") +
                "," + mis("one", R"(, "one_sample": true)") + "]");
    ASSERT_TRUE(r.ok()) << r.error;
    Workspace ws;
    for (const EstimatorSpec& spec : r.value.estimators)
        for (uint64_t n = 1; n <= 40; ++n) {
            Pcg32 rng(n, 9u);
            const RunResult run = run_estimate(r.value.problem, spec, n, rng, ws);
            EXPECT_EQ(run.n, n) << spec.name;
            EXPECT_TRUE(std::isfinite(run.estimate)) << spec.name << " n = " << n;
        }
}
