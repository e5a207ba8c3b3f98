#!/usr/bin/env bash
# The mcplay CLI through its real executable: exit codes, one-line errors, output formats.
# Usage: cli_test.sh SOURCE_DIR MCPLAY_EXECUTABLE (a .js file is run with node)
set -u
src=${1:?source dir}
exe=${2:?mcplay executable}
cd "$src"
case "$exe" in
    *.js) mcplay="node --no-experimental-fetch $exe" ;;  # Node 20 fetch() cannot load file paths
    *) mcplay="$exe" ;;
esac
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0

check() {  # check NAME EXPECTED_EXIT PATTERN_IN_OUTPUT -- ARGS...
    local name=$1 want=$2 pattern=$3
    shift 4
    $mcplay "$@" >"$tmp/out" 2>"$tmp/err"
    local got=$?
    if [ "$got" != "$want" ]; then
        echo "FAIL $name: exit $got, expected $want"; cat "$tmp/err"; failed=$((failed + 1)); return
    fi
    if [ -n "$pattern" ] && ! grep -qE -- "$pattern" "$tmp/out" "$tmp/err"; then
        echo "FAIL $name: output lacks /$pattern/"; head -5 "$tmp/out" "$tmp/err"; failed=$((failed + 1)); return
    fi
    passed=$((passed + 1))
}

small=(--n-min 16 --n-max 256 --reps 4)
check help 0 'usage:' -- --help
check version 0 '^mcplay [0-9]+\.[0-9]+' -- --version
check no-args 2 'usage:' --
check unknown-command 2 "unknown command 'frobnicate'" -- frobnicate
check unknown-option 2 "unknown option '--fast'" -- run exp_1d --fast
check bad-number 2 "--n-min: expected a whole number >= 0, got 'abc'" -- run exp_1d --n-min abc
check negative-number 2 "--reps: expected a whole number >= 0, got '-3'" -- run exp_1d --reps -3
check missing-value 2 '--seed needs a value' -- run exp_1d --seed
check bad-format 2 "--format: expected table, json or csv, got 'xml'" -- run exp_1d --format xml
check two-scenes 2 'run takes one scene' -- run exp_1d disk_quarter
check no-scene 2 'run needs a scene' -- run
check missing-scene 3 "no scene file 'nowhere'" -- run nowhere
# Bad values typed on the command line are bad arguments (2); the same in a scene file, 3.
check bad-settings 2 'options: reps must be in 2' -- run exp_1d --reps 1
check bad-range 2 'n_max \(8\) must be >= n_min \(64\)' -- run exp_1d --n-min 64 --n-max 8
check unknown-estimator 2 "unknown estimator 'faure'" -- run exp_1d --estimators faure "${small[@]}"
printf '{"f": "x", "reps": 1}' >"$tmp/reps1.json"
check bad-settings-scene 3 'scene: reps must be in 2' -- run "$tmp/reps1.json"
# A long study is announced before it starts (from a timed pilot); the run is then stopped.
timeout 5 $mcplay run exp_1d --estimators uniform --n-max 68719476736 --reps 2 >"$tmp/out" 2>"$tmp/err"
if [ $? = 124 ] && grep -qE '^mcplay: this study is predicted to take about [0-9.]+ (min|hours)' "$tmp/err"; then
    passed=$((passed + 1))
else
    echo "FAIL long-study-notice: no notice before a long study"; cat "$tmp/err"; failed=$((failed + 1))
fi
timeout 8 $mcplay run cornell_box --n-max 1024 --width 512 --height 512 --no-cache >"$tmp/out" 2>"$tmp/err"
if [ $? = 124 ] && grep -qE '^mcplay: this study is predicted to take about [0-9.]+ (min|hours) \([0-9.e+]+ samples' "$tmp/err"; then
    passed=$((passed + 1))
else
    echo "FAIL long-render-notice: no notice before a long render study"; cat "$tmp/err"; failed=$((failed + 1))
fi
printf '{"integrand": {"type": "monomial", "powers": [1]}, "n_mx": 3}' >"$tmp/typo.json"
check scene-typo 3 "unknown field 'n_mx'" -- run "$tmp/typo.json"
printf '{"integrand": ' >"$tmp/broken.json"
check scene-broken 3 'invalid JSON' -- run "$tmp/broken.json"
check table 0 'fitted order: variance ~ N\^' -- run exp_1d "${small[@]}"
check by-path 0 'scene exp_1d' -- run scenes/exp_1d.json "${small[@]}"
check csv 0 '^scene,estimator,sampler,pdf,n,' -- run exp_1d "${small[@]}" --format csv
check estimators 0 '^"exp_1d","importance"' -- run exp_1d "${small[@]}" --format csv --estimators importance
check json 0 '"version": 1' -- run disk_quarter "${small[@]}" --format json
check out-file 0 '' -- run exp_1d "${small[@]}" --format json --out "$tmp/result.json"
if node -e 'const r = JSON.parse(require("fs").readFileSync(process.argv[1])); if (r.version !== 1 || r.estimators.length < 3) process.exit(1)' "$tmp/result.json"; then
    passed=$((passed + 1))
