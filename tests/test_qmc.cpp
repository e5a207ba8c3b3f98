// Randomized quasi-Monte Carlo points: Sobol' digits against an independent Bratley-Fox
// recurrence, the (t, m, 2)-net property of pairs and its invariance under scrambling, 1-D
// stratification of Halton and lattice points, uniformity of every randomization (including
// the fill bits), unbiasedness, block generation against random access, and the n^-3 variance
// of Owen-scrambled Sobol' points on a smooth integrand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <set>
#include <utility>
#include <vector>

#include "core/qmc.h"
#include "core/rng.h"
#include "test_support.h"

using namespace mcp;

namespace {

struct Combo {
    QmcKind kind;
    QmcRandomization r;
};

const Combo kRandomized[] = {
    {QmcKind::Sobol, QmcRandomization::Owen},
    {QmcKind::Sobol, QmcRandomization::LmsShift},
    {QmcKind::Sobol, QmcRandomization::DigitalShift},
    {QmcKind::Halton, QmcRandomization::Owen},
    {QmcKind::Halton, QmcRandomization::Permutation},
    {QmcKind::Lattice, QmcRandomization::RandomShift},
};

const Combo kAll[] = {
    {QmcKind::Sobol, QmcRandomization::None},
    {QmcKind::Sobol, QmcRandomization::Owen},
    {QmcKind::Sobol, QmcRandomization::LmsShift},
    {QmcKind::Sobol, QmcRandomization::DigitalShift},
    {QmcKind::Halton, QmcRandomization::None},
    {QmcKind::Halton, QmcRandomization::Owen},
    {QmcKind::Halton, QmcRandomization::Permutation},
    {QmcKind::Lattice, QmcRandomization::None},
    {QmcKind::Lattice, QmcRandomization::RandomShift},
};

std::string label(const Combo& c) {
    return std::string(qmc_kind_name(c.kind)) + "/" + randomization_name(c.r);
}

// Points first .. first + n - 1 of a randomization, coordinate j of point i at [j][i].
std::vector<std::vector<double>> points(const QmcRandomizer& r, uint64_t first, size_t n) {
    PointBlock u;
    u.reset(r.dim, n);
    qmc_points(r, first, n, u);
    std::vector<std::vector<double>> pts(static_cast<size_t>(r.dim));
    for (int j = 0; j < r.dim; ++j) pts[j].assign(u.coord(j), u.coord(j) + n);
    return pts;
}

uint64_t bits_of(double x) {
    uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}

// ---------------------------------------------------------------------------------------------
// Sobol' digits by the recurrence of Bratley and Fox (ACM TOMS 14, 1988), written here
// independently of the implementation: m_k = 2 a_1 m_(k-1) ^ 4 a_2 m_(k-2) ^ ... ^
// 2^(s-1) a_(s-1) m_(k-s+1) ^ 2^s m_(k-s) ^ m_(k-s), v_k = m_k / 2^k, and point n = point n-1
// XOR v_c with c the position of the lowest zero bit of n - 1 (Antonov-Saleev).
struct JoeKuoRow {
    int s;
    unsigned a;
    std::vector<uint64_t> m;
};

std::vector<uint32_t> bratley_fox_points(const JoeKuoRow& row, int count) {
    std::vector<uint64_t> m = row.m;
    for (int k = static_cast<int>(m.size()); k < 32; ++k) {
        uint64_t x = (m[k - row.s] << row.s) ^ m[k - row.s];
        for (int i = 1; i < row.s; ++i)
            if ((row.a >> (row.s - 1 - i)) & 1u) x ^= m[k - i] << i;
        m.push_back(x);
    }
    std::vector<uint32_t> pts(static_cast<size_t>(count), 0);
    for (int n = 1; n < count; ++n) {
        int c = 0; // 0-based position of the lowest zero bit of n - 1
        while (((n - 1) >> c) & 1) ++c;
        pts[n] = pts[n - 1] ^ static_cast<uint32_t>(m[c] << (31 - c));
    }
    return pts;
}

// ---------------------------------------------------------------------------------------------
// (t, m, 2)-nets: the smallest t such that every elementary interval
// [a1/2^k1, (a1+1)/2^k1) x [a2/2^k2, (a2+1)/2^k2) with k1 + k2 = m - t holds exactly 2^t of the
// 2^m points.
int net_t(const std::vector<double>& x, const std::vector<double>& y, int m) {
    const size_t n = size_t(1) << m;
    for (int t = 0; t <= m; ++t) {
        bool ok = true;
        for (int k1 = 0; k1 <= m - t && ok; ++k1) {
            const int k2 = m - t - k1;
            std::vector<int> count(size_t(1) << (m - t), 0);
            for (size_t i = 0; i < n; ++i) {
                // Scaling by a power of two is exact, so the cell of a 53-bit double is exact.
                const auto c1 = static_cast<size_t>(std::ldexp(x[i], k1));
                const auto c2 = static_cast<size_t>(std::ldexp(y[i], k2));
                ++count[(c1 << k2) | c2];
            }
            for (int c : count) ok = ok && c == (1 << t);
        }
        if (ok) return t;
    }
    return m + 1;
}

// Estimate of the integral of f over [0,1)^d from points first .. first + n - 1.
template <class F> double estimate(const QmcRandomizer& r, size_t n, F f) {
    auto pts = points(r, 0, n);
    double sum = 0.0;
    std::vector<double> p(static_cast<size_t>(r.dim));
    for (size_t i = 0; i < n; ++i) {
        for (int j = 0; j < r.dim; ++j) p[j] = pts[j][i];
        sum += f(p);
    }
    return sum / static_cast<double>(n);
}

} // namespace

