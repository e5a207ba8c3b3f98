// libFuzzer target: image bytes -> mcp::decode_hdr (src/render_api/image_io.h), the reader of
// reference images (Radiance .hdr, or any float image stb_image reads).
// Invariants: on success the image has positive dimensions within the renderer's cap, exactly
// 3 finite, non-negative values per pixel and zero variance; on failure a message.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "render_api/image_io.h"

namespace {
[[noreturn]] void violation(const char* what) {
    std::fprintf(stderr, "fuzz_hdr: %s\n", what);
    std::abort();
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    mcp::RenderImage image;
    std::string error;
    if (!mcp::decode_hdr(bytes, &image, &error)) {
        if (error.empty()) violation("failure without a message");
        return 0;
    }
    if (image.width <= 0 || image.height <= 0) violation("non-positive size");
    if (image.rgb.size() != image.pixel_count() * 3) violation("rgb size is not 3 x pixels");
    if (image.variance.size() != image.rgb.size()) violation("variance size differs from rgb");
    for (double v : image.rgb)
        if (!std::isfinite(v) || v < 0.0) violation("a pixel value is not finite and >= 0");
    return 0;
}
