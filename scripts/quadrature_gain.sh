#!/bin/sh
# What a spectral quadrature gains: the RMSE of linear RGB against a
# converged render, as a function of the wavelength count N, for two
# builds (e.g. one before a change of the quadrature and one after).
# Fresnel at WIDTH x HEIGHT (default 64 x 48), N = 4 8 16 32 64 128 256,
# with --no-dispersion (every path the same at every wavelength: the
# error is the quadrature's alone) on the shipped scenes with coloured
# surfaces, machined_parts, desk_lamp, mirror_ball and plan_view (the
# others are grey under white light, exact at any N); with DISPERSION=1
# also with dispersion on default, biconcave and desk_lamp.  The
# converged render is NEW_BIN's at REF wavelengths (default 4096: without
# dispersion it is then within ~1e-7 of the limit; with it, a dispersed
# path's steps leave it ~1e-4 off, enough to rank the counts up to 256).
#   sh scripts/quadrature_gain.sh OLD_BIN NEW_BIN [WIDTH HEIGHT]
# OLD_BIN and NEW_BIN are directories holding lensrender.  Prints one line
# per scene, setting and N: the two RMSEs and their ratio.
set -eu
if [ $# -ne 2 ] && [ $# -ne 4 ]; then
    echo "usage: sh scripts/quadrature_gain.sh OLD_BIN NEW_BIN [WIDTH HEIGHT]" >&2
    exit 2
fi
old=$1
new=$2
W=${3:-64}
H=${4:-48}
REF=${REF:-4096}
for b in "$old" "$new"; do
    [ -x "$b/lensrender" ] || { echo "quadrature_gain: no lensrender in $b" >&2; exit 2; }
done
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. scripts/pfm.sh

# render BIN SCENE N OUT [--no-dispersion]
render() {
    # shellcheck disable=SC2086 # $5 is empty or one word
    "$1/lensrender" "scenes/$2.scene" --width "$W" --height "$H" --mode fresnel \
        --wavelengths "$3" ${5:-} --quiet -o "$tmp/x.png" --pfm "$4"
}

# one SCENE FLAG: the table's lines of a scene in one setting.
one() {
    render "$new" "$1" "$REF" "$tmp/ref.pfm" "$2"
    for n in 4 8 16 32 64 128 256; do
        render "$old" "$1" "$n" "$tmp/old.pfm" "$2"
        render "$new" "$1" "$n" "$tmp/new.pfm" "$2"
        a=$(pfm_rmse "$tmp/old.pfm" "$tmp/ref.pfm" "$tmp")
        b=$(pfm_rmse "$tmp/new.pfm" "$tmp/ref.pfm" "$tmp")
        printf '%-15s %-15s %6d %10s %10s %8s\n' "$1" "${2:-dispersion}" "$n" "$a" "$b" \
            "$(awk -v a="$a" -v b="$b" 'BEGIN { if (b > 0) printf "%.1f", a / b; else print "-" }')"
    done
}

printf '%-15s %-15s %6s %10s %10s %8s\n' scene setting N old new old/new
for s in machined_parts desk_lamp mirror_ball plan_view; do
    one "$s" --no-dispersion
done
if [ "${DISPERSION:-0}" = 1 ]; then
    for s in default biconcave desk_lamp; do
        one "$s" ""
    done
fi