TEST(Qmc, NamesParsingAndLimits) {
    for (const Combo& c : kAll) {
        QmcRandomization parsed = QmcRandomization::None;
        ASSERT_TRUE(parse_randomization(randomization_name(c.r), &parsed));
        EXPECT_EQ(parsed, c.r);
        EXPECT_EQ(check_randomization(c.kind, c.r), "") << label(c);
    }
    QmcRandomization r;
    EXPECT_FALSE(parse_randomization("scrambled", &r));
    EXPECT_FALSE(parse_randomization("", &r));
    EXPECT_EQ(check_randomization(QmcKind::Sobol, QmcRandomization::Permutation),
              "randomization 'permutation' does not apply to sobol points (sobol: owen, "
              "lms_shift, digital_shift, none)");
    EXPECT_EQ(check_randomization(QmcKind::Halton, QmcRandomization::RandomShift),
              "randomization 'random_shift' does not apply to halton points (halton: owen, "
              "permutation, none)");
    EXPECT_EQ(check_randomization(QmcKind::Lattice, QmcRandomization::Owen),
              "randomization 'owen' does not apply to lattice points (lattice: random_shift, "
              "none)");
    EXPECT_NE(check_randomization(QmcKind::Halton, QmcRandomization::LmsShift), "");
    EXPECT_NE(check_randomization(QmcKind::Lattice, QmcRandomization::DigitalShift), "");
    EXPECT_EQ(default_randomization(QmcKind::Sobol), QmcRandomization::Owen);
    EXPECT_EQ(default_randomization(QmcKind::Halton), QmcRandomization::Owen);
    EXPECT_EQ(default_randomization(QmcKind::Lattice), QmcRandomization::RandomShift);
    EXPECT_STREQ(qmc_kind_name(QmcKind::Lattice), "lattice");
    for (QmcKind k : {QmcKind::Sobol, QmcKind::Halton, QmcKind::Lattice})
        EXPECT_EQ(qmc_max_dim(k), 1024);
    EXPECT_EQ(qmc_max_points(QmcKind::Sobol), uint64_t(1) << 32);
    EXPECT_EQ(qmc_max_points(QmcKind::Halton), uint64_t(1) << 48);
    EXPECT_EQ(qmc_max_points(QmcKind::Lattice), uint64_t(1) << 20);
}

