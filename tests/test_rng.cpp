// PCG32: reference outputs, stream independence, 53-bit doubles, bounded integers, jumps.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/rng.h"
#include "test_support.h"

using namespace mcp;

// The reference implementation's demo (pcg32-demo, seed 42, stream 54) prints these six
// outputs first [ONeill14]. Integer-only arithmetic: native and wasm must both match.
TEST(Pcg32, MatchesReferenceSequence) {
    Pcg32 rng(42u, 54u);
    const uint32_t expected[] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u,
                                 0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
    for (uint32_t e : expected) EXPECT_EQ(rng.next_u32(), e);
}

TEST(Pcg32, AdvanceMatchesStepping) {
    Pcg32 a(7u, 3u), b(7u, 3u);
    for (int i = 0; i < 1000; ++i) a.next_u32();
    b.advance(1000);
    EXPECT_EQ(a.state(), b.state());
    b.advance(-1000);
    Pcg32 c(7u, 3u);
    EXPECT_EQ(b.state(), c.state());
}

TEST(Pcg32, StreamsDiffer) {
    Pcg32 a(1u, 1u), b(1u, 2u);
    int equal = 0;
    for (int i = 0; i < 1000; ++i) equal += a.next_u32() == b.next_u32();
    EXPECT_LT(equal, 3);
}

TEST(Pcg32, DoublesAreOpenIntervalWith53Bits) {
    Pcg32 rng(3u, 9u);
    std::set<uint64_t> low_bits;
    double min_u = 1.0, max_u = 0.0;
    for (int i = 0; i < 100000; ++i) {
        double u = rng.next_double();
        ASSERT_GT(u, 0.0);
        ASSERT_LT(u, 1.0);
        min_u = std::fmin(min_u, u);
        max_u = std::fmax(max_u, u);
        // (k + 1/2) 2^-53: u * 2^53 - 1/2 must be an integer with bits below 2^-32 set.
        double k = u * 0x1p53 - 0.5;
        ASSERT_EQ(k, std::floor(k));
        low_bits.insert(static_cast<uint64_t>(k) & 0x1fffffu);
    }
    // With only 32 random bits the 21 low bits of k would always be zero.
    EXPECT_GT(low_bits.size(), 1000u);
    EXPECT_LT(min_u, 1e-3);
    EXPECT_GT(max_u, 1.0 - 1e-3);
}

TEST(Pcg32, DoublesUniformChiSquare) {
    Pcg32 rng(11u, 5u);
    const int bins = 100, n = 200000;
    std::vector<double> obs(bins, 0.0), expct(bins, double(n) / bins);
    for (int i = 0; i < n; ++i) obs[static_cast<int>(rng.next_double() * bins)] += 1.0;
    auto r = test::chi_square(obs, expct);
    EXPECT_GT(r.p_value, 1e-4) << "chi2=" << r.statistic;
}

TEST(Pcg32, BoundedIntegersUniform) {
    Pcg32 rng(5u, 77u);
    const uint32_t bound = 7;
    const int n = 70000;
    std::vector<double> obs(bound, 0.0), expct(bound, double(n) / bound);
    for (int i = 0; i < n; ++i) {
        uint32_t v = rng.next_below(bound);
        ASSERT_LT(v, bound);
        obs[v] += 1.0;
    }
    EXPECT_GT(test::chi_square(obs, expct).p_value, 1e-4);
}
