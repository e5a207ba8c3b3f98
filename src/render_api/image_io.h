// Image files: PNG for looking (exposure, clip, sRGB), Radiance HDR for measuring (linear),
// a false-colour relative-error PNG, and the reference cache (exact doubles). Encoders write
// to memory so that the browser gets the same bytes as the CLI.
#pragma once

#include <cstdint>
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
/// Largest reference image (HDR file or cache): the render's own limits.
constexpr int64_t kMaxReferenceSide = 4096;
constexpr uint64_t kMaxReferencePixels = uint64_t(1) << 22; ///< 2048 x 2048

/// Reads a Radiance .hdr (RGBE, '-Y <height> +X <width>') as a reference with zero variance.
/// The header, the size line, the size limits and the presence of every scanline are checked
/// before anything is allocated or decoded; false with a message (never quoting the file's
/// content) when any fails, e.g. "the HDR data ends after 3 of 8 scanlines".
bool decode_hdr(const std::string& bytes, RenderImage* out, std::string* error);

/// The reference cache: a small binary file with the means and their variances as doubles.
bool write_reference_cache(const std::string& path, const RenderImage& image);
/// Reads a cache file written by write_reference_cache: a regular file of at most
/// kMaxCacheFileBytes (api/files.h), with the magic, sizes within the limits above, spp >= 1,
/// exactly the bytes those sizes need, and no infinite mean or negative variance. Anything
/// else is ignored (false, `image` untouched): the caller renders the reference again.
bool read_reference_cache(const std::string& path, RenderImage* image);

std::string base64_encode(const std::string& bytes);

} // namespace mcp
