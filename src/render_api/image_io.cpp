// Image files (image_io.h): the PNG, Radiance HDR, PFM and error-PNG encoders, the checked
// HDR reader, the reference format and its cache file, and base64.
#include "render_api/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>

#include "api/files.h"

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

constexpr char kCacheMagic[8] = {'M', 'C', 'R', 'E', 'F', '0', '2', '\n'};

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

std::string encode_pfm(const RenderImage& image) {
    // Portable Float Map: "PF", the size, a negative scale for little-endian, then the rows
    // bottom to top as float32 RGB. NaN pixels (every sample discarded) stay NaN.
    std::string out =
        "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
    out.reserve(out.size() + image.pixel_count() * 3 * sizeof(float));
    for (int y = image.height - 1; y >= 0; --y) {
        for (int x = 0; x < image.width; ++x) {
            for (int c = 0; c < 3; ++c) {
                const float v =
                    float(image.rgb[(size_t(y) * size_t(image.width) + size_t(x)) * 3 + size_t(c)]);
                // little-endian whatever the host: byte 0 is the least significant
                uint8_t b[4];
                uint32_t u;
                std::memcpy(&u, &v, 4);
                for (int k = 0; k < 4; ++k) b[k] = uint8_t(u >> (8 * k));
                out.append(reinterpret_cast<const char*>(b), 4);
            }
        }
    }
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

namespace {

/// Sizes an HDR reference or a cached reference may have: those of a render (4096 a side,
/// 2048 x 2048 pixels in all), checked before anything is allocated.
bool image_size_ok(int64_t w, int64_t h) {
    return w >= 1 && h >= 1 && w <= kMaxReferenceSide && h <= kMaxReferenceSide &&
           uint64_t(w) * uint64_t(h) <= kMaxReferencePixels;
}

std::string size_limit_text() {
    return "at most " + std::to_string(kMaxReferenceSide) + " a side and " +
           std::to_string(kMaxReferencePixels) + " pixels in all";
}

/// A positive decimal number of at most 9 digits at bytes[*at], advancing *at; -1 if none.
int64_t read_size(const std::string& bytes, size_t* at) {
    int64_t v = 0;
    size_t start = *at;
    while (*at < bytes.size() && *at - start < 10 && bytes[*at] >= '0' && bytes[*at] <= '9')
        v = v * 10 + (bytes[(*at)++] - '0');
    size_t digits = *at - start;
    return digits >= 1 && digits <= 9 && v > 0 ? v : -1;
}

/// Walks the Radiance RGBE pixel data [Ward91] of an h x w image starting at bytes[at] as
/// stb_image reads it (new-style run-length scanlines for 8 <= w < 32768, else flat; a
/// scanline without the RLE marker makes the rest of the image flat), without reading past
/// the end. Returns the number of complete scanlines, or -1 - y when scanline y is corrupt.
int64_t hdr_scanlines(const std::string& bytes, size_t at, int64_t w, int64_t h) {
    const size_t size = bytes.size();
    auto byte = [&](size_t i) { return uint8_t(bytes[i]); };
    const uint64_t flat_line = uint64_t(w) * 4;
    for (int64_t y = 0; y < h; ++y) {
        bool rle = w >= 8 && w < 32768 && size - at >= 4 && byte(at) == 2 && byte(at + 1) == 2 &&
                   !(byte(at + 2) & 0x80);
        if (!rle) { // flat from here to the end of the image
            uint64_t lines = uint64_t(size - at) / flat_line;
            return y + int64_t(std::min<uint64_t>(lines, uint64_t(h - y)));
        }
        if (((int64_t(byte(at + 2)) << 8) | byte(at + 3)) != w) return -1 - y;
        at += 4;
        for (int channel = 0; channel < 4; ++channel) {
            int64_t i = 0;
            while (i < w) {
                if (at >= size) return y;
                int64_t count = byte(at++);
                if (count > 128) { // a run: one value repeated count - 128 times
                    count -= 128;
                    if (count > w - i) return -1 - y;
                    if (at >= size) return y;
                    ++at;
                } else { // count literal values
                    if (count == 0 || count > w - i) return -1 - y;
                    if (uint64_t(size - at) < uint64_t(count)) return y;
                    at += size_t(count);
                }
                i += count;
            }
        }
    }
    return h;
}

} // namespace

bool decode_hdr(const std::string& bytes, RenderImage* out, std::string* error) {
    // Everything stb_image will read is checked here first, within the buffer: the header,
    // the size line, the limits, and that every scanline is there. No message quotes the
    // file's content.
    if (bytes.size() > size_t(kMaxReferenceFileBytes)) {
        *error = "the HDR file has " + std::to_string(bytes.size()) +
                 " bytes, more than the limit of " + std::to_string(kMaxReferenceFileBytes);
        return false;
    }
    size_t at = 0;
    for (const char* magic : {"#?RADIANCE\n", "#?RGBE\n"})
        if (bytes.compare(0, std::strlen(magic), magic) == 0) at = std::strlen(magic);
    if (at == 0) {
        *error = "not a Radiance HDR file (expected it to start with '#?RADIANCE' or '#?RGBE')";
        return false;
    }
    bool format = false;
    for (;;) { // header lines up to an empty line
        size_t end = bytes.find('\n', at);
        if (end == std::string::npos) {
            *error = "the HDR header does not end (no empty line before the size line)";
            return false;
        }
        if (end == at) {
            ++at;
            break;
        }
        // stb_image ends the header at a line starting with NUL, where this loop would not:
        // control characters are refused, so both read the same size line (found by
        // fuzz/fuzz_hdr.cpp: a 16 x 2 size line checked here, 16777215 x 10 decoded by stb).
        for (size_t k = at; k < end; ++k)
            if (static_cast<unsigned char>(bytes[k]) < 0x20 && bytes[k] != '\t' &&
                bytes[k] != '\r') {
                *error = "the HDR header has a control character (byte " + std::to_string(k) + ")";
                return false;
            }
        if (bytes.compare(at, end - at, "FORMAT=32-bit_rle_rgbe") == 0) format = true;
        at = end + 1;
    }
    if (!format) {
        *error = "the HDR header has no 'FORMAT=32-bit_rle_rgbe' line (only RGBE is read)";
        return false;
    }
    int64_t h = -1, w = -1;
    if (bytes.compare(at, 3, "-Y ") == 0) {
        at += 3;
        h = read_size(bytes, &at);
        if (h > 0 && bytes.compare(at, 4, " +X ") == 0) {
            at += 4;
            w = read_size(bytes, &at);
        }
    }
    if (h < 1 || w < 1 || at >= bytes.size() || bytes[at] != '\n') {
        *error = "the HDR header's size line is invalid: expected '-Y <height> +X <width>' with "
                 "positive whole sizes (other orientations are not read)";
        return false;
    }
    ++at;
    if (!image_size_ok(w, h)) {
        *error = "the HDR image is " + std::to_string(w) + "x" + std::to_string(h) +
                 ", larger than a reference may be (" + size_limit_text() + ")";
        return false;
    }
    int64_t lines = hdr_scanlines(bytes, at, w, h);
    if (lines < 0) {
        *error = "the HDR data is corrupt in scanline " + std::to_string(-lines) + " of " +
                 std::to_string(h) + " (bad run-length encoding)";
        return false;
    }
    if (lines < h) {
        *error = "the HDR data ends after " + std::to_string(lines) + " of " + std::to_string(h) +
                 " scanlines";
        return false;
    }
    int sw = 0, sh = 0, channels = 0;
    float* data = stbi_loadf_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()),
                                         int(bytes.size()), &sw, &sh, &channels, 3);
    if (!data || sw != int(w) || sh != int(h)) {
        if (data) stbi_image_free(data);
        *error = "cannot decode the HDR data";
        return false;
    }
    out->width = sw;
    out->height = sh;
    out->spp = 0;
    out->rgb.assign(data, data + size_t(sw) * size_t(sh) * 3);
    out->variance.assign(out->rgb.size(), 0.0);
    out->diagnostics = RenderDiagnostics();
    stbi_image_free(data);
    return true;
}

