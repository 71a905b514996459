#!/bin/sh
# Speed against accuracy: sweep every scene in scenes/ over light model x
# wavelength count x depth x cut-off, plus --mode auto and POV-Ray, each
# timed on one thread against a converged reference, and write
# docs/speed-accuracy.csv, docs/speed-accuracy.png and
# docs/speed-accuracy.md.  Builds first (Release).  A benchmark, not a
# test: it takes a long time (the references dominate) and its times
# depend on the machine.
#   sh scripts/speed_accuracy.sh [speed_accuracy options...]
# e.g. --scene default --runs 5 --width 64 --height 48; see
# build/bin/speed_accuracy --help.  MPIRUN="mpirun -n 8" (any launcher
# command) runs the renders across the processes of an MPI run: the same
# table but for the times.
set -eu
cd "$(dirname "$0")/.."
sh scripts/setup.sh build
mkdir -p docs build/speed-accuracy
# shellcheck disable=SC2086
${MPIRUN:-} build/bin/speed_accuracy --bin build/bin --scenes scenes --docs docs \
    --work build/speed-accuracy "$@"
echo "speed_accuracy: wrote docs/speed-accuracy.csv, docs/speed-accuracy.png, docs/speed-accuracy.md"