else
    echo "FAIL out-file: $tmp/result.json is not the documented JSON"; failed=$((failed + 1))
fi
check out-unwritable 2 "--out: cannot write" -- run exp_1d "${small[@]}" --out /nonexistent-dir/x.json
# An --out that is checked up front is removed again when the run then fails.
printf '{"f": "x", "estimators": ["unifrom"]}' >"$tmp/typo.json"
check out-removed-on-scene-error 3 "did you mean 'uniform'" -- run "$tmp/typo.json" --out "$tmp/typo.out"
if [ -e "$tmp/typo.out" ]; then echo "FAIL out-removed-on-scene-error: $tmp/typo.out left behind"; failed=$((failed + 1)); else passed=$((passed + 1)); fi
check list 0 'disk_quarter' -- list
check list-presets 0 'stratified_importance' -- list
check list-bad-dir 2 'cannot open scenes directory' -- list --scenes /nonexistent-dir
mkdir -p "$tmp/fifos" && mkfifo "$tmp/fifos/blocked.json" && cp scenes/exp_1d.json "$tmp/fifos/"
check list-fifo 0 'blocked.json +UNREADABLE: .* not a regular file' -- list --scenes "$tmp/fifos"
check scene-directory 3 'is a directory, not a scene file' -- run scenes
check scene-dev-zero 3 'not a regular file' -- run /dev/zero
check threads 0 '1 thread' -- run exp_1d "${small[@]}" --threads 1

# Render scenes: studies through `run`, images through `render`.
tiny=(--width 8 --height 6 --no-cache)
check render-study 0 'fitted order: relative MSE ~ spp\^' -- run quad_light_floor --n-min 1 --n-max 4 --reps 2 --estimators bsdf,mis_power "${tiny[@]}"
check render-list 0 'cornell_box +render, [0-9]+ triangles' -- list
check render-ris 0 'ris_32 +\[ris, lights by uniform' -- run many_lights --n-min 1 --n-max 2 --reps 2 --estimators light_solid_angle,ris_32 "${tiny[@]}"
mkdir -p "$tmp/ris" && cp scenes/quad_light_floor.gltf "$tmp/ris/"
printf '{"render": {"gltf": "quad_light_floor.gltf", "estimators": [{"strategy": "ris", "candidates": 0}]}}' >"$tmp/ris/r.json"
check render-ris-bad-m 3 'estimators\[0\]\.candidates: must be a whole number in 1\.\.64 or "auto", got 0' -- run "$tmp/ris/r.json"
check render-png 0 'quad_light_floor: light_area at 4 spp, 8x6' -- render quad_light_floor --estimator light_area --spp 4 --out "$tmp/img.png" "${tiny[@]}"
if [ "$(head -c 8 "$tmp/img.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ]; then
    passed=$((passed + 1))
else
    echo "FAIL render-png: $tmp/img.png is not a PNG"; failed=$((failed + 1))
fi
check render-hdr 0 'relative MSE against the reference' -- render quad_light_floor --spp 2 --out "$tmp/img.hdr" --error-out "$tmp/err.png" "${tiny[@]}"
if [ "$(head -c 10 "$tmp/img.hdr")" = "#?RADIANCE" ]; then
    passed=$((passed + 1))
else
    echo "FAIL render-hdr: $tmp/img.hdr is not a Radiance HDR file"; failed=$((failed + 1))
fi
check render-pfm 0 'quad_light_floor: mis_power at 2 spp, 8x6' -- render quad_light_floor --spp 2 --out "$tmp/img.pfm" "${tiny[@]}"
if [ "$(head -c 3 "$tmp/img.pfm")" != "$(printf 'PF\n')" ] || [ "$(stat -c %s "$tmp/img.pfm")" -ne $((12 + 8 * 6 * 12)) ]; then
    echo "FAIL render-pfm: $tmp/img.pfm is not an 8x6 float RGB map"; failed=$((failed + 1))
