#!/bin/sh
# Render every scene in scenes/ at 320x240 in the polarized model into
# docs/images/<scene>.png (the pictures the README shows), plus the
# crossed-polarizer scene in the fresnel model for comparison.
set -eu
cd "$(dirname "$0")/.."
[ -x build/bin/lensrender ] || sh scripts/setup.sh build
mkdir -p docs/images
for s in scenes/*.scene; do
    n=$(basename "$s" .scene)
    build/bin/lensrender "$s" -o "docs/images/$n.png" --width 320 --height 240 --quiet
done
build/bin/lensrender scenes/crossed_polarizers.scene -o docs/images/crossed_polarizers_fresnel.png \
    --width 320 --height 240 --mode fresnel --quiet
# high interference orders need finer wavelength sampling than the default 16
build/bin/lensrender scenes/michel_levy.scene -o docs/images/michel_levy.png \
    --width 320 --height 240 --wavelengths 64 --quiet
# the polarizing microscope (its own directory: scenes/microscope/)
for n in microscope microscope_empty; do
    build/bin/lensrender "scenes/microscope/$n.scene" -o "docs/images/$n.png" \
        --width 320 --height 240 --quiet
done
echo "render_examples: wrote docs/images/*.png"
