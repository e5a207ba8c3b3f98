// Image files: PNG for looking (exposure, clip, sRGB), Radiance HDR for measuring (linear),
// a false-colour relative-error PNG, and the reference cache (exact doubles). Encoders write
// to memory so that the browser gets the same bytes as the CLI.
#pragma once

#include <string>

#include "render/renderer.h"

namespace mcp {

/// 8-bit sRGB PNG of linear radiance times 2^exposure, clipped to [0, 1] (IEC 61966-2-1).
std::string encode_png(const RenderImage& image, double exposure);
/// Radiance RGBE .hdr of the linear pixel means [Ward91].
std::string encode_hdr(const RenderImage& image);
/// False colour of the per-pixel relative error |I - R| / (R + eps) of luminance, on a log
/// scale from 1e-3 (dark blue) to 1 and above (yellow); eps = 1e-2 of R's mean luminance.
std::string encode_error_png(const RenderImage& image, const RenderImage& reference);
/// Reads a Radiance .hdr (or any float image stb_image reads) as a reference with zero
/// variance; false with a message when it cannot.
bool decode_hdr(const std::string& bytes, RenderImage* out, std::string* error);

/// The reference cache: a small binary file with the means and their variances as doubles.
bool write_reference_cache(const std::string& path, const RenderImage& image);
bool read_reference_cache(const std::string& path, RenderImage* image);

std::string base64_encode(const std::string& bytes);

} // namespace mcp
