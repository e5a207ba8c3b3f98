// Sample values for one pixel's samples, addressed by (pixel, sample index, dimension):
//
// - independent: independent uniforms from the pixel's own PCG32 stream.
// - stratified: every 1D and 2D dimension of the path is stratified over the pixel's spp
//   samples on its own and the strata of different dimensions are paired by keyed random
//   permutations ("padding", as in pbrt's stratified sampler [PBR4, 8.5]): for spp up to
//   kTableMaxSpp each pixel and dimension shuffles a table of its spp strata once, by
//   Fisher and Yates's shuffle in Durstenfeld's inside-out form [Knuth97, 3.4.2 algorithm P]
//   with bounded draws [Lemire19] from a PCG32 stream keyed by the pixel and the dimension,
//   so that a sample reads its stratum instead of hashing it; beyond, the keyed bijection of
//   the core's Latin hypercube sampler [Kensler13] (O(1) memory).
// - sobol: Owen-scrambled Sobol' points with the pixels decorrelated by a randomly permuted
//   Morton (Z) order of the image, so that neighbouring pixels get complementary points and
//   the error is spread as blue noise [AhmedWonka20; PBR4, 8.7]. Written from the papers'
//   description:
//     * every request (a 1D or 2D draw) is a "dimension" d of the sample; its key is a hash of
//       the image's key (seed, estimator, spp, replicate) and d, the same for every pixel;
//     * the sample's global index is I = morton(x, y) spp + i, with the Morton grid rounded
//       up to a power of two at least as large as the image's larger side, i the sample index
//       (spp must be a power of two, so I's bits are the Morton bits then the sample bits),
//       both permuted per dimension:
//     * the base-4 digits of the Morton index (from the top) go through random permutations
//       of {0, 1, 2, 3} chosen by a hash of the dimension's key, the digit's position and the
//       digits above it (a nested random permutation, so a bijection of the pixels' blocks of
//       indices): the quadrants of every level of the image's quadtree are shuffled, and the
//       4^k pixels of an aligned 2^k x 2^k square always share an aligned block of 4^k spp
//       consecutive indices, whose points form a net together [AhmedWonka20]. The sample
//       index goes through a keyed random permutation of [0, spp) (keyed by the dimension and
//       the pixel), so that a pixel's samples of different requests are paired at random
//       ("padding"; pbrt permutes these base-4 digits too, which pairs them less randomly:
//       balanced within every group of 4 samples);
//     * the Sobol' point of that index (Gray-code order, sobol_u32) in Sobol' dimension 0 for
//       a 1D request, dimensions 0 and 1 for a 2D request: (0, 2)-sequence, so the spp points of
//       a pixel in one 2D request form a (0, m, 2)-net (each elementary interval of area 1/spp
//       holds exactly one point) [Sobol67; JoeKuo08]. A discrete choice and the 2D sample it
//       conditions (get_choice_2d: a light and a point on it, a BSDF lobe and a direction)
//       take dimensions 0, 1 for the point and 2 for the choice of one index, so that the
//       samples making one choice keep stratified points;
//     * nested uniform (Owen) scrambling of the 32 digits with a seed per dimension (a hash of
//       the dimension's key) [Owen95; owen_scramble_u32], then 21 more bits hashed from the
//       scrambled digits, 53 random bits per value in (0, 1) (bits53_to_unit).
//   Indices beyond 32 bits (images and spp so large that 2 log2(side) + log2(spp) > 32) keep
//   their low 32 bits for the Sobol' point and fold the rest into the scrambling seed: each
//   block of 2^32 indices is an independently scrambled copy of the sequence.
// - padded_sobol: every pixel and every request d has its own Owen-scrambled Sobol' sequence
//   (pbrt-v4's PaddedSobolSampler [PBR4, 8.7]), so that a pixel's samples do not depend on its
//   spp and a render can go on from where it stopped (the progressive live view):
//     * the request's key is a hash of the pixel's key (the image's key and the pixel) and d;
//     * sample index i is shuffled by Owen scrambling its 32 binary digits as a number, most
//       significant first, with a seed from the key [Burley20]: the flip of a digit depends on
//       the digits above it only, so the first 2^k indices map onto one aligned block of 2^k
//       indices, and every power-of-two prefix of the pixel's samples is the point set of an
//       aligned block: a (0, k, 2)-net in each 2D request [Sobol67];
//     * that index's Sobol' point (dimensions 0, 1 and 2 for get_choice_2d, as above),
//       Owen-scrambled per request with 53 random bits per value (sobol_value).
//   Independent shuffles per request pair the requests of a sample at random ("padding").
//   Pixels are independent of each other (white noise between pixels, where the sobol sampler
//   spreads the error as blue noise). spp need not be a power of two (the first spp samples
//   of the sequence), but only powers of two are whole nets.
//
// Which samplers extend (sampler_extends): the first n samples of a pixel are the same for every
// spp >= n for independent and padded_sobol, so n more samples continue a pixel's image. The
// stratified sampler cuts each dimension into spp strata and the sobol sampler gives a pixel a
// block of spp indices of the image's sequence: both depend on the final spp from the first
// sample, and a pixel of 2n samples does not begin with the pixel of n.
//
// Everything here is integer hashing (the independent and stratified kinds add IEEE
// arithmetic on exact values): the same numbers natively and in wasm, for any thread count.
// No allocation per pixel or sample (configure allocates once per image), no virtual calls.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/points.h"
#include "core/qmc.h"
#include "core/rng.h"
#include "core/samplers.h"
#include "core/warps.h"

