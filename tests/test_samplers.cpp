// Unit-cube samplers: grid rule, one point per stratum, N-rooks property, permutations,
// uniformity, and block-size independence (streaming).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/samplers.h"
#include "test_support.h"

using namespace mcp;

namespace {

// All points of a run, generated in blocks of `block` points.
std::vector<std::vector<double>> generate_all(SamplerKind kind, int dim, uint64_t n, uint64_t seed,
                                              size_t block) {
    Pcg32 rng(seed, 7);
    SamplerPlan plan = make_sampler_plan(kind, dim, n, rng);
    PointBlock u;
    u.reset(dim, block);
    std::vector<std::vector<double>> pts;
    for (uint64_t first = 0; first < n; first += block) {
        size_t count = static_cast<size_t>(std::min<uint64_t>(block, n - first));
        generate_block(plan, first, count, u);
        for (size_t i = 0; i < count; ++i) {
            std::vector<double> p(static_cast<size_t>(dim));
            for (int j = 0; j < dim; ++j) p[static_cast<size_t>(j)] = u.coord(j)[i];
            pts.push_back(p);
        }
    }
    return pts;
}

} // namespace

TEST(StratificationGrid, ProductIsNAndBalanced) {
    for (int dim = 1; dim <= 5; ++dim)
        for (uint64_t n :
             {1ull, 2ull, 7ull, 12ull, 16ull, 64ull, 97ull, 100ull, 1000ull, 4096ull, 65536ull}) {
            auto k = stratification_grid(n, dim);
            uint64_t prod = 1;
            for (uint64_t v : k) prod *= v;
            EXPECT_EQ(prod, n) << "n=" << n << " dim=" << dim;
        }
    // Powers of two: counts within a factor 2 of each other.
    for (int dim = 1; dim <= 4; ++dim)
        for (int m = 0; m <= 20; ++m) {
            auto k = stratification_grid(uint64_t(1) << m, dim);
            uint64_t lo = *std::min_element(k.begin(), k.end()),
                     hi = *std::max_element(k.begin(), k.end());
            EXPECT_LE(hi, 2 * lo) << "m=" << m << " dim=" << dim;
        }
    EXPECT_EQ(stratification_grid(64, 3), (std::vector<uint64_t>{4, 4, 4}));
    EXPECT_EQ(stratification_grid(97, 2), (std::vector<uint64_t>{1, 97})); // prime: slabs
}

TEST(Samplers, StratifiedPutsOnePointPerCell) {
    for (auto [dim, n] :
         std::vector<std::pair<int, uint64_t>>{{1, 37}, {2, 64}, {2, 128}, {3, 100}}) {
        auto k = stratification_grid(n, dim);
        auto pts = generate_all(SamplerKind::Stratified, dim, n, 3, 16);
        std::set<std::vector<uint64_t>> cells;
        for (auto& p : pts) {
            std::vector<uint64_t> c;
            for (int j = 0; j < dim; ++j) {
                ASSERT_GE(p[j], 0.0);
                ASSERT_LT(p[j], 1.0);
                c.push_back(static_cast<uint64_t>(p[j] * static_cast<double>(k[j])));
            }
            cells.insert(c);
        }
        EXPECT_EQ(cells.size(), n) << "dim=" << dim << " n=" << n;
    }
}

TEST(Samplers, LatinHypercubeOnePointPerSlab) {
    for (auto [dim, n] :
         std::vector<std::pair<int, uint64_t>>{{1, 10}, {2, 100}, {3, 257}, {5, 1000}}) {
        auto pts = generate_all(SamplerKind::LatinHypercube, dim, n, 5, 64);
        for (int j = 0; j < dim; ++j) {
            std::set<uint64_t> slabs;
            for (auto& p : pts) slabs.insert(static_cast<uint64_t>(p[j] * static_cast<double>(n)));
            EXPECT_EQ(slabs.size(), n) << "dim=" << dim << " axis " << j;
        }
    }
}

TEST(Samplers, PermuteIndexIsAPermutation) {
    for (uint64_t n : {1ull, 2ull, 3ull, 5ull, 64ull, 100ull, 1023ull, 1025ull})
        for (uint64_t key : {0ull, 1ull, 0xdeadbeefull}) {
            std::set<uint64_t> seen;
            for (uint64_t i = 0; i < n; ++i) {
                uint64_t p = permute_index(i, n, key);
                ASSERT_LT(p, n);
                seen.insert(p);
            }
            EXPECT_EQ(seen.size(), n);
        }
    // Different keys give different orders.
    int same = 0;
    for (uint64_t i = 0; i < 1000; ++i)
        same += permute_index(i, 1000, 1) == permute_index(i, 1000, 2);
    EXPECT_LT(same, 20);
}

TEST(Samplers, MarginalsUniformChiSquare) {
    const uint64_t n = 20000;
    const int bins = 50;
    const SamplerKind kinds[] = {SamplerKind::Independent, SamplerKind::Stratified,
                                 SamplerKind::LatinHypercube};
    const double level = test::sidak_level(0.01, 3 * 3);
    for (SamplerKind kind : kinds) {
        // Many short runs pooled, so that a stratified run's exact balance does not make the
        // test trivially pass: each coordinate must be uniform marginally.
        std::vector<std::vector<double>> obs(3, std::vector<double>(bins, 0.0));
        for (uint64_t run = 0; run < n / 20; ++run) {
            auto pts = generate_all(kind, 3, 20, 100 + run, 8);
            for (auto& p : pts)
                for (int j = 0; j < 3; ++j) obs[j][static_cast<int>(p[j] * bins)] += 1.0;
        }
        for (int j = 0; j < 3; ++j) {
            auto r = test::chi_square(obs[j], std::vector<double>(bins, double(n) / bins));
            EXPECT_GT(r.p_value, level) << sampler_name(kind) << " axis " << j;
        }
    }
}