fi
check render-no-out 2 'render needs --out FILE' -- render quad_light_floor
check render-bad-ext 2 'must end in .png, .hdr or .pfm' -- render quad_light_floor --out "$tmp/x.jpg"
check render-bad-estimator 2 "unknown estimator 'lite'" -- render quad_light_floor --estimator lite --out "$tmp/x.png" "${tiny[@]}"
# An estimator object (splitting: light samples per shading point; "auto" reports its pilot).
check render-estimator-object 0 '"light_samples": 3' -- render quad_light_floor --estimator '{"strategy": "mis_power", "light_samples": 3}' --spp 4 --out "$tmp/split.png" --format json "${tiny[@]}"
check render-estimator-auto 0 '"split_pilot"' -- render quad_light_floor --estimator '{"strategy": "light_area", "light_samples": "auto"}' --spp 4 --out "$tmp/split.png" --format json "${tiny[@]}"
check render-estimator-bad-json 2 'is not valid JSON' -- render quad_light_floor --estimator '{"strategy"' --out "$tmp/x.png" "${tiny[@]}"
check render-estimator-auto-candidates 0 '"candidate_pilot"' -- render quad_light_floor --estimator '{"strategy": "path", "candidates": "auto"}' --spp 4 --out "$tmp/ris.png" --format json "${tiny[@]}"
check render-estimator-bad-count 2 'options.estimator.light_samples: must be a whole number in 1..64 or "auto", got 0' -- render quad_light_floor --estimator '{"strategy": "mis_power", "light_samples": 0}' --out "$tmp/x.png" "${tiny[@]}"
check render-bad-spp 2 "--spp: expected a whole number" -- render quad_light_floor --spp many --out "$tmp/x.png"
check render-width-on-integral 2 'for render scenes' -- run exp_1d --width 8
printf '{"render": {"gltf": "missing.gltf"}}' >"$tmp/r.json"
check render-missing-gltf 3 "scene.render.gltf: 'missing.gltf' does not exist" -- run "$tmp/r.json"
# The path rule lets a scene use its own subfolders and links that stay inside its folder: a
# glTF in sub/ whose buffer is one level up (still inside), reached through a symbolic link.
mkdir -p "$tmp/own/sub"
node -e '
const fs = require("fs"), [src, dir] = process.argv.slice(1);
const g = JSON.parse(fs.readFileSync(src + "/scenes/quad_light_floor.gltf"));
fs.writeFileSync(dir + "/q.bin", Buffer.from(g.buffers[0].uri.split(",")[1], "base64"));
g.buffers[0].uri = "../q.bin";
fs.writeFileSync(dir + "/sub/q.gltf", JSON.stringify(g));
fs.writeFileSync(dir + "/r.json", JSON.stringify({ name: "own", render: { gltf: "link.gltf",
  width: 8, height: 6, spp_min: 1, spp_max: 2, reps: 2, estimators: ["light_area"] } }));
' "$src" "$tmp/own"
ln -s sub/q.gltf "$tmp/own/link.gltf"
check render-own-subfolder 0 'fitted order' -- run "$tmp/own/r.json" --no-cache
ln -s "$(cd "$src" && pwd)/scenes/quad_light_floor.gltf" "$tmp/own/escape.gltf"
printf '{"render": {"gltf": "escape.gltf"}}' >"$tmp/own/escape.json"
check render-link-outside 3 "scene.render.gltf: 'escape.gltf' lies outside the scene's folder" -- run "$tmp/own/escape.json"
printf '{"render": {"gltf": {"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 1}]}]}}}' >"$tmp/lines.json"
check render-bad-gltf 3 'scene.render.gltf: ' -- run "$tmp/lines.json"

# Pixel samplers: --pixel-sampler for run (every estimator) and render; the Sobol' sampler
# needs a power-of-two spp, named in the error, never silently changed.
check render-sobol-study 0 'sobol pixels' -- run quad_light_floor --n-min 1 --n-max 4 --reps 2 --estimators light_solid_angle --pixel-sampler sobol "${tiny[@]}"
check render-sobol-image 0 'quad_light_floor: mis_power at 4 spp, 8x6' -- render quad_light_floor --estimator mis_power --spp 4 --pixel-sampler sobol --out "$tmp/sobol.png" "${tiny[@]}"
check render-sobol-spp 2 "options.spp: the 'sobol' pixel sampler needs a power-of-two spp, got 3 \(the nearest are 2 and 4\)" -- render quad_light_floor --spp 3 --pixel-sampler sobol --out "$tmp/x.png" "${tiny[@]}"
check render-bad-pixel-sampler 2 "--pixel-sampler: unknown pixel sampler 'halton' \(known: independent, stratified, sobol, padded_sobol\)" -- render quad_light_floor --pixel-sampler halton --out "$tmp/x.png"
check run-bad-pixel-sampler 2 "--pixel-sampler: unknown pixel sampler 'zsobol'" -- run quad_light_floor --pixel-sampler zsobol
check pixel-sampler-on-integral 2 'for render scenes' -- run exp_1d --pixel-sampler sobol
printf '{"render": {"gltf": "quad_light_floor.gltf", "spp_max": 4, "estimators": [{"strategy": "mis_power", "pixel_sampler": "sobol"}], "reference": {"estimator": {"strategy": "mis_power", "pixel_sampler": "sobol"}, "spp": 100}}}' >"$tmp/own/sobol_ref.json"
cp scenes/quad_light_floor.gltf "$tmp/own/"
check render-sobol-reference-spp 3 "scene.render.reference.spp: the 'sobol' pixel sampler needs a power-of-two spp, got 100" -- run "$tmp/own/sobol_ref.json" --no-cache

