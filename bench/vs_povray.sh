#!/bin/sh
# vs_povray.sh -- POV-Ray 3.7 against lensrender on the same scenes.
#
# A benchmark, not a test.  Each row renders one scene with POV-Ray (on
# the .pov that pov_compare translates it to) and with lensrender in every
# light model, one thread each, adc_bailout 0 on both sides, the same size
# and depth.  The renders are interleaved (POV-Ray, then each mode, then
# POV-Ray again, ...) for RUNS rounds, and the table gives the median
# seconds of each and the median of the per-round ratios POV-Ray / ours,
# so that a machine whose speed drifts during the run still compares
# like with like.  Times are CPU seconds (user + sys) of the whole
# process; wall-clock ratios are printed below the table.
#
# Rows (the scenes of the speed goals in the README):
#   1  scenes/default.scene 640x480, dispersion off on both sides
#      (lensrender --no-dispersion, POV-Ray's plain ior)
#   2  bench/scenes/two_lenses.scene 480x360 (N-BK7 and N-SF11 lenses, a
#      lit sphere, a checker floor), dispersion off on both sides
#   3  scenes/newtons_rings.scene 640x480, dispersion off on both sides
#   4  scenes/default.scene 640x480, dispersion on both sides: POV-Ray's
#      `dispersion` (n(380 nm)/n(780 nm) of the glass, from lenstrace)
#      with `dispersion_samples` equal to lensrender's 16 wavelengths
#
# usage: bench/vs_povray.sh [--runs N] [--scale F] [--rows "1 2 3 4"]
#                           [--modes "fresnel polarized schlick rgb"]
#                           [--bin DIR]
#   --runs N    interleaved rounds (default 3)
#   --scale F   multiply every image size by F (default 1; 0.25 for a quick look)
#   --rows L    which rows (default all)
#   --modes L   which lensrender modes (default all four; fresnel first:
#               the ratio polarized/fresnel needs both)
#   --bin DIR   where lensrender, pov_compare and lenstrace are (default build/bin)
set -eu
cd "$(dirname "$0")/.."

RUNS=3
SCALE=1
ROWS="1 2 3 4"
MODES="fresnel polarized schlick rgb"
BIN=build/bin
while [ $# -gt 0 ]; do
    case "$1" in
    --runs) RUNS=$2; shift 2 ;;
    --scale) SCALE=$2; shift 2 ;;
    --rows) ROWS=$2; shift 2 ;;
    --modes) MODES=$2; shift 2 ;;
    --bin) BIN=$2; shift 2 ;;
    -h|--help) sed -n '2,35p' "$0"; exit 0 ;;
    *) echo "vs_povray.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
case "$RUNS" in ''|*[!0-9]*) echo "vs_povray.sh: --runs must be a number" >&2; exit 2 ;; esac
[ "$RUNS" -ge 1 ] || { echo "vs_povray.sh: --runs must be >= 1" >&2; exit 2; }
BIN=$(cd "$BIN" && pwd)
for p in lensrender pov_compare lenstrace; do
    [ -x "$BIN/$p" ] || { echo "vs_povray.sh: $BIN/$p not found (build first)" >&2; exit 2; }
done
command -v povray >/dev/null 2>&1 || {
    echo "vs_povray.sh: povray (POV-Ray 3.7) not found on PATH (scripts/setup.sh installs it)" >&2
    exit 2
}

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM

# CPU (user + sys) and wall seconds of one command, appended to file $1.
timed() {
    out=$1
    shift
    /usr/bin/time -f '%U %S %e' -o "$tmp/t" "$@" >/dev/null 2>"$tmp/err" || {
        echo "vs_povray.sh: failed: $*" >&2
        cat "$tmp/err" >&2
        exit 1
    }
    awk '{ printf "%.3f %.3f\n", $1 + $2, $3 }' "$tmp/t" >>"$out"
}