uint64_t pixels_beyond_float32(const RenderImage& image) {
    const double float_max = double(std::numeric_limits<float>::max());
    uint64_t count = 0;
    for (size_t p = 0; p + 2 < image.rgb.size(); p += 3) {
        bool beyond = false;
        for (size_t c = 0; c < 3; ++c) {
            const double v = std::fabs(image.rgb[p + c]);
            beyond = beyond || (std::isfinite(v) && v > float_max);
        }
        count += beyond;
    }
    return count;
}

std::string encode_reference(const RenderImage& image, uint64_t key) {
    const int64_t header[3] = {image.width, image.height, int64_t(image.spp)};
    std::string out(kCacheMagic, sizeof kCacheMagic);
    out.append(reinterpret_cast<const char*>(&key), sizeof key);
    out.append(reinterpret_cast<const char*>(header), sizeof header);
    out.append(reinterpret_cast<const char*>(image.rgb.data()), image.rgb.size() * sizeof(double));
    out.append(reinterpret_cast<const char*>(image.variance.data()),
               image.variance.size() * sizeof(double));
    return out;
}

namespace {
constexpr size_t kReferenceHead = sizeof kCacheMagic + sizeof(uint64_t) + 3 * sizeof(int64_t);
} // namespace

bool is_encoded_reference(const std::string& bytes) {
    return bytes.size() >= kReferenceHead &&
           std::memcmp(bytes.data(), kCacheMagic, sizeof kCacheMagic) == 0;
}