# References made once: `reference` writes one, and the cache it fills serves the next run.
check reference-write 0 'quad_light_floor: reference 8x6 at [0-9]+ spp \(mis_power, rendered\)' -- reference quad_light_floor --width 8 --height 6 --out "$tmp/q.mcref" --cache "$tmp/refcache"
if [ "$(head -c 8 "$tmp/q.mcref")" != "MCREF02" ]; then
    echo "FAIL reference-write: $tmp/q.mcref does not start with the magic"; failed=$((failed + 1))
fi
check reference-cached 0 '\(mis_power, cache\)' -- reference quad_light_floor --width 8 --height 6 --out "$tmp/q2.mcref" --cache "$tmp/refcache"
if ! cmp -s "$tmp/q.mcref" "$tmp/q2.mcref"; then
    echo "FAIL reference-cached: the cached reference differs from the rendered one"; failed=$((failed + 1))
fi
check reference-no-out 2 'reference needs --out' -- reference quad_light_floor
check reference-integral 2 'reference is for render scenes' -- reference exp_1d --out "$tmp/x.mcref"
check reference-live 0 'quad_light_floor: reference 16x16 at [0-9]+ spp' -- reference quad_light_floor --live --long-side 16 --out "$tmp/live.mcref" --cache "$tmp/livecache"
if [ "$(head -c 8 "$tmp/live.mcref")" != "MCREF02" ]; then
    echo "FAIL reference-live: $tmp/live.mcref does not start with the magic"; failed=$((failed + 1))
fi
check reference-long-side-not-live 2 '--long-side sizes the live view.s reference: it needs --live' -- reference quad_light_floor --long-side 16 --out "$tmp/x.mcref"

# Progressive renders (the live view's progression): each estimator in passes to 1, 2, 4 spp,
# a PNG and an HDR and one JSON line at each; the reference from the cache reference-live filled.
check progressive 0 '"spp":4' -- render quad_light_floor --progressive --spp 4 --long-side 16 --out-dir "$tmp/prog" --cache "$tmp/livecache" --quiet
if node -e '
const fs = require("fs"), [out, dir] = process.argv.slice(1);
const lines = fs.readFileSync(out, "utf8").trim().split("\n").map((l) => JSON.parse(l));
const names = ["uniform_hemisphere", "cosine_hemisphere", "bsdf", "light_area"]; // the first four
const bad = (why) => { console.error(why); process.exit(1); };
if (lines.length !== 12) bad(`${lines.length} lines, expected 12`);
for (const name of names) {
  const mine = lines.filter((l) => l.estimator === name);
  if (mine.map((l) => l.spp).join() !== "1,2,4") bad(`${name}: spp ${mine.map((l) => l.spp)}`);
  for (const l of mine) {
    if (!(Number.isFinite(l.relative_mse) && l.relative_mse >= 0)) bad(`${name}: relative_mse ${l.relative_mse}`);
    if (l.relative_mse_reason !== null) bad(`${name}: a reason beside a number: ${l.relative_mse_reason}`);
    if (!Number.isFinite(l.relative_mse_raw) || !Number.isFinite(l.seconds)) bad(`${name}: ${JSON.stringify(l)}`);
    if (l.width !== 16 || l.height !== 16) bad(`${name}: ${l.width}x${l.height}, expected 16x16`);
    const png = `${dir}/${name}_${l.spp}spp.png`, hdr = `${dir}/${name}_${l.spp}spp.hdr`;
    if (l.png !== png || l.hdr !== hdr) bad(`${name}: files ${l.png} ${l.hdr}`);
    if (fs.readFileSync(png).subarray(1, 4).toString() !== "PNG") bad(`${png} is not a PNG`);
    if (fs.readFileSync(hdr).subarray(0, 10).toString() !== "#?RADIANCE") bad(`${hdr} is not an HDR`);
  }
  if (!(mine[2].seconds >= mine[0].seconds)) bad(`${name}: seconds fall`);
}
' "$tmp/out" "$tmp/prog"; then
    passed=$((passed + 1))
else
    echo "FAIL progressive-output: not 1, 2, 4 spp images and JSON lines for each estimator"; failed=$((failed + 1))