namespace mcp {

enum class PixelSamplerKind { Independent, Stratified, Sobol, PaddedSobol };

/// "independent", "stratified", "sobol", "padded_sobol".
const char* pixel_sampler_name(PixelSamplerKind kind);
/// Are a pixel's first n samples the same whatever its spp (>= n), so that a render can add
/// samples to an image (independent, padded_sobol; see the header comment)?
bool sampler_extends(PixelSamplerKind kind);
/// Every kind's name, in the enum's order.
std::vector<std::string> pixel_sampler_names();
bool parse_pixel_sampler(const std::string& name, PixelSamplerKind* kind);
/// "" when the sampler can take `spp` samples per pixel, else why not (the Sobol' sampler
/// needs a power of two, so that a pixel's samples are a whole net: "the 'sobol' pixel
/// sampler needs a power-of-two spp, got 3 (the nearest are 2 and 4)").
std::string check_pixel_sampler_spp(PixelSamplerKind kind, uint64_t spp);

namespace pixel_sampler_detail {

/// The 24 permutations of {0, 1, 2, 3}, each packed as four 2-bit images (entry j at bits
/// 2j, 2j + 1), in lexicographic order.
struct Perm4Table {
    uint8_t p[24] = {};
    constexpr Perm4Table() {
        int n = 0;
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                for (int c = 0; c < 4; ++c)
                    for (int d = 0; d < 4; ++d)
                        if (a != b && a != c && a != d && b != c && b != d && c != d)
                            p[n++] = uint8_t(a | (b << 2) | (c << 4) | (d << 6));
    }
};
inline constexpr Perm4Table kPerm4{};

/// Bits x0 y0 x1 y1 ... of the 16-bit coordinates interleaved (x in the even bits).
inline uint64_t morton2(uint32_t x, uint32_t y) {
    auto spread = [](uint64_t v) {
        v &= 0xffffu;
        v = (v | (v << 8)) & 0x00ff00ffu;
        v = (v | (v << 4)) & 0x0f0f0f0fu;
        v = (v | (v << 2)) & 0x33333333u;
        v = (v | (v << 1)) & 0x55555555u;
        return v;
    };
    return spread(x) | (spread(y) << 1);
}

/// Smallest k with 2^k >= n (0 for n <= 1).
inline int ceil_log2(uint64_t n) {
    int k = 0;
    while (k < 63 && (uint64_t(1) << k) < n) ++k;
    return k;
}

/// Division by a stratum count n: (k + u) / n and k / n. A power of two takes a
/// multiplication by its exact reciprocal and a shift, which give the division's bits
/// (scaling by a power of two is exact) without its latency; other counts divide.
class StrataScale {
  public:
    StrataScale() = default;
    explicit StrataScale(uint64_t n)
        : n_(n > 0 ? n : 1), pow2_((n_ & (n_ - 1)) == 0), shift_(ceil_log2(n_)),
          count_(u63_to_double(n_)), inverse_(1.0 / count_) {}
    double position(uint64_t k, double u) const {
        const double x = u63_to_double(k) + u;
        return pow2_ ? x * inverse_ : x / count_;
    }
    uint64_t quotient(uint64_t k) const { return pow2_ ? k >> shift_ : k / n_; }

