// Genz's six test families for multidimensional integration on [0,1]^d [Genz84, Genz87],
// evaluated a block of points at a time, with their exact integrals computed stably in
// any dimension up to 64.
//
//   oscillatory    f = cos(2 pi u_1 + sum a_i x_i)
//   product_peak   f = prod_i 1 / (a_i^-2 + (x_i - u_i)^2)
//   corner_peak    f = (1 + sum a_i x_i)^-(d+1)
//   gaussian       f = exp(-sum a_i^2 (x_i - u_i)^2)
//   continuous     f = exp(-sum a_i |x_i - u_i|)
//   discontinuous  f = 0 if x_1 > u_1 or x_2 > u_2 (only x_1 when d = 1), else exp(sum a_i x_i)
//
// a (the "difficulty" parameters) sharpen the feature, u (the shift) moves it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/made.h"
#include "core/points.h"

namespace mcp {

enum class GenzFamily { Oscillatory, ProductPeak, CornerPeak, Gaussian, Continuous, Discontinuous };

/// "genz_oscillatory", "genz_product_peak", "genz_corner_peak", "genz_gaussian",
/// "genz_continuous", "genz_discontinuous".
const char* genz_family_name(GenzFamily f);
bool parse_genz_family(const std::string& name, GenzFamily* out);

struct GenzParams {
    GenzFamily family = GenzFamily::Oscillatory;
    std::vector<double> a, u;
    int dim() const { return int(a.size()); }
};

/// Validates: 1 <= d = a.size() <= 64, u.size() == a.size(), all values finite, u_i in [0, 1],
/// a_i > 0, except the oscillatory family where a_i >= 0 is allowed (a_i = 0 just removes
/// x_i from the phase; its closed form uses sin(a/2)/(a/2), continuous at 0). For the other
/// families a_i = 0 would be a division by zero in the closed forms (and an infinite peak
/// for product_peak). The error names the family, field and index, e.g.
/// "genz_gaussian: a[3] must be > 0, got -1".
Made<GenzParams> make_genz(GenzFamily f, std::vector<double> a, std::vector<double> u);

/// Genz's normalisation [Genz87]: r_i ~ U(0,1) for i < d, then u_i ~ U(0,1) for i < d, all
/// drawn (in that order) from Pcg32(seed, stream = hash_string("genz")) with next_double, so
/// the same seed gives the same raw draws for every family; then a_i = r_i * S / sum_j r_j with
/// S = difficulty * h / d^e and (h, e) = (110, 1.5), (600, 2), (600, 2), (100, 1), (150, 2),
/// (100, 2) for the six families in the order of GenzFamily. difficulty = 1 is Genz's standard.
/// dim is clamped to 1..64 and a non-positive or non-finite difficulty is treated as 1, so the
/// result always passes make_genz.
GenzParams genz_random(GenzFamily f, int dim, uint64_t seed, double difficulty = 1.0);

/// out[i] = f(x_i) for the x.n points of the block (x.dim must equal p.dim()); one switch per
/// block and a tight loop per coordinate. No allocation.
void genz_evaluate_block(const GenzParams& p, const PointBlock& x, double* out);

/// f at one point x[0..d-1]; the same arithmetic in the same order as genz_evaluate_block, so
/// the results are bit-identical. No allocation.
double genz_evaluate_point(const GenzParams& p, const double* x);

/// Exact integral over [0,1]^d. Products over dimensions carry their binary exponent
/// separately, so only a result that is itself outside the double range under/overflows
/// (product_peak at d = 64 with Genz's normalisation is ~1e-340: it returns 0, see
/// genz_log_exact). corner_peak is a one-dimensional integral evaluated by adaptive
/// quadrature (requested 1e-13 relative; ~1e-15 measured against 30-digit quadrature, d <= 64).
double genz_exact(const GenzParams& p);

/// log |I| and the sign of I (+1, -1, or 0 with log |I| = -infinity), for integrals whose
/// magnitude lies outside the double range.
double genz_log_exact(const GenzParams& p, int* sign);

} // namespace mcp
