#!/bin/sh
# Set up a Debian 12 machine for lensprim and build it.
#   scripts/setup.sh [BUILD_DIR [extra cmake args...]]
# Installs whatever of the build dependencies is missing (apt-get, needs
# root or sudo), then configures and builds in BUILD_DIR (default: build).
set -eu
cd "$(dirname "$0")/.."

# Open MPI (libopenmpi-dev, openmpi-bin) builds lensrender-mpi and runs the
# sweeps across processes (LENSPRIM_MPI, README "Beyond one machine").
PACKAGES="gcc make cmake libc6-dev pkg-config libpng-dev zlib1g-dev povray povray-includes
          libopenmpi-dev openmpi-bin"

missing=""
for p in $PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
        missing="$missing $p"
done
if [ -n "$missing" ]; then
    echo "setup: installing$missing" >&2
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >&2
fi

build=${1:-build}
[ $# -gt 0 ] && shift
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DLENSPRIM_WERROR=ON "$@" >/dev/null
cmake --build "$build" -j"$(nproc)" >&2
