#!/bin/sh
# Render time of every scene at 640x480 in each light model on all cores,
# and the thread-scaling ratio (1 thread / 2 threads) of the default scene
# in the polarized model, measured in one run.  A benchmark, not a test.
#   bench/render_times.sh [WIDTH HEIGHT]
set -eu
cd "$(dirname "$0")/.."
[ -x build/bin/lensrender ] || sh scripts/setup.sh build
W=${1:-640}
H=${2:-480}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }
sub() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }
printf '%-22s %10s %10s %10s %10s\n' scene polarized fresnel schlick rgb
for s in scenes/*.scene; do
    n=$(basename "$s" .scene)
    printf '%-22s' "$n"
    for m in polarized fresnel schlick rgb; do
        t0=$(now)
        build/bin/lensrender "$s" -o "$tmp/x.png" --width "$W" --height "$H" --mode "$m" --quiet
        t1=$(now)
        printf ' %9ss' "$(sub "$t0" "$t1")"
    done
    printf '\n'
done
t0=$(now); build/bin/lensrender scenes/default.scene -o "$tmp/x.png" --width "$W" --height "$H" --threads 1 --quiet; t1=$(now)
build/bin/lensrender scenes/default.scene -o "$tmp/x.png" --width "$W" --height "$H" --threads 2 --quiet; t2=$(now)
awk -v a="$t0" -v b="$t1" -v c="$t2" 'BEGIN { printf "thread scaling (default.scene, polarized): 1 thread %.2f s, 2 threads %.2f s, ratio %.2f\n", b - a, c - b, (b - a) / (c - b) }'
