// Throughput benchmark: samples per second of the estimator hot loop on several scenes, and
// raw PCG32 draws per second. Prints "BENCH <case> <samples/s>" lines that run_bench.sh
// sets side by side for the native and the WebAssembly builds.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "api/scene.h"
#include "core/point_analysis.h"
#include "core/rng.h"
#include "core/stats.h"
#include "estimators/named_warps.h"
#include "estimators/warp_test.h"
#include "render_api/render_request.h"

#include "bench_rays.h"

using namespace mcp;
using namespace mcp::bench;

namespace {

bool load(const std::string& dir, const std::string& name, SceneRequest* out) {
    std::ifstream in(dir + "/" + name + ".json");
    if (!in) return false;
    std::stringstream ss;
    ss << in.rdbuf();
    Made<Json> j = parse_json(ss.str().c_str(), name.c_str());
    if (!j.ok()) return false;
    Made<SceneRequest> r = build_request(j.value, Json());
    if (!r.ok()) return false;
    *out = r.value;
    return true;
}

// Best of five timed runs of n samples, after one warm-up run (V8 tiers wasm up only
// between calls, see TOOLCHAIN.md).
double samples_per_second(const SceneRequest& req, const EstimatorSpec& spec, uint64_t n) {
    Workspace ws;
    Pcg32 rng(1, 1);
    run_estimate(req.problem, spec, n / 8, rng, ws);
    double best = 1e300;
    for (int rep = 0; rep < 5; ++rep) {
        auto t0 = std::chrono::steady_clock::now();
        RunResult r = run_estimate(req.problem, spec, n, rng, ws);
        double t = seconds_since(t0);
        if (r.estimate != r.estimate) std::fprintf(stderr, "NaN estimate\n");
        if (t < best) best = t;
    }
    return static_cast<double>(n) / best;
}

// The work of a uniform estimate on the unit interval written out by hand, nothing else: PCG32
// 53-bit uniforms (Pcg32::next_double, point-major like the independent sampler), the scene's
// integrand through evaluate_block (the block function run_estimate calls), and Welford moments
// (RunningMoments::add_block, as run_estimate keeps them). No sampler plan, no warp (x = u on
// [0, 1]), no density, no diagnostics.
struct HandLoop {
    const Integrand& integrand;
    PointBlock x;
    std::vector<double> f;
    explicit HandLoop(const Integrand& g) : integrand(g), f(kBlockSize) {
        x.reset(g.dim, kBlockSize);
    }
    double run(Pcg32& run_rng, uint64_t count) {
        const int d = integrand.dim;
        // The generator the independent sampler's plan draws from run_rng (its seed and stream),
        // so that both loops see the same uniforms.
        const uint64_t seed = (uint64_t(run_rng.next_u32()) << 32) | run_rng.next_u32();
        const uint64_t stream = (uint64_t(run_rng.next_u32()) << 32) | run_rng.next_u32();
        Pcg32 rng(seed, stream);
        RunningMoments moments;
        for (uint64_t first = 0; first < count; first += kBlockSize) {
            const size_t m = static_cast<size_t>(std::min<uint64_t>(kBlockSize, count - first));
            x.n = m;
            for (size_t i = 0; i < m; ++i)
                for (int j = 0; j < d; ++j) x.coord(j)[i] = rng.next_double();
            evaluate_block(integrand, x, f.data());
            moments.add_block(f.data(), m);
        }
        return moments.mean();
    }
};

// exp_1d uniform: mcplay's run_estimate against the hand loop above, n samples each, timed in
// alternation (best of five each, after a warm-up of n/8 each) so that both see the same machine
// load. Prints "BENCH exp_1d/uniform_hand_loop" (run_bench.sh sets it beside the wasm figure)
// and "LOOP ..." with both rates, their ratio mcplay/hand, and whether one run of each from
// the same seed gave the same estimate (it should: the same draws, values and sums).
void estimator_overhead(const SceneRequest& req, uint64_t n) {
    const Domain& dom = req.problem.domain;
    if (dom.kind != DomainKind::Box || dom.lo != std::vector<double>(dom.lo.size(), 0.0) ||
        dom.hi != std::vector<double>(dom.hi.size(), 1.0) ||
        dom.point_dim() != req.problem.integrand.dim) {
        std::fprintf(stderr, "bench: the hand loop needs a unit-cube scene\n");
        return;
    }
    for (const EstimatorSpec& spec : req.estimators) {
        if (spec.name != "uniform") continue;
        Workspace ws;
        HandLoop hand(req.problem.integrand);
        Pcg32 a(7, 11), b(7, 11);
        const double mcplay_estimate = run_estimate(req.problem, spec, n, a, ws).estimate;
        const double hand_estimate = hand.run(b, n);
        Pcg32 rng_m(1, 1), rng_h(1, 1);
        run_estimate(req.problem, spec, n / 8, rng_m, ws);
        hand.run(rng_h, n / 8);
        double best_m = 1e300, best_h = 1e300, checksum = 0.0;
        for (int rep = 0; rep < 5; ++rep) {
            auto t0 = std::chrono::steady_clock::now();
            checksum += run_estimate(req.problem, spec, n, rng_m, ws).estimate;
            best_m = std::min(best_m, seconds_since(t0));
            t0 = std::chrono::steady_clock::now();
            checksum += hand.run(rng_h, n);
            best_h = std::min(best_h, seconds_since(t0));
        }
        if (checksum != checksum) std::fprintf(stderr, "NaN estimate\n");
        const double mcplay = double(n) / best_m, by_hand = double(n) / best_h;
        std::printf("BENCH exp_1d/uniform_hand_loop %.6e\n", by_hand);
        std::printf("LOOP exp_1d/uniform: run_estimate %.3e, hand loop %.3e samples/s, "
                    "mcplay/hand %.2f; one run of each from the same seed: estimates %s\n",
                    mcplay, by_hand, mcplay / by_hand,
                    mcplay_estimate == hand_estimate ? "identical" : "DIFFER");
    }
}

// 2^26 raw 32-bit draws; the checksum keeps the loop from being optimised away.
double pcg32_draws_per_second() {
    Pcg32 rng(1, 2);
    uint32_t acc = 0;
    const uint64_t draws = uint64_t(1) << 26;
    auto t0 = std::chrono::steady_clock::now();
    for (uint64_t i = 0; i < draws; ++i) acc ^= rng.next_u32();
    double t = seconds_since(t0);
    if (acc == 0x12345678u) std::fprintf(stderr, "(checksum %u)\n", acc);
    return static_cast<double>(draws) / t;
}

// Integrand evaluations per second over blocks of kBlockSize points: six passes of `total`
// evaluations (the first a warm-up), each timed in slices of 2^16 evaluations (a millisecond or
// so), the best slice kept: on a shared machine some slices run unpreempted.
double evaluations_per_second(const Integrand& f, uint64_t total) {
    PointBlock x;
    x.reset(f.dim, kBlockSize);
    x.n = kBlockSize;
    Pcg32 rng(3, 4);
    for (int j = 0; j < f.dim; ++j)
        for (size_t i = 0; i < kBlockSize; ++i) x.coord(j)[i] = rng.next_double();
    std::vector<double> out(kBlockSize);
    const uint64_t slice =
        std::max<uint64_t>(kBlockSize, (uint64_t(1) << 16) / kBlockSize * kBlockSize);
    double best = 1e300, checksum = 0.0;
    for (int rep = 0; rep < 6; ++rep) { // the first pass is the warm-up
        for (uint64_t start = 0; start < total; start += slice) {
            auto t0 = std::chrono::steady_clock::now();
            for (uint64_t done = 0; done < slice; done += kBlockSize) {
                evaluate_block(f, x, out.data());
                checksum += out[0];
            }
            const double t = seconds_since(t0);
            if (rep > 0 && t < best) best = t;
        }
    }
    if (checksum == 0.123) std::fprintf(stderr, "(checksum)\n");
    return static_cast<double>(slice) / best;
}

// Summing 2^30 copies of 0.1: a naive double sum, a naive float sum and mcplay's compensated
// sum, against the exact 2^30 * fl(0.1).
void accumulation_accuracy() {
    const uint64_t n = uint64_t(1) << 30;
    const double term = 0.1;
    double naive = 0.0;
    float naive_float = 0.0f;
    NeumaierSum compensated;
    auto t0 = std::chrono::steady_clock::now();
    for (uint64_t i = 0; i < n; ++i) {
        naive += term;
        naive_float += static_cast<float>(term);
        compensated.add(term);
    }
    const double t = seconds_since(t0);
    const double exact = term * static_cast<double>(n); // exact: a power-of-two multiple
    std::printf("ACCUM sum of 2^30 x 0.1 (%.1f s): relative error naive double %.2e, naive float "
                "%.2e, compensated %.2e\n",
                t, std::fabs(naive - exact) / exact,
                std::fabs(static_cast<double>(naive_float) - exact) / exact,
                std::fabs(compensated.value() - exact) / exact);
}

// Rays per second of one thread rendering a render scene with an estimator (camera, shadow
// and bounce rays alike), best of three renders after a warm-up render.
void render_rays_per_second(const std::string& dir, const char* scene, const char* estimator) {
    const std::shared_ptr<RenderRequest> request = load_render(dir, scene);
    if (!request) return;
    RenderScene rs;
    rs.build(*request->scene, request->accel);
    for (const RenderEstimator& e : request->estimators) {
        if (e.name != estimator) continue;
        RenderSettings st;
        st.width = st.height = 64;
        st.spp = 4;
        st.threads = 1;
        render_image(rs, e, st);
        st.spp = 16;
        double best = 0.0;
        for (int rep = 0; rep < 3; ++rep) {
            RenderImage im = render_image(rs, e, st);
            best = std::max(best, double(im.diagnostics.rays) / im.seconds);
        }
        std::printf("BENCH render/%s/%s_rays %.6e\n", scene, estimator, best);
    }
}

// Rays per second of the accelerator alone on the direct-lighting ray sets of bench_rays.h,
// one thread, best of three after a warm-up; the rays are made before the clock starts.
void traversal_rays_per_second(const std::string& dir, const char* scene) {
    const std::shared_ptr<RenderRequest> request = load_render(dir, scene);
    if (!request) return;
    RenderScene rs;
    rs.build(*request->scene, request->accel);
    const DirectRays rays = direct_lighting_rays(rs, request->scene->camera);
    const std::vector<Ray>&camera = rays.camera, &shadow = rays.shadow;
    const Accelerator& a = rs.accel;
    size_t camera_hits = 0, occluded = 0;
    const double camera_rate =
        best_rays_per_second([&] { return closest_hits(a, camera); }, camera.size(), &camera_hits);
    const double shadow_rate = best_rays_per_second(
        [&] {
            size_t hits = 0;
            for (const Ray& ray : shadow) hits += a.occluded(ray);
            return hits;
        },
        shadow.size(), &occluded);
    std::printf("BENCH rays/%s/camera %.6e\n", scene, camera_rate);
    std::printf("BENCH rays/%s/shadow %.6e\n", scene, shadow_rate);
    std::printf("INFO rays/%s: %zu camera rays (%.3f hit), %zu shadow rays (%.3f occluded)\n",
                scene, camera.size(), double(camera_hits) / double(camera.size()), shadow.size(),
                double(occluded) / double(std::max<size_t>(shadow.size(), 1)));
}

// Where brute force stops paying (Accelerator::kBruteForceMaxTriangles): rays per second of
// both structures on closed polyhedra around the rays' origins (every ray hits one face, as in
// a room), from 4 to 80 triangles. Random origins inside, random directions, best of three.
void brute_force_crossover() {
    // Unit-sphere polyhedra: tetrahedron, octahedron, icosahedron, and each face of the
    // octahedron and icosahedron split in four (32 and 80 faces).
    auto polyhedron = [](int kind) {
        Mesh m;
        const double t = (1.0 + std::sqrt(5.0)) / 2.0;
        if (kind == 0) {
            m.position = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
            m.index = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
        } else if (kind == 1 || kind == 3) {
            m.position = {Vec3(1, 0, 0),  Vec3(-1, 0, 0), Vec3(0, 1, 0),
                          Vec3(0, -1, 0), Vec3(0, 0, 1),  Vec3(0, 0, -1)};
            m.index = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
        } else {
            m.position = {Vec3(-1, t, 0), Vec3(1, t, 0), Vec3(-1, -t, 0), Vec3(1, -t, 0),
                          Vec3(0, -1, t), Vec3(0, 1, t), Vec3(0, -1, -t), Vec3(0, 1, -t),
                          Vec3(t, 0, -1), Vec3(t, 0, 1), Vec3(-t, 0, -1), Vec3(-t, 0, 1)};
            m.index = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
        }
        if (kind >= 3) { // split each face in four at its edge midpoints
            std::vector<std::array<uint32_t, 3>> split;
            for (const auto& f : m.index) {
                uint32_t mid[3];
                for (int k = 0; k < 3; ++k) {
                    mid[k] = uint32_t(m.position.size());
                    m.position.push_back(0.5 * (m.position[f[k]] + m.position[f[(k + 1) % 3]]));
                }
                split.push_back({f[0], mid[0], mid[2]});
                split.push_back({mid[0], f[1], mid[1]});
                split.push_back({mid[2], mid[1], f[2]});
                split.push_back({mid[0], mid[1], mid[2]});
            }
            m.index = split;
        }
        for (Vec3& p : m.position) p = glm::normalize(p);
        return m;
    };
    Pcg32 rng(11u, 5u);
    std::vector<Ray> rays(1 << 16);
    for (Ray& r : rays) {
        r.origin =
            0.3 * Vec3(rng.next_double() - 0.5, rng.next_double() - 0.5, rng.next_double() - 0.5);
        const double z = 2.0 * rng.next_double() - 1.0, phi = 6.283185307179586 * rng.next_double();
        const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
        r.direction = Vec3(s * std::cos(phi), s * std::sin(phi), z);
    }
    for (int kind = 0; kind < 5; ++kind) {
        const Mesh mesh = polyhedron(kind);
        for (AccelKind k : {AccelKind::BruteForce, AccelKind::Bvh}) {
            Accelerator a;
            a.build(mesh, k);
            size_t hits = 0;
            const double best =
                best_rays_per_second([&] { return closest_hits(a, rays); }, rays.size(), &hits);
            std::printf("BENCH rays/closed_%zu/%s %.6e\n", mesh.triangle_count(),
                        k == AccelKind::Bvh ? "bvh" : "brute_force",
                        hits == rays.size() ? best : 0.0);
            if (k == AccelKind::Bvh)
                std::printf("INFO rays/closed_%zu: BVH expects %.3f node visits and %.3f "
                            "triangle tests (%.3f pair tests) per ray\n",
                            mesh.triangle_count(), a.stats().expected_node_visits,
                            a.stats().expected_triangle_tests, a.stats().expected_pair_tests);
        }
    }
}

// The sampler lab's point-set analysis, one thread, runs per second (best of three after a
// warm-up run): the exact L2-star discrepancy of 16384 independent points in 8 dimensions (its
// O(N^2 d) double sum: 1.07e9 pair-coordinates) and the periodogram of 4096 points on a
// 256 x 256 grid of frequencies (1.35e8 complex multiply-adds).
void point_analysis_cases() {
    auto random_points = [](uint64_t n, int dim) {
        PointSet s;
        s.n = n;
        s.dim = dim;
        Pcg32 rng(5, 6);
        s.coords.resize(n * uint64_t(dim));
        for (double& x : s.coords) x = rng.next_double();
        return s;
    };
    auto runs_per_second = [](auto&& run) {
        double checksum = run(), best = 1e300;
        for (int rep = 0; rep < 3; ++rep) {
            const auto t0 = std::chrono::steady_clock::now();
            checksum += run();
            best = std::min(best, seconds_since(t0));
        }
        if (checksum != checksum) std::fprintf(stderr, "NaN analysis result\n");
        return 1.0 / best;
    };
    const PointSet a = random_points(16384, 8);
    const double star = runs_per_second([&] { return l2_star_discrepancy(a, 1); });
    std::printf("BENCH analysis/l2star_16384_d8 %.6e\n", star);
    std::printf("INFO analysis/l2star_16384_d8: %.3f s a run, %.3e pair-coordinates per second\n",
                1.0 / star, pair_coordinates(a.n, a.dim) * star);
    const PointSet b = random_points(4096, 2);
    const double spectrum =
        runs_per_second([&] { return power_spectrum(b, 0, 1, 256, 1).power[0]; });
    std::printf("BENCH analysis/spectrum_4096_256 %.6e\n", spectrum);
    std::printf("INFO analysis/spectrum_4096_256: %.3f s a run, %.3e complex multiply-adds per "
                "second\n",
                1.0 / spectrum, spectrum_operations(b.n, 256) * spectrum);
    // A warp test of 10^6 samples (the lab's default): the concentric disk (named) and the polar
    // disk typed as expressions, each a whole run_warp_test (quadrature, sampling, binning).
    const Made<NamedWarp> concentric = make_named_warp("concentric_disk");
    const double named = runs_per_second([&] {
        return run_warp_test(concentric.value.domain, concentric.value.warp).value.p_value;
    });
    std::printf("BENCH warp/concentric_disk_1e6 %.6e\n", named);
    std::printf("INFO warp/concentric_disk_1e6: %.3f s a test of 10^6 samples\n", 1.0 / named);
    const Made<Domain> disk = make_disk({0.0, 0.0}, 1.0);
    const Made<Warp> typed = make_expression_warp(
        disk.value, {"sqrt(u1)*cos(2*pi*u2)", "sqrt(u1)*sin(2*pi*u2)"}, "1/pi");
    const double expression =
        runs_per_second([&] { return run_warp_test(disk.value, typed.value).value.p_value; });
    std::printf("BENCH warp/expression_disk_1e6 %.6e\n", expression);
    std::printf("INFO warp/expression_disk_1e6: %.3f s a test of 10^6 samples\n", 1.0 / expression);
}

// An expression against the same integrand compiled in C++: exp(-(x-0.5)^2/0.01) is the
// built-in Gaussian with 2 sigma^2 = 0.01.
bool expression_cases(uint64_t n) {
    Made<Integrand> expr = make_expression_integrand("exp(-(x-0.5)^2/0.01)", 1);
    Made<Integrand> gauss =
        make_integrand(IntegrandKind::Gaussian, 1, 1.0, {}, {0.5}, std::sqrt(0.005));
    if (!expr.ok() || !gauss.ok()) return false;
    const double e = evaluations_per_second(expr.value, n),
                 g = evaluations_per_second(gauss.value, n);
    std::printf("BENCH eval/expression_gaussian %.6e\n", e);
    std::printf("BENCH eval/compiled_gaussian %.6e\n", g);
    std::printf("RATIO compiled/expression %.2f\n", g / e);
    return true;
}

void render_cases(const std::string& dir) {
    brute_force_crossover();
    traversal_rays_per_second(dir, "cornell_box");
    traversal_rays_per_second(dir, "veach_mis");
    traversal_rays_per_second(dir, "quad_light_floor");

    render_rays_per_second(dir, "cornell_box", "mis_power");
    render_rays_per_second(dir, "cornell_box", "light_area");
    render_rays_per_second(dir, "cornell_box_path", "path_mis");
    render_rays_per_second(dir, "veach_mis", "mis_power");
    render_rays_per_second(dir, "quad_light_floor", "mis_power");
}

} // namespace

