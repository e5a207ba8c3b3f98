#!/usr/bin/env bash
# `make format` covers every C++ source a contributor has, committed or not: in a small git
# repository holding the work tree's Makefile (and the files it includes), `make -s
# format-files` must list a committed and an untracked source and leave out an ignored one and
# a committed one deleted from the work tree.
# Usage: make_format_test.sh SOURCE_DIR
set -u
src=${1:?source directory}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
mkdir -p bench examples src build
cp "$src/Makefile" "$src/.gitignore" . && cp "$src/bench/python.mk" bench/ &&
    cp "$src/examples/notebook.mk" examples/ || { echo "make_format: copying the Makefile failed"; exit 1; }
echo 'int kept();' > src/kept.cpp
echo 'int gone();' > src/gone.h
{ git init -q . && git add . && git -c user.name=t -c user.email=t@t commit -qm files; } ||
    { echo "make_format: git init failed"; exit 1; }
rm src/gone.h
echo 'int untracked();' > src/untracked.cpp
echo 'int ignored();' > build/ignored.cpp
listed=$(make -s format-files) || { echo "make_format: make format-files failed"; exit 1; }
fail=0
for f in src/kept.cpp src/untracked.cpp; do
    grep -qx "$f" <<<"$listed" || { echo "make_format: $f is not listed"; fail=1; }
done
for f in src/gone.h build/ignored.cpp; do
    grep -qx "$f" <<<"$listed" && { echo "make_format: $f is listed"; fail=1; }
done
[ "$fail" = 0 ] && echo "make_format: committed and untracked sources listed, ignored and deleted ones not"
exit "$fail"
