#!/bin/sh
# The whole test suite under valgrind memcheck, the programs the tests run
# included.  A test passes when its own checks pass AND memcheck reports no
# error and no leak (definite, indirect or possible) in it or its children.
#
#   sh scripts/valgrind.sh      -> one line per test, then "valgrind: N passed, N failed"
#
# VALGRIND_ONLY (a grep -E pattern) runs only the tests it matches;
# VALGRIND_JOBS (default: the number of cores) runs that many at once.
# Logs: build-vg/valgrind/TEST.log (the test's output) and TEST.PID.vg
# (memcheck's report for each process; kept only when not empty).
#
# Children: lensrender, lenstrace, pov_compare and model_limits, run by the
# CLI tests, are traced and checked like the tests.  Not traced: system
# programs (/bin, /usr/bin: the shell, POV-Ray) and tests/common/measure_child,
# which runs the programs whose peak memory test_hostile_scenes bounds --
# memcheck's own memory would be counted in that peak, so those runs are
# native (their code paths are memchecked by the other tests).
# test_pov_compare renders its nine scenes at 80 x 60 here instead of
# 320 x 240 (LP_POV_COMPARE_SIZE; memcheck runs the renderer 30-50x slower);
# its checks are the same at any size.
set -eu
cd "$(dirname "$0")/.."
logs=build-vg/valgrind

# One test: prints "valgrind: NAME ok|FAILED ...".
run_one() {
    n=$1
    t0=$(date +%s)
    rc=0
    (cd build-vg/tests && LP_POV_COMPARE_SIZE=80x60 valgrind --quiet --leak-check=full \
        --errors-for-leak-kinds=definite,indirect,possible --error-exitcode=99 \
        --trace-children=yes \
        --trace-children-skip='/bin/*,/usr/bin/*,/usr/local/bin/*,*/povray,*/measure_child' \
        --log-file="../valgrind/$n.%p.vg" \
        "../bin/$n" >"../valgrind/$n.log" 2>&1) || rc=$?
    t=$(($(date +%s) - t0))
    errs=""
    for f in "$logs/$n".*.vg; do
        [ -e "$f" ] || continue
        if [ -s "$f" ]; then errs="$errs $f"; else rm -f "$f"; fi
    done
    if [ -n "$errs" ]; then
        echo "valgrind: $n FAILED: memcheck errors or leaks ($t s):$errs"
    elif [ "$rc" -eq 77 ]; then
        echo "valgrind: $n skipped by the test itself ($t s): $(tail -n 1 "$logs/$n.log")"
    elif [ "$rc" -ne 0 ]; then
        echo "valgrind: $n FAILED: its checks failed, exit $rc ($t s; $logs/$n.log)"
    else
        echo "valgrind: $n ok ($t s)"
    fi
}

if [ "${1-}" = "--one" ]; then
    run_one "$2"
    exit 0
fi

command -v valgrind >/dev/null 2>&1 || {
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends valgrind >&2
}
sh scripts/setup.sh build-vg -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLENSPRIM_WERROR=OFF
rm -rf "$logs"
mkdir -p "$logs"

jobs=${VALGRIND_JOBS-$(nproc 2>/dev/null || echo 2)}
only=${VALGRIND_ONLY-}

t_start=$(date +%s)
for t in build-vg/bin/test_*; do
    n=$(basename "$t")
    if [ -n "$only" ] && ! echo "$n" | grep -Eq "$only"; then
        continue
    fi
    echo "$n"
done | xargs -n 1 -P "$jobs" sh scripts/valgrind.sh --one | tee "$logs/summary.txt"
pass=$(grep -c ' ok (' "$logs/summary.txt" || true)
fail=$(grep -c ' FAILED' "$logs/summary.txt" || true)
skipped=$(grep -c ' skipped ' "$logs/summary.txt" || true)
echo "valgrind: memcheck --leak-check=full, children traced, $jobs at a time, $(($(date +%s) - t_start)) s"
echo "valgrind: $pass passed, $fail failed, $skipped skipped"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ]
