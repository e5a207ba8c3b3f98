// mcplay's ray-scene intersection beside Embree 3 (Debian's libembree-dev), the ray tracing
// kernels under Mitsuba's llvm variants: rays per second of one thread on the same rays
// (bench_rays.h: a 64x64 image's 16 jittered camera rays per pixel and a shadow ray from each
// hit to a light sample, as `make bench` times them), and how often the two agree.
//
//   embree_compare [SCENES_DIR] [SCENE ...]      (`make bench-embree`)
//
// Embree is timed one ray at a time (rtcIntersect1 / rtcOccluded1, as mcplay traces) and as
// packets of 16 consecutive rays (rtcIntersect16 / rtcOccluded16: a pixel's camera rays, or 16
// shadow rays from neighbouring samples), which is how a renderer running 16 samples in SIMD
// lanes would call it. Embree's scene is built with high quality and, in a second form, with
// its robust flag (no early culling, watertight edges), from float copies of the vertices.
// A comparison only: nothing in mcplay links Embree.
#include <embree3/rtcore.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "bench_rays.h"

using namespace mcp;
using namespace mcp::bench;

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

/// Embree's scene over the render scene's mesh, from float copies of its vertices.
RTCScene embree_scene(RTCDevice device, const Mesh& mesh, bool robust) {
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                           RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                           mesh.position.size()));
    for (size_t i = 0; i < mesh.position.size(); ++i) {
        for (int k = 0; k < 3; ++k) v[3 * i + size_t(k)] = static_cast<float>(mesh.position[i][k]);
    }
    unsigned* index = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.index.size()));
    for (size_t t = 0; t < mesh.index.size(); ++t) {
        for (int k = 0; k < 3; ++k) index[3 * t + size_t(k)] = mesh.index[t][size_t(k)];
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
    return scene;
}

RTCRayHit embree_ray(const Ray& r) {
    RTCRayHit rh;
    std::memset(&rh, 0, sizeof rh);
    rh.ray.org_x = float(r.origin.x), rh.ray.org_y = float(r.origin.y);
    rh.ray.org_z = float(r.origin.z);
    rh.ray.dir_x = float(r.direction.x), rh.ray.dir_y = float(r.direction.y);
    rh.ray.dir_z = float(r.direction.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::isinf(r.t_max) ? kInfF : float(r.t_max);
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

/// Closest hits one at a time; the hit triangle (or -1) of each ray in *prim.
size_t intersect1(RTCScene scene, const std::vector<Ray>& rays, std::vector<long>* prim) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    size_t hits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        RTCRayHit rh = embree_ray(rays[i]);
        rtcIntersect1(scene, &context, &rh);
        const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        hits += hit;
        if (prim) (*prim)[i] = hit ? long(rh.hit.primID) : -1;
    }
    return hits;
}

size_t occluded1(RTCScene scene, const std::vector<Ray>& rays) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    size_t hits = 0;
    for (const Ray& r : rays) {
        RTCRay ray = embree_ray(r).ray;
        rtcOccluded1(scene, &context, &ray);
        hits += ray.tfar < 0.0f;
    }
    return hits;
}

/// Packets of 16 consecutive rays (the tail masked off).
template <bool kOccluded> size_t packets16(RTCScene scene, const std::vector<Ray>& rays) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    size_t hits = 0;
    for (size_t base = 0; base < rays.size(); base += 16) {
        alignas(64) int valid[16];
        alignas(64) RTCRayHit16 p;
        for (int l = 0; l < 16; ++l) {
            const size_t i = base + size_t(l);
            valid[l] = i < rays.size() ? -1 : 0;
            const RTCRayHit rh = embree_ray(rays[i < rays.size() ? i : base]);
            p.ray.org_x[l] = rh.ray.org_x, p.ray.org_y[l] = rh.ray.org_y;
            p.ray.org_z[l] = rh.ray.org_z;
            p.ray.dir_x[l] = rh.ray.dir_x, p.ray.dir_y[l] = rh.ray.dir_y;
            p.ray.dir_z[l] = rh.ray.dir_z;
            p.ray.tnear[l] = 0.0f, p.ray.tfar[l] = rh.ray.tfar, p.ray.time[l] = 0.0f;
            p.ray.mask[l] = ~0u, p.ray.id[l] = 0, p.ray.flags[l] = 0;
            p.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        }
        if (kOccluded) {
            rtcOccluded16(valid, scene, &context, &p.ray);
            for (int l = 0; l < 16; ++l) hits += valid[l] && p.ray.tfar[l] < 0.0f;
        } else {
            rtcIntersect16(valid, scene, &context, &p);
            for (int l = 0; l < 16; ++l)
                hits += valid[l] && p.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID;
        }
    }
    return hits;
}

