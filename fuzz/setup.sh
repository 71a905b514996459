#!/bin/sh
# Set up the fuzz build (not part of the default setup, scripts/setup.sh).
#   fuzz/setup.sh [BUILD_DIR]          (default: build-fuzz)
# Installs clang 14 and its libFuzzer/sanitizer runtimes if missing
# (Debian 12: clang-14, libclang-rt-14-dev; apt-get, needs root or sudo),
# then configures with -DLENSPRIM_FUZZ=ON and builds the three targets.
set -eu
cd "$(dirname "$0")/.."

PACKAGES="clang-14 libclang-rt-14-dev"
missing=""
for p in $PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
        missing="$missing $p"
done
if [ -n "$missing" ]; then
    echo "fuzz/setup: installing$missing" >&2
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >&2
fi

cc=clang
command -v clang >/dev/null 2>&1 || cc=clang-14
build=${1:-build-fuzz}
cmake -S . -B "$build" -DCMAKE_C_COMPILER="$cc" -DLENSPRIM_FUZZ=ON >/dev/null
cmake --build "$build" -j"$(nproc)" --target fuzz_scene fuzz_lenstrace_args fuzz_agf >&2
echo "fuzz/setup: built $build/bin/fuzz_scene, fuzz_lenstrace_args, fuzz_agf" >&2