  private:
    uint64_t n_ = 1;
    bool pow2_ = true;
    int shift_ = 0;
    double count_ = 1.0, inverse_ = 1.0; // n and 1 / n
};

} // namespace pixel_sampler_detail

struct ChoiceSample {
    double choice = 0.5;
    Vec2 u{0.5};
};

class PixelSampler {
  public:
    /// Dimensions past this many per sample are independent in the stratified sampler (a
    /// path's deep bounces gain little from stratification). The Sobol' sampler has no limit.
    static constexpr int kStratifiedDimensions = 32;
    /// The Sobol' sampler prepares the first this many requests of a sample once per pixel
    /// (their permuted Morton index, seeds, sample permutation and the Sobol' digits of the
    /// index's pixel part); later requests are computed in full each time.
    static constexpr int kSobolPreparedRequests = 64;
    /// Both samplers keep shuffled tables of the sample permutations up to this many spp (a
    /// row of spp 16-bit entries per dimension: 256 KiB stratified, 512 KiB Sobol' at most,
    /// allocated per image); beyond, the core's keyed bijection.
    static constexpr uint64_t kTableMaxSpp = 4096;

    /// Plans an image of width x height pixels of `spp` samples, keyed by `image_key` (the
    /// image's stream); allocation happens here (once per image), not per pixel. The Sobol'
    /// sampler expects a power-of-two spp (check_pixel_sampler_spp; the render API refuses
    /// others): given another, a pixel takes the first spp indices of a block of the next
    /// power of two (still unbiased, but not a net). Sides up to 65536 pixels, spp up to 2^32.
    void configure(PixelSamplerKind kind, uint64_t spp, int width, int height, uint64_t image_key) {
        using namespace pixel_sampler_detail;
        kind_ = kind;
        spp_ = spp;
        width_ = width > 0 ? uint64_t(width) : 1;
        image_key_ = image_key;
        sobol_ = &sobol_byte_tables();
        auto grid = stratification_grid(spp, 2);
        grid_x_ = grid[0];
        grid_y_ = grid[1];
        strata_1d_ = StrataScale(spp);
        strata_x_ = StrataScale(grid_x_);
        strata_y_ = StrataScale(grid_y_);
        int side = width > height ? width : height;
        sample_bits_ = ceil_log2(spp);
        if (sample_bits_ > 32) sample_bits_ = 32;
        morton_bits_ = 2 * ceil_log2(uint64_t(side > 1 ? side : 1));
        if (morton_bits_ > 32) morton_bits_ = 32;
        const int rows = kind == PixelSamplerKind::Stratified ? kStratifiedDimensions
                         : kind == PixelSamplerKind::Sobol    ? kSobolPreparedRequests
                                                              : 0;
        if (rows > 0 && spp > 1 && spp <= kTableMaxSpp)
            strata_.resize(size_t(rows) * size_t(spp));
        else
            strata_.clear();
    }

    /// Starts pixel (x, y). The independent and stratified samplers give it its own PCG32
    /// stream keyed by a hash of the image's key and the pixel number (the stream also keys
    /// the stratum permutations); the Sobol' sampler keeps its Morton index.
    void start_pixel(int x, int y) {
        key_ = hash_combine(image_key_, uint64_t(y) * width_ + uint64_t(x));
        prepared_ = 0; // the pixel's permutations are prepared on first use
        if (kind_ == PixelSamplerKind::Sobol)
            morton_ = pixel_sampler_detail::morton2(uint32_t(x), uint32_t(y));
        else if (kind_ != PixelSamplerKind::PaddedSobol)
            rng_.set_seed(mix64(key_), key_);
    }

    /// Starts pixel (x, y) where an earlier pass left it: as start_pixel, with the pixel's
    /// generator (independent and stratified samplers) as pixel_rng() returned it then.
    void resume_pixel(int x, int y, const Pcg32& rng) {
        start_pixel(x, y);
        rng_ = rng;
    }
    /// The pixel's generator after the samples drawn so far (independent, stratified).
    const Pcg32& pixel_rng() const { return rng_; }

    void start_sample(uint64_t index) {
        index_ = index;
        dimension_ = 0;
    }

