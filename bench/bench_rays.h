// The ray sets the accelerator benchmarks time, shared by `make bench` (bench.cpp, native and
// wasm) and `make bench-embree` (embree_compare.cpp), so that both time the same rays.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/rng.h"
#include "render_api/render_request.h"

namespace mcp {
namespace bench {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The render request of scenes/<scene>.json, or null (with the reason on stderr).
inline std::shared_ptr<RenderRequest> load_render(const std::string& dir, const char* scene) {
    std::ifstream in(dir + "/" + scene + ".json");
    std::stringstream ss;
    ss << in.rdbuf();
    Made<Json> j = parse_json(ss.str().c_str(), scene);
    if (!j.ok()) return nullptr;
    Made<std::shared_ptr<RenderRequest>> r = build_render_request(j.value, Json{{"base_dir", dir}});
    if (!r.ok()) {
        std::fprintf(stderr, "bench: %s: %s\n", scene, r.error.c_str());
        return nullptr;
    }
    return r.value;
}

/// Rays as the direct-lighting integrator traces them: 16 jittered camera rays per pixel of a
/// 64x64 image, in pixel order (closest hit), and a shadow ray from each camera ray's hit to a
/// point sampled on the scene's lights by solid angle (any hit, t_max = 1 just short of the
/// light). Fixed seed.
struct DirectRays {
    std::vector<Ray> camera, shadow;
};
inline DirectRays direct_lighting_rays(const RenderScene& rs, const Camera& camera) {
    const int size = 64, per_pixel = 16;
    const CameraRays cam = camera_rays(camera, size, size);
    DirectRays out;
    Pcg32 rng(7u, 3u);
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            for (int i = 0; i < per_pixel; ++i) {
                const Ray ray = ray_through(cam, x + rng.next_double(), y + rng.next_double());
                out.camera.push_back(ray);
                Hit hit;
                if (!rs.accel.intersect(ray, &hit)) continue;
                const Vec3 p = ray.origin + hit.t * ray.direction;
                const LightSample ls = rs.lights_power.sample(
                    p, rng.next_double(), Vec2(rng.next_double(), rng.next_double()),
                    LightSampling::SolidAngle);
                if (!ls.valid) continue;
                Ray s;
                s.origin = p + 1e-6 * (ls.point - p);
                s.direction = (ls.point - s.origin) * (1.0 - 1e-6);
                s.t_max = 1.0;
                out.shadow.push_back(s);
            }
        }
    }
    return out;
}

/// Rays per second of trace() (which traces `rays` rays and returns its hit count, so that the
/// calls are not dropped): best of 24 after a warm-up. A call takes a few milliseconds, so on a
/// shared machine some of them run unpreempted and the best is the machine's rate, not its load.
template <typename Trace> double best_rays_per_second(Trace&& trace, size_t rays, size_t* hits) {
    double best = 0.0;
    for (int rep = 0; rep < 25; ++rep) {
        auto t0 = std::chrono::steady_clock::now();
        *hits = trace();
        const double s = seconds_since(t0);
        if (rep > 0) best = std::max(best, double(rays) / s);
    }
    return best;
}

/// How many of the rays hit something (closest-hit queries).
inline size_t closest_hits(const Accelerator& accel, const std::vector<Ray>& rays) {
    size_t hits = 0;
    for (const Ray& ray : rays) {
        Hit h;
        hits += accel.intersect(ray, &h);
    }
    return hits;
}

} // namespace bench
} // namespace mcp