int main(int argc, char** argv) {
    const std::string dir = argc > 1 ? argv[1] : "scenes";
    const uint64_t n = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : (uint64_t(1) << 22);

    // Raw generator throughput: the second call is timed (V8 tiers wasm up between calls).
    pcg32_draws_per_second();
    std::printf("BENCH pcg32_u32_draws %.6e\n", pcg32_draws_per_second());
    const char* cases[][2] = {
        {"exp_1d", "uniform"},
        {"exp_1d", "stratified"},
        {"exp_1d", "importance"},
        {"exp_1d", "latin_hypercube"},
        {"gaussian_2d", "uniform"},
        {"gaussian_2d", "stratified_table"},
        {"disk_quarter", "stratified_concentric"},
        {"hemisphere_cos2", "cosine"},
    };
    // --only NAME: one estimator case, "render" for the render cases alone, "rays" for the
    // accelerator rows alone, "eval" for the expression rows alone, or "analysis" for the
    // sampler lab's cases alone (point-set analysis, warp tests).
    const char* only = argc > 4 && std::string(argv[3]) == "--only" ? argv[4] : nullptr;
    const bool render_only = only && std::string(only) == "render";
    if (only && std::string(only) == "analysis") {
        point_analysis_cases();
        return 0;
    }
    if (only && std::string(only) == "rays") { // the accelerator rows alone
        for (const char* scene : {"cornell_box", "veach_mis", "quad_light_floor"})
            traversal_rays_per_second(dir, scene);
        return 0;
    }
    if (only && std::string(only) == "eval") return expression_cases(n) ? 0 : 1;
    for (auto& c : cases) {
        if (only && std::string(c[1]) != only) continue;
        SceneRequest req;
        if (!load(dir, c[0], &req)) {
            std::fprintf(stderr, "bench: cannot load scene %s from %s\n", c[0], dir.c_str());
            return 1;
        }
        for (const EstimatorSpec& spec : req.estimators)
            if (spec.name == c[1])
                std::printf("BENCH %s/%s %.6e\n", c[0], c[1], samples_per_second(req, spec, n));
    }

    if (render_only) {
        render_cases(dir);
        return 0;
    }
    if (only) return 0;
    // run_estimate's overhead over the bare work of a uniform estimate.
    {
        SceneRequest req;
        if (load(dir, "exp_1d", &req)) estimator_overhead(req, n);
    }

    if (!expression_cases(n)) return 1;
    render_cases(dir);
    point_analysis_cases();
    if (argc > 3 && std::string(argv[3]) == "--accumulation") accumulation_accuracy();
    return 0;
}
