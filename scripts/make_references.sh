#!/bin/sh
# (Re)generate the reference renders of the regression test
# tests/renderer/test_references.c: every scene in scenes/*.scene at
# 80 x 60, polarized mode, default settings, as 16-bit linear PNGs in
# tests/renderer/ref/<name>.png.
#   scripts/make_references.sh [BUILD_DIR]     (default: build)
# Run it after an intended change of the renderer's output or of a scene,
# look at the new references, and commit them with the change.
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$(nproc)" --target test_references >&2
mkdir -p tests/renderer/ref
rm -f tests/renderer/ref/*.png
"$build/bin/test_references" --regenerate tests/renderer/ref
"$build/bin/test_references"
