#!/bin/sh
# What MPI costs: the wall time and the CPU time of one render with
#   1 process  x 1 thread    lensrender --threads 1
#   2 processes x 1 thread   mpirun -n 2 lensrender-mpi --threads 1
#   1 process  x 2 threads   lensrender --threads 2
# in interleaved rounds (A B C, A B C, ...), each figure the median of its
# rounds, then the ratios: 2 processes against 2 threads (MPI's cost over
# threads on one machine: process start-up, the scene read by each
# process, the regions' messages) and 1 thread against 2 processes (the
# speed-up).  The CPU time (user + system of the command and everything
# it started: mpirun, its processes) is what the work costs wherever it
# ran; on a machine busy with other work the wall times say more about
# the kernel's sharing than about MPI (mpirun's processes run in a session
# of their own, which the kernel's autogroup scheduling gives a share of
# its own).  A benchmark, not a test: read the ratios, and the load
# average it prints.
#   bench/mpi.sh [SCENE [WIDTH HEIGHT [ROUNDS]]]
# (default scenes/default.scene 800 600, 5 rounds).  Needs a build with
# MPI (build/bin/lensrender-mpi).  MPIRUN (default mpirun) and MPIRUN_FLAGS
# (default: what Open MPI needs for 2 processes as root in a container)
# choose the launcher.
set -eu
cd "$(dirname "$0")/.."
SCENE=${1:-scenes/default.scene}
W=${2:-800}
H=${3:-600}
ROUNDS=${4:-5}
[ -x build/bin/lensrender-mpi ] || sh scripts/setup.sh build
if [ ! -x build/bin/lensrender-mpi ]; then
    echo "bench/mpi.sh: no build/bin/lensrender-mpi (MPI not found by the build)" >&2
    exit 1
fi
MPIRUN=${MPIRUN:-mpirun}
if [ -z "${MPIRUN_FLAGS+x}" ]; then
    MPIRUN_FLAGS="-q"
    [ "$(id -u)" -ne 0 ] || MPIRUN_FLAGS="$MPIRUN_FLAGS --allow-run-as-root"
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }
common="$SCENE --width $W --height $H --quiet"

one() { # name command...: appends the wall and CPU times of the command
    name=$1    # to $tmp/name and $tmp/name.cpu
    shift
    t0=$(now)
    cpu=$("$@" >/dev/null; times)
    t1=$(now)
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f\n", b - a }' >>"$tmp/$name"
    # the second line of times: the children's user and system time, "XmY.Zs"
    echo "$cpu" | tail -n 1 | awk '{ split($1, u, "m"); split($2, s, "m")
        printf "%.4f\n", u[1] * 60 + u[2] + s[1] * 60 + s[2] }' >>"$tmp/$name.cpu"
}
median() { sort -n "$tmp/$1" | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else printf "%.4f\n", (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "bench/mpi.sh: $SCENE at ${W}x$H, $ROUNDS rounds on $(nproc) cores; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq "$ROUNDS"); do
    # shellcheck disable=SC2086
    one t1 build/bin/lensrender $common --threads 1 -o "$tmp/a.png"
    # shellcheck disable=SC2086
    one m2 $MPIRUN $MPIRUN_FLAGS -n 2 build/bin/lensrender-mpi $common --threads 1 -o "$tmp/b.png"
    # shellcheck disable=SC2086
    one t2 build/bin/lensrender $common --threads 2 -o "$tmp/c.png"
done
cmp -s "$tmp/a.png" "$tmp/b.png" && cmp -s "$tmp/a.png" "$tmp/c.png" ||
    echo "bench/mpi.sh: the images differ" >&2
a=$(median t1)
b=$(median m2)
c=$(median t2)
ac=$(median t1.cpu)
bc=$(median m2.cpu)
cc=$(median t2.cpu)
printf '                        wall (median of %d)  CPU\n' "$ROUNDS"
printf '1 process  x 1 thread : %8.3f s           %8.3f s\n' "$a" "$ac"
printf '2 processes x 1 thread: %8.3f s           %8.3f s\n' "$b" "$bc"
printf '1 process  x 2 threads: %8.3f s           %8.3f s\n' "$c" "$cc"
awk -v a="$a" -v b="$b" -v c="$c" -v ac="$ac" -v bc="$bc" -v cc="$cc" 'BEGIN {
    printf "MPI / threads (2 processes / 2 threads): wall %.3f, CPU %.3f  (goal: within 1.10)\n", b / c, bc / cc
    printf "speed-up of 2 processes over 1 thread:   wall %.2f\n", a / b
}'
echo "bench/mpi.sh: load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