# Median of column $2 of file $1.
median() {
    awk -v c="$2" '{ print $c }' "$1" | sort -g |
        awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2];
                                  else printf "%.4g\n", (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

# Median over rounds of column $3 of file $1 divided by column $3 of file $2.
median_ratio() {
    paste -d' ' "$1" "$2" | awk -v c="$3" '{ n = NF / 2; if ($(n + c) > 0) printf "%.4f\n", $c / $(n + c) }' |
        sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) print "-"; else if (NR % 2) print v[(NR + 1) / 2];
                                           else printf "%.4f\n", (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

# The index of a catalog glass at a wavelength in air: the optical path of
# a ray straight through a 1 mm flat plate of it (lenstrace).
glass_index() {
    "$BIN/lenstrace" --lens "R1=inf,R2=inf,t=1,D=10,glass=$1" \
        --ray "o=0,0,-1 d=0,0,1 lambda=$2 vp=1,0,0" --depth 2 |
        sed -n 's/.*"depth":2,"kind":"transmit".*"op":\([^,]*\),.*/\1/p'
}

# Add POV-Ray's dispersion to every lens interior of $2 (a .pov written
# from scene $1): the k-th interior gets the k-th `glass "NAME"` of the
# scene.
add_dispersion() {
    glasses=$(sed -n 's/.*glass *"\([^"]*\)".*/\1/p' "$1")
    n_int=$(grep -c 'PC_Interior_[0-9]* = interior { ior' "$2" || true)
    n_gl=$(printf '%s\n' "$glasses" | grep -c . || true)
    [ "$n_int" = "$n_gl" ] || {
        echo "vs_povray.sh: $1: $n_gl catalog glasses for $n_int lens interiors" >&2
        exit 1
    }
    k=0
    for g in $glasses; do
        nv=$(glass_index "$g" 380)
        nr=$(glass_index "$g" 780)
        ratio=$(awk -v a="$nv" -v b="$nr" 'BEGIN { printf "%.10g", a / b }')
        sed -i "s/\(PC_Interior_$k = interior { ior [^ ]*\)/\1 dispersion $ratio dispersion_samples 16/" "$2"
        k=$((k + 1))
    done
}

row() {
    id=$1 scene=$2 w=$3 h=$4 disp=$5
    W=$(awk -v a="$w" -v s="$SCALE" 'BEGIN { v = int(a * s + 0.5); print v < 4 ? 4 : v }')
    H=$(awk -v a="$h" -v s="$SCALE" 'BEGIN { v = int(a * s + 0.5); print v < 3 ? 3 : v }')
    d="$tmp/row$id"
    mkdir -p "$d"
    # The translation at a small size of the same shape (the .pov's camera
    # depends only on the aspect ratio); its renders are not used.
    "$BIN/pov_compare" "$scene" --out "$d/pc" --width "$((w / 20))" --height "$((h / 20))" \
        --lens-inc scenes/lens.inc --threads 1 --quiet >/dev/null 2>"$d/pc.err" || true
    [ -s "$d/pc/scene.pov" ] || {
        echo "vs_povray.sh: pov_compare wrote no scene.pov for $scene:" >&2
        cat "$d/pc.err" >&2
        exit 1
    }
    if [ "$disp" = on ]; then
        add_dispersion "$scene" "$d/pc/scene.pov"
        nodisp=""
    else
        nodisp="--no-dispersion"
    fi
    r=1
    while [ "$r" -le "$RUNS" ]; do
        (cd "$d/pc" && timed "$d/povray" povray -D -V -GS -GR +Iscene.pov +O"$d/pov.png" \
            +W"$W" +H"$H" -A +Q9 -UA +FN16 File_Gamma=1.0 Dither=off +WT1)
        for m in $MODES; do
            # shellcheck disable=SC2086
            timed "$d/$m" "$BIN/lensrender" "$scene" -o "$d/ours.png" --width "$W" --height "$H" \
                --mode "$m" --threads 1 --cutoff 0 --quiet $nodisp
        done
        r=$((r + 1))
    done
    line=$(printf '%-3s %-42s %8s' "$id" "$(basename "$scene") ${W}x${H} dispersion $disp" \
        "$(median "$d/povray" 1)")
    ratios=""
    wall=""
    for m in $MODES; do
        line="$line $(printf '%9s' "$(median "$d/$m" 1)")"
        ratios="$ratios $(printf '%9s' "$(median_ratio "$d/povray" "$d/$m" 1)")"
        wall="$wall $(printf '%9s' "$(median_ratio "$d/povray" "$d/$m" 2)")"
    done
    printf '%s\n' "$line" >>"$tmp/table_s"
    printf '%-3s %-42s %8s%s\n' "$id" "" "" "$ratios" >>"$tmp/table_r"
    printf '%-3s %-42s %8s%s\n' "$id" "" "" "$wall" >>"$tmp/table_w"
    # (one pattern per mode: in " fresnel polarized " the space between
    # the two names can serve only one of them)
    case " $MODES " in
    *" fresnel "*)
        case " $MODES " in
        *" polarized "*)
            printf '%-3s polarized / fresnel time: %s\n' "$id" \
                "$(median_ratio "$d/polarized" "$d/fresnel" 1)" >>"$tmp/table_p" ;;
        esac ;;
    esac
}

for id in $ROWS; do
    case "$id" in
    1) row 1 scenes/default.scene 640 480 off ;;
    2) row 2 bench/scenes/two_lenses.scene 480 360 off ;;
    3) row 3 scenes/newtons_rings.scene 640 480 off ;;
    4) row 4 scenes/default.scene 640 480 on ;;
    *) echo "vs_povray.sh: no row $id (rows are 1 2 3 4)" >&2; exit 2 ;;
    esac
done

hdr=""
for m in $MODES; do hdr="$hdr $(printf '%9s' "$m")"; done
echo "POV-Ray 3.7 against lensrender: 1 thread each, adc_bailout 0, $RUNS interleaved rounds, medians"
echo
echo "CPU seconds (user + sys):"
printf '%-3s %-42s %8s%s\n' row scene povray "$hdr"
cat "$tmp/table_s"
echo
echo "POV-Ray time / lensrender time (median of the per-round ratios; >= 1: lensrender is faster):"
printf '%-3s %-42s %8s%s\n' row "" "" "$hdr"
cat "$tmp/table_r"
echo
echo "the same ratios in wall-clock time:"
printf '%-3s %-42s %8s%s\n' row "" "" "$hdr"
cat "$tmp/table_w"
if [ -s "$tmp/table_p" ]; then
    echo
    cat "$tmp/table_p"
fi
