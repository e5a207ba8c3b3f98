#include "core/samplers.h"

#include <algorithm>
#include <cmath>

namespace mcp {

const char* sampler_name(SamplerKind kind) {
    switch (kind) {
    case SamplerKind::Independent: return "independent";
    case SamplerKind::Stratified: return "stratified";
    case SamplerKind::LatinHypercube: return "latin_hypercube";
    case SamplerKind::Sobol: return "sobol";
    case SamplerKind::Halton: return "halton";
    case SamplerKind::Lattice: return "lattice";
    }
    return "?";
}

const char* sampler_names() {
    return "independent, stratified, latin_hypercube, sobol, halton, lattice";
}

bool is_qmc(SamplerKind kind) {
    return kind == SamplerKind::Sobol || kind == SamplerKind::Halton ||
           kind == SamplerKind::Lattice;
}

QmcKind qmc_kind_of(SamplerKind kind) {
    return kind == SamplerKind::Halton    ? QmcKind::Halton
           : kind == SamplerKind::Lattice ? QmcKind::Lattice
                                          : QmcKind::Sobol;
}

std::string check_sampler_options(SamplerKind kind, const SamplerOptions& options, int dim) {
    if (options.per_stratum != 1 && kind != SamplerKind::Stratified)
        return "samples_per_stratum: applies to the stratified sampler only";
    if (!is_qmc(kind)) return "";
    const QmcKind q = qmc_kind_of(kind);
    std::string bad = check_randomization(q, options.randomization);
    if (!bad.empty()) return "randomization: " + bad;
    const int k = options.randomizations;
    if (options.randomization == QmcRandomization::None) {
        if (k != 1)
            return "randomizations: points without randomization are one deterministic set "
                   "(randomizations = 1, and the run has no error bar), got " +
                   std::to_string(k);
    } else if (k < 2 || k > kMaxRandomizations || (k & (k - 1)) != 0) {
        return "randomizations: must be a power of two from 2 to " +
               std::to_string(kMaxRandomizations) +
               " (the error bar comes from the spread of the randomizations), got " +
               std::to_string(k);
    }
    if (dim > qmc_max_dim(q))
        return std::string(sampler_name(kind)) + ": " + std::to_string(dim) +
               " dimensions exceed the " + std::to_string(qmc_max_dim(q)) + " its table supports";
    return "";
}

bool parse_sampler(const std::string& name, SamplerKind* kind) {
    if (name == "independent")
        *kind = SamplerKind::Independent;
    else if (name == "stratified")
        *kind = SamplerKind::Stratified;
    else if (name == "latin_hypercube")
        *kind = SamplerKind::LatinHypercube;
    else if (name == "sobol")
        *kind = SamplerKind::Sobol;
    else if (name == "halton")
        *kind = SamplerKind::Halton;
    else if (name == "lattice")
        *kind = SamplerKind::Lattice;
    else
        return false;
    return true;
}

namespace {

// Largest divisor of n that is <= limit (limit >= 1).
uint64_t largest_divisor_at_most(uint64_t n, double limit) {
    uint64_t best = 1;
    for (uint64_t q = 1; q * q <= n; ++q) {
        if (n % q) continue;
        uint64_t p = n / q;
        if (static_cast<double>(q) <= limit && q > best) best = q;
        if (static_cast<double>(p) <= limit && p > best) best = p;
    }
    return best;
}

} // namespace

std::vector<uint64_t> stratification_grid(uint64_t n, int dim) {
    std::vector<uint64_t> k(static_cast<size_t>(dim), 1);
    uint64_t remaining = n;
    for (int j = 0; j < dim - 1; ++j) {
        // The tiny allowance keeps exact roots exact: 64^(1/3) may round to 3.9999999.
        double root = std::pow(static_cast<double>(remaining), 1.0 / (dim - j)) * (1.0 + 1e-12);
        k[j] = largest_divisor_at_most(remaining, root);
        remaining /= k[j];
    }
    k[dim - 1] = remaining;
    return k;
}

namespace {

// One keyed bijection of [0, 2^bits): each step (xor with a constant, multiplication by an
// odd number, xorshift to the right, addition) is invertible modulo 2^bits. `rk` are its four
// round keys, mix64(key + round).
inline uint64_t bijection(uint64_t x, uint64_t mask, int bits, const uint64_t* rk) {
    int shift = bits > 1 ? bits / 2 : 1;
    for (int round = 0; round < 4; ++round) {
        x ^= rk[round] & mask;
        x = (x * (rk[round] | 1u)) & mask;
        x ^= x >> shift;
        x = (x * 0x9e3779b97f4a7c15ULL) & mask; // odd multiplier: a bijection mod 2^bits
        x ^= x >> (shift > 1 ? shift - 1 : 1);
        x = (x + (rk[round] >> 32)) & mask;
    }
    return x;
}

} // namespace

IndexPermutation index_permutation(uint64_t n, uint64_t key) {
    IndexPermutation p;
    p.n = n;
    while (p.bits < 64 && (uint64_t(1) << p.bits) < n) ++p.bits;
    p.mask = p.bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << p.bits) - 1;
    for (int round = 0; round < 4; ++round) p.round_key[round] = mix64(key + uint64_t(round));
    return p;
}

