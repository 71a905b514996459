#!/bin/sh
# many_objects.sh -- render time against the number of objects.
#
# A benchmark, not a test.  Writes scenes of N diffuse spheres (N = 100,
# 1000, 10000 by default) scattered in a fixed 100 mm cube, their radius
# shrinking as N^(-1/3) so that they cover about as much of the image at
# every N, behind a 10 x 10 grid of 100 lenses, lit by one light (so every
# shaded point also casts a shadow ray), and renders each with lensrender
# on one thread.  Prints the CPU seconds (user + sys, median of RUNS
# interleaved rounds) and the time per camera ray; with a bounding volume
# hierarchy the time per ray grows like log N, not like N.
#
# usage: bench/many_objects.sh [--runs N] [--size WxH] [--mode M]
#                              [--counts "100 1000 10000"] [--bin DIR]
set -eu
cd "$(dirname "$0")/.."

RUNS=3
SIZE=160x120
MODE=fresnel
COUNTS="100 1000 10000"
BIN=build/bin
while [ $# -gt 0 ]; do
    case "$1" in
    --runs) RUNS=$2; shift 2 ;;
    --size) SIZE=$2; shift 2 ;;
    --mode) MODE=$2; shift 2 ;;
    --counts) COUNTS=$2; shift 2 ;;
    --bin) BIN=$2; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "many_objects.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
W=${SIZE%x*}
H=${SIZE#*x}
[ -x "$BIN/lensrender" ] || { echo "many_objects.sh: $BIN/lensrender not found (build first)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM

# The scene with $1 spheres (deterministic positions: a linear
# congruential generator, so every run and machine renders the same).
write_scene() {
    awk -v n="$1" 'BEGIN {
        print "global_settings { max_trace_level 5 adc_bailout 0.002 }"
        print "camera { location <0, 0, -260> look_at <0, 0, 0> right x*image_width/image_height angle 40 }"
        print "background { rgb <0.2, 0.3, 0.5> }"
        print "light_source { <150, 200, -300> color rgb 1 }"
        seed = 12345
        r = 0.35 * 100 / exp(log(n) / 3)
        for (i = 0; i < n; i++) {
            for (k = 0; k < 3; k++) {
                seed = (seed * 1103515245 + 12345) % 2147483648
                c[k] = -50 + 100 * seed / 2147483648
            }
            printf "sphere { <%.4f, %.4f, %.4f>, %.4f pigment { color rgb <%.2f, %.2f, %.2f> } finish { ambient 0.1 diffuse 0.8 } }\n",
                c[0], c[1], c[2], r, 0.3 + 0.7 * (i % 3 == 0), 0.3 + 0.7 * (i % 3 == 1), 0.3 + 0.7 * (i % 3 == 2)
        }
        for (i = 0; i < 10; i++)
            for (j = 0; j < 10; j++)
                printf "lens { radius1 40 radius2 -40 thickness 4 diameter 9 glass \"N-BK7\" translate <%d, %d, -70> }\n",
                    -45 + 10 * i, -45 + 10 * j
    }' >"$tmp/many_$1.scene"
}

for n in $COUNTS; do
    write_scene "$n"
    : >"$tmp/t_$n"
done
r=1
while [ "$r" -le "$RUNS" ]; do
    for n in $COUNTS; do
        /usr/bin/time -f '%U %S' -o "$tmp/t" "$BIN/lensrender" "$tmp/many_$n.scene" \
            -o "$tmp/many.png" --width "$W" --height "$H" --mode "$MODE" --threads 1 --quiet
        awk '{ printf "%.3f\n", $1 + $2 }' "$tmp/t" >>"$tmp/t_$n"
    done
    r=$((r + 1))
done
echo "$MODE, ${W}x${H}, 1 thread, 100 lenses + N spheres, median of $RUNS rounds"
printf '%8s %10s %14s\n' N seconds "us/camera ray"
for n in $COUNTS; do
    s=$(sort -g "$tmp/t_$n" | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
    printf '%8s %10s %14s\n' "$n" "$s" "$(awk -v s="$s" -v p="$((W * H))" 'BEGIN { printf "%.2f", 1e6 * s / p }')"
done
