#!/bin/sh
# (Re)generate the reference renders of the regression test
# tests/renderer/test_references.c: every scene in scenes/*.scene and
# tests/renderer/scenes/*.scene in each light model (polarized at 80 x 60;
# fresnel, schlick, rgb at 40 x 30), default settings, as float PFMs in
# tests/renderer/ref/<name>.<mode>.pfm.
#   scripts/make_references.sh [BUILD_DIR]     (default: build)
# Run it only after an intended change of the renderer's output or of a
# scene whose physics a closed-form test confirms; look at the new
# references, and commit them with the change, naming that test.
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$(nproc)" --target test_references >&2
mkdir -p tests/renderer/ref
rm -f tests/renderer/ref/*.png tests/renderer/ref/*.pfm
"$build/bin/test_references" --regenerate tests/renderer/ref
"$build/bin/test_references"