    double get_1d() {
        int d = dimension_++;
        if (kind_ == PixelSamplerKind::PaddedSobol) {
            const PaddedRequest r = padded_request(d);
            return sobol_value(uint32_t(sobol_->point_2d(r.index)), 0, r.seeds);
        }
        if (kind_ == PixelSamplerKind::Sobol) {
            uint32_t v[1];
            const uint64_t seeds = sobol_point(d, 1, v);
            return sobol_value(v[0], 0, seeds);
        }
        if (kind_ == PixelSamplerKind::Independent || d >= kStratifiedDimensions || spp_ <= 1)
            return rng_.next_double();
        uint64_t stratum = stratum_of_sample(d);
        return clamp_open(strata_1d_.position(stratum, rng_.next_double()));
    }

    // The two draws are separate statements: the order in which function arguments are
    // evaluated is unspecified (g++ and clang differ), and native and wasm must agree.
    Vec2 get_2d() {
        int d = dimension_;
        dimension_ += 2;
        if (kind_ == PixelSamplerKind::PaddedSobol) {
            const PaddedRequest r = padded_request(d);
            const uint64_t xy = sobol_->point_2d(r.index);
            double u0 = sobol_value(uint32_t(xy), 0, r.seeds);
            double u1 = sobol_value(uint32_t(xy >> 32), 1, r.seeds);
            return Vec2(u0, u1);
        }
        if (kind_ == PixelSamplerKind::Sobol) {
            uint32_t v[2];
            const uint64_t seeds = sobol_point(d, 2, v);
            double u0 = sobol_value(v[0], 0, seeds);
            double u1 = sobol_value(v[1], 1, seeds);
            return Vec2(u0, u1);
        }
        double u0 = rng_.next_double();
        double u1 = rng_.next_double();
        if (kind_ == PixelSamplerKind::Independent || d >= kStratifiedDimensions || spp_ <= 1)
            return Vec2(u0, u1);
        uint64_t cell = stratum_of_sample(d);
        uint64_t cy = strata_x_.quotient(cell), cx = cell - cy * grid_x_;
        return Vec2(clamp_open(strata_x_.position(cx, u0)), clamp_open(strata_y_.position(cy, u1)));
    }

    /// A discrete choice and the 2D sample it conditions (a light and a point on it, a BSDF
    /// lobe and a direction), drawn together. The independent and stratified samplers draw
    /// them as get_1d() then get_2d(); the Sobol' sampler takes Sobol' dimensions 0 and 1 of
    /// one index for the point and dimension 2 for the choice, so that the samples making
    /// each choice still have stratified points (the first three Sobol' dimensions form a
    /// (1, 3)-sequence: the half of a pixel's 2^m points with the choice below 1/2 is a
    /// (1, m - 1, 2)-net in the other two) instead of a random subset of them.
    ChoiceSample get_choice_2d() {
        if (kind_ != PixelSamplerKind::Sobol && kind_ != PixelSamplerKind::PaddedSobol) {
            ChoiceSample c;
            c.choice = get_1d();
            c.u = get_2d();
            return c;
        }
        int d = dimension_;
        dimension_ += 3;
        uint32_t v[3];
        uint64_t seeds;
        if (kind_ == PixelSamplerKind::PaddedSobol) {
            const PaddedRequest r = padded_request(d);
            const uint64_t xy = sobol_->point_2d(r.index);
            v[0] = uint32_t(xy);
            v[1] = uint32_t(xy >> 32);
            v[2] = sobol_->coordinate_2(r.index);
            seeds = r.seeds;
        } else {
            seeds = sobol_point(d, 3, v);
        }
        ChoiceSample c;
        double u0 = sobol_value(v[0], 0, seeds);
        double u1 = sobol_value(v[1], 1, seeds);
        c.u = Vec2(u0, u1);
        c.choice = sobol_value(v[2], 2, seeds);
        return c;
    }

  private:
    static double clamp_open(double u) { return below_one(u); }

