#!/bin/sh
# The whole test suite under valgrind memcheck (leaks are errors).
#   sh scripts/valgrind.sh       -> ctest's summary; logs in build-vg/Testing
set -eu
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null 2>&1 || {
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends valgrind >&2
}
sh scripts/setup.sh build-vg -DCMAKE_BUILD_TYPE=RelWithDebInfo
ctest --test-dir build-vg -j2 -T memcheck \
    --overwrite MemoryCheckCommandOptions="--leak-check=full --show-leak-kinds=definite,indirect,possible --errors-for-leak-kinds=definite,indirect,possible --error-exitcode=1 --track-origins=yes" \
    --timeout 1800