TEST(Qmc, SobolMatchesBratleyFoxRecurrence) {
    // Rows d = 2 .. 8 and d = 1024 of new-joe-kuo-6.21201 (s, a, m_1 .. m_s); d = 1 is the van
    // der Corput sequence, m_k = 1 for every k (the identity generator matrix).
    const std::vector<std::pair<int, JoeKuoRow>> rows = {
        {1, {0, 0, std::vector<uint64_t>(32, 1)}},
        {2, {1, 0, {1}}},
        {3, {2, 1, {1, 3}}},
        {4, {3, 1, {1, 3, 1}}},
        {5, {3, 2, {1, 1, 1}}},
        {6, {4, 1, {1, 1, 3, 3}}},
        {7, {4, 4, {1, 3, 5, 13}}},
        {8, {5, 2, {1, 1, 5, 5, 17}}},
        {1024, {13, 3538, {1, 1, 5, 11, 11, 33, 37, 29, 263, 1019, 657, 1453, 7807}}},
    };
    const int n = 4096;
    for (const auto& [d, row] : rows) {
        auto expected = bratley_fox_points(row, n);
        for (int i = 0; i < n; ++i)
            ASSERT_EQ(sobol_u32(static_cast<uint64_t>(i), d - 1), expected[i])
                << "dimension " << d << " point " << i;
    }
    // The first points of the two-dimensional sequence.
    const uint32_t first[][2] = {{0x00000000, 0x00000000}, {0x80000000, 0x80000000},
                                 {0xc0000000, 0x40000000}, {0x40000000, 0xc0000000},
                                 {0x60000000, 0x60000000}, {0xe0000000, 0xe0000000}};
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 2; ++j) EXPECT_EQ(sobol_u32(static_cast<uint64_t>(i), j), first[i][j]);
    // Unscrambled coordinates are the digits exactly.
    auto r = make_qmc_randomizer(QmcKind::Sobol, QmcRandomization::None, 3, 1);
    EXPECT_EQ(qmc_coordinate(r, 0, 2), 0.0);
    EXPECT_EQ(qmc_coordinate(r, 12345, 2), sobol_u32(12345, 2) * 0x1p-32);
}

TEST(Qmc, SobolByteTablesMatchTheGrayCodeLoop) {
    // The pixel samplers' table lookups against sobol_u32 on indices spread over 32 bits:
    // the first 4096, every single bit and pseudo-random ones.
    const SobolByteTables& t = sobol_byte_tables();
    std::vector<uint32_t> indices;
    for (uint32_t i = 0; i < 4096; ++i) indices.push_back(i);
    for (int b = 0; b < 32; ++b) indices.push_back(uint32_t(1) << b);
    Pcg32 rng(7, 3);
    for (int i = 0; i < 20000; ++i) indices.push_back(rng.next_u32());
    indices.push_back(0xffffffffu);
    for (uint32_t i : indices) {
        const uint64_t xy = t.point_2d(i);
        ASSERT_EQ(uint32_t(xy), sobol_u32(i, 0)) << i;
        ASSERT_EQ(uint32_t(xy >> 32), sobol_u32(i, 1)) << i;
        ASSERT_EQ(t.coordinate_2(i), sobol_u32(i, 2)) << i;
    }
}

TEST(Qmc, HaltonAndLatticeKnownValues) {
    auto h = make_qmc_randomizer(QmcKind::Halton, QmcRandomization::None, 1024, 1);
    const double base2[] = {0.0, 0.5, 0.25, 0.75, 0.125, 0.625};
    for (int i = 0; i < 6; ++i) EXPECT_EQ(qmc_coordinate(h, static_cast<uint64_t>(i), 0), base2[i]);
    EXPECT_DOUBLE_EQ(qmc_coordinate(h, 1, 1), 1.0 / 3.0);
    EXPECT_DOUBLE_EQ(qmc_coordinate(h, 5, 1), 2.0 / 3.0 + 1.0 / 9.0); // 5 = 12 in base 3
    EXPECT_DOUBLE_EQ(qmc_coordinate(h, 7, 2), 2.0 / 5.0 + 1.0 / 25.0);
    EXPECT_DOUBLE_EQ(qmc_coordinate(h, 1, 1023), 1.0 / 8161.0); // the 1024th prime
    EXPECT_DOUBLE_EQ(qmc_coordinate(h, 8162, 1023), 1.0 / 8161.0 + 1.0 / (8161.0 * 8161.0));

    // Point 2^19 of the lattice sequence is point 1 of the rule: z_j / 2^20.
    auto l = make_qmc_randomizer(QmcKind::Lattice, QmcRandomization::None, 1024, 1);
    EXPECT_EQ(qmc_coordinate(l, uint64_t(1) << 19, 0), 1.0 * 0x1p-20);
    EXPECT_EQ(qmc_coordinate(l, uint64_t(1) << 19, 1), 182667.0 * 0x1p-20);
    EXPECT_EQ(qmc_coordinate(l, uint64_t(1) << 19, 1023), 9575.0 * 0x1p-20);
    // Point 1 is 1/2 in every coordinate (z_j odd), point 0 the origin.
    for (int j : {0, 1, 500, 1023}) {
        EXPECT_EQ(qmc_coordinate(l, 1, j), 0.5);
        EXPECT_EQ(qmc_coordinate(l, 0, j), 0.0);
    }
}