uint64_t encoded_reference_key(const std::string& bytes) {
    uint64_t key = 0;
    if (is_encoded_reference(bytes))
        std::memcpy(&key, bytes.data() + sizeof kCacheMagic, sizeof key);
    return key;
}

bool decode_reference(const std::string& bytes, uint64_t key, RenderImage* image,
                      std::string* why) {
    constexpr size_t kHead = kReferenceHead;
    // Made for another scene, size or reference estimator: not this reference.
    if (!is_encoded_reference(bytes) || encoded_reference_key(bytes) != key) return false;
    int64_t header[3];
    std::memcpy(header, bytes.data() + sizeof kCacheMagic + sizeof key, sizeof header);
    if (!image_size_ok(header[0], header[1]) || header[2] < 1) return false;
    size_t n = size_t(header[0]) * size_t(header[1]) * 3;
    if (bytes.size() != kHead + 2 * n * sizeof(double)) return false;
    RenderImage im;
    im.width = int(header[0]);
    im.height = int(header[1]);
    im.spp = uint64_t(header[2]);
    im.rgb.resize(n);
    im.variance.resize(n);
    std::memcpy(im.rgb.data(), bytes.data() + kHead, n * sizeof(double));
    std::memcpy(im.variance.data(), bytes.data() + kHead + n * sizeof(double), n * sizeof(double));
    // The renderer writes a NaN mean only for a pixel whose every sample was discarded, and a
    // NaN variance only beside it or at 1 sample per pixel (one kept sample has no variance);
    // never an infinite mean or a negative or infinite variance. Any other NaN variance would
    // be read as 0 by the relative MSE's reference term and move it silently.
    for (size_t k = 0; k < n; ++k) {
        const double mean = im.rgb[k], var = im.variance[k];
        const char* bad = std::isinf(mean)  ? "an infinite mean"
                          : var < 0.0       ? "a negative variance"
                          : std::isinf(var) ? "an infinite variance"
                          : std::isnan(var) && !std::isnan(mean) && im.spp > 1 ? "a NaN variance"
                                                                               : nullptr;
        if (bad) {
            if (why) {
                const size_t pixel = k / 3;
                *why = "pixel (" + std::to_string(pixel % size_t(im.width)) + ", " +
                       std::to_string(pixel / size_t(im.width)) + ") has " + bad + " (in channel " +
                       std::to_string(k % 3) + ")";
            }
            return false;
        }
    }
    *image = std::move(im);
    return true;
}

bool write_reference_cache(const std::string& path, const RenderImage& image, uint64_t key) {
    std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) return false;
        const std::string bytes = encode_reference(image, key);
        out.write(bytes.data(), std::streamsize(bytes.size()));
        if (!out) return false;
    }
    return std::rename(tmp.c_str(), path.c_str()) == 0; // atomic: no half-written cache
}