void compare(RTCDevice device, const std::string& dir, const char* name) {
    const std::shared_ptr<RenderRequest> request = load_render(dir, name);
    if (!request) return;
    RenderScene rs;
    rs.build(*request->scene, request->accel);
    const DirectRays rays = direct_lighting_rays(rs, request->scene->camera);
    const Accelerator& a = rs.accel;
    const Mesh& mesh = request->scene->mesh;
    std::printf("%s: %zu triangles, %zu camera rays, %zu shadow rays; mcplay's structure: %s\n",
                name, mesh.triangle_count(), rays.camera.size(), rays.shadow.size(),
                a.stats().kind == AccelKind::Bvh ? "BVH" : "brute force");

    size_t n = 0;
    const double m_cam =
        best_rays_per_second([&] { return closest_hits(a, rays.camera); }, rays.camera.size(), &n);
    const double m_sh = best_rays_per_second(
        [&] {
            size_t hits = 0;
            for (const Ray& r : rays.shadow) hits += a.occluded(r);
            return hits;
        },
        rays.shadow.size(), &n);
    std::printf("  %-30s camera %9.3e rays/s   shadow %9.3e rays/s\n", "mcplay, one ray", m_cam,
                m_sh);

    for (bool robust : {false, true}) {
        RTCScene scene = embree_scene(device, mesh, robust);
        const char* form = robust ? "robust" : "default";
        const double e_cam = best_rays_per_second(
            [&] { return intersect1(scene, rays.camera, nullptr); }, rays.camera.size(), &n);
        const double e_sh = best_rays_per_second([&] { return occluded1(scene, rays.shadow); },
                                                 rays.shadow.size(), &n);
        const double p_cam = best_rays_per_second(
            [&] { return packets16<false>(scene, rays.camera); }, rays.camera.size(), &n);
        const double p_sh = best_rays_per_second(
            [&] { return packets16<true>(scene, rays.shadow); }, rays.shadow.size(), &n);
        std::printf("  Embree %-23s camera %9.3e rays/s   shadow %9.3e rays/s   (x%.2f, x%.2f)\n",
                    (std::string(form) + ", one ray").c_str(), e_cam, e_sh, e_cam / m_cam,
                    e_sh / m_sh);
        std::printf("  Embree %-23s camera %9.3e rays/s   shadow %9.3e rays/s   (x%.2f, x%.2f)\n",
                    (std::string(form) + ", packets of 16").c_str(), p_cam, p_sh, p_cam / m_cam,
                    p_sh / m_sh);

        // Agreement: the same triangle for closest hits, the same answer for shadow rays.
        std::vector<long> prim(rays.camera.size());
        intersect1(scene, rays.camera, &prim);
        size_t same = 0;
        for (size_t i = 0; i < rays.camera.size(); ++i) {
            Hit h;
            const long mine = a.intersect(rays.camera[i], &h) ? long(h.triangle) : -1;
            same += mine == prim[i];
        }
        size_t same_shadow = 0;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (const Ray& r : rays.shadow) {
            RTCRay ray = embree_ray(r).ray;
            rtcOccluded1(scene, &context, &ray);
            same_shadow += a.occluded(r) == (ray.tfar < 0.0f);
        }
        std::printf("  agreement (%s): same triangle for %zu of %zu camera rays, same answer for "
                    "%zu of %zu shadow rays\n",
                    form, same, rays.camera.size(), same_shadow, rays.shadow.size());
        rtcReleaseScene(scene);
    }
}

} // namespace

int main(int argc, char** argv) {
    const std::string dir = argc > 1 ? argv[1] : "scenes";
    std::vector<std::string> names;
    for (int i = 2; i < argc; ++i) names.push_back(argv[i]);
    if (names.empty()) names = {"cornell_box", "veach_mis", "quad_light_floor"};
    RTCDevice device = rtcNewDevice("threads=1");
    if (!device) {
        std::fprintf(stderr, "embree_compare: Embree device: error %d\n",
                     int(rtcGetDeviceError(nullptr)));
        return 1;
    }
    std::printf("Embree %ld.%ld.%ld (native 16-wide packets: %s) beside mcplay, one thread\n",
                long(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MAJOR)),
                long(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MINOR)),
                long(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_PATCH)),
                rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? "yes"
                                                                                         : "no");
    for (const std::string& name : names) compare(device, dir, name.c_str());
    rtcReleaseDevice(device);
    return 0;
}
