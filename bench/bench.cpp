// Throughput benchmark: samples per second of the estimator hot loop on several scenes, and
// raw PCG32 draws per second. Prints "BENCH <case> <samples/s>" lines that run_bench.sh
// sets side by side for the native and the WebAssembly builds.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "api/scene.h"

using namespace mcp;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

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
    for (auto& c : cases) {
        SceneRequest req;
        if (!load(dir, c[0], &req)) {
            std::fprintf(stderr, "bench: cannot load scene %s from %s\n", c[0], dir.c_str());
            return 1;
        }
        for (const EstimatorSpec& spec : req.estimators)
            if (spec.name == c[1])
                std::printf("BENCH %s/%s %.6e\n", c[0], c[1], samples_per_second(req, spec, n));
    }
    return 0;
}
