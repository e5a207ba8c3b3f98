#!/usr/bin/env bash
# Replays the bad-input corpus (tests/corpus/cases.tsv, written by make_corpus.mjs) through the
# mcplay CLI: every case must exit with its code (2 bad arguments, 3 bad scene) and print exactly
# one line on standard error, "mcplay: ...", containing the expected words; never a signal, an
# abort, a wasm trap or a hang (each case gets 60 s, far above the few seconds any takes).
# Usage: replay.sh SOURCE_DIR MCPLAY_EXECUTABLE (a .js file is run with node)
set -u
src=${1:?source dir}
exe=${2:?mcplay executable}
case "$exe" in
    *.js) mcplay=(node --no-experimental-fetch "$exe") ;;
    *) mcplay=("$exe") ;;
esac
case "$exe" in /*) ;; *) exe="$PWD/$exe"; mcplay[${#mcplay[@]}-1]="$exe" ;; esac
cd "$src/tests/corpus" || exit 1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Inputs that cannot live in git: a FIFO, a file over the scene size limit (sparse), and a
# symbolic link from a scene's folder to a file outside it.
mkfifo "$tmp/fifo.json"
truncate -s 70M "$tmp/sparse.json"
mkdir -p "$tmp/scene" "$tmp/cache"
cp outside.bin "$tmp/outside.bin"
ln -s ../outside.bin "$tmp/scene/link.bin"
cp runtime/*.json "$tmp/scene/"
export MCPLAY_CACHE="$tmp/cache" HOME="$tmp"

passed=0 failed=0 slowest=0 slowest_case=""
while IFS=$'\t' read -r want args expect name; do
    [ -z "$want" ] || [ "${want:0:1}" = "#" ] && continue
    name=${name#\# }
    args=${args//\{T\}/$tmp}
    read -r -a argv <<<"$args"
    start=$(date +%s%N)
    timeout 60 "${mcplay[@]}" "${argv[@]}" >"$tmp/out" 2>"$tmp/err" </dev/null
    got=$?
    ms=$((($(date +%s%N) - start) / 1000000))
    if [ "$ms" -gt "$slowest" ]; then slowest=$ms slowest_case=$name; fi
    lines=$(grep -c '' "$tmp/err")
    problem=""
    if [ "$got" = 124 ]; then
        problem="no answer within 60 s (a hang)"
    elif [ "$got" -gt 128 ]; then
        problem="killed by signal $((got - 128))"
    elif [ "$got" != "$want" ]; then
        problem="exit $got, expected $want"
    elif grep -qE 'Aborted|RuntimeError|Segmentation|AddressSanitizer|runtime error|terminate called' "$tmp/err" "$tmp/out"; then
        problem="an abort, trap or sanitizer report"
    elif [ "$lines" != 1 ]; then
        problem="$lines lines on standard error, expected one"
    elif ! head -c 8 "$tmp/err" | grep -q '^mcplay: '; then
        problem="the message does not start with 'mcplay: '"
    elif ! grep -qF -- "$expect" "$tmp/err"; then
        problem="the message lacks '$expect'"
    fi
    if [ -n "$problem" ]; then
        echo "FAIL $name: $problem"
        echo "     mcplay $args"
        head -c 600 "$tmp/err" | sed 's/^/     | /'
        failed=$((failed + 1))
    else
        passed=$((passed + 1))
    fi
done <cases.tsv
echo "corpus: slowest case $slowest_case, $slowest ms"
echo "corpus: $passed passed, $failed failed"
[ "$failed" = 0 ]
