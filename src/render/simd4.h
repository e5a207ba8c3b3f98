// Four floats in one register, written once for both builds: SSE natively, and the same
// intrinsics in WebAssembly, where Emscripten maps them to SIMD128 (-msimd128 -msse). A plain
// array stands in elsewhere. Only what the BVH's box test needs.
#pragma once

#if defined(__EMSCRIPTEN__) && !defined(__SSE__)
#error "build with -msimd128 -msse: the SIMD path is the one the native build tests"
#endif
#if defined(__SSE__)
#include <xmmintrin.h>
#endif
#if defined(__EMSCRIPTEN__)
#include <wasm_simd128.h>
#endif

namespace mcp {

#if defined(__SSE__)

struct F4 {
    __m128 v;
};
inline F4 f4_load(const float* p) { // p 16-byte aligned
    return {_mm_load_ps(p)};
}
inline F4 f4_set1(float x) {
    return {_mm_set1_ps(x)};
}
inline F4 operator+(F4 a, F4 b) {
    return {_mm_add_ps(a.v, b.v)};
}
inline F4 operator-(F4 a, F4 b) {
    return {_mm_sub_ps(a.v, b.v)};
}
inline F4 operator*(F4 a, F4 b) {
    return {_mm_mul_ps(a.v, b.v)};
}
/// x > y ? x : y per lane: y when x is NaN.
inline F4 f4_max_keep(F4 x, F4 y) {
#if defined(__EMSCRIPTEN__)
    // Emscripten's _mm_max_ps is a compare and a bitselect; f32x4.pmax(a, b) = a < b ? b : a
    // is one instruction with maxps's semantics (V8 emits maxps).
    return {(__m128)wasm_f32x4_pmax((v128_t)y.v, (v128_t)x.v)};
#else
    return {_mm_max_ps(x.v, y.v)};
#endif
}
/// x < y ? x : y per lane: y when x is NaN.
inline F4 f4_min_keep(F4 x, F4 y) {
#if defined(__EMSCRIPTEN__)
    // f32x4.pmin(a, b) = b < a ? b : a, as for pmax above.
    return {(__m128)wasm_f32x4_pmin((v128_t)y.v, (v128_t)x.v)};
#else
    return {_mm_min_ps(x.v, y.v)};
#endif
}
/// Bit i set where lane i of a <= b.
inline int f4_le_mask(F4 a, F4 b) {
    return _mm_movemask_ps(_mm_cmple_ps(a.v, b.v));
}
inline void f4_store(float* p, F4 a) { // p 16-byte aligned
    _mm_store_ps(p, a.v);
}

#else

struct F4 {
    float v[4];
};
inline F4 f4_load(const float* p) {
    return {{p[0], p[1], p[2], p[3]}};
}
inline F4 f4_set1(float x) {
    return {{x, x, x, x}};
}
#define MCP_F4_LANES(expr)                                                                         \
    F4 r;                                                                                          \
    for (int i = 0; i < 4; ++i) r.v[i] = (expr);                                                   \
    return r
inline F4 operator+(F4 a, F4 b) {
    MCP_F4_LANES(a.v[i] + b.v[i]);
}
inline F4 operator-(F4 a, F4 b) {
    MCP_F4_LANES(a.v[i] - b.v[i]);
}
inline F4 operator*(F4 a, F4 b) {
    MCP_F4_LANES(a.v[i] * b.v[i]);
}
inline F4 f4_max_keep(F4 x, F4 y) {
    MCP_F4_LANES(x.v[i] > y.v[i] ? x.v[i] : y.v[i]);
}
inline F4 f4_min_keep(F4 x, F4 y) {
    MCP_F4_LANES(x.v[i] < y.v[i] ? x.v[i] : y.v[i]);
}
#undef MCP_F4_LANES
inline int f4_le_mask(F4 a, F4 b) {
    int m = 0;
    for (int i = 0; i < 4; ++i) m |= (a.v[i] <= b.v[i] ? 1 : 0) << i;
    return m;
}
inline void f4_store(float* p, F4 a) {
    for (int i = 0; i < 4; ++i) p[i] = a.v[i];
}

#endif

} // namespace mcp
