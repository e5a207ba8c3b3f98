#include "render_api/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>

namespace mcp {

namespace {

void append_bytes(void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

/// sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
double srgb_encode(double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

uint8_t to_byte(double x) {
    return static_cast<uint8_t>(std::lround(std::clamp(x, 0.0, 1.0) * 255.0));
}

std::string png_of(int w, int h, const std::vector<uint8_t>& rgb) {
    std::string out;
    stbi_write_png_to_func(append_bytes, &out, w, h, 3, rgb.data(), w * 3);
    return out;
}

/// A perceptually ordered ramp from dark blue through teal and green to yellow (control
/// points chosen here, in the spirit of viridis), t in [0, 1].
Vec3 error_ramp(double t) {
    static const Vec3 kStops[] = {{0.07, 0.02, 0.30},
                                  {0.17, 0.32, 0.55},
                                  {0.13, 0.57, 0.55},
                                  {0.37, 0.79, 0.38},
                                  {0.99, 0.91, 0.15}};
    t = std::clamp(t, 0.0, 1.0) * 4.0;
    int i = std::min(3, int(t));
    double f = t - i;
    return kStops[i] * (1.0 - f) + kStops[i + 1] * f;
}

constexpr char kCacheMagic[8] = {'M', 'C', 'R', 'E', 'F', '0', '1', '\n'};

} // namespace

std::string encode_png(const RenderImage& image, double exposure) {
    double scale = std::exp2(exposure);
    std::vector<uint8_t> rgb(image.pixel_count() * 3);
    for (size_t k = 0; k < rgb.size(); ++k) {
        double x = image.rgb[k] * scale;
        rgb[k] = to_byte(std::isfinite(x) ? srgb_encode(x) : 0.0);
    }
    return png_of(image.width, image.height, rgb);
}

std::string encode_hdr(const RenderImage& image) {
    std::vector<float> rgb(image.pixel_count() * 3);
    for (size_t k = 0; k < rgb.size(); ++k)
        rgb[k] = std::isfinite(image.rgb[k]) ? float(std::max(0.0, image.rgb[k])) : 0.0f;
    std::string out;
    stbi_write_hdr_to_func(append_bytes, &out, image.width, image.height, 3, rgb.data());
    return out;
}

std::string encode_error_png(const RenderImage& image, const RenderImage& reference) {
    size_t n = std::min(image.pixel_count(), reference.pixel_count());
    double mean = 0.0;
    for (size_t p = 0; p < n; ++p) {
        const double* r = &reference.rgb[p * 3];
        mean += luminance(Vec3(r[0], r[1], r[2])) / double(n ? n : 1);
    }
    double eps = std::max(1e-2 * mean, 1e-300);
    std::vector<uint8_t> rgb(image.pixel_count() * 3, 0);
    for (size_t p = 0; p < n; ++p) {
        const double *a = &image.rgb[p * 3], *r = &reference.rgb[p * 3];
        double li = luminance(Vec3(a[0], a[1], a[2])), lr = luminance(Vec3(r[0], r[1], r[2]));
        double rel = std::fabs(li - lr) / (std::fabs(lr) + eps);
        Vec3 c = std::isfinite(rel) ? error_ramp((std::log10(std::max(rel, 1e-3)) + 3.0) / 3.0)
                                    : Vec3(1.0, 0.0, 1.0); // magenta: not a number
        for (int k = 0; k < 3; ++k) rgb[p * 3 + size_t(k)] = to_byte(c[k]);
    }
    return png_of(image.width, image.height, rgb);
}

bool decode_hdr(const std::string& bytes, RenderImage* out, std::string* error) {
    if (bytes.size() > size_t(1) << 30) {
        *error = "image file too large";
        return false;
    }
    int w = 0, h = 0, channels = 0;
    float* data = stbi_loadf_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()),
                                         int(bytes.size()), &w, &h, &channels, 3);
    if (!data) {
        *error = std::string("cannot decode the image: ") + stbi_failure_reason();
        return false;
    }
    out->width = w;
    out->height = h;
    out->spp = 0;
    out->rgb.assign(data, data + size_t(w) * size_t(h) * 3);
    out->variance.assign(out->rgb.size(), 0.0);
    stbi_image_free(data);
    return true;
}

bool write_reference_cache(const std::string& path, const RenderImage& image) {
    std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) return false;
        int64_t header[3] = {image.width, image.height, int64_t(image.spp)};
        out.write(kCacheMagic, sizeof kCacheMagic);
        out.write(reinterpret_cast<const char*>(header), sizeof header);
        out.write(reinterpret_cast<const char*>(image.rgb.data()),
                  std::streamsize(image.rgb.size() * sizeof(double)));
        out.write(reinterpret_cast<const char*>(image.variance.data()),
                  std::streamsize(image.variance.size() * sizeof(double)));
        if (!out) return false;
    }
    return std::rename(tmp.c_str(), path.c_str()) == 0; // atomic: no half-written cache
}

bool read_reference_cache(const std::string& path, RenderImage* image) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    char magic[8];
    int64_t header[3];
    in.read(magic, sizeof magic);
    in.read(reinterpret_cast<char*>(header), sizeof header);
    if (!in || std::memcmp(magic, kCacheMagic, sizeof magic) != 0) return false;
    if (header[0] < 1 || header[1] < 1 || header[0] > 4096 || header[1] > 4096) return false;
    image->width = int(header[0]);
    image->height = int(header[1]);
    image->spp = uint64_t(header[2]);
    size_t n = image->pixel_count() * 3;
    image->rgb.resize(n);
    image->variance.resize(n);
    in.read(reinterpret_cast<char*>(image->rgb.data()), std::streamsize(n * sizeof(double)));
    in.read(reinterpret_cast<char*>(image->variance.data()), std::streamsize(n * sizeof(double)));
    return bool(in);
}

std::string base64_encode(const std::string& bytes) {
    static const char kAlphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        uint32_t v = (uint32_t(uint8_t(bytes[i])) << 16) | (uint32_t(uint8_t(bytes[i + 1])) << 8) |
                     uint32_t(uint8_t(bytes[i + 2]));
        for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
    }
    if (i < bytes.size()) {
        uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

} // namespace mcp