TEST(Samplers, BlockSizeDoesNotChangePoints) {
    for (SamplerKind kind :
         {SamplerKind::Independent, SamplerKind::Stratified, SamplerKind::LatinHypercube}) {
        auto a = generate_all(kind, 3, 1000, 42, 1000);
        auto b = generate_all(kind, 3, 1000, 42, 7);
        EXPECT_EQ(a, b) << sampler_name(kind);
    }
}

// Stratified blocks that start anywhere (mid-cell with two points per cell, mid-row of the
// grid) give the points sample_coordinate gives, and every cell holds its two points.
TEST(Samplers, StratifiedBlocksStartingMidCellAgreeWithRandomAccess) {
    SamplerOptions options;
    options.per_stratum = 2;
    for (int dim : {1, 2, 3}) {
        const uint64_t n = 2 * 210; // 210 cells: grids 210, 14 x 15, 5 x 6 x 7
        Pcg32 rng(5, 3);
        const SamplerPlan plan = make_sampler_plan(SamplerKind::Stratified, dim, n, rng, options);
        PointBlock u;
        u.reset(dim, 13);
        std::vector<int> per_cell(n / 2, 0);
        for (uint64_t first = 0; first < n; first += 13) {
            const size_t count = static_cast<size_t>(std::min<uint64_t>(13, n - first));
            generate_block(plan, first, count, u);
            for (size_t i = 0; i < count; ++i) {
                uint64_t cell = 0;
                for (int j = 0; j < dim; ++j) {
                    const double x = u.coord(j)[i];
                    ASSERT_EQ(x, sample_coordinate(plan, first + i, j))
                        << "dim " << dim << " point " << first + i << " axis " << j;
                    const uint64_t k = plan.strata[static_cast<size_t>(j)];
                    cell = cell * k + static_cast<uint64_t>(x * static_cast<double>(k));
                }
                EXPECT_EQ(cell, (first + i) / 2) << "dim " << dim << " point " << first + i;
                ++per_cell[static_cast<size_t>(cell)];
            }
        }
        for (int c : per_cell) EXPECT_EQ(c, 2);
    }
}

// A point is addressed by (plan, index, dimension): blocks generated backwards, one point at a
// time, and sample_coordinate all give the points of the forward run, bit for bit.
TEST(Samplers, PointsAreAddressableInAnyOrder) {
    const SamplerKind kinds[] = {SamplerKind::Independent,    SamplerKind::Stratified,
                                 SamplerKind::LatinHypercube, SamplerKind::Sobol,
                                 SamplerKind::Halton,         SamplerKind::Lattice};
    const int dim = 3;
    const uint64_t n = 640;
    for (SamplerKind kind : kinds) {
        SamplerOptions options;
        options.randomization =
            default_randomization(is_qmc(kind) ? qmc_kind_of(kind) : QmcKind::Sobol);
        options.randomizations = is_qmc(kind) ? 4 : 1;
        Pcg32 rng(99, 5);
        const SamplerPlan plan = make_sampler_plan(kind, dim, n, rng, options);
        PointBlock forward, piece;
        forward.reset(dim, n);
        generate_block(plan, 0, n, forward);
        piece.reset(dim, 100);
        for (uint64_t end = n; end > 0;) { // backwards, in blocks of 100 (the first block 40)
            const uint64_t first = end >= 100 ? end - 100 : 0;
            generate_block(plan, first, size_t(end - first), piece);
            for (uint64_t i = first; i < end; ++i)
                for (int j = 0; j < dim; ++j)
                    ASSERT_EQ(piece.coord(j)[i - first], forward.coord(j)[i])
                        << sampler_name(kind) << " point " << i << " dim " << j;
            end = first;
        }
        for (uint64_t i : {uint64_t(0), uint64_t(1), uint64_t(159), uint64_t(160), n - 1})
            for (int j = 0; j < dim; ++j)
                ASSERT_EQ(sample_coordinate(plan, i, j), forward.coord(j)[i])
                    << sampler_name(kind) << " point " << i << " dim " << j;
    }
}

// Two runs planned in turn from one generator draw different jitter.
TEST(Samplers, PlansFromOneGeneratorAreDistinct) {
    Pcg32 rng(7, 7);
    const SamplerPlan a = make_sampler_plan(SamplerKind::Independent, 2, 64, rng);
    const SamplerPlan b = make_sampler_plan(SamplerKind::Independent, 2, 64, rng);
    PointBlock ua, ub;
    ua.reset(2, 64);
    ub.reset(2, 64);
    generate_block(a, 0, 64, ua);
    generate_block(b, 0, 64, ub);
    int equal = 0;
    for (size_t i = 0; i < 64; ++i) equal += ua.coord(0)[i] == ub.coord(0)[i];
    EXPECT_EQ(equal, 0);
}

TEST(Samplers, ParseNames) {
    SamplerKind k;
    EXPECT_TRUE(parse_sampler("latin_hypercube", &k));
    EXPECT_EQ(k, SamplerKind::LatinHypercube);
    EXPECT_FALSE(parse_sampler("faure", &k));
    EXPECT_TRUE(parse_sampler("sobol", &k));
    EXPECT_EQ(k, SamplerKind::Sobol);
}