fi
# The 4 spp image of the passes is the one-shot 4 spp image (same seed, size and pixel sampler).
check progressive-one-estimator 0 '"estimator":"mis_power","spp":4' -- render quad_light_floor --progressive --spp 4 --estimator mis_power --width 12 --height 8 --out-dir "$tmp/prog1" --no-cache --quiet
check progressive-one-shot 0 '' -- render quad_light_floor --estimator mis_power --spp 4 --pixel-sampler padded_sobol --width 12 --height 8 --out "$tmp/oneshot.hdr" --no-cache
if ! cmp -s "$tmp/prog1/mis_power_4spp.hdr" "$tmp/oneshot.hdr"; then
    echo "FAIL progressive-equals-one-shot: the 4 spp pass image differs from a 4 spp render"; failed=$((failed + 1))
fi
# A null relative MSE says why (issue 48): a camera far away and turned from the scene sees a
# black reference, which gives a relative error no scale.
node -e '
const fs = require("fs"), [src, out] = process.argv.slice(1);
const g = JSON.parse(fs.readFileSync(src + "/scenes/quad_light_floor.gltf", "utf8"));
const camera = g.nodes.find((n) => n.camera !== undefined);
camera.translation = [0, 0.95, 1e5];
camera.rotation = [0, 1, 0, 0]; // looking along +z, away from the floor and the light
const render = { gltf: g, width: 8, height: 8, spp_min: 1, spp_max: 2, reps: 2, estimators: ["light_area"] };
fs.writeFileSync(out, JSON.stringify({ name: "black", render }));
' "$src" "$tmp/black.json"
check progressive-null-reason 0 '"relative_mse":null,"relative_mse_raw":null,"relative_mse_reason":"the reference is black' -- render "$tmp/black.json" --progressive --spp 2 --long-side 16 --out-dir "$tmp/black" --no-cache --quiet
touch "$tmp/afile"
prog=(quad_light_floor --progressive --spp 4 --no-cache)
check progressive-no-out-dir 2 '--progressive needs --out-dir DIR' -- render "${prog[@]}"
check progressive-with-out 2 '--progressive writes its images to --out-dir' -- render "${prog[@]}" --out-dir "$tmp/p" --out "$tmp/x.png"
check progressive-spp 2 '--spp: --progressive needs a power of two, got 100 \(the nearest are 64 and 128\)' -- render quad_light_floor --progressive --spp 100 --out-dir "$tmp/p"
check progressive-no-spp 2 '--progressive needs --spp N' -- render quad_light_floor --progressive --out-dir "$tmp/p"
check progressive-integral 2 "--progressive is for render scenes; 'exp_1d' is an integral" -- render exp_1d --progressive --spp 4 --out-dir "$tmp/p"
check progressive-five 2 '--estimators: at most 4 side by side, got 5' -- render "${prog[@]}" --out-dir "$tmp/p" --estimators bsdf,light_area,mis_power,mis_balance,cosine_hemisphere
check progressive-long-side-small 2 '--long-side: expected 16 to 4096 pixels, got 8' -- render "${prog[@]}" --out-dir "$tmp/p" --long-side 8
check progressive-long-side-large 2 '--long-side: expected 16 to 4096 pixels, got 5000' -- render "${prog[@]}" --out-dir "$tmp/p" --long-side 5000
check progressive-long-side-and-width 2 '--long-side or --width and --height' -- render "${prog[@]}" --out-dir "$tmp/p" --long-side 16 --width 8 --height 8
check progressive-out-dir-file 2 "--out-dir: '$tmp/afile' exists and is not a directory" -- render "${prog[@]}" --out-dir "$tmp/afile"
check progressive-out-dir-deep 2 "--out-dir: cannot create '$tmp/no/such'" -- render "${prog[@]}" --out-dir "$tmp/no/such"
check progressive-stratified 2 "the 'stratified' sampler cannot .*use 'padded_sobol' or 'independent'" -- render "${prog[@]}" --out-dir "$tmp/p" --long-side 16 --pixel-sampler stratified
if [ -e "$tmp/p" ]; then echo "FAIL progressive-out-dir-removed: $tmp/p left behind by a failed run"; failed=$((failed + 1)); else passed=$((passed + 1)); fi
check progressive-options-alone 2 '--out-dir, --estimators and --long-side are for --progressive' -- render quad_light_floor --long-side 16 --out "$tmp/x.png"

# A study split over runs (machines) by replicate: `run --part I/K --format json` writes the
# parts, `merge` gives the whole study's numbers (seconds aside), as the table run prints.
split=(quad_light_floor --n-min 1 --n-max 4 --reps 3 --estimators light_area,bsdf "${tiny[@]}" --quiet)
for i in 0 1 2; do
    check "split-part-$i" 0 '' -- run "${split[@]}" --part "$i/3" --format json --out "$tmp/part$i.json"
