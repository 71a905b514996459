#!/bin/sh
# Fit the automatic mode's cost model, rs_work_cost (renderer/src/
# integrator.c), to callgrind's instruction counts.  A benchmark, not a
# test; one command reproduces the constants in the tree:
#     bench/work_cost_fit.sh [-j JOBS] [-v] [BIN_DIR]
# BIN_DIR (default build/bin) holds bench_render_work and work_cost_fit
# (cmake --build build --target bench_render_work work_cost_fit).
#
# The fit set: every scene in scenes/ but conoscope (the slowest), in every
# mode -- polarized, fresnel and schlick at 4, 16 and 64 wavelengths, and
# rgb -- at depth 4 and 16 and cut-off 1e-3 and 1e-6, on one thread, at
# 24 x 18 pixels (michel_levy, newtons_rings and polariscope, 10-40 times
# slower per pixel, at 12 x 9): 40 renders a scene.  Each render counts its
# work (bench_render_work: rays, lane_rays, builds, gathered, pixels) and
# callgrind counts the instructions executed inside rs_integrator_pixel
# during it (--toggle-collect, one dump per render); what is priced is the
# pixels, not the loading and set-up, which auto's choice does not change.
# work_cost_fit fits per mode, by non-negative least squares of the
# relative error, instructions ~ a rays + b lane_rays + c builds +
# d gathered + e pixels, and prints the constants, the range of
# predicted / count and the RMS of the relative error of the fit and of the
# model in the tree, and the fitted function body to paste.  -v also
# prints each render's line.  Jobs (a scene and a mode each) run JOBS at a
# time (default 2); about 7 minutes of CPU.
set -eu
if [ "${1:-}" = --job ]; then
    # one job: --job SCENE W H MODE OUT_PREFIX BIN_DIR
    scene=$2 w=$3 h=$4 mode=$5 out=$6 bin=$7
    set --
    for wl in 4 16 64; do
        [ "$mode" = rgb ] && [ "$wl" != 16 ] && continue
        for d in 4 16; do
            for c in 1e-3 1e-6; do
                set -- "$@" "$mode:$wl:$d:$c"
            done
        done
    done
    valgrind -q --tool=callgrind --callgrind-out-file="$out.cg" \
        --toggle-collect=rs_integrator_pixel --dump-after=lr_render_region_work \
        "$bin/bench_render_work" "$scene" "$w" "$h" "$@" >"$out.work"
    k=0
    while read -r name md wl d c px rays lanes builds gathered cost; do
        k=$((k + 1))
        ins=$(sed -n 's/^summary: *//p' "$out.cg.$k")
        printf '%s %s %s %s %s %s %s %s %s %s %s %s\n' "$name" "$md" "$wl" "$d" "$c" \
            "${ins:-0}" "$px" "$rays" "$lanes" "$builds" "$gathered" "$cost"
    done <"$out.work" >"$out.rows"
    [ "$k" -eq "$#" ] || { echo "work_cost_fit.sh: $scene $mode: $k of $# renders" >&2; exit 1; }
    exit 0
fi

self=$(cd "$(dirname "$0")" && pwd)/$(basename "$0")
root=$(dirname "$(dirname "$self")")
jobs=2
verbose=0
bin=$root/build/bin
while [ $# -gt 0 ]; do
    case $1 in
    -j) jobs=$2; shift 2 ;;
    -j*) jobs=${1#-j}; shift ;;
    -v) verbose=1; shift ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    *) bin=$(cd "$1" && pwd); shift ;;
    esac
done
cd "$root"
command -v valgrind >/dev/null || { echo "work_cost_fit.sh: valgrind not found" >&2; exit 2; }
for p in bench_render_work work_cost_fit; do
    [ -x "$bin/$p" ] || { echo "work_cost_fit.sh: no $bin/$p (cmake --build build --target bench_render_work work_cost_fit)" >&2; exit 2; }
done
skip=" conoscope "
small=" michel_levy newtons_rings polariscope "
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The slow scenes' jobs first, polarized first, so that the last jobs are short.
for pass in small rest; do
    for m in polarized fresnel schlick rgb; do
        for s in scenes/*.scene; do
            n=$(basename "$s" .scene)
            case $skip in *" $n "*) continue ;; esac
            case $small in
            *" $n "*) [ $pass = small ] || continue; w=12 h=9 ;;
            *) [ $pass = rest ] || continue; w=24 h=18 ;;
            esac
            echo "$s $w $h $m $tmp/$n.$m $bin"
        done
    done
done >"$tmp/jobs"
xargs -P "$jobs" -L 1 sh "$self" --job <"$tmp/jobs"

cat "$tmp"/*.rows >"$tmp/all"
if awk '$6 <= 0 { bad = 1 } END { exit !bad }' "$tmp/all"; then
    echo "work_cost_fit.sh: no instructions counted inside rs_integrator_pixel (inlined?)" >&2
    exit 1
fi
if [ $verbose = 1 ]; then
    echo "scene mode wavelengths depth cutoff instructions pixels rays lane_rays builds gathered cost"
    cat "$tmp/all"
    echo
fi
echo "rs_work_cost fitted to callgrind's instructions of $(wc -l <"$tmp/all") renders; ratio = predicted / count:"
awk '{ print $1, $2, $6, $7, $8, $9, $10, $11, $12 }' "$tmp/all" | "$bin/work_cost_fit"
