#!/bin/sh
# Does --mode auto keep its promise at a size the chart does not run?
# For each SCENE: a reference rendered here -- polarized, depth 32,
# cut-off 1e-7, WAVELENGTHS wavelengths (default 1024), and again at half
# as many, whose RMSE against it is printed as U (the midpoint rule's
# error falls at least as 1/N, so the reference's own error is about U or
# less) -- then --mode auto at each tolerance E: its RMSE of linear RGB
# against the reference, and "yes" when RMSE + U <= E, "NO" when
# RMSE - U > E, "unresolved" between; and what auto chose.
#   sh scripts/auto_check.sh [--bin DIR] [--size W H] [--wavelengths N]
#                            [--tolerances "1e-2 1e-3"] [--work DIR] SCENE...
# --bin: where lensrender is (default build/bin); --size: default 320 240
# (lensrender's default); --work: keep the references there and reuse
# them (default: a temporary directory).  The references take a while:
# 1024 wavelengths at 320 x 240 are 10-60 s a scene on two cores.  Exit
# status 0 when every render meets E, 1 when one does not, 2 on bad
# arguments or a failed render.
set -eu
bin=build/bin
W=320
H=240
N=1024
tols="1e-2 1e-3"
work=
usage() {
    echo "usage: sh scripts/auto_check.sh [--bin DIR] [--size W H] [--wavelengths N]" \
        "[--tolerances \"E ...\"] [--work DIR] SCENE..." >&2
    exit 2
}
while [ $# -gt 0 ]; do
    case $1 in
    --bin) [ $# -ge 2 ] || usage; bin=$2; shift 2 ;;
    --size) [ $# -ge 3 ] || usage; W=$2; H=$3; shift 3 ;;
    --wavelengths) [ $# -ge 2 ] || usage; N=$2; shift 2 ;;
    --tolerances) [ $# -ge 2 ] || usage; tols=$2; shift 2 ;;
    --work) [ $# -ge 2 ] || usage; work=$2; shift 2 ;;
    -*) usage ;;
    *) break ;;
    esac
done
[ $# -ge 1 ] || usage
case $N in '' | *[!0-9]*) usage ;; esac
[ "$N" -ge 2 ] || usage
[ -x "$bin/lensrender" ] || { echo "auto_check: no lensrender in $bin" >&2; exit 2; }
. "$(dirname "$0")/pfm.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ -n "$work" ] || work=$tmp/refs
mkdir -p "$work"

render() { # OUT.pfm ARGS...: a render, its line kept in $tmp/log
    out=$1
    shift
    "$bin/lensrender" "$@" --width "$W" --height "$H" -o "$tmp/r.png" --pfm "$out" \
        >"$tmp/log" 2>&1 || {
        echo "auto_check: lensrender $* failed:" >&2
        cat "$tmp/log" >&2
        exit 2
    }
}

over=0
for s in "$@"; do
    [ -f "$s" ] || { echo "auto_check: no scene $s" >&2; exit 2; }
    name=$(basename "$s" .scene)
    ref=$work/$name.${W}x$H.$N.pfm
    half=$work/$name.${W}x$H.$((N / 2)).pfm
    for f in "$half:$((N / 2))" "$ref:$N"; do
        [ -f "${f%%:*}" ] || render "${f%%:*}" "$s" --mode polarized --depth 32 --cutoff 1e-7 \
            --wavelengths "${f##*:}"
    done
    U=$(pfm_rmse "$half" "$ref" "$tmp")
    for E in $tols; do
        render "$tmp/auto.pfm" "$s" --mode auto --tolerance "$E"
        choice=$(sed -n 's/^lensrender: auto: \([^:]*\) for E = .*/\1/p' "$tmp/log")
        e=$(pfm_rmse "$tmp/auto.pfm" "$ref" "$tmp")
        verdict=$(awk -v e="$e" -v u="$U" -v E="$E" \
            'BEGIN { v = "unresolved"; if (e + u <= E) v = "yes"; else if (e - u > E) v = "NO"; print v }')
        [ "$verdict" = NO ] && over=$((over + 1))
        echo "$name ${W}x$H E = $E: rmse $e, U $U, meets E: $verdict ($choice)"
    done
done
[ "$over" -eq 0 ]
