// The exponential of a block of arguments, the same bits natively and in wasm, within 0.51 ulp.
#pragma once

#include <cstddef>

namespace mcp {

/// e^x by [Tang89]'s table method with 128 entries; the same bits as one lane of exp_block.
/// Arguments with |x| >= 704 (and NaN) go to std::exp, whose results near overflow and in the
/// subnormal range it leaves as they are.
double exp_tang(double x);

/// out[i] = exp_tang(x[i]) for i < n, two arguments at a time (one SIMD128 or SSE2 register).
/// out may be x.
void exp_block(const double* x, double* out, size_t n);

} // namespace mcp
