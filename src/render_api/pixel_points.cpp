// mcp_render_pixel_points: the points one pixel's samples take from a render pixel sampler,
// for the sampler lab (its analysis is mcp_points_analyze's: the same JSON rows).
#include <string>
#include <vector>

#include "api/boundary.h"
#include "api/json_read.h"
#include "render/pixel_sampler.h"
#include "render_api/mcplay_render.h"

using mcp::boundary::copy_out;
using mcp::boundary::dump;
using mcp::boundary::fail;

namespace {

/// At most this many samples of one pixel, and 2D requests per sample.
constexpr uint64_t kMaxPixelPoints = uint64_t(1) << 16;
constexpr uint64_t kMaxPixelRequests = 4;

} // namespace

extern "C" int mcp_render_pixel_points(const char* request_json, char** points_json) {
    if (!points_json)
        return fail(MCP_ERROR_ARGUMENT, "mcp_render_pixel_points: points_json is NULL");
    *points_json = nullptr;
    mcp::Made<mcp::Json> request = mcp::parse_json(request_json, "request");
    if (!request.ok()) return fail(MCP_ERROR_ARGUMENT, request.error);
    const mcp::Json& j = request.value;
    mcp::Ctx c;
    if (!j.is_object()) return fail(MCP_ERROR_ARGUMENT, "request: expected an object");
    if (!mcp::check_keys(c, j, "request",
                         {"pixel_sampler", "spp", "dim", "seed", "width", "height", "pixel"}))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    std::string name = "sobol";
    uint64_t spp = 64, dim = 2, seed = 1, width = 1, height = 1;
    std::vector<double> pixel{0, 0};
    if (!mcp::get_string(c, j, "pixel_sampler", "request", &name) ||
        !mcp::get_count(c, j, "spp", "request", &spp) ||
        !mcp::get_count(c, j, "dim", "request", &dim) ||
        !mcp::get_count(c, j, "seed", "request", &seed) ||
        !mcp::get_count(c, j, "width", "request", &width) ||
        !mcp::get_count(c, j, "height", "request", &height) ||
        !mcp::get_numbers(c, j, "pixel", "request", &pixel))
        return fail(MCP_ERROR_ARGUMENT, c.error);
    mcp::PixelSamplerKind kind;
    if (!mcp::parse_pixel_sampler(name, &kind))
        return fail(MCP_ERROR_ARGUMENT, "request.pixel_sampler: unknown pixel sampler '" + name +
                                            "' (known: independent, stratified, sobol)");
    if (spp < 1 || spp > kMaxPixelPoints)
        return fail(MCP_ERROR_ARGUMENT, "request.spp: expected 1 to " +
                                            std::to_string(kMaxPixelPoints) + ", got " +
                                            std::to_string(spp));
    const std::string why = mcp::check_pixel_sampler_spp(kind, spp);
    if (!why.empty()) return fail(MCP_ERROR_ARGUMENT, "request.spp: " + why);
    if (dim < 2 || dim > 2 * kMaxPixelRequests || dim % 2)
        return fail(MCP_ERROR_ARGUMENT, "request.dim: expected 2, 4, 6 or 8 (the sample's first "
                                        "dim / 2 two-dimensional requests), got " +
                                            std::to_string(dim));
    if (width < 1 || height < 1 || width > 65536 || height > 65536)
        return fail(MCP_ERROR_ARGUMENT, "request: width and height must be 1 to 65536");
    if (pixel.size() != 2 || pixel[0] < 0 || pixel[1] < 0 || pixel[0] >= double(width) ||
        pixel[1] >= double(height) || pixel[0] != double(int64_t(pixel[0])) ||
        pixel[1] != double(int64_t(pixel[1])))
        return fail(MCP_ERROR_ARGUMENT, "request.pixel: expected [x, y], whole numbers inside "
                                        "the width x height image");
    mcp::PixelSampler sampler;
    sampler.configure(kind, spp, static_cast<int>(width), static_cast<int>(height), seed);
    sampler.start_pixel(static_cast<int>(pixel[0]), static_cast<int>(pixel[1]));
    mcp::Json rows = mcp::Json::array();
    for (uint64_t i = 0; i < spp; ++i) {
        sampler.start_sample(i);
        mcp::Json row = mcp::Json::array();
        for (uint64_t r = 0; r < dim / 2; ++r) {
            const mcp::Vec2 u = sampler.get_2d();
            row.push_back(u.x);
            row.push_back(u.y);
        }
        rows.push_back(std::move(row));
    }
    mcp::Json out{{"pixel_sampler", mcp::pixel_sampler_name(kind)},
                  {"n", spp},
                  {"dim", dim},
                  {"seed", seed},
                  {"width", width},
                  {"height", height},
                  {"pixel", {int64_t(pixel[0]), int64_t(pixel[1])}},
                  {"points", rows}};
    *points_json = copy_out(dump(out));
    if (!*points_json) return fail(MCP_ERROR_INTERNAL, "out of memory writing the points");
    return mcp::boundary::succeed();
}
