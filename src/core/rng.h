// PCG32 random number generator [ONeill14]: 64-bit LCG state, XSH-RR output permutation,
// 2^63 selectable streams. Everything here is integer arithmetic, so the raw output is
// bit-identical on every platform (native and WebAssembly alike).
#pragma once

#include <cstdint>

namespace mcp {

class Pcg32 {
  public:
    static constexpr uint64_t kMultiplier = 6364136223846793005ULL;
    static constexpr uint64_t kDefaultState = 0x853c49e6748fea9bULL;
    static constexpr uint64_t kDefaultStream = 0xda3e39cb94b95bdbULL;

    Pcg32() : state_(kDefaultState), inc_(kDefaultStream) {}
    Pcg32(uint64_t seed, uint64_t stream) { set_seed(seed, stream); }

    /// Seeding as in the reference pcg32_srandom_r [ONeill14]: the stream picks the LCG
    /// increment (any odd number), the seed the starting point on that cycle.
    void set_seed(uint64_t seed, uint64_t stream) {
        state_ = 0;
        inc_ = (stream << 1u) | 1u;
        next_u32();
        state_ += seed;
        next_u32();
    }

    /// 32 uniformly distributed bits.
    uint32_t next_u32() {
        uint64_t old = state_;
        state_ = old * kMultiplier + inc_;
        uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }

    /// Uniform double in the open interval (0, 1) carrying 53 random bits from two draws:
    /// u = (k + 1/2) 2^-53 with k uniform on [0, 2^53). Never 0 and never 1, so integrands
    /// singular at an end point (x^-0.9 at 0) are sampled down to 2^-54 without hitting
    /// the singularity itself, and log(u), 1/u are always finite.
    double next_double() {
        uint64_t hi = next_u32() >> 5; // 27 bits
        uint64_t lo = next_u32() >> 6; // 26 bits
        uint64_t k = (hi << 26) | lo;
        // k + 1/2 is rounded above 2^52 (ties to even): k = 2^53 - 1 would give exactly 1.
        // k < 2^53 converts exactly as a signed integer: one instruction (unsigned 64-bit
        // conversions take a branchy sequence natively and in wasm).
        const double u = (static_cast<double>(static_cast<int64_t>(k)) + 0.5) * 0x1p-53;
        return u < 1.0 ? u : 0x1.fffffffffffffp-1;
    }

    /// Uniform integer in [0, bound) without modulo bias (Lemire's rejection on the
    /// 32x32 -> 64 bit product [Lemire19]).
    uint32_t next_below(uint32_t bound) {
        uint64_t m = uint64_t(next_u32()) * bound;
        uint32_t low = static_cast<uint32_t>(m);
        if (low < bound) {
            uint32_t threshold = (0u - bound) % bound;
            while (low < threshold) {
                m = uint64_t(next_u32()) * bound;
                low = static_cast<uint32_t>(m);
            }
        }
        return static_cast<uint32_t>(m >> 32);
    }

    /// Jump ahead (or back, for negative delta) by delta steps in O(log delta) [Brown94].
    void advance(int64_t delta) {
        uint64_t cur_mult = kMultiplier, cur_plus = inc_;
        uint64_t acc_mult = 1u, acc_plus = 0u;
        uint64_t d = static_cast<uint64_t>(delta);
        while (d > 0) {
            if (d & 1u) {
                acc_mult *= cur_mult;
                acc_plus = acc_plus * cur_mult + cur_plus;
            }
            cur_plus = (cur_mult + 1u) * cur_plus;
            cur_mult *= cur_mult;
            d >>= 1u;
        }
        state_ = acc_mult * state_ + acc_plus;
    }

    uint64_t state() const { return state_; }
    uint64_t increment() const { return inc_; }

  private:
    uint64_t state_;
    uint64_t inc_;
};

/// SplitMix64 finaliser [Steele14]: a bijective 64-bit mix used to derive independent
/// seeds and stream ids from (seed, estimator, N, replicate) tuples.
inline uint64_t mix64(uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/// Combines words into one 64-bit key, order-sensitive.
inline uint64_t hash_combine(uint64_t h, uint64_t v) {
    return mix64(h ^ mix64(v));
}

/// FNV-1a of a string, for hashing estimator names into stream ids.
inline uint64_t hash_string(const char* s) {
    uint64_t h = 0xcbf29ce484222325ULL;
    for (; *s; ++s) h = (h ^ static_cast<unsigned char>(*s)) * 0x100000001b3ULL;
    return h;
}

} // namespace mcp