TEST(Qmc, OwenScrambleIsNestedBitFlipping) {
    // Flips depend only on earlier digits: two values sharing exactly p leading digits still
    // share exactly p leading digits after scrambling (a bijection of every dyadic interval).
    uint64_t state = 12345;
    for (int trial = 0; trial < 2000; ++trial) {
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        const auto v = static_cast<uint32_t>(state >> 32);
        const int p = trial % 32;
        const uint32_t lower_digits = (0x80000000u >> p) - 1u; // digits after digit p + 1
        const uint32_t w = v ^ (0x80000000u >> p) ^ (static_cast<uint32_t>(state) & lower_digits);
        const uint32_t seed = static_cast<uint32_t>(state >> 7);
        const uint32_t sv = owen_scramble_u32(v, seed), sw = owen_scramble_u32(w, seed);
        const int common = __builtin_clz(sv ^ sw);
        ASSERT_EQ(common, p) << "trial " << trial;
    }
    // And the flips do depend on the earlier digits: digit 2 of 0x40000000 and of 0xc0000000
    // (different first digits) is flipped differently for about half of the seeds; a digital
    // shift would flip both alike.
    int differ = 0;
    for (uint32_t seed = 0; seed < 256; ++seed)
        differ += ((owen_scramble_u32(0x40000000u, seed * 0x9e3779b9u) ^
                    owen_scramble_u32(0xc0000000u, seed * 0x9e3779b9u)) >>
                   30) &
                  1u;
    EXPECT_GT(differ, 128 - 4 * 8); // Binomial(256, 1/2): mean 128, sd 8
    EXPECT_LT(differ, 128 + 4 * 8);
}

TEST(Qmc, HaltonOwenIsNestedPermutationIsNot) {
    // Indices 0 + b and 1 + b share their second digit (1) and differ in the first. Random
    // digit permutations map the shared digit alike, always; a nested scramble permutes it
    // by a permutation drawn for each first digit, so the images agree with probability 1/b.
    const int keys = 600;
    for (auto dim_base : {std::pair<int, int>{0, 2}, {1, 3}, {2, 5}}) {
        const int dim = dim_base.first, b = dim_base.second;
        int agree_owen = 0, agree_perm = 0;
        for (int k = 0; k < keys; ++k) {
            auto second_digit = [&](const QmcRandomizer& r, uint64_t index) {
                const double x = qmc_coordinate(r, index, dim);
                return static_cast<int>(std::floor(x * b * b)) % b;
            };
            auto owen = make_qmc_randomizer(QmcKind::Halton, QmcRandomization::Owen, 3,
                                            static_cast<uint64_t>(k));
            auto perm = make_qmc_randomizer(QmcKind::Halton, QmcRandomization::Permutation, 3,
                                            static_cast<uint64_t>(k));
            const auto i0 = static_cast<uint64_t>(b), i1 = static_cast<uint64_t>(b + 1);
            agree_owen += second_digit(owen, i0) == second_digit(owen, i1);
            agree_perm += second_digit(perm, i0) == second_digit(perm, i1);
        }
        EXPECT_EQ(agree_perm, keys) << "base " << b;
        const double p = 1.0 / b, mean = keys * p, sd = std::sqrt(keys * p * (1.0 - p));
        EXPECT_LT(std::fabs(agree_owen - mean), 4.0 * sd) << "base " << b;
    }
}

