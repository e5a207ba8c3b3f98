#!/usr/bin/env bash
# Every C++ source `make format` reaches (committed or untracked, tests/make_format_test.sh) is
# as clang-format leaves it under the project's .clang-format: the files that are not are named,
# with the command that fixes them.
# Usage: formatted_test.sh SOURCE_DIR
set -u
src=${1:?source directory}
cd "$src" || exit 1
command -v clang-format >/dev/null || { echo "formatted: clang-format is not installed (make deps)"; exit 1; }
files=$(make -s format-files) || { echo "formatted: make format-files failed"; exit 1; }
[ -n "$files" ] || { echo "formatted: make format-files listed no source"; exit 1; }
# One clang-format for all (it names each file with a violation: "FILE:LINE:COL: error: ...").
mapfile -t list <<<"$files"
bad=$(clang-format --dry-run -Werror "${list[@]}" 2>&1 | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: .*/\1/p' | sort -u | tr '\n' ' ')
if [ -n "$bad" ]; then
    echo "formatted: not clang-formatted (run make format): $bad"
    exit 1
fi
echo "formatted: $(wc -l <<<"$files") sources as clang-format leaves them"
