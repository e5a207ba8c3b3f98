#include "core/quadrature.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <vector>

namespace mcp {

namespace {

// The 15-point Kronrod rule and its embedded 7-point Gauss-Legendre rule on [-1, 1]
// [Kronrod65], as tabulated in QUADPACK's QK15 [Piessens83]: nodes in decreasing order,
// kXgk[1], kXgk[3], kXgk[5], kXgk[7] = 0 are the Gauss nodes (roots of P_7). The digits were
// recomputed to 34 places (Gauss nodes by Newton on P_7, weights 2 / ((1 - x^2) P_7'(x)^2),
// then the Kronrod nodes and weights as the solution of the 12 moment equations
// sum w x^2k = 2 / (2k + 1), k = 0..11); they agree with QUADPACK's table except kXgk[4],
// whose published value is wrong from the 27th digit on (harmless in double precision).
// tests/test_quadrature.cpp checks exactness up to degree 22 (K15) and 13 (G7), which
// determines every digit that a double can hold.
constexpr double kXgk[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144838258730, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
constexpr double kWgk[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kWg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                           0.381830050505118944950369775488975,
                           0.417959183673469387755102040816327};

struct Interval {
    double a, b, value, error;
};

bool smaller_error(const Interval& x, const Interval& y) {
    return x.error < y.error;
}

// Bisection must leave children whose outermost nodes (at 0.43% of the width from an end)
// are distinct from the end points and from each other, and in the normal range.
bool bisectable(const Interval& w) {
    const double width = w.b - w.a;
    const double scale = std::max(std::fabs(w.a), std::fabs(w.b));
    return width > 2000.0 * DBL_EPSILON * scale && width > 0x1p-900;
}

} // namespace

GaussKronrodEstimate gauss_kronrod_15(const std::function<double(double)>& f, double a, double b) {
    const double center = 0.5 * a + 0.5 * b; // no overflow for huge |a|, |b|
    const double half = 0.5 * b - 0.5 * a;
    const double abs_half = std::fabs(half);

    const double fc = f(center);
    double res_g = fc * kWg[3];
    double res_k = fc * kWgk[7];
    double res_abs = std::fabs(res_k);
    double fv1[7], fv2[7];
    for (int j = 0; j < 7; ++j) {
        const double dx = half * kXgk[j];
        const double f1 = f(center - dx), f2 = f(center + dx);
        fv1[j] = f1;
        fv2[j] = f2;
        res_k += kWgk[j] * (f1 + f2);
        res_abs += kWgk[j] * (std::fabs(f1) + std::fabs(f2));
        if (j % 2 == 1) res_g += kWg[j / 2] * (f1 + f2);
    }
    const double mean = 0.5 * res_k;
    double res_asc = kWgk[7] * std::fabs(fc - mean);
    for (int j = 0; j < 7; ++j)
        res_asc += kWgk[j] * (std::fabs(fv1[j] - mean) + std::fabs(fv2[j] - mean));

    GaussKronrodEstimate r;
    r.kronrod = res_k * half;
    r.gauss = res_g * half;
    r.abs = res_abs * abs_half;
    r.asc = res_asc * abs_half;
    double err = std::fabs((res_k - res_g) * half);
    if (r.asc != 0.0 && err != 0.0) err = r.asc * std::min(1.0, std::pow(200.0 * err / r.asc, 1.5));
    if (r.abs > DBL_MIN / (50.0 * DBL_EPSILON)) err = std::max(50.0 * DBL_EPSILON * r.abs, err);
    r.error = err;
    return r;
}

QuadratureResult integrate_adaptive(const std::function<double(double)>& f, double a, double b,
                                    double rel_tol, double abs_tol, int max_intervals) {
    QuadratureResult out;
    if (a == b) {
        out.converged = true;
        return out;
    }
    if (!std::isfinite(a) || !std::isfinite(b)) {
        out.value = NAN;
        out.error_estimate = INFINITY;
        return out;
    }
    double sign = 1.0;
    if (b < a) {
        std::swap(a, b);
        sign = -1.0;
    }
    const size_t limit = static_cast<size_t>(std::max(1, max_intervals));
    auto tolerance = [&](double v) { return std::max(abs_tol, rel_tol * std::fabs(v)); };

    std::vector<Interval> heap; // max-heap on error
    heap.reserve(std::min<size_t>(limit + 1, 4096));
    const GaussKronrodEstimate first = gauss_kronrod_15(f, a, b);
    out.evaluations = 15;
    heap.push_back({a, b, first.kronrod, first.error});
    double value = first.kronrod, error = first.error;
    bool converged = std::isfinite(value) && error <= tolerance(value);
    int roundoff = 0;

    while (!converged && std::isfinite(value) && heap.size() < limit) {
        std::pop_heap(heap.begin(), heap.end(), smaller_error);
        const Interval worst = heap.back();
        if (!bisectable(worst)) {
            std::push_heap(heap.begin(), heap.end(), smaller_error);
            break;
        }
        heap.pop_back();
        const double mid = 0.5 * worst.a + 0.5 * worst.b;
        const GaussKronrodEstimate left = gauss_kronrod_15(f, worst.a, mid);
        const GaussKronrodEstimate right = gauss_kronrod_15(f, mid, worst.b);
        out.evaluations += 30;
        const double value12 = left.kronrod + right.kronrod;
        const double error12 = left.error + right.error;
        // QUADPACK's round-off test [Piessens83, QAG]: bisection changed neither the value nor
        // (by more than 1%) the error, so the error is rounding noise.
        if (std::fabs(worst.value - value12) <= 1e-5 * std::fabs(value12) &&
            error12 >= 0.99 * worst.error)
            ++roundoff;
        heap.push_back({worst.a, mid, left.kronrod, left.error});
        std::push_heap(heap.begin(), heap.end(), smaller_error);
        heap.push_back({mid, worst.b, right.kronrod, right.error});
        std::push_heap(heap.begin(), heap.end(), smaller_error);

        // Re-sum (at most max_intervals terms) rather than update, so no drift accumulates.
        value = 0.0;
        error = 0.0;
        for (const Interval& w : heap) {
            value += w.value;
            error += w.error;
        }
        converged = std::isfinite(value) && error <= tolerance(value);
        if (roundoff >= 6) break;
    }
    out.value = sign * value;
    out.error_estimate = std::isfinite(value) ? error : INFINITY;
    out.converged = converged;
    return out;
}

QuadratureResult integrate_to_infinity(const std::function<double(double)>& f, double a,
                                       double rel_tol, double abs_tol, int max_intervals) {
    if (!std::isfinite(a)) {
        QuadratureResult out;
        out.value = NAN;
        out.error_estimate = INFINITY;
        return out;
    }
    // dx = dt / (1 - t)^2. Divide twice: (1 - t)^2 could underflow where f(x) / (1 - t) does
    // not (and the nodes never reach t = 1, see bisectable).
    auto g = [&f, a](double t) {
        const double s = 1.0 - t;
        if (!(s > 0.0)) return 0.0;
        return f(a + t / s) / s / s;
    };
    return integrate_adaptive(g, 0.0, 1.0, rel_tol, abs_tol, max_intervals);
}

} // namespace mcp