    /// The padded Sobol' sampler's request d for the current sample: the shuffled index of
    /// the sample in the request's own sequence, and the request's scrambling seeds (keyed by
    /// the pixel, d, and the index's bits above 32: each block of 2^32 samples is another
    /// scrambled copy). The first kSobolPreparedRequests requests keep their seeds per pixel.
    struct PaddedRequest {
        uint32_t index = 0;
        uint32_t shuffle = 0; ///< the index's scrambling seed
        uint64_t seeds = 0;   ///< the value's scrambling seeds (sobol_value)
    };
    static PaddedRequest padded_seeds(uint64_t key) {
        PaddedRequest r;
        r.shuffle = uint32_t(mix64(key ^ 0x73687566666c65ULL)); // "shuffle"
        r.seeds = hash_combine(key ^ 0x6f77656e5365656eULL, 0); // "owenSeen"
        return r;
    }
    PaddedRequest padded_request(int d) {
        const uint64_t block = index_ >> 32;
        PaddedRequest r;
        if (d < kSobolPreparedRequests && block == 0) {
            if (!((prepared_ >> d) & 1u)) {
                padded_requests_[d] = padded_seeds(hash_combine(key_, uint64_t(d)));
                prepared_ |= uint64_t(1) << d;
            }
            r = padded_requests_[d];
        } else {
            uint64_t key = hash_combine(key_, uint64_t(d));
            if (block != 0) key = hash_combine(key, block);
            r = padded_seeds(key);
        }
        r.index = owen_scramble_u32(uint32_t(index_), r.shuffle);
        return r;
    }

    /// The stratum of the current sample in dimension d (d < kStratifiedDimensions) of the
    /// stratified sampler: its index through the pixel's permutation of [0, spp) for d, keyed
    /// by the pixel and d and prepared on the dimension's first use in the pixel.
    uint64_t stratum_of_sample(int d) {
        const bool prepared = (prepared_ >> d) & 1u;
        prepared_ |= uint64_t(1) << d;
        if (strata_.empty()) {
            if (!prepared)
                permutations_[d] = index_permutation(spp_, hash_combine(key_, uint64_t(d)));
            return permute_index(index_, permutations_[d]);
        }
        uint16_t* row = strata_.data() + size_t(d) * size_t(spp_);
        if (!prepared) shuffle_row(row, hash_combine(key_, uint64_t(d)));
        return row[index_ < spp_ ? index_ : index_ % spp_];
    }

    /// Fills a table row with a uniform random permutation of [0, spp) keyed by `key`:
    /// the inside-out shuffle, after whose step i row[0..i] is a uniform permutation of 0..i.
    void shuffle_row(uint16_t* row, uint64_t key) const {
        Pcg32 shuffle;
        shuffle.set_seed(mix64(key), key);
        for (uint32_t i = 0; i < uint32_t(spp_); ++i) {
            const uint32_t j = shuffle.next_below(i + 1);
            row[i] = row[j];
            row[j] = uint16_t(i);
        }
    }

    /// What the Sobol' sampler's request d needs of the pixel, the same for all its samples.
    /// The request's global index is I = (M' << sample_bits) | s' with M' the Morton index
    /// with its base-4 digits through a nested random permutation (each digit's permutation
    /// keyed by the dimension, the digit's position and the original digits above it: a
    /// bijection that keeps aligned quads of pixels on aligned blocks of indices) and s' the
    /// sample index through a keyed random permutation of [0, spp) (keyed by the dimension and
    /// the pixel: requests are paired at random within the pixel, as for the stratified
    /// sampler). The Sobol' point takes I's low 32 bits; since the Gray code and the Sobol'
    /// digits are linear over GF(2) and the two parts have disjoint bits, its digits are
    /// sobol_u32(low 32 bits of M' << sample_bits) ^ sobol_u32(s'): the pixel's part is
    /// computed once here.
    struct SobolRequest {
        uint64_t high = 0;  ///< M' << sample_bits
        uint64_t seeds = 0; ///< two 32-bit scrambling seeds, keyed by the image, d and high >> 32
        uint32_t high_digits[3] = {0, 0, 0}; ///< sobol_u32(low 32 bits of high, c), c = 0, 1, 2
        IndexPermutation permutation;        ///< of the sample index, when there is no table
    };

