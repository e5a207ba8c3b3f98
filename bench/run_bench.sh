#!/usr/bin/env bash
# Runs the throughput benchmark natively and in WebAssembly under Node and prints the
# figures side by side with their ratio. Usage: run_bench.sh NATIVE_BENCH "WASM_COMMAND"
set -eu
native=${1:?native bench}
wasm=${2:?wasm bench command}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "mcplay bench: samples per second of the estimator loop (best of 5 runs of 2^22 samples, one thread;"
echo "  render/*_rays: rays per second per core (camera, shadow and bounce rays), 64x64 at 16 spp, best of 3;"
echo "  rays/*: the accelerator alone, rays per second: a pixel's camera rays, shadow rays to the lights;"
echo "  analysis/*, warp/*: the sampler lab, runs per second (L2-star of 16,384 points in d = 8, the"
echo "  spectrum of 4,096 points on 256 x 256 frequencies, a warp test of 10^6 samples);"
echo "  wasm under node --no-liftoff: steady-state optimised code, as a browser reaches after tier-up)"
echo "machine: $(nproc) cores, $(uname -m), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
$native scenes $((1 << 22)) --accumulation >"$tmp/native"
$wasm scenes $((1 << 22)) --accumulation >"$tmp/wasm"
# The estimator cases again, native and wasm in turn, case by case (ROUNDS more times): both
# sides of a ratio then see the same machine load, and each figure is the best of its rounds.
rounds=${ROUNDS:-2}
cases=$(grep ^BENCH "$tmp/native" | awk '{print $2}' | grep -v '^render/\|^rays/\|^eval/\|^pcg32\|hand_loop\|^analysis/\|^warp/' |
        cut -d/ -f2 | sort -u)
for ((r = 0; r < rounds; ++r)); do
    for c in $cases; do
        $native scenes $((1 << 22)) --only "$c" | grep -v pcg32 >>"$tmp/native"
        $wasm scenes $((1 << 22)) --only "$c" | grep -v pcg32 >>"$tmp/wasm"
    done
done
best() { grep ^BENCH "$1" | awk '{ if ($3 > b[$2]) b[$2] = $3 } END { for (k in b) print k, b[k] }' | sort; }
echo "  (estimator cases: best of the full run and $rounds more rounds, native and wasm in turn)"
printf '%-44s %14s %14s %8s\n' case native wasm native/wasm
join <(best "$tmp/native") <(best "$tmp/wasm") |
    awk '{ printf "%-44s %14.3e %14.3e %7.2fx\n", $1, $2, $3, $2 / $3 }'
echo
echo "expression vs the same integrand compiled in C++ (evaluations per second; target ratio <= 3):"
echo "  native: $(grep '^RATIO compiled/expression' "$tmp/native" | cut -d' ' -f2-)    wasm: $(grep '^RATIO compiled/expression' "$tmp/wasm" | cut -d' ' -f2-)"
echo "run_estimate vs a hand-written loop doing the same work (PCG32 53-bit uniforms, the scene's block"
echo "  integrand, Welford moments; best of 5 runs of 2^22 each, alternating; ratio mcplay/hand, 1 = no overhead):"
echo "  native: $(grep '^LOOP exp_1d/uniform' "$tmp/native" | cut -d' ' -f2-)"
echo "  wasm:   $(grep '^LOOP exp_1d/uniform' "$tmp/wasm" | cut -d' ' -f2-)"
echo "accumulation over 2^30 terms:"
echo "  native: $(grep ^ACCUM "$tmp/native" | cut -d' ' -f2-)"
echo "  wasm:   $(grep ^ACCUM "$tmp/wasm" | cut -d' ' -f2-)"