TEST(Qmc, SobolNetPropertySurvivesScrambling) {
    // The first 2^m points projected on two of the first 8 dimensions form a (t, m, 2)-net.
    // For the Joe-Kuo numbers and m = 4 .. 10 the pair (0, 1) has t = 0 for every m and the
    // largest t of the 28 pairs is 4 (dimensions 1, 7 at m = 6 and 0, 7 at m = 9; 0-based).
    const int kMaxT = 4;
    const int d = 8, mmax = 10;
    auto none = make_qmc_randomizer(QmcKind::Sobol, QmcRandomization::None, d, 0);
    auto base = points(none, 0, size_t(1) << mmax);
    std::vector<std::vector<int>> t0(static_cast<size_t>(mmax + 1));
    int worst = 0;
    for (int m = 4; m <= mmax; ++m) {
        std::vector<std::vector<double>> sub(d);
        for (int j = 0; j < d; ++j) sub[j].assign(base[j].begin(), base[j].begin() + (1 << m));
        for (int a = 0; a < d; ++a)
            for (int b = a + 1; b < d; ++b) {
                const int t = net_t(sub[a], sub[b], m);
                t0[m].push_back(t);
                worst = std::max(worst, t);
                if (a == 0 && b == 1) {
                    EXPECT_EQ(t, 0) << "m=" << m;
                }
            }
    }
    EXPECT_LE(worst, kMaxT);
    EXPECT_GE(worst, 1); // the test would not notice a scramble that destroyed the structure

    for (QmcRandomization r :
         {QmcRandomization::Owen, QmcRandomization::LmsShift, QmcRandomization::DigitalShift})
        for (uint64_t key : {1ull, 77ull, 0xfeedfaceull}) {
            auto rr = make_qmc_randomizer(QmcKind::Sobol, r, d, key);
            auto pts = points(rr, 0, size_t(1) << mmax);
            for (int m = 4; m <= mmax; ++m) {
                std::vector<std::vector<double>> sub(d);
                for (int j = 0; j < d; ++j)
                    sub[j].assign(pts[j].begin(), pts[j].begin() + (1 << m));
                size_t pair = 0;
                for (int a = 0; a < d; ++a)
                    for (int b = a + 1; b < d; ++b, ++pair)
                        ASSERT_EQ(net_t(sub[a], sub[b], m), t0[m][pair])
                            << randomization_name(r) << " key " << key << " m=" << m << " dims "
                            << a << "," << b;
            }
        }
}

TEST(Qmc, HaltonOneDimensionalStratification) {
    // The first b^m points fall one in each interval [k/b^m, (k+1)/b^m).
    struct Case {
        int dim;
        uint64_t base;
        int m;
    };
    const Case cases[] = {{0, 2, 12}, {1, 3, 7},    {2, 5, 5},      {3, 7, 4},
                          {9, 29, 2}, {99, 541, 1}, {1023, 8161, 1}};
    for (QmcRandomization r :
         {QmcRandomization::None, QmcRandomization::Owen, QmcRandomization::Permutation})
        for (uint64_t key : {3ull, 4ull}) {
            auto h = make_qmc_randomizer(QmcKind::Halton, r, 1024, key);
            for (const Case& cs : cases) {
                const int j = cs.dim;
                uint64_t n = 1;
                for (int k = 0; k < cs.m; ++k) n *= cs.base;
                std::set<uint64_t> cells;
                for (uint64_t i = 0; i < n; ++i) {
                    const double x = qmc_coordinate(h, i, j);
                    ASSERT_GE(x, 0.0);
                    ASSERT_LT(x, 1.0);
                    // Unscrambled points sit exactly on k/b^m (up to rounding): round, not floor.
                    const double scaled = x * static_cast<double>(n);
                    cells.insert(static_cast<uint64_t>(r == QmcRandomization::None
                                                           ? std::floor(scaled + 0.5)
                                                           : std::floor(scaled)));
                }
                EXPECT_EQ(cells.size(), n) << randomization_name(r) << " dim " << j << " base "
                                           << cs.base << " m " << cs.m;
            }
        }
}

