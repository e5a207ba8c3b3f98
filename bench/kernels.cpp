// The kernels behind `make bench`'s slowest wasm/native rows, timed as the best of many short
// repetitions (a millisecond or so each): on a shared machine some repetitions run unpreempted,
// so the best is the machine's speed and not its load. Built three ways by
// bench/kernels.sh: natively as the build is (AVX2 clones, glibc's ifunc-chosen libm), natively
// with the loops' baseline x86-64 code (two doubles a register, wasm's width), and in wasm.
// Prints nanoseconds per evaluation and milliseconds per analysis.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/point_analysis.h"
#include "core/points.h"
#include "core/rng.h"
#include "integrands/integrand.h"

using namespace mcp;

namespace {

template <class F> double best_seconds(F run, int reps) {
    double best = 1e300, checksum = 0.0;
    for (int r = 0; r < reps; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        checksum += run();
        const double t =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (r > 0 && t < best) best = t; // the first is the warm-up
    }
    if (checksum != checksum) std::printf("(NaN)\n");
    return best;
}

double ns_per_evaluation(const Integrand& f) {
    PointBlock x;
    x.reset(f.dim, kBlockSize);
    x.n = kBlockSize;
    Pcg32 rng(3, 4);
    for (int j = 0; j < f.dim; ++j)
        for (size_t i = 0; i < kBlockSize; ++i) x.coord(j)[i] = rng.next_double();
    std::vector<double> out(kBlockSize);
    const int blocks = 4;
    const double s = best_seconds(
        [&] {
            double c = 0.0;
            for (int k = 0; k < blocks; ++k) {
                evaluate_block(f, x, out.data());
                c += out[0];
            }
            return c;
        },
        20000);
    return s / double(blocks * kBlockSize) * 1e9;
}

PointSet random_points(uint64_t n, int dim) {
    PointSet s;
    s.n = n;
    s.dim = dim;
    Pcg32 rng(5, 6);
    s.coords.resize(n * uint64_t(dim));
    for (double& x : s.coords) x = rng.next_double();
    return s;
}

} // namespace

int main() {
    const Made<Integrand> expr = make_expression_integrand("exp(-(x-0.5)^2/0.01)", 1);
    const Made<Integrand> gauss =
        make_integrand(IntegrandKind::Gaussian, 1, 1.0, {}, {0.5}, std::sqrt(0.005));
    const Made<Integrand> no_exp = make_expression_integrand("(x-0.5)^2/0.01", 1);
    if (!expr.ok() || !gauss.ok() || !no_exp.ok()) return 1;
    const PointSet a = random_points(2048, 8), b = random_points(512, 2);
    std::printf("KERNEL eval/expression_gaussian %.3f ns\n", ns_per_evaluation(expr.value));
    std::printf("KERNEL eval/compiled_gaussian %.3f ns\n", ns_per_evaluation(gauss.value));
    std::printf("KERNEL eval/expression_without_exp %.3f ns\n", ns_per_evaluation(no_exp.value));
    std::printf("KERNEL analysis/l2star_2048_d8 %.3f ms\n",
                1e3 * best_seconds([&] { return l2_star_discrepancy(a, 1); }, 200));
    std::printf("KERNEL analysis/spectrum_512_256 %.3f ms\n",
                1e3 * best_seconds([&] { return power_spectrum(b, 0, 1, 256, 1).power[0]; }, 100));
    return 0;
}
