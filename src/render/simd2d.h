// Two doubles in one register, written once for both builds: SSE2 natively, and the same
// intrinsics in WebAssembly, where Emscripten maps them to SIMD128's f64x2 (-msimd128 -msse2).
// A plain array stands in elsewhere. Only what the two-triangle test of accel.cpp needs; every
// operation is the IEEE operation of its scalar form, lane by lane, so a lane's result is the
// scalar code's bit for bit. Comparisons give lane masks (all bits set or clear).
#pragma once

#if defined(__EMSCRIPTEN__) && !defined(__SSE2__)
#error "build with -msimd128 -msse2: the SIMD path is the one the native build tests"
#endif
#if defined(__SSE2__)
#include <emmintrin.h>
#else
#include <cstdint>
#include <cstring>
#endif

namespace mcp {

#if defined(__SSE2__)

struct D2 {
    __m128d v;
};
inline D2 d2_load(const double* p) { // p 16-byte aligned
    return {_mm_load_pd(p)};
}
inline D2 d2_set1(double x) {
    return {_mm_set1_pd(x)};
}
inline D2 operator+(D2 a, D2 b) {
    return {_mm_add_pd(a.v, b.v)};
}
inline D2 operator-(D2 a, D2 b) {
    return {_mm_sub_pd(a.v, b.v)};
}
inline D2 operator*(D2 a, D2 b) {
    return {_mm_mul_pd(a.v, b.v)};
}
inline D2 operator/(D2 a, D2 b) {
    return {_mm_div_pd(a.v, b.v)};
}
inline D2 operator&(D2 a, D2 b) {
    return {_mm_and_pd(a.v, b.v)};
}
inline D2 operator|(D2 a, D2 b) {
    return {_mm_or_pd(a.v, b.v)};
}
inline D2 d2_lt(D2 a, D2 b) {
    return {_mm_cmplt_pd(a.v, b.v)};
}
inline D2 d2_gt(D2 a, D2 b) {
    return {_mm_cmpgt_pd(a.v, b.v)};
}
inline D2 d2_le(D2 a, D2 b) {
    return {_mm_cmple_pd(a.v, b.v)};
}
inline D2 d2_eq(D2 a, D2 b) {
    return {_mm_cmpeq_pd(a.v, b.v)};
}
/// ~a & b per bit.
inline D2 d2_andnot(D2 a, D2 b) {
    return {_mm_andnot_pd(a.v, b.v)};
}
/// Bit i set where lane i of the mask is set.
inline int d2_mask_bits(D2 mask) {
    return _mm_movemask_pd(mask.v);
}
inline void d2_store(double* p, D2 a) { // p 16-byte aligned
    _mm_store_pd(p, a.v);
}

#else

struct D2 {
    double v[2];
};
inline D2 d2_load(const double* p) {
    return {{p[0], p[1]}};
}
inline D2 d2_set1(double x) {
    return {{x, x}};
}
inline uint64_t d2_bits(double x) {
    uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}
inline double d2_double(uint64_t b) {
    double x;
    std::memcpy(&x, &b, sizeof x);
    return x;
}
#define MCP_D2_LANES(expr)                                                                         \
    D2 r;                                                                                          \
    for (int i = 0; i < 2; ++i) r.v[i] = (expr);                                                   \
    return r
inline D2 operator+(D2 a, D2 b) {
    MCP_D2_LANES(a.v[i] + b.v[i]);
}
inline D2 operator-(D2 a, D2 b) {
    MCP_D2_LANES(a.v[i] - b.v[i]);
}
inline D2 operator*(D2 a, D2 b) {
    MCP_D2_LANES(a.v[i] * b.v[i]);
}
inline D2 operator/(D2 a, D2 b) {
    MCP_D2_LANES(a.v[i] / b.v[i]);
}
inline D2 operator&(D2 a, D2 b) {
    MCP_D2_LANES(d2_double(d2_bits(a.v[i]) & d2_bits(b.v[i])));
}
inline D2 operator|(D2 a, D2 b) {
    MCP_D2_LANES(d2_double(d2_bits(a.v[i]) | d2_bits(b.v[i])));
}
inline D2 d2_lt(D2 a, D2 b) {
    MCP_D2_LANES(d2_double(a.v[i] < b.v[i] ? ~uint64_t(0) : 0));
}
inline D2 d2_gt(D2 a, D2 b) {
    MCP_D2_LANES(d2_double(a.v[i] > b.v[i] ? ~uint64_t(0) : 0));
}
inline D2 d2_le(D2 a, D2 b) {
    MCP_D2_LANES(d2_double(a.v[i] <= b.v[i] ? ~uint64_t(0) : 0));
}
inline D2 d2_eq(D2 a, D2 b) {
    MCP_D2_LANES(d2_double(a.v[i] == b.v[i] ? ~uint64_t(0) : 0));
}
inline D2 d2_andnot(D2 a, D2 b) {
    MCP_D2_LANES(d2_double(~d2_bits(a.v[i]) & d2_bits(b.v[i])));
}
#undef MCP_D2_LANES
inline int d2_mask_bits(D2 mask) {
    return int(d2_bits(mask.v[0]) >> 63) | int(d2_bits(mask.v[1]) >> 63) << 1;
}
inline void d2_store(double* p, D2 a) {
    p[0] = a.v[0];
    p[1] = a.v[1];
}

#endif

} // namespace mcp