done
check merge-table 0 'fitted order: relative MSE ~ spp\^' -- merge "$tmp/part2.json" "$tmp/part0.json" "$tmp/part1.json"
$mcplay merge "$tmp/part0.json" "$tmp/part1.json" "$tmp/part2.json" --format csv --out "$tmp/merged.csv" 2>/dev/null
$mcplay run "${split[@]}" --format csv --out "$tmp/whole.csv" 2>/dev/null
# the CSV without its timing columns (seconds, efficiency) must be the same
# columns 20 and 21 of the CSV are time_mean_s and efficiency (checked on the header)
strip_times() { cut -d, -f1-19,22- "$1"; }
if [ "$(head -1 "$tmp/whole.csv" | cut -d, -f20-21)" != "time_mean_s,efficiency" ]; then
    echo "FAIL merge-csv-columns: $(head -1 "$tmp/whole.csv")"; failed=$((failed + 1))
fi
if [ "$(strip_times "$tmp/merged.csv")" != "$(strip_times "$tmp/whole.csv")" ]; then
    echo "FAIL merge-equals-whole: the merged parts differ from the whole study"; failed=$((failed + 1))
else
    passed=$((passed + 1))
fi
check merge-missing-part 2 'is 3, but 2 parts were given' -- merge "$tmp/part0.json" "$tmp/part1.json"
check merge-twice 2 'must be given once' -- merge "$tmp/part0.json" "$tmp/part0.json" "$tmp/part2.json"
check merge-not-json 2 'merged.csv: parse error at line 1' -- merge "$tmp/merged.csv"
$mcplay run "${split[@]}" --format json --out "$tmp/whole.json" 2>/dev/null
check merge-whole 2 'not a part of a split study' -- merge "$tmp/whole.json"
check merge-nothing 2 'merge needs the JSON results of run --part' -- merge
check merge-no-file 2 "cannot open '$tmp/none.json'" -- merge "$tmp/none.json"
check part-bad 2 '--part: expected I/K' -- run quad_light_floor --part 3 --format json
check part-table 2 '--part needs --format json' -- run quad_light_floor --part 0/2
check part-too-many 2 '--part 0/4 \(K\): must be in 1..reps = 3, got 4' -- run "${split[@]}" --part 0/4 --format json
# Parts of one render study only: another seed is refused (named), the same seed accepted.
check split-seed-1 0 '' -- run "${split[@]}" --seed 1 --part 0/2 --format json --out "$tmp/seed1.json"
check split-seed-9 0 '' -- run "${split[@]}" --seed 9 --part 1/2 --format json --out "$tmp/seed9.json"
check split-seed-1b 0 '' -- run "${split[@]}" --seed 1 --part 1/2 --format json --out "$tmp/seed1b.json"
check merge-seeds 2 "part 1.settings.seed: is 9, part 0's is 1" -- merge "$tmp/seed1.json" "$tmp/seed9.json"
check merge-same-seed 0 'fitted order' -- merge "$tmp/seed1.json" "$tmp/seed1b.json"
sed 's/"coverage": [0-9][0-9.e+-]*/"coverage": 7/' "$tmp/seed1b.json" >"$tmp/coverage7.json"
check merge-coverage-7 2 'coverage: out of range: expected 0..1, got 7' -- merge "$tmp/seed1.json" "$tmp/coverage7.json"
# A render spp ladder with no power of two is refused, naming why; 4..4 has one level.
check spp-ladder-empty 2 'spp_max: no power of two lies between spp_min = 3 and spp_max = 3' -- run quad_light_floor --n-min 3 --n-max 3 --reps 2 "${tiny[@]}" --quiet
check spp-ladder-one 0 'light_area' -- run quad_light_floor --n-min 4 --n-max 4 --reps 2 --estimators light_area "${tiny[@]}" --quiet

