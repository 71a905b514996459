#!/bin/sh
# The paper's experiments (section 5), one command: builds the programs if
# needed, renders one lens scene in the four light models, then runs
# paper_experiments, which writes docs/paper-experiments.md and its
# figures and tables in docs/paper-experiments/.
#
#   sh scripts/paper_experiments.sh [SCENE]     (default scenes/dispersion.scene)
#
# Environment: BUILD (build directory, default build), WIDTH, HEIGHT
# (render size, default 320 x 240), THREADS (default 2), WAVELENGTHS
# (spectral samples per pixel, default 64: N-SF11 disperses strongly, and
# fewer samples split a white edge into separate coloured copies).
set -eu
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
SCENE=${1:-scenes/dispersion.scene}
WIDTH=${WIDTH:-320}
HEIGHT=${HEIGHT:-240}
THREADS=${THREADS:-2}
WAVELENGTHS=${WAVELENGTHS:-64}
if [ ! -x "$BUILD/bin/paper_experiments" ] || [ ! -x "$BUILD/bin/lensrender" ]; then
    cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$BUILD" -j2 --target lensrender paper_experiments >/dev/null
fi
renders=$(mktemp -d "${TMPDIR:-/tmp}/paper_experiments.XXXXXX")
trap 'rm -rf "$renders"' EXIT
for mode in rgb fresnel polarized schlick; do
    "$BUILD/bin/lensrender" "$SCENE" --mode "$mode" --width "$WIDTH" --height "$HEIGHT" \
        --threads "$THREADS" --wavelengths "$WAVELENGTHS" --pfm "$renders/$mode.pfm" -o "$renders/$mode.png" --quiet
done
"$BUILD/bin/paper_experiments" --renders "$renders" --scene-name "$(basename "$SCENE")" \
    --wavelengths "$WAVELENGTHS" \
    --scenes scenes --out docs/paper-experiments --md docs/paper-experiments.md
