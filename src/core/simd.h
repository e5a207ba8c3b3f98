// Compiler hints for the vectorized loops over points.
#pragma once

/// MCP_VECTOR_CLONES before a function whose loops vectorize: on x86-64 Linux with GCC the
/// function is compiled twice, for AVX2 and for the baseline (SSE2, which has no 32-bit
/// vector multiply), and the loader picks the one the CPU runs. Elsewhere (wasm with SIMD128,
/// other compilers) it is empty. Both versions compute the same results bit for bit: the loops
/// that use it do integer arithmetic and exact or singly rounded floating-point steps.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) &&       \
    !defined(__SANITIZE_ADDRESS__)
#define MCP_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define MCP_VECTOR_CLONES
#endif