    void prepare_sobol(int d, SobolRequest* r, uint16_t* row) const {
        using pixel_sampler_detail::kPerm4;
        const uint64_t dim_key = hash_combine(image_key_, uint64_t(d));
        uint64_t morton = 0;
        for (int shift = morton_bits_ - 2; shift >= 0; shift -= 2) {
            const uint64_t higher = morton_ >> (shift + 2);
            const uint64_t h = mix64(dim_key ^ ((higher << 6) | uint64_t(shift)));
            const uint32_t p = uint32_t((uint64_t(uint32_t(h >> 32)) * 24u) >> 32);
            const uint32_t digit = uint32_t(morton_ >> shift) & 3u;
            morton |= uint64_t((kPerm4.p[p] >> (2 * digit)) & 3u) << shift;
        }
        r->high = morton << sample_bits_;
        // The sample part lies below bit 32 (sample_bits <= 32): the bits of I above 32 are
        // the pixel's, so the seeds are too.
        r->seeds = hash_combine(dim_key ^ 0x6f77656e5365656eULL, r->high >> 32); // "owenSeen"
        const uint64_t xy = sobol_->point_2d(uint32_t(r->high));
        r->high_digits[0] = uint32_t(xy);
        r->high_digits[1] = uint32_t(xy >> 32);
        r->high_digits[2] = sobol_->coordinate_2(uint32_t(r->high));
        const uint64_t key = hash_combine(dim_key, morton_);
        if (row != nullptr)
            shuffle_row(row, key);
        else
            r->permutation = index_permutation(spp_, key);
    }

    /// The unscrambled Sobol' digits of coordinates 0..count-1 (count <= 3) of request d's
    /// point for the current sample; returns the request's seeds.
    uint64_t sobol_point(int d, int count, uint32_t* digits) {
        SobolRequest unprepared;
        const SobolRequest* r = &unprepared;
        const uint16_t* row = nullptr;
        if (d < kSobolPreparedRequests) {
            uint16_t* own_row =
                strata_.empty() ? nullptr : strata_.data() + size_t(d) * size_t(spp_);
            if (!((prepared_ >> d) & 1u)) {
                prepare_sobol(d, &sobol_requests_[d], own_row);
                prepared_ |= uint64_t(1) << d;
            }
            r = &sobol_requests_[d];
            row = own_row;
        } else {
            prepare_sobol(d, &unprepared, nullptr);
        }
        uint64_t sample;
        if (index_ >= spp_)
            sample = index_ & ((uint64_t(1) << sample_bits_) - 1);
        else if (row != nullptr)
            sample = row[index_];
        else
            sample = permute_index(index_, r->permutation);
        // sample < 2^32 (sample_bits <= 32).
        const uint64_t xy = sobol_->point_2d(uint32_t(sample));
        digits[0] = r->high_digits[0] ^ uint32_t(xy);
        if (count > 1) digits[1] = r->high_digits[1] ^ uint32_t(xy >> 32);
        if (count > 2) digits[2] = r->high_digits[2] ^ sobol_->coordinate_2(uint32_t(sample));
        return r->seeds;
    }

    /// Sobol' coordinate `sobol_dim` (0, 1 or 2) of a point, from its digits, Owen-scrambled
    /// with a 32-bit seed from `seeds` (its low half, its high half, a hash of it), with 21
    /// fill bits hashed from the scrambled digits and the coordinate: a value in (0, 1).
    static double sobol_value(uint32_t digits, int sobol_dim, uint64_t seeds) {
        const uint32_t seed =
            sobol_dim < 2 ? uint32_t(seeds >> (32 * sobol_dim)) : uint32_t(mix64(seeds));
        const uint32_t v = owen_scramble_u32(digits, seed);
        const uint64_t fill = mix64(seeds ^ ((uint64_t(v) << 2) | uint64_t(sobol_dim))) >> 43;
        return bits53_to_unit((uint64_t(v) << 21) | fill);
    }

    PixelSamplerKind kind_ = PixelSamplerKind::Independent;
    uint64_t spp_ = 1, grid_x_ = 1, grid_y_ = 1;
    pixel_sampler_detail::StrataScale strata_1d_, strata_x_, strata_y_; // spp_, grid_x_, grid_y_
    uint64_t width_ = 1, image_key_ = 0;
    uint64_t key_ = 0, index_ = 0, morton_ = 0;
    int sample_bits_ = 0, morton_bits_ = 0;
    int dimension_ = 0;
    Pcg32 rng_;
    const SobolByteTables* sobol_ = nullptr; ///< set by configure
    uint64_t prepared_ = 0; ///< bit d: dimension (request) d is prepared for this pixel
    static_assert(kStratifiedDimensions <= 64 && kSobolPreparedRequests <= 64,
                  "one bit of prepared_ per dimension");
    IndexPermutation permutations_[kStratifiedDimensions]; ///< spp > kTableMaxSpp
    SobolRequest sobol_requests_[kSobolPreparedRequests];
    PaddedRequest padded_requests_[kSobolPreparedRequests];
    std::vector<uint16_t> strata_; ///< row d: the pixel's shuffled strata of dimension d
};

} // namespace mcp
