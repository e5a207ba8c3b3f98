#!/usr/bin/env bash
# bench/kernels.cpp three ways, in turn, ROUNDS times (default 3), then each kernel's best:
#   native    g++ -O3 against build/libmcplay_core.a, as the build runs (GCC's AVX2 clones of the
#             pair loops and the periodogram, glibc's libm with its FMA variants);
#   native128 the same with the clones' baseline x86-64 code (two doubles a register; the pair
#             loops' file by clang++ when installed) and glibc's non-AVX libm (GLIBC_TUNABLES):
#             the width and instructions wasm has;
#   wasm      em++ against build-wasm/libmcplay_core.a under node --no-liftoff.
# Usage: bash bench/kernels.sh [BUILD=build] [BUILD_WASM=build-wasm]
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
build_wasm=$(cd "${2:-$root/build-wasm}" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
flags=(-O3 -DNDEBUG -std=c++17 -ffp-contract=off -fno-exceptions -Wno-psabi -I"$root/src")
g++ "${flags[@]}" -I"$build/deps_include" "$root/bench/kernels.cpp" "$build/libmcplay_core.a" \
    -lpthread -o "$tmp/native"
# The pair loops' file without its target_clones attribute: the default (baseline) code alone.
sed 's/^MCP_VECTOR_CLONES //' "$root/src/core/point_analysis.cpp" >"$tmp/point_analysis.cpp"
# Compiled by clang++ when there is one (the compiler em++ wraps): GCC lowers the pair loops'
# 256-bit generic vectors without AVX to scalar code through the stack, clang to two SSE2
# registers, as it lowers them to two SIMD128 values for wasm.
cxx128=$(command -v clang++ || echo g++)
"$cxx128" "${flags[@]}" -I"$build/deps_include" -iquote "$root/src/core" -c "$tmp/point_analysis.cpp" \
    -o "$tmp/point_analysis.o"
g++ "${flags[@]}" -I"$build/deps_include" "$root/bench/kernels.cpp" "$tmp/point_analysis.o" \
    "$build/libmcplay_core.a" -lpthread -o "$tmp/native128"
NODE_PATH=${NODE_PATH:-/usr/share/nodejs} em++ "${flags[@]}" -msimd128 -msse -msse2 \
    -mnontrapping-fptoint -fno-slp-vectorize -I"$build_wasm/deps_include" \
    "$root/bench/kernels.cpp" "$build_wasm/libmcplay_core.a" -sENVIRONMENT=node \
    -sALLOW_MEMORY_GROWTH=1 -o "$tmp/wasm.js"
for ((r = 0; r < ${ROUNDS:-3}; ++r)); do
    "$tmp/native" | sed 's/^KERNEL/native/' >>"$tmp/out"
    GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-AVX "$tmp/native128" | sed 's/^KERNEL/native128/' >>"$tmp/out"
    node --no-experimental-fetch --no-liftoff "$tmp/wasm.js" | sed 's/^KERNEL/wasm/' >>"$tmp/out"
done
echo "best of ${ROUNDS:-3} rounds; wasm/native: speed ratio (1 = as fast as native)"
printf '%-36s %5s %9s %9s %9s %12s %15s\n' kernel unit native native128 wasm wasm/native wasm/native128
awk '{ k = $2; v = $3; key = $1 SUBSEP k; if (!(key in b) || v < b[key]) b[key] = v; unit[k] = $4; ks[k] = 1 }
     END { for (k in ks) printf "%-36s %5s %9.3f %9.3f %9.3f %12.2f %15.2f\n", k, unit[k],
           b["native", k], b["native128", k], b["wasm", k], b["native", k] / b["wasm", k],
           b["native128", k] / b["wasm", k] }' "$tmp/out" | sort