# Integration studies and stopping runs split the same way: merged parts are the whole study,
# every number but the timing fields (wall_time_s, time_*, training_time_*, efficiency, seconds).
strip_json_times() {  # the JSON on one line, each timing field (a number or an [lo, hi] pair) cut
    tr -d ' \n' <"$1" | sed -E 's/"(wall_time_s|efficiency|time_[a-z0-9_]*|training_time_[a-z0-9_]*|[a-z_]*seconds[a-z_]*)":(\[[^]]*\]|[^],}]*),?//g'
}
for study in "exp_1d --n-min 16 --n-max 1024 --reps 5 --seed 3" \
             "vegas_corner_peak --n-min 64 --n-max 1024 --reps 4" \
             "exp_1d --rel-tol 1e-2 --reps 5 --estimators uniform,stratified"; do
    read -r -a args <<<"$study --quiet"
    name=${args[0]}-${#args[@]}
    check "int-whole-$name" 0 '' -- run "${args[@]}" --format json --out "$tmp/int_whole.json"
    for i in 0 1 2; do
        check "int-part-$name-$i" 0 '' -- run "${args[@]}" --part "$i/3" --format json --out "$tmp/int$i.json"
    done
    check "int-merge-$name" 0 '' -- merge "$tmp/int2.json" "$tmp/int0.json" "$tmp/int1.json" --format json --out "$tmp/int_merged.json"
    if [ "$(strip_json_times "$tmp/int_merged.json")" != "$(strip_json_times "$tmp/int_whole.json")" ]; then
        echo "FAIL int-merge-equals-whole-$name: the merged parts differ from the whole study"
        failed=$((failed + 1))
    else
        passed=$((passed + 1))
    fi
done
check int-merge-table 0 'uniform' -- merge "$tmp/int0.json" "$tmp/int1.json" "$tmp/int2.json"
check int-merge-missing 2 'part 2 of 3 is missing' -- merge "$tmp/int0.json" "$tmp/int1.json"
check int-merge-twice 2 'part 1 of 3 is given twice' -- merge "$tmp/int0.json" "$tmp/int1.json" "$tmp/int1.json"
check int-part-seed-9 0 '' -- run exp_1d --rel-tol 1e-2 --reps 5 --estimators uniform,stratified --seed 9 --part 2/3 --format json --out "$tmp/int_seed9.json"
check int-merge-seeds 2 'options.seed: differs from parts\[0\]' -- merge "$tmp/int0.json" "$tmp/int1.json" "$tmp/int_seed9.json"
check int-merge-render 2 'kind' -- merge "$tmp/int0.json" "$tmp/seed1b.json"
check int-part-bad 2 '--part 3/3 \(I\): must be in 0..K - 1 = 2, got 3' -- run exp_1d --part 3/3 --format json

# A result that cannot be written is a failure: a full disk (--out, standard output) and a
# closed standard output exit 1 with a message, never 0 with the result lost.
if [ -w /dev/full ]; then
    check out-dev-full 1 "cannot write '/dev/full'" -- run exp_1d "${small[@]}" --out /dev/full
    $mcplay run exp_1d "${small[@]}" >/dev/full 2>"$tmp/err"
    if [ $? = 1 ] && grep -q 'cannot write standard output' "$tmp/err"; then passed=$((passed + 1)); else
        echo "FAIL stdout-full: $(cat "$tmp/err")"; failed=$((failed + 1)); fi
    $mcplay merge "$tmp/int0.json" "$tmp/int1.json" "$tmp/int2.json" >/dev/full 2>"$tmp/err"
    if [ $? = 1 ]; then passed=$((passed + 1)); else echo "FAIL merge-stdout-full"; failed=$((failed + 1)); fi
fi
case "$exe" in
    *.js) ;; # node owns its standard output
    *)
        $mcplay run exp_1d "${small[@]}" >&- 2>"$tmp/err"
        if [ $? = 1 ] && grep -q 'cannot write standard output' "$tmp/err"; then passed=$((passed + 1)); else
            echo "FAIL stdout-closed: $(cat "$tmp/err")"; failed=$((failed + 1)); fi
        ;;
esac
# --cache (or $MCPLAY_CACHE) naming a file is an error naming it; a folder is used.
: >"$tmp/cachefile"
check cache-file 2 "--cache: '$tmp/cachefile' is not a directory" -- run quad_light_floor --cache "$tmp/cachefile" --n-max 2 --reps 2 --width 8 --height 6 --quiet
# The wasm CLI sees Emscripten's own environment, not the shell's: the native run checks it.
# The wasm CLI reads the shell's environment too (src/wasm/node_pre.js).
MCPLAY_CACHE="$tmp/cachefile" check cache-env-file 2 "MCPLAY_CACHE: '$tmp/cachefile' is not a directory" -- reference quad_light_floor --width 8 --height 6 --out "$tmp/ref.pfm"
check cache-dir 0 '' -- run quad_light_floor --cache "$tmp/cachedir" --n-max 2 --reps 2 --width 8 --height 6 --estimators light_area --quiet

# Issue 48: quad_light_floor split in two at its default settings has images whose relative MSE
# is negative (8 of them: closer to the truth than the reference can tell); merge took them for
# malformed ("rel_mse: out of range: expected 0..-, got -2.1e-05"). About 9 s.
check part0-default 0 '' -- run quad_light_floor --part 0/2 --format json --quiet --no-cache --out "$tmp/q0.json"
check part1-default 0 '' -- run quad_light_floor --part 1/2 --format json --quiet --no-cache --out "$tmp/q1.json"
check merge-negative-rel-mse 0 'render scene quad_light_floor' -- merge "$tmp/q0.json" "$tmp/q1.json"

# The sampler lab: points, analyze, warp-test (docs/sampler-lab.md).
check points-csv 0 '^x1,x2,x3$' -- points sobol --n 16 --dim 3 --seed 2
check points-out 0 '' -- points halton --n 256 --dim 2 --out "$tmp/h.csv"
if [ "$(wc -l <"$tmp/h.csv")" != 257 ]; then
    echo "FAIL points-out: $tmp/h.csv has $(wc -l <"$tmp/h.csv") lines, expected 257"; failed=$((failed + 1))
