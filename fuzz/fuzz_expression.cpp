// libFuzzer target: expression text -> mcp::compile_expression for dimensions 1..3, then the
// compiled program run over a block of points (src/integrands/expression.h).
// Invariants checked besides the sanitizers': an error reads "at position P: ..."; the block
// evaluation (out of place, in place, and a block longer than kBlockSize) gives exactly the
// same numbers as evaluate_point (NaN equal to NaN): otherwise a fused or folded instruction
// computes a silently different number.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "integrands/expression.h"

namespace {

[[noreturn]] void violation(const char* what, const std::string& text, int dim, size_t i = 0) {
    std::fprintf(stderr, "fuzz_expression: %s (dim %d, point %zu, expression of %zu bytes)\n", what,
                 dim, i, text.size());
    std::abort();
}

bool same(double a, double b) {
    if (std::isnan(a) && std::isnan(b)) return true;
    return std::memcmp(&a, &b, sizeof a) == 0; // bitwise: -0 and +0 differ too
}

// Point i's coordinate j: ordinary values, edges of [0, 1], and awkward doubles.
double coordinate(size_t i, int j) {
    static const double kValues[] = {0.5,      0.0,  1.0,     0.25, -0.0,    1e-300,
                                     0.999999, -1.0, 3.14159, 1e-8, 2.0,     0.75,
                                     1e300,    -2.5, 0.1,     0.9,  4.9e-324};
    const size_t n = sizeof kValues / sizeof kValues[0];
    return kValues[(i * 7 + size_t(j) * 3 + i / n) % n];
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    constexpr size_t kN = 300; // longer than one block (kBlockSize = 256)
    for (int dim = 1; dim <= 3; ++dim) {
        mcp::Made<std::shared_ptr<const mcp::ExprProgram>> made =
            mcp::compile_expression(text, dim);
        if (!made.ok()) {
            if (made.error.compare(0, 12, "at position ") != 0)
                violation("error does not start with 'at position '", text, dim);
            continue;
        }
        if (!made.value) violation("ok without a program", text, dim);
        const mcp::ExprProgram& prog = *made.value;
        if (prog.dimension() != dim) violation("dimension() differs from the request", text, dim);

        std::vector<std::vector<double>> cols(static_cast<size_t>(dim), std::vector<double>(kN));
        for (int j = 0; j < dim; ++j)
            for (size_t i = 0; i < kN; ++i) cols[size_t(j)][i] = coordinate(i, j);
        std::vector<const double*> vars;
        for (int j = 0; j < dim; ++j) vars.push_back(cols[size_t(j)].data());

        std::vector<double> out(kN);
        prog.evaluate(vars.data(), kN, out.data());
        // A short block too (a tail smaller than any vector width).
        std::vector<double> out3(3);
        prog.evaluate(vars.data(), 3, out3.data());

        for (size_t i = 0; i < kN; i += (i < 20 ? 1 : 37)) {
            double x[3];
            for (int j = 0; j < dim; ++j) x[j] = cols[size_t(j)][i];
            const double v = prog.evaluate_point(x);
            if (!same(v, out[i])) {
                std::fprintf(stderr, "evaluate_point = %.17g, evaluate = %.17g\n", v, out[i]);
                violation("block and point evaluation differ", text, dim, i);
            }
            if (i < 3 && !same(out3[i], out[i])) violation("a 3-point block differs", text, dim, i);
        }
        // In place: out is the first variable's array.
        std::vector<double> inplace = cols[0];
        std::vector<const double*> vars2 = vars;
        vars2[0] = inplace.data();
        prog.evaluate(vars2.data(), kN, inplace.data());
        for (size_t i = 0; i < kN; ++i)
            if (!same(inplace[i], out[i])) violation("in-place evaluation differs", text, dim, i);
    }
    return 0;
}
