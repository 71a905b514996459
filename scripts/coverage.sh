#!/bin/sh
# Line coverage of lensprim by the whole test suite (gcov + lcov).
#   sh scripts/coverage.sh        -> build-cov/coverage/index.html and a summary
set -eu
cd "$(dirname "$0")/.."
command -v lcov >/dev/null 2>&1 || {
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends lcov >&2
}
sh scripts/setup.sh build-cov -DCMAKE_BUILD_TYPE=Debug -DLENSPRIM_COVERAGE=ON -DLENSPRIM_WERROR=OFF
lcov --quiet --zerocounters --directory build-cov
# -O0 with gcov makes the renderer several times slower: test_pov_compare
# renders at 80 x 60 here (its checks are the same at any size).
LP_POV_COMPARE_SIZE=80x60 ctest --test-dir build-cov -j2 --output-on-failure >build-cov/ctest.log || {
    tail -n 40 build-cov/ctest.log >&2
    echo "coverage: the suite failed in the coverage build (build-cov/ctest.log)" >&2
    exit 1
}
lcov --quiet --capture --directory build-cov --output-file build-cov/all.info
lcov --quiet --extract build-cov/all.info "$(pwd)/lensprim/src/*" --output-file build-cov/lensprim.info
genhtml --quiet build-cov/lensprim.info --output-directory build-cov/coverage
lcov --summary build-cov/lensprim.info 2>&1 | sed -n 's/^ *lines\.*: /lensprim line coverage: /p'