fi
check points-pixel 0 '^x1,x2$' -- points pixel_sobol --n 64
check points-pixel-spp 2 "needs a power-of-two spp" -- points pixel_sobol --n 48
check points-unknown 2 "unknown sampler 'faure'" -- points faure --n 16
check points-no-n 2 'points needs --n N' -- points sobol
check points-too-many 2 'n: expected 1 to 1048576 points' -- points sobol --n 2000000
check analyze-table 0 'L2-star discrepancy \(Warnock\) +[0-9.e-]+ +\(independent points' -- analyze "$tmp/h.csv"
check analyze-json 0 '"l2_star_discrepancy": [0-9.e-]+' -- analyze "$tmp/h.csv" --format json --spectrum-out "$tmp/h.png"
# --axes counts the columns from 1 as they are named (x1, x2: the header above), in the table
# too (issue 48: it printed "axes 0, 1" for --axes 1,2); the JSON's spectrum.axes count from 0.
check analyze-axes-table 0 'power spectrum of x2, x1 on a' -- analyze "$tmp/h.csv" --axes 2,1
$mcplay analyze "$tmp/h.csv" --axes 2,1 --format json >"$tmp/axes.json" 2>/dev/null
if node -e 'const r = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
process.exit(r.spectrum.axes.join() === "1,0" ? 0 : 1)' "$tmp/axes.json"; then
    passed=$((passed + 1))
else
    echo "FAIL analyze-axes-json: spectrum.axes is not [1, 0] for --axes 2,1"; failed=$((failed + 1))
fi
if [ "$(head -c 4 "$tmp/h.png" | tail -c 3)" != "PNG" ]; then
    echo "FAIL analyze-png: $tmp/h.png is not a PNG"; failed=$((failed + 1))
fi
printf '0.1,0.2\n0.3\n' >"$tmp/short.csv"
check analyze-columns 2 'row 2: expected 2 columns, got 1' -- analyze "$tmp/short.csv"
printf 'x,y\n0.1,0.2\n0.3,1.5\n' >"$tmp/outside.csv"
check analyze-range 2 "row 3, column 2: '1.5' is outside \[0, 1\)" -- analyze "$tmp/outside.csv"
printf '0.1,0.2\n0.3,abc\n' >"$tmp/text.csv"
check analyze-text 2 "row 2, column 2: 'abc' is not a number" -- analyze "$tmp/text.csv"
check analyze-missing 2 "cannot open '$tmp/none.csv'" -- analyze "$tmp/none.csv"
# A right warp is rejected at level 0.01 by 1% of seeds: seed 2 fixed (seed 1 is one of them
# with the 12 x 12 bins of 1e5 samples).
check warp-pass 0 'verdict: passed' -- warp-test warp_disk_polar --samples 100000 --seed 2
check warp-json-outcome 0 '"outcome": "failed"' -- warp-test warp_disk_polar_wrong --samples 100000 --format json
check warp-fail 0 'verdict: rejected' -- warp-test warp_disk_polar_wrong --samples 100000
# A failed test says where the mass is wrong and lists the bins farthest from the density; a
# passed one lists no bins.
check warp-fail-where 0 'too many samples near the centre .*in every direction' -- warp-test warp_disk_polar_wrong --samples 100000
check warp-fail-bins 0 '^bins farthest from the density' -- warp-test warp_disk_polar_wrong --samples 100000
$mcplay warp-test warp_disk_polar --samples 100000 --seed 2 >"$tmp/out" 2>&1
if grep -q 'bins farthest' "$tmp/out"; then
    echo "FAIL warp-pass-no-bins: a passed test lists bins"; failed=$((failed + 1))
else
    passed=$((passed + 1))
fi
# p = 2/pi with the right map: off by a constant (seed 2, as for warp_disk_polar above).
check warp-constant 0 'the pdf is off by a constant factor 2 \(it integrates to 2 ' -- warp-test warp_pdf_off_by_constant --samples 100000 --seed 2
check warp-json 0 '"passed": false' -- warp-test warp_disk_polar_wrong --samples 100000 --format json
check warp-no-warp 3 'no "warp" to test' -- warp-test exp_1d
printf '{"warp": {"domain": {"type": "disk"}, "g": ["2*sqrt(u1)*cos(2*pi*u2)", "2*sqrt(u1)*sin(2*pi*u2)"], "p": "1/pi"}}' >"$tmp/outside_warp.json"
check warp-outside 3 'sample [0-9]+ \(u = .*outside' -- warp-test "$tmp/outside_warp.json" --samples 1000
check warp-bad-samples 2 'options.samples: expected 1 to' -- warp-test warp_disk_polar --samples 0

echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
