#!/bin/sh
# Are two builds' renders the same?  Renders every shipped scene
# (scenes/*.scene and scenes/*/*.scene) in every light model, with and
# without --no-dispersion, with lensrender from OLD_BIN and from NEW_BIN,
# and compares the float renders (--pfm): a file equal byte for byte is
# "identical"; otherwise the largest absolute difference of a sample is
# printed.  For a speed change that must not change results.
#   sh scripts/same_renders.sh OLD_BIN NEW_BIN [WIDTH HEIGHT [WAVELENGTHS]]
# WAVELENGTHS (default: lensrender's) for the spectral models: e.g. 1024
# to take the paths a packet of many wavelengths takes at a lens.
# OLD_BIN and NEW_BIN are directories holding lensrender (e.g. a build of
# the commit before, and build/bin).  Exit status 0 when every render is
# identical, 1 when one differs, 2 on bad arguments or a failed render.
set -eu
if [ $# -ne 2 ] && [ $# -ne 4 ] && [ $# -ne 5 ]; then
    echo "usage: sh scripts/same_renders.sh OLD_BIN NEW_BIN [WIDTH HEIGHT [WAVELENGTHS]]" >&2
    exit 2
fi
old=$1
new=$2
W=${3:-64}
H=${4:-48}
N=${5:-}
case $N in
*[!0-9]*) echo "same_renders: WAVELENGTHS must be a count" >&2; exit 2 ;;
esac
for b in "$old" "$new"; do
    [ -x "$b/lensrender" ] || { echo "same_renders: no lensrender in $b" >&2; exit 2; }
done
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

. scripts/pfm.sh

# The largest |a - b| over the float samples of two PFM files of one size.
largest_difference() {
    pfm_samples "$1" "$tmp/a1.txt"
    pfm_samples "$2" "$tmp/b1.txt"
    paste "$tmp/a1.txt" "$tmp/b1.txt" | awk '
        $1 == $2 { next }
        $1 ~ /n/ || $2 ~ /n/ { odd = 1; next } # nan or inf on one side
        { d = $1 - $2; if (d < 0) d = -d; if (d > m) m = d }
        END { printf "%.3g%s", m, odd ? " (and non-finite samples that differ)" : "" }'
}

same=0
differ=0
for s in scenes/*.scene scenes/*/*.scene; do
    [ -f "$s" ] || continue
    n=$(basename "$s" .scene)
    for m in polarized fresnel schlick rgb; do
        for d in "" --no-dispersion; do
            wl=
            [ -z "$N" ] || [ "$m" = rgb ] || wl="--wavelengths $N"
            for side in old new; do
                eval "bin=\$$side"
                # shellcheck disable=SC2086 # $d is empty or one word, $wl two
                if ! "$bin/lensrender" "$s" --width "$W" --height "$H" --mode "$m" $d $wl \
                        --quiet -o "$tmp/$side.png" --pfm "$tmp/$side.pfm" 2>"$tmp/err"; then
                    echo "same_renders: $bin/lensrender $s --mode $m $d $wl failed:" >&2
                    cat "$tmp/err" >&2
                    exit 2
                fi
            done
            if cmp -s "$tmp/old.pfm" "$tmp/new.pfm"; then
                same=$((same + 1))
            else
                differ=$((differ + 1))
                printf '%s %s %s: largest difference %s\n' "$n" "$m" "${d:-dispersion}" \
                    "$(largest_difference "$tmp/old.pfm" "$tmp/new.pfm")"
            fi
        done
    done
done
printf '%d renders identical, %d differ (%dx%d%s)\n' "$same" "$differ" "$W" "$H" \
    "${N:+, $N wavelengths}"
[ "$differ" -eq 0 ]