// A Halton Owen randomization told how many points it serves (as a run's batches are) hashes
// the digits where those points' prefixes can agree and draws the rest at once. It must keep
// the stratification of every b^m prefix, equal random access, stay unbiased, and put the
// points uniformly inside their finest cells.
TEST(Qmc, HaltonOwenBoundedByItsPointCount) {
    struct Case {
        int dim;
        uint64_t base;
        int m;
    };
    for (const Case& cs : {Case{0, 2, 10}, Case{1, 3, 6}, Case{4, 11, 2}}) {
        uint64_t n = 1;
        for (int k = 0; k < cs.m; ++k) n *= cs.base;
        for (uint64_t key : {5ull, 6ull}) {
            auto h = make_qmc_randomizer(QmcKind::Halton, QmcRandomization::Owen, 8, key, n);
            PointBlock u;
            u.reset(8, size_t(n));
            qmc_points(h, 0, size_t(n), u);
            for (uint64_t prefix = 1; prefix <= n; prefix *= cs.base) {
                std::set<uint64_t> cells;
                for (uint64_t i = 0; i < prefix; ++i)
                    cells.insert(uint64_t(std::floor(u.coord(cs.dim)[i] * double(prefix))));
                EXPECT_EQ(cells.size(), prefix) << "base " << cs.base << " prefix " << prefix;
            }
            // Positions inside the finest cells, x b^m - floor: uniform (chi-square, 8 bins).
            std::vector<double> counts(8, 0.0);
            for (uint64_t i = 0; i < n; ++i) {
                ASSERT_EQ(qmc_coordinate(h, i, cs.dim), u.coord(cs.dim)[i]);
                const double t = u.coord(cs.dim)[i] * double(n);
                counts[size_t((t - std::floor(t)) * 8.0)] += 1.0;
            }
            double chi2 = 0.0;
            for (double c : counts)
                chi2 += (c - double(n) / 8) * (c - double(n) / 8) / (double(n) / 8);
            EXPECT_LT(chi2, 24.3) << "base " << cs.base; // chi^2_7 upper 0.001 quantile
        }
    }
    // Unbiased: 300 randomizations of 243 points (3^5) of prod 3 x_j^2 in 3 dimensions.
    double sum = 0.0, sum2 = 0.0;
    const int reps = 300;
    for (int rep = 0; rep < reps; ++rep) {
        auto h = make_qmc_randomizer(QmcKind::Halton, QmcRandomization::Owen, 3, 900 + rep, 243);
        double e = 0.0;
        for (uint64_t i = 0; i < 243; ++i) {
            double p = 1.0;
            for (int j = 0; j < 3; ++j) p *= 3.0 * std::pow(qmc_coordinate(h, i, j), 2);
            e += p / 243.0;
        }
        sum += e;
        sum2 += e * e;
    }
    const double mean = sum / reps, se = std::sqrt((sum2 / reps - mean * mean) / (reps - 1));
    EXPECT_LT(std::fabs(mean - 1.0), 4.0 * se);
}

TEST(Qmc, LatticeOneDimensionalStratification) {
    // The first 2^m points of the sequence form a lattice: one point per [k/2^m, (k+1)/2^m)
    // (z_j odd). All 2^20 points through blocks in the first dimensions (a randomizer of fewer
    // dimensions has the same first coordinates), fewer through random access in the last ones.
    auto check = [](QmcRandomization r, int m, int j, auto coordinate) {
        const size_t n = size_t(1) << m;
        std::vector<char> seen(n, 0);
        size_t distinct = 0;
        for (size_t i = 0; i < n; ++i) {
            const auto c = static_cast<size_t>(std::ldexp(coordinate(i), m));
            ASSERT_LT(c, n);
            distinct += seen[c] == 0;
            seen[c] = 1;
        }
        EXPECT_EQ(distinct, n) << randomization_name(r) << " dim " << j << " m " << m;
    };
    for (QmcRandomization r : {QmcRandomization::None, QmcRandomization::RandomShift}) {
        auto wide = make_qmc_randomizer(QmcKind::Lattice, r, 1024, 9);
        for (int j : {511, 1022, 1023})
            for (int m : {1, 4, 10, 14})
                check(r, m, j, [&](size_t i) { return qmc_coordinate(wide, i, j); });
        auto narrow = make_qmc_randomizer(QmcKind::Lattice, r, 3, 9);
        auto all = points(narrow, 0, size_t(1) << 20);
        for (int j = 0; j < 3; ++j)
            for (int m : {1, 7, 12, 20}) check(r, m, j, [&](size_t i) { return all[j][i]; });
    }
}

