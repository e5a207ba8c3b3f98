// Sine and cosine for the warps: of an angle already in [-pi/4, pi/4], and of a fraction of a
// full turn. Plain arithmetic (no libm call), so the same on every platform and inlinable into
// the block loops; within 2 ulp of the exact values (1.3 ulp measured for sincos_quarter, 1.8
// for sincos_turns; tests/test_warps.cpp asserts 2).
#pragma once

#include "core/float_index.h"
#include "core/special.h"

namespace mcp {

struct SinCos {
    double sin = 0.0, cos = 1.0;
};

/// c[0] x^7 + c[1] x^6 + ... + c[7] by Estrin's scheme: pairs, then pairs of pairs, three
/// dependent multiply-adds deep instead of Horner's seven (the warps are latency-bound).
inline double estrin8(double x, const double* c) {
    const double x2 = x * x, x4 = x2 * x2;
    const double a0 = c[0] * x + c[1], a1 = c[2] * x + c[3];
    const double a2 = c[4] * x + c[5], a3 = c[6] * x + c[7];
    return (a0 * x2 + a1) * x4 + (a2 * x2 + a3);
}

/// sin t = t + t^3 P(t^2) and cos t = 1 + t^2 Q(t^2): the Taylor coefficients, highest first:
/// P from (-1)^8/17! to -1/3!, Q from (-1)^9/18! to -1/2! (17! and 18! are exact in double).
constexpr double kSinTaylor[] = {
    1.0 / 355687428096000.0, -1.0 / 1307674368000.0, 1.0 / 6227020800.0, -1.0 / 39916800.0,
    1.0 / 362880.0,          -1.0 / 5040.0,          1.0 / 120.0,        -1.0 / 6.0};
constexpr double kCosTaylor[] = {-1.0 / 6402373705728000.0,
                                 1.0 / 20922789888000.0,
                                 -1.0 / 87178291200.0,
                                 1.0 / 479001600.0,
                                 -1.0 / 3628800.0,
                                 1.0 / 40320.0,
                                 -1.0 / 720.0,
                                 1.0 / 24.0,
                                 -0.5};

/// sin t and cos t for |t| <= pi/4 by their Taylor polynomials to degree 17 and 18: the
/// truncation error is below (pi/4)^19 / 19! < 1e-19, so only the rounding of the evaluation
/// remains.
inline SinCos sincos_quarter(double t) {
    const double t2 = t * t;
    SinCos r;
    const double t8 = (t2 * t2) * (t2 * t2);
    r.sin = t + t * t2 * estrin8(t2, kSinTaylor);
    r.cos = 1.0 + t2 * (kCosTaylor[0] * t8 + estrin8(t2, kCosTaylor + 1));
    return r;
}

/// sin(2 pi u) and cos(2 pi u) for u in [0, 1]. The reduction is exact: 4u = q + f with q the
/// nearest integer (the quarter turn; floor of 4u + 1/2 >= 0) and |f| <= 1/2, f exact;
/// then t = f pi/2 is the one rounded step, and the quadrant rotates (sin, cos) of t:
/// q = 0, 1, 2, 3 give (s, c), (c, -s), (-s, -c), (-c, s). More accurate than
/// std::sin(2 pi u), which rounds 2 pi u first. The rotation is selects and exact sign
/// flips, not a branch on the quadrant (random in a block loop, so mispredicted).
inline SinCos sincos_turns(double u) {
    const double v = 4.0 * u;
    const int q = static_cast<int>(floor_to_index(v + 0.5));
    const SinCos a = sincos_quarter((v - q) * (0.5 * kPi));
    const bool odd = (q & 1) != 0;
    const double sin_sign = (q & 2) != 0 ? -1.0 : 1.0;
    const double cos_sign = ((q + 1) & 2) != 0 ? -1.0 : 1.0;
    return {sin_sign * (odd ? a.cos : a.sin), cos_sign * (odd ? a.sin : a.cos)};
}

} // namespace mcp
