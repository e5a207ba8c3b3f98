// Pixel sampler names and the spp check; the samplers themselves are inline in
// pixel_sampler.h.
#include "render/pixel_sampler.h"

namespace mcp {

namespace {

struct PixelSamplerName {
    PixelSamplerKind kind;
    const char* name;
};
constexpr PixelSamplerName kPixelSamplerNames[] = {
    {PixelSamplerKind::Independent, "independent"},
    {PixelSamplerKind::Stratified, "stratified"},
    {PixelSamplerKind::Sobol, "sobol"},
    {PixelSamplerKind::PaddedSobol, "padded_sobol"},
};

} // namespace

const char* pixel_sampler_name(PixelSamplerKind kind) {
    for (const auto& n : kPixelSamplerNames)
        if (n.kind == kind) return n.name;
    return "?";
}

bool sampler_extends(PixelSamplerKind kind) {
    return kind == PixelSamplerKind::Independent || kind == PixelSamplerKind::PaddedSobol;
}

std::vector<std::string> pixel_sampler_names() {
    std::vector<std::string> names;
    for (const auto& n : kPixelSamplerNames) names.push_back(n.name);
    return names;
}

bool parse_pixel_sampler(const std::string& name, PixelSamplerKind* kind) {
    for (const auto& n : kPixelSamplerNames)
        if (name == n.name) {
            *kind = n.kind;
            return true;
        }
    return false;
}

std::string check_pixel_sampler_spp(PixelSamplerKind kind, uint64_t spp) {
    if (kind != PixelSamplerKind::Sobol || spp == 0 || (spp & (spp - 1)) == 0) return "";
    uint64_t below = 1;
    while (below <= spp / 2) below <<= 1;
    return std::string("the '") + pixel_sampler_name(kind) +
           "' pixel sampler needs a power-of-two spp, got " + std::to_string(spp) +
           " (the nearest are " + std::to_string(below) + " and " + std::to_string(2 * below) + ")";
}

} // namespace mcp