TEST(Qmc, RandomizedPointsAreUniform) {
    // Over many keys, a fixed point's coordinate is uniform on (0, 1), and so are its lowest
    // digits: the 8 lowest bits of floor(x 2^53) (exact below 1/2), which a randomization
    // without fill bits would leave constant.
    const int keys = 4096, bins = 64;
    const int kTests = 6 * 4;
    const double level = test::sidak_level(0.01, kTests);
    const std::pair<uint64_t, int> cases[] = {{0, 0}, {0, 5}, {37, 1}};
    for (const Combo& c : kRandomized) {
        std::vector<std::vector<double>> obs(3, std::vector<double>(bins, 0.0));
        std::vector<double> low(256, 0.0);
        double low_total = 0.0;
        for (int k = 0; k < keys; ++k) {
            auto r = make_qmc_randomizer(c.kind, c.r, 6, 1000 + static_cast<uint64_t>(k));
            for (int t = 0; t < 3; ++t) {
                const double x = qmc_coordinate(r, cases[t].first, cases[t].second);
                ASSERT_GT(x, 0.0);
                ASSERT_LT(x, 1.0);
                obs[t][static_cast<size_t>(x * bins)] += 1.0;
                if (x < 0.5) {
                    low[static_cast<uint64_t>(std::ldexp(x, 53)) & 255u] += 1.0;
                    low_total += 1.0;
                }
            }
        }
        for (int t = 0; t < 3; ++t) {
            auto res = test::chi_square(obs[t], std::vector<double>(bins, double(keys) / bins));
            EXPECT_GT(res.p_value, level)
                << label(c) << " point " << cases[t].first << " dim " << cases[t].second;
        }
        auto res = test::chi_square(low, std::vector<double>(256, low_total / 256));
        EXPECT_GT(res.p_value, level) << label(c) << " low bits";
    }
}

TEST(Qmc, OwenFillBitsVaryFromPointToPoint) {
    // Within one Owen-scrambled Sobol' randomization the fill bits differ between points
    // (a hash of the digits), unlike a digital shift's constant fill.
    auto r = make_qmc_randomizer(QmcKind::Sobol, QmcRandomization::Owen, 2, 2024);
    auto pts = points(r, 0, 1 << 14);
    std::vector<double> low(256, 0.0);
    double total = 0.0;
    for (int j = 0; j < 2; ++j)
        for (double x : pts[j])
            if (x < 0.5) {
                low[static_cast<uint64_t>(std::ldexp(x, 53)) & 255u] += 1.0;
                total += 1.0;
            }
    auto res = test::chi_square(low, std::vector<double>(256, total / 256));
    EXPECT_GT(res.p_value, 1e-3);
}

TEST(Qmc, EstimatesAreUnbiased) {
    // 200 randomizations of 256 points; the mean of the estimates within 4 standard errors.
    const int reps = 200;
    const size_t n = 256;
    auto cubic = [](const std::vector<double>& x) {
        double p = 1.0;
        for (double v : x) p *= 3.0 * v * v;
        return p;
    };
    auto corner = [](const std::vector<double>& x) { return x[0] + x[1] < 0.7 ? 1.0 : 0.0; };
    for (const Combo& c : kRandomized) {
        for (int which = 0; which < 2; ++which) {
            const int d = which == 0 ? 4 : 2;
            const double exact = which == 0 ? 1.0 : 0.245;
            double sum = 0.0, sum2 = 0.0;
            for (int rep = 0; rep < reps; ++rep) {
                auto r = make_qmc_randomizer(c.kind, c.r, d, 500 + static_cast<uint64_t>(rep));
                const double e = which == 0 ? estimate(r, n, cubic) : estimate(r, n, corner);
                sum += e;
                sum2 += e * e;
            }
            const double mean = sum / reps;
            const double var = (sum2 - reps * mean * mean) / (reps - 1);
            const double se = std::sqrt(std::max(var, 0.0) / reps);
            EXPECT_GT(se, 0.0) << label(c);
            EXPECT_LT(std::fabs(mean - exact), 4.0 * se)
                << label(c) << (which == 0 ? " prod 3x^2" : " x0+x1<0.7") << " mean " << mean;
        }
    }
}

TEST(Qmc, BlocksEqualRandomAccess) {
    const std::vector<std::pair<uint64_t, size_t>> blocks = {
        {0, 1}, {1, 7}, {13, 301}, {1000, 257}, {3, 1}, {255, 2}, {511, 513}};
    for (const Combo& c : kAll) {
        for (int d : {5, 1024}) {
            auto r = make_qmc_randomizer(c.kind, c.r, d, 31337);
            std::vector<std::pair<uint64_t, size_t>> all = blocks;
            // Large indices: near the end of each point set.
            const uint64_t end = std::min<uint64_t>(qmc_max_points(c.kind), uint64_t(1) << 40);
            all.push_back({end - 37, 37});
            if (c.kind == QmcKind::Sobol) all.push_back({(uint64_t(1) << 31) - 5, 11});
            PointBlock u;
            u.reset(d, 1100);
            for (auto [first, count] : all) {
                if (d == 1024 && count > 40) count = 40; // keep the wide case quick
                const size_t offset = 3;
                qmc_points(r, first, count, u, offset);
                for (int j = 0; j < d; ++j)
                    for (size_t i = 0; i < count; ++i) {
                        const double x = qmc_coordinate(r, first + i, j);
                        ASSERT_EQ(bits_of(u.coord(j)[offset + i]), bits_of(x))
                            << label(c) << " d " << d << " first " << first << " point " << i
                            << " dim " << j;
                        ASSERT_GE(x, 0.0);
                        ASSERT_LT(x, 1.0);
                        if (c.r != QmcRandomization::None) {
                            ASSERT_GT(x, 0.0);
                        }
                    }
            }
        }
    }
}