uint64_t permute_index(uint64_t index, const IndexPermutation& p) {
    if (p.n <= 1) return 0;
    // Cycle walking: apply the bijection until the value falls back inside [0, n). The
    // orbit of an index < n returns to [0, n), so this is a permutation of [0, n).
    uint64_t x = index;
    do {
        x = bijection(x, p.mask, p.bits, p.round_key);
    } while (x >= p.n);
    return x;
}

uint64_t permute_index(uint64_t index, uint64_t n, uint64_t key) {
    if (n <= 1) return 0;
    return permute_index(index, index_permutation(n, key));
}

SamplerPlan make_sampler_plan(SamplerKind kind, int dim, uint64_t n, Pcg32& rng,
                              const SamplerOptions& options) {
    SamplerPlan plan;
    plan.kind = kind;
    plan.dim = dim;
    plan.total = n;
    const uint64_t per_stratum = options.per_stratum;
    if (is_qmc(kind)) {
        const uint64_t k = std::max<uint64_t>(
            1, std::min<uint64_t>(static_cast<uint64_t>(std::max(options.randomizations, 1)), n));
        plan.randomizers.reserve(static_cast<size_t>(k));
        const uint64_t per_batch = (n + k - 1) / k; // the largest batch
        for (uint64_t b = 0; b < k; ++b) {
            const uint64_t hi = rng.next_u32(), lo = rng.next_u32();
            plan.randomizers.push_back(make_qmc_randomizer(qmc_kind_of(kind), options.randomization,
                                                           dim, (hi << 32) | lo, per_batch));
        }
    }
    if (kind == SamplerKind::Stratified) {
        plan.per_stratum = per_stratum >= 1 && n % per_stratum == 0 ? per_stratum : 1;
        plan.strata = stratification_grid(n / plan.per_stratum, dim);
    }
    if (kind == SamplerKind::LatinHypercube) {
        for (int j = 0; j < dim; ++j) {
            uint64_t hi = rng.next_u32(), lo = rng.next_u32();
            plan.perm_keys.push_back((hi << 32) | lo);
        }
    }
    if (!is_qmc(kind)) {
        // Its own seed and stream: two plans drawn in turn from one generator never share draws.
        const uint64_t seed = (uint64_t(rng.next_u32()) << 32) | rng.next_u32();
        const uint64_t stream = (uint64_t(rng.next_u32()) << 32) | rng.next_u32();
        plan.jitter = Pcg32(seed, stream);
    }
    return plan;
}

namespace {

// The digits of cell `cell` in the mixed radix of the strata, last axis fastest.
void cell_digits(const SamplerPlan& plan, uint64_t cell, uint64_t* digits) {
    for (int j = plan.dim - 1; j >= 0; --j) {
        const uint64_t k = plan.strata[static_cast<size_t>(j)];
        digits[j] = cell % k;
        cell /= k;
    }
}

double stratified_coordinate(const SamplerPlan& plan, const uint64_t* digits, int j, double xi) {
    const double k = u63_to_double(plan.strata[static_cast<size_t>(j)]);
    return below_one((u63_to_double(digits[j]) + xi) / k);
}

double latin_coordinate(const SamplerPlan& plan, uint64_t index, int j, double xi) {
    const uint64_t slab = permute_index(index, plan.total, plan.perm_keys[static_cast<size_t>(j)]);
    return below_one((u63_to_double(slab) + xi) / u63_to_double(plan.total));
}

} // namespace

