#!/usr/bin/env bash
# ctest runs mcplay_tests once per module, filtered to the suites CMake read from that module's
# file. This fails if the executable holds a test that no module's filter selects (a TEST macro
# CMake's pattern did not see would otherwise never run).
# Usage: unlisted_tests.sh MCPLAY_TESTS_EXECUTABLE NEGATIVE_FILTER (a .js file is run with node)
set -u
exe=${1:?mcplay_tests executable}
filter=${2:?filter}
case "$exe" in
    *.js) run=(node --no-experimental-fetch "$exe") ;;
    *) run=("$exe") ;;
esac
# --gtest_list_tests prints "Suite." lines and an indented line per test (gtest_main adds a
# "Running main()" line first).
listed=$("${run[@]}" --gtest_list_tests | grep -E '^(  [A-Za-z0-9_/]|[A-Za-z0-9_/]+\.)') ||
    { echo "unlisted: listing the tests failed"; exit 1; }
[ -n "$listed" ] || { echo "unlisted: the executable lists no test"; exit 1; }
left=$("${run[@]}" --gtest_list_tests "--gtest_filter=-$filter" | grep -E '^(  [A-Za-z0-9_/]|[A-Za-z0-9_/]+\.)')
if [ -n "$left" ]; then
    echo "unlisted: tests that no module's filter selects:"
    echo "$left"
    exit 1
fi
echo "unlisted: every test belongs to a module"
