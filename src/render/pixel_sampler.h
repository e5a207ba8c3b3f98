// Sample values for one pixel's samples: independent uniforms, or stratified ones where every
// 1D and 2D dimension of the path is stratified over the pixel's spp samples on its own and
// the strata of different dimensions are paired by keyed random permutations ("padding", as
// in pbrt's stratified sampler [PBR4, 8.5]; the permutations are those of
// the core's Latin hypercube sampler [Kensler13]).
#pragma once

#include <cstdint>

#include "core/rng.h"
#include "core/samplers.h"
#include "core/warps.h"

namespace mcp {

enum class PixelSamplerKind { Independent, Stratified };

class PixelSampler {
  public:
    /// Dimensions past this many per sample are independent (a path's deep bounces gain
    /// little from stratification).
    static constexpr int kStratifiedDimensions = 32;

    /// Plans a pixel of `spp` samples; allocation happens here (once per image), not per pixel.
    void configure(PixelSamplerKind kind, uint64_t spp) {
        kind_ = kind;
        spp_ = spp;
        auto grid = stratification_grid(spp, 2);
        grid_x_ = grid[0];
        grid_y_ = grid[1];
    }

    /// Starts pixel `pixel_key` (a hash of the image's stream and the pixel) with its own PCG32
    /// stream; the stream also keys the stratum permutations.
    void start_pixel(uint64_t pixel_key) {
        key_ = pixel_key;
        rng_.set_seed(mix64(pixel_key), pixel_key);
    }

    void start_sample(uint64_t index) {
        index_ = index;
        dimension_ = 0;
    }

    double get_1d() {
        int d = dimension_++;
        if (kind_ == PixelSamplerKind::Independent || d >= kStratifiedDimensions || spp_ <= 1)
            return rng_.next_double();
        uint64_t stratum = permute_index(index_, spp_, hash_combine(key_, uint64_t(d)));
        return clamp_open((static_cast<double>(stratum) + rng_.next_double()) /
                          static_cast<double>(spp_));
    }

    // The two draws are separate statements: the order in which function arguments are
    // evaluated is unspecified (g++ and clang differ), and native and wasm must agree.
    Vec2 get_2d() {
        int d = dimension_;
        dimension_ += 2;
        double u0 = rng_.next_double();
        double u1 = rng_.next_double();
        if (kind_ == PixelSamplerKind::Independent || d >= kStratifiedDimensions || spp_ <= 1)
            return Vec2(u0, u1);
        uint64_t cell = permute_index(index_, spp_, hash_combine(key_, uint64_t(d)));
        uint64_t cx = cell % grid_x_, cy = cell / grid_x_;
        return Vec2(clamp_open((static_cast<double>(cx) + u0) / static_cast<double>(grid_x_)),
                    clamp_open((static_cast<double>(cy) + u1) / static_cast<double>(grid_y_)));
    }

    /// The raw generator, for choices that are not sample dimensions (Russian roulette).
    Pcg32& rng() { return rng_; }

  private:
    static double clamp_open(double u) { return u < 1.0 ? u : 0x1.fffffffffffffp-1; }

    PixelSamplerKind kind_ = PixelSamplerKind::Independent;
    uint64_t spp_ = 1, grid_x_ = 1, grid_y_ = 1;
    uint64_t key_ = 0, index_ = 0;
    int dimension_ = 0;
    Pcg32 rng_;
};

} // namespace mcp