bool read_reference_cache(const std::string& path, uint64_t key, RenderImage* image,
                          std::string* why) {
    // A regular file of bounded size, read whole; anything that is not exactly what
    // write_reference_cache writes is ignored (the caller renders the reference again).
    std::string bytes, error;
    if (!read_regular_file(path, kMaxCacheFileBytes, &bytes, &error)) return false;
    return decode_reference(bytes, key, image, why);
}

// The base64 codec writes into a string sized once and decodes through a table: the live
// view hands each session a reference of about 4 MB of base64, and a character at a time through
// push_back and a chain of range tests took about a fifth of that call in wasm.

std::string base64_encode(const std::string& bytes) {
    static const char kAlphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out((bytes.size() + 2) / 3 * 4, '=');
    const unsigned char* in = reinterpret_cast<const unsigned char*>(bytes.data());
    char* o = &out[0];
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3, o += 4) {
        const uint32_t v = (uint32_t(in[i]) << 16) | (uint32_t(in[i + 1]) << 8) | in[i + 2];
        o[0] = kAlphabet[v >> 18];
        o[1] = kAlphabet[(v >> 12) & 63];
        o[2] = kAlphabet[(v >> 6) & 63];
        o[3] = kAlphabet[v & 63];
    }
    if (i < bytes.size()) { // one or two bytes left: '=' pads the group (already in place)
        uint32_t v = uint32_t(in[i]) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(in[i + 1]) << 8;
        o[0] = kAlphabet[v >> 18];
        o[1] = kAlphabet[(v >> 12) & 63];
        if (i + 1 < bytes.size()) o[2] = kAlphabet[(v >> 6) & 63];
    }
    return out;
}

namespace {

/// The value of each base64 character, 64 for any other byte.
struct Base64Values {
    uint8_t v[256];
    constexpr Base64Values() : v() {
        for (int c = 0; c < 256; ++c) v[c] = 64;
        for (int k = 0; k < 26; ++k) {
            v['A' + k] = uint8_t(k);
            v['a' + k] = uint8_t(26 + k);
        }
        for (int k = 0; k < 10; ++k) v['0' + k] = uint8_t(52 + k);
        v[int('+')] = 62;
        v[int('/')] = 63;
    }
};
constexpr Base64Values kBase64Values;

} // namespace

bool base64_decode(const std::string& text, std::string* bytes) {
    // RFC 4648 section 4, padded: a length that is a multiple of 4, '=' only at the end.
    if (text.size() % 4 != 0) return false;
    // Padding: '=' in the last one or two places of the last group only.
    size_t pad = 0;
    if (!text.empty() && text.back() == '=') pad = text[text.size() - 2] == '=' ? 2 : 1;
    std::string out(text.size() / 4 * 3 - pad, '\0');
    const unsigned char* in = reinterpret_cast<const unsigned char*>(text.data());
    char* o = &out[0];
    const size_t full = text.empty() ? 0 : text.size() - 4; // the groups before the last
    uint32_t bad = 0; // the OR of the values read: bit 6 set after any other character
    for (size_t i = 0; i < full; i += 4, o += 3) {
        const uint32_t a = kBase64Values.v[in[i]], b = kBase64Values.v[in[i + 1]],
                       c = kBase64Values.v[in[i + 2]], d = kBase64Values.v[in[i + 3]];
        bad |= a | b | c | d;
        const uint32_t v = (a << 18) | (b << 12) | (c << 6) | d;
        o[0] = char(v >> 16);
        o[1] = char((v >> 8) & 255);
        o[2] = char(v & 255);
    }
    if (!text.empty()) { // the last group: 4 - pad characters carry data
        const size_t used = 4 - pad;
        uint32_t v = 0;
        for (size_t k = 0; k < 4; ++k) {
            const uint32_t d = k < used ? kBase64Values.v[in[full + k]] : 0;
            bad |= d;
            v = (v << 6) | (d & 63);
        }
        o[0] = char(v >> 16);
        if (used > 2) o[1] = char((v >> 8) & 255);
        if (used > 3) o[2] = char(v & 255);
    }
    if (bad & 64) return false;
    *bytes = std::move(out);
    return true;
}

} // namespace mcp
