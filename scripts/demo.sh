#!/bin/sh
# Set everything up, then render the default scene (a biconvex N-BK7 lens
# over a checkerboard) in the polarized light model and say where the
# picture is.
set -eu
cd "$(dirname "$0")/.."
sh scripts/setup.sh build
mkdir -p out
build/bin/lensrender scenes/default.scene -o out/default.png --width 640 --height 480
echo "demo: the picture is $(pwd)/out/default.png"