double sample_coordinate(const SamplerPlan& plan, uint64_t index, int dim) {
    if (is_qmc(plan.kind)) {
        size_t batch = 0;
        while (batch + 1 < plan.batches() && plan.batch_begin(batch + 1) <= index) ++batch;
        return qmc_coordinate(plan.randomizers[batch], index - plan.batch_begin(batch), dim);
    }
    Pcg32 g = plan.jitter_at(index);
    g.advance(2 * dim);
    const double xi = g.next_double();
    switch (plan.kind) {
    case SamplerKind::Stratified: {
        uint64_t digits[64];
        cell_digits(plan, index / plan.per_stratum, digits);
        return stratified_coordinate(plan, digits, dim, xi);
    }
    case SamplerKind::LatinHypercube: return latin_coordinate(plan, index, dim, xi);
    default: return xi;
    }
}

void generate_block(const SamplerPlan& plan, uint64_t first, size_t count, PointBlock& u) {
    u.n = count;
    const int d = plan.dim;
    Pcg32 rng = is_qmc(plan.kind) ? Pcg32() : plan.jitter_at(first);
    switch (plan.kind) {
    case SamplerKind::Independent:
        // Point-major draw order so that a point's coordinates come from consecutive draws.
        for (size_t i = 0; i < count; ++i)
            for (int j = 0; j < d; ++j) u.coord(j)[i] = rng.next_double();
        break;
    case SamplerKind::Stratified: {
        // Cell index in mixed radix, last axis fastest: cell = ((c_0 k_1 + c_1) k_2 + c_2)...
        // Consecutive indices are neighbouring cells, which the collapsed-strata variance
        // estimate relies on (pairs 2m, 2m+1).
        // Two passes: the jitter in draw order (point-major), then axis by axis the cell
        // offset, with an odometer digit per axis that steps every `stride` points (the
        // block's first cell once by division, then no division by the strata per sample).
        for (size_t i = 0; i < count; ++i)
            for (int j = 0; j < d; ++j) u.coord(j)[i] = rng.next_double();
        uint64_t digits[64];
        cell_digits(plan, first / plan.per_stratum, digits);
        uint64_t stride = plan.per_stratum;         // points per step of axis j's digit
        uint64_t within = first % plan.per_stratum; // points of the first cell already past
        for (int j = d - 1; j >= 0; --j) {
            const uint64_t k = plan.strata[static_cast<size_t>(j)];
            const double kd = u63_to_double(k);
            double digit = u63_to_double(digits[j]); // integers, exact in a double
            uint64_t left = stride - within;         // points until the digit steps
            double* x = u.coord(j);
            for (size_t i = 0; i < count; ++i) {
                x[i] = below_one((digit + x[i]) / kd);
                if (--left == 0) {
                    left = stride;
                    digit = digit + 1.0 < kd ? digit + 1.0 : 0.0;
                }
            }
            // The next axis steps when this one wraps: its first step is after the points
            // remaining in this digit's current run of k values.
            within += digits[j] * stride;
            stride *= k;
        }
        break;
    }
    case SamplerKind::LatinHypercube:
        for (size_t i = 0; i < count; ++i)
            for (int j = 0; j < d; ++j)
                u.coord(j)[i] = latin_coordinate(plan, first + i, j, rng.next_double());
        break;
    case SamplerKind::Sobol:
    case SamplerKind::Halton:
    case SamplerKind::Lattice: {
        // The block may span several batches: each part comes from its own randomization,
        // indexed from the start of its batch.
        const size_t batches = plan.batches();
        // total x batches stays far below 2^64 (runs are at most 2^36 points, K <= 1024).
        size_t batch = static_cast<size_t>(first * batches / plan.total);
        while (batch + 1 < batches && plan.batch_begin(batch + 1) <= first) ++batch;
        while (plan.batch_begin(batch) > first) --batch;
        size_t done = 0;
        while (done < count) {
            const uint64_t index = first + done;
            const uint64_t begin = plan.batch_begin(batch), end = plan.batch_begin(batch + 1);
            const size_t part = static_cast<size_t>(std::min<uint64_t>(count - done, end - index));
            qmc_points(plan.randomizers[batch], index - begin, part, u, done);
            done += part;
            ++batch;
        }
        break;
    }
    }
}

} // namespace mcp
