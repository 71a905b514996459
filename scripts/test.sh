#!/bin/sh
# Set everything up and run the whole test suite: first under
# AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/), then the
# release build (build/), whose ctest summary line ends the output.
set -eu
cd "$(dirname "$0")/.."
sh scripts/setup.sh build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLENSPRIM_SANITIZE=ON
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j2 >build-asan/ctest.log 2>&1 || {
    cat build-asan/ctest.log
    echo "test: the sanitizer build of the suite failed" >&2
    exit 1
}
grep "tests passed" build-asan/ctest.log | sed "s/^/sanitizers: /"
sh scripts/setup.sh build
ctest --test-dir build --output-on-failure -j2
