#!/bin/sh
# Do two builds' --mode auto choose the same?  Renders every shipped scene
# (scenes/*.scene and scenes/*/*.scene) with --mode auto at tolerances
# 1e-2, 1e-3 and 1e-4 with lensrender from OLD_BIN and from NEW_BIN, and
# compares auto's line saying what it chose and why -- all of it but the
# probe's share of the render's cost, which a cheaper probe changes -- and
# the float renders (--pfm) byte for byte.  For a change to the probe's
# cost that must not change what auto chooses.  The renders at 1e-4 take
# long (minutes a scene at 128 x 96): TOLERANCES="1e-2 1e-3" skips them.
#   sh scripts/same_auto_choices.sh OLD_BIN NEW_BIN [WIDTH HEIGHT]
# OLD_BIN and NEW_BIN are directories holding lensrender.  Exit status 0
# when every choice and render is the same, 1 when one differs, 2 on bad
# arguments or a failed render.
set -eu
if [ $# -ne 2 ] && [ $# -ne 4 ]; then
    echo "usage: sh scripts/same_auto_choices.sh OLD_BIN NEW_BIN [WIDTH HEIGHT]" >&2
    exit 2
fi
old=$1
new=$2
W=${3:-128}
H=${4:-96}
for b in "$old" "$new"; do
    [ -x "$b/lensrender" ] || { echo "same_auto_choices: no lensrender in $b" >&2; exit 2; }
done
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# auto's line, the probe's share of the cost masked
choice() {
    grep '^lensrender: auto:' "$1" | sed -E 's/, [0-9.e+-]+ % of the render.s cost/, _ % of the render'"'"'s cost/'
}

same=0
differ=0
for s in scenes/*.scene scenes/*/*.scene; do
    for E in ${TOLERANCES:-1e-2 1e-3 1e-4}; do
        for side in old new; do
            eval "bin=\$$side"
            "$bin/lensrender" "$s" --mode auto --tolerance "$E" --width "$W" --height "$H" \
                -o "$tmp/$side.png" --pfm "$tmp/$side.pfm" 2>"$tmp/$side.log" >/dev/null || {
                echo "same_auto_choices: $s at E = $E failed with $bin" >&2
                cat "$tmp/$side.log" >&2
                exit 2
            }
        done
        if [ "$(choice "$tmp/old.log")" = "$(choice "$tmp/new.log")" ] &&
            cmp -s "$tmp/old.pfm" "$tmp/new.pfm"; then
            same=$((same + 1))
            echo "$s E = $E: same"
        else
            differ=$((differ + 1))
            echo "$s E = $E: DIFFERS"
            choice "$tmp/old.log"
            choice "$tmp/new.log"
            cmp "$tmp/old.pfm" "$tmp/new.pfm" || true
        fi
    done
done
echo "same_auto_choices: $same the same, $differ differ"
[ "$differ" -eq 0 ]
