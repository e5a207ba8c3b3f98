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
/// Linear float32 RGB as a Portable Float Map (little-endian): no 8-bit mantissa, for measuring.
std::string encode_pfm(const RenderImage& image);
/// Pixels with a channel whose mean is finite in double but beyond the float32 range (above
/// 3.4e38 in magnitude): the HDR, PFM and page images hold them as inf (black in the PNG).
uint64_t pixels_beyond_float32(const RenderImage& image);
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

/// A reference image as bytes (the cache file, and what options.reference_data carries): the
/// magic "MCREF02\n", `key` (the hash of everything the reference was rendered from, see
/// reference_key in render_reference.h), width, height and spp as int64, then the means and
/// their variances as doubles, native (little-endian) byte order.
std::string encode_reference(const RenderImage& image, uint64_t key);
/// Reads what encode_reference wrote: the magic, the same `key`, sizes within the limits above,
/// spp >= 1, exactly the bytes those sizes need, no infinite mean, no negative or infinite
/// variance, and no NaN variance beside a finite mean when spp > 1. Anything else is refused
/// (false, `image` untouched); for a refused pixel value `why` (when given) names the pixel.
bool decode_reference(const std::string& bytes, uint64_t key, RenderImage* image,
                      std::string* why = nullptr);
/// Do the bytes start like encode_reference's (the magic and a whole header)?
bool is_encoded_reference(const std::string& bytes);
/// The key encode_reference stored (bytes accepted by is_encoded_reference).
uint64_t encoded_reference_key(const std::string& bytes);

/// The reference cache: encode_reference's bytes in a file, written whole or not at all.
bool write_reference_cache(const std::string& path, const RenderImage& image, uint64_t key);
/// Reads a cache file: a regular file of at most kMaxCacheFileBytes (api/files.h) that
/// decode_reference accepts. Anything else is ignored (false, `image` untouched): the caller
/// renders the reference again.
bool read_reference_cache(const std::string& path, uint64_t key, RenderImage* image,
                          std::string* why = nullptr);

std::string base64_encode(const std::string& bytes);
/// Standard padded base64 (RFC 4648); false on any other character, length or padding.
bool base64_decode(const std::string& text, std::string* bytes);

} // namespace mcp