TEST(Qmc, BlocksOutOfOrderAndPrefixDimensions) {
    // Blocks in any order give the points of one pass; a randomizer of fewer dimensions gives
    // the same first coordinates; another key gives other points.
    for (const Combo& c : kRandomized) {
        auto r = make_qmc_randomizer(c.kind, c.r, 6, 8);
        auto whole = points(r, 0, 600);
        PointBlock u;
        u.reset(6, 600);
        for (uint64_t first : {400ull, 0ull, 200ull}) qmc_points(r, first, 200, u, first);
        for (int j = 0; j < 6; ++j)
            for (size_t i = 0; i < 600; ++i)
                ASSERT_EQ(bits_of(u.coord(j)[i]), bits_of(whole[j][i])) << label(c);
        auto narrow = points(make_qmc_randomizer(c.kind, c.r, 3, 8), 0, 600);
        auto other = points(make_qmc_randomizer(c.kind, c.r, 6, 9), 0, 600);
        int same = 0;
        for (int j = 0; j < 3; ++j)
            for (size_t i = 0; i < 600; ++i) {
                ASSERT_EQ(bits_of(narrow[j][i]), bits_of(whole[j][i])) << label(c);
                same += whole[j][i] == other[j][i];
            }
        EXPECT_EQ(same, 0) << label(c);
    }
}

TEST(Qmc, OwenScrambledVarianceFallsLikeNToTheMinus3) {
    // f(x) = x0 e^x0 x1 e^x1 (integral 1): smooth, so the variance of Owen-scrambled Sobol'
    // estimates is O(n^-3 (log n)^(d-1)) [Owen97b], and so is that of the linear matrix
    // scramble, which has the same variance [Owen03]. The fitted slope of log var against
    // log n over n = 2^6 .. 2^14 must be at most -2 (plain Monte Carlo: -1); the fitted values
    // are recorded as test properties (--gtest_output=xml).
    const int reps = 64, mmin = 6, mmax = 14;
    for (QmcRandomization rand : {QmcRandomization::Owen, QmcRandomization::LmsShift}) {
        std::vector<double> sum(mmax + 1, 0.0), sum2(mmax + 1, 0.0);
        for (int rep = 0; rep < reps; ++rep) {
            auto r = make_qmc_randomizer(QmcKind::Sobol, rand, 2, 7000 + uint64_t(rep));
            auto pts = points(r, 0, size_t(1) << mmax);
            double acc = 0.0;
            size_t i = 0;
            for (int m = 0; m <= mmax; ++m) {
                for (; i < (size_t(1) << m); ++i) {
                    const double x = pts[0][i], y = pts[1][i];
                    acc += x * std::exp(x) * y * std::exp(y);
                }
                const double e = acc / static_cast<double>(size_t(1) << m);
                sum[m] += e;
                sum2[m] += e * e;
            }
        }
        std::vector<double> lx, ly;
        for (int m = mmin; m <= mmax; ++m) {
            const double mean = sum[m] / reps;
            const double var = (sum2[m] - reps * mean * mean) / (reps - 1);
            ASSERT_GT(var, 0.0);
            lx.push_back(m * std::log(2.0));
            ly.push_back(std::log(var));
        }
        const double mx = std::accumulate(lx.begin(), lx.end(), 0.0) / lx.size();
        const double my = std::accumulate(ly.begin(), ly.end(), 0.0) / ly.size();
        double sxy = 0.0, sxx = 0.0;
        for (size_t k = 0; k < lx.size(); ++k) {
            sxy += (lx[k] - mx) * (ly[k] - my);
            sxx += (lx[k] - mx) * (lx[k] - mx);
        }
        const double slope = sxy / sxx;
        EXPECT_LE(slope, -2.0) << randomization_name(rand);
        RecordProperty(std::string("slope_") + randomization_name(rand), std::to_string(slope));
    }
}
