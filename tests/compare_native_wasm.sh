#!/usr/bin/env bash
# The same studies through the native CLI and the WebAssembly CLI under Node must give the
# same numbers: integer work (RNG, samplers) is bit-identical; transcendental functions may
# differ in the last bit between glibc and musl, so estimates are compared to 1e-12 relative.
set -eu
native=${1:?native mcplay}
wasm=${2:?wasm mcplay command}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
# The wasm CLI as a user runs it (issue 48): plain `node mcplay.js`, no flags (Node 20's fetch()
# once made it fail without --no-experimental-fetch), from another folder, finding its scene
# through $MCPLAY_SCENES (which it ignored) and giving the native CLI's numbers.
js=${wasm##* }
case "$js" in /*) ;; *) js="$PWD/$js" ;; esac
mkdir "$tmp/elsewhere"
cp scenes/exp_1d.json "$tmp/elsewhere/only_here.json"
env_run=(run only_here --n-min 16 --n-max 256 --reps 4 --quiet --format json)
if (cd "$tmp" && MCPLAY_SCENES="$tmp/elsewhere" node "$js" list) | grep only_here >/dev/null &&
    (cd "$tmp" && MCPLAY_SCENES="$tmp/elsewhere" node "$js" "${env_run[@]}" --out "$tmp/env.wasm.json"); then
    MCPLAY_SCENES="$tmp/elsewhere" $native "${env_run[@]}" --threads 2 --out "$tmp/env.native.json"
    node tests/compare_results.mjs "$tmp/env.native.json" "$tmp/env.wasm.json" || status=1
else
    echo "FAIL plain node $js: no scene from \$MCPLAY_SCENES listed or run"
    status=1
fi
for scene in scenes/*.json; do
    name=$(basename "$scene" .json)
    if grep -q '"render"' "$scene"; then
        # Render studies: tiny images, the reference rendered (not cached) on both sides.
        small=(--n-min 1 --n-max 4 --reps 2 --width 12 --height 10 --no-cache --quiet --format json)
        $native run "$scene" "${small[@]}" --threads 2 --out "$tmp/$name.native.json"
        $wasm run "$scene" "${small[@]}" --out "$tmp/$name.wasm.json"
        node tests/compare_results.mjs "$tmp/$name.native.json" "$tmp/$name.wasm.json" || status=1
        continue
    fi
    $native run "$scene" --n-min 16 --n-max 1024 --reps 4 --threads 2 --quiet --format json --out "$tmp/$name.native.json"
    $wasm run "$scene" --n-min 16 --n-max 1024 --reps 4 --quiet --format json --out "$tmp/$name.wasm.json"
    node tests/compare_results.mjs "$tmp/$name.native.json" "$tmp/$name.wasm.json" || status=1
done
exit $status
