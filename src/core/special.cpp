#include "core/special.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace mcp {

double normal_cdf(double x) {
    return 0.5 * std::erfc(-x / kSqrt2);
}

namespace {

// Lower-tail quantile for p <= 0.5, where Phi(x) = erfc(-x/sqrt2)/2 has no cancellation.
double normal_quantile_lower(double p) {
    // Starting value [AS64, 26.2.23], |error| < 4.5e-4.
    double t = std::sqrt(-2.0 * std::log(p));
    double x = -(t - (2.515517 + t * (0.802853 + t * 0.010328)) /
                         (1.0 + t * (1.432788 + t * (0.189269 + t * 0.001308))));
    // Halley refinement: e = Phi(x) - p, u = e / phi(x).
    // Halley converges cubically: 4.5e-4 -> ~1e-10 -> below double precision.
    for (int it = 0; it < 2; ++it) {
        double e = normal_cdf(x) - p;
        double u = e * std::sqrt(2.0 * kPi) * std::exp(0.5 * x * x);
        x -= u / (1.0 + 0.5 * x * u);
    }
    return x;
}

} // namespace

double normal_quantile(double p) {
    if (!(p > 0.0)) return -std::numeric_limits<double>::infinity();
    if (!(p < 1.0)) return std::numeric_limits<double>::infinity();
    if (p <= 0.5) return normal_quantile_lower(p);
    return -normal_quantile_lower(1.0 - p);
}

double student_t_quantile(double p, double nu) {
    if (nu <= 1.0) return std::tan(kPi * (p - 0.5));
    if (nu <= 2.0) return (2.0 * p - 1.0) / std::sqrt(2.0 * p * (1.0 - p));
    double x = normal_quantile(p);
    double x2 = x * x;
    double g1 = (x2 + 1.0) * x / 4.0;
    double g2 = ((5.0 * x2 + 16.0) * x2 + 3.0) * x / 96.0;
    double g3 = (((3.0 * x2 + 19.0) * x2 + 17.0) * x2 - 15.0) * x / 384.0;
    double g4 = ((((79.0 * x2 + 776.0) * x2 + 1482.0) * x2 - 1920.0) * x2 - 945.0) * x / 92160.0;
    return x + g1 / nu + g2 / (nu * nu) + g3 / (nu * nu * nu) + g4 / (nu * nu * nu * nu);
}

