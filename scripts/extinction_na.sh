#!/bin/sh
# The empty polarizing microscope's extinction against its numerical
# aperture, one command: builds extinction_na if needed and runs it on
# scenes/microscope/microscope_empty.scene, writing docs/extinction-na.csv
# and docs/extinction-na.png (the leak between crossed polarizers, traced
# through the library against the closed form of the surfaces' s and p
# transmissions; README, "The polarizing microscope").
#
#   sh scripts/extinction_na.sh [extinction_na options...]
#
# Environment: BUILD (build directory, default build); MPIRUN="mpirun -n 4"
# (any launcher command) shares the NA points among the processes of an
# MPI run (the same outputs).
set -eu
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
if [ ! -x "$BUILD/bin/extinction_na" ]; then
    cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$BUILD" -j2 --target extinction_na >/dev/null
fi
# shellcheck disable=SC2086
${MPIRUN:-} "$BUILD/bin/extinction_na" --scene scenes/microscope/microscope_empty.scene \
    --csv docs/extinction-na.csv --png docs/extinction-na.png "$@"
