#!/usr/bin/env bash
# `make format` covers every C++ source a contributor has, committed or not: in a clone of the
# source tree, `make -s format-files` must list an untracked new file and leave out an ignored
# one and a tracked file deleted from the work tree.
# Usage: make_format_test.sh SOURCE_DIR
set -u
src=${1:?source directory}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
git clone -q "$src" "$tmp/clone" || { echo "make_format: git clone of $src failed"; exit 1; }
cd "$tmp/clone" || exit 1
tracked=$(git ls-files '*.cpp' | head -1)
[ -n "$tracked" ] || { echo "make_format: the clone has no tracked .cpp file"; exit 1; }
mkdir -p src/core build
echo 'int untracked_probe();' > src/core/zz_untracked_probe.cpp
echo 'int ignored_probe();' > build/zz_ignored_probe.cpp
rm "$tracked"
listed=$(make -s format-files) || { echo "make_format: make format-files failed"; exit 1; }
fail=0
grep -qx 'src/core/zz_untracked_probe.cpp' <<<"$listed" ||
    { echo "make_format: the untracked src/core/zz_untracked_probe.cpp is not listed"; fail=1; }
grep -q 'zz_ignored_probe' <<<"$listed" &&
    { echo "make_format: the ignored build/zz_ignored_probe.cpp is listed"; fail=1; }
grep -qx "$tracked" <<<"$listed" &&
    { echo "make_format: the deleted $tracked is listed"; fail=1; }
grep -qx 'tests/support.cpp' <<<"$listed" ||
    { echo "make_format: the tracked tests/support.cpp is not listed"; fail=1; }
[ "$fail" = 0 ] && echo "make_format: untracked sources listed, ignored and deleted ones not"
exit "$fail"