namespace {

constexpr double kGammaEps = 1e-15;
constexpr int kGammaMaxIter = 10000;
constexpr double kTiny = 1e-300;

// Series gamma(a,x) * e^x x^-a / Gamma(a) = sum x^n / (a (a+1) ... (a+n)).
double gamma_p_series(double a, double x) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < kGammaMaxIter; ++n) {
        term *= x / (a + n);
        sum += term;
        if (std::fabs(term) < std::fabs(sum) * kGammaEps) break;
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Continued fraction for Q(a, x), modified Lentz evaluation.
double gamma_q_fraction(double a, double x) {
    double b = x + 1.0 - a;
    double c = 1.0 / kTiny;
    double d = 1.0 / b;
    double h = d;
    for (int i = 1; i < kGammaMaxIter; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::fabs(d) < kTiny) d = kTiny;
        c = b + an / c;
        if (std::fabs(c) < kTiny) c = kTiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (std::fabs(delta - 1.0) < kGammaEps) break;
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

} // namespace

double gamma_p(double a, double x) {
    if (!(x > 0.0)) return 0.0;
    if (std::isinf(x)) return 1.0;
    return x < a + 1.0 ? gamma_p_series(a, x) : 1.0 - gamma_q_fraction(a, x);
}

double gamma_q(double a, double x) {
    if (!(x > 0.0)) return 1.0;
    if (std::isinf(x)) return 0.0;
    return x < a + 1.0 ? 1.0 - gamma_p_series(a, x) : gamma_q_fraction(a, x);
}

double chi_square_sf(double x, double k) {
    return gamma_q(0.5 * k, 0.5 * x);
}

double chi_square_quantile(double p, double k) {
    if (!(p > 0.0)) return 0.0;
    if (!(p < 1.0)) return std::numeric_limits<double>::infinity();
    // Wilson-Hilferty start, then safeguarded Newton on P(k/2, x/2) = p.
    double z = normal_quantile(p);
    double h = 2.0 / (9.0 * k);
    double x = k * std::pow(std::fmax(1.0 - h + z * std::sqrt(h), 0.05), 3.0);
    double lo = 0.0, hi = std::numeric_limits<double>::infinity();
    for (int it = 0; it < 100; ++it) {
        double f = gamma_p(0.5 * k, 0.5 * x) - p;
        if (f > 0)
            hi = x;
        else
            lo = x;
        double log_pdf = (0.5 * k - 1.0) * std::log(x) - 0.5 * x - 0.5 * k * std::log(2.0) -
                         std::lgamma(0.5 * k);
        double step = f / std::exp(log_pdf);
        double next = x - step;
        if (!(next > lo && next < hi)) next = std::isinf(hi) ? 2.0 * x + 1.0 : 0.5 * (lo + hi);
        if (std::fabs(next - x) <= 1e-14 * x) return next;
        x = next;
    }
    return x;
}

double trigamma(double x) {
    double acc = 0.0;
    while (x < 10.0) {
        acc += 1.0 / (x * x);
        x += 1.0;
    }
    double r = 1.0 / x, r2 = r * r;
    // psi'(x) ~ 1/x + 1/(2x^2) + sum_k B_2k / x^(2k+1) [AS64, 6.4.12]; at x >= 10 the first
    // omitted term, 691/2730 x^-13, is below 3e-14.
    double series =
        r + 0.5 * r2 +
        r * r2 *
            (1.0 / 6.0 -
             r2 * (1.0 / 30.0 - r2 * (1.0 / 42.0 - r2 * (1.0 / 30.0 - r2 * 5.0 / 66.0))));
    return acc + series;
}

namespace {

// Continued fraction of I_x(a, b) by the modified Lentz method [NR07, 6.4].
double beta_continued_fraction(double a, double b, double x) {
    const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
    double c = 1.0, d = 1.0 - qab * x / qap;
    if (std::fabs(d) < kTiny) d = kTiny;
    d = 1.0 / d;
    double h = d;
    for (int m = 1; m < kGammaMaxIter; ++m) {
        const double m2 = 2.0 * m;
        double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if (std::fabs(d) < kTiny) d = kTiny;
        c = 1.0 + aa / c;
        if (std::fabs(c) < kTiny) c = kTiny;
        d = 1.0 / d;
        h *= d * c;
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if (std::fabs(d) < kTiny) d = kTiny;
        c = 1.0 + aa / c;
        if (std::fabs(c) < kTiny) c = kTiny;
        d = 1.0 / d;
        const double del = d * c;
        h *= del;
        if (std::fabs(del - 1.0) < kGammaEps) break;
    }
    return h;
}

} // namespace

double beta_regularized(double a, double b, double x) {
    if (!(x > 0.0)) return 0.0;
    if (!(x < 1.0)) return 1.0;
    // x^a (1-x)^b / (a B(a, b)), in logs.
    const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                  a * std::log(x) + b * std::log1p(-x));
    if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_continued_fraction(a, b, x) / a;
    return 1.0 - front * beta_continued_fraction(b, a, 1.0 - x) / b;
}

double student_t_sf(double t, double nu) {
    if (std::isnan(t)) return t;
    if (std::isinf(t)) return t > 0.0 ? 0.0 : 1.0;
    const double half_tail = 0.5 * beta_regularized(0.5 * nu, 0.5, nu / (nu + t * t));
    return t >= 0.0 ? half_tail : 1.0 - half_tail;
}

double student_t_isf(double tail, double nu) {
    if (!(tail > 0.0) || !(nu > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    if (tail >= 0.5) return 0.0;
    if (nu == 1.0) return 1.0 / std::tan(kPi * tail);
    if (nu == 2.0) return (1.0 - 2.0 * tail) / std::sqrt(2.0 * tail * (1.0 - tail));
    if (nu >= 100.0) return student_t_quantile(1.0 - tail, nu); // the expansion converges there
    // t's tails are heavier than the normal's: its quantile bounds t from below.
    double lo = std::max(0.0, -normal_quantile(tail)), hi = std::max(2.0 * lo, 1.0);
    for (int i = 0; i < 1100 && student_t_sf(hi, nu) > tail; ++i) hi *= 2.0;
    for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
        const double mid = 0.5 * (lo + hi);
        (student_t_sf(mid, nu) > tail ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double widened_limit(double z, double nu) {
    const double widened = z * student_t_quantile(0.975, nu) / kNormal975;
    if (!(nu < kWidenedReferenceDof)) return widened;
    const double at_reference = z * student_t_quantile(0.975, kWidenedReferenceDof) / kNormal975;
    const double tail = student_t_sf(at_reference, kWidenedReferenceDof);
    return std::max(widened, student_t_isf(tail, nu));
}

double f_sf(double f, double d1, double d2) {
    if (!(f > 0.0)) return 1.0;
    if (std::isinf(f)) return 0.0;
    return beta_regularized(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

std::string p_value_text(double p, int digits) {
    if (std::isnan(p)) return "p = -";
    if (p < 1e-300) return "p < 1e-300";
    char buf[48];
    std::snprintf(buf, sizeof buf, "p = %.*g", digits, p);
    return buf;
}

} // namespace mcp
