#!/bin/sh
# Every test program under valgrind memcheck; any error or leak fails it.
#   sh scripts/valgrind.sh       -> one line per test, then "N passed, N failed"
# VALGRIND_SKIP (a grep -E pattern, default test_pov_compare: it renders
# nine scenes in five light models plus POV-Ray, hours under memcheck)
# names tests to leave out.
set -eu
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null 2>&1 || {
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends valgrind >&2
}
sh scripts/setup.sh build-vg -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLENSPRIM_WERROR=OFF
mkdir -p build-vg/valgrind
pass=0
fail=0
asserts=0
skip=${VALGRIND_SKIP-test_pov_compare}
for t in build-vg/bin/test_*; do
    n=$(basename "$t")
    if [ -n "$skip" ] && echo "$n" | grep -Eq "$skip"; then
        echo "valgrind: $n skipped"
        continue
    fi
    if (cd build-vg/tests && valgrind --quiet --leak-check=full \
            --errors-for-leak-kinds=definite,indirect,possible --error-exitcode=99 \
            "../bin/$n" >"../valgrind/$n.log" 2>&1); then
        pass=$((pass + 1)); echo "valgrind: $n ok"
    else
        rc=$?
        if [ "$rc" -eq 99 ]; then
            fail=$((fail + 1)); echo "valgrind: $n MEMCHECK ERRORS (build-vg/valgrind/$n.log)"
        else
            # No memory error or leak, but the test's own checks failed:
            # valgrind computes long double in double precision and is
            # 20-50x slower, which breaks long-double reference checks and
            # timing/memory measurements.  Reported, not hidden.
            asserts=$((asserts + 1))
            echo "valgrind: $n memcheck clean, test checks failed under valgrind (build-vg/valgrind/$n.log)"
        fi
    fi
done
echo "valgrind: memcheck clean in $((pass + asserts)) programs ($asserts of them with checks that fail under valgrind's emulation); $fail with memcheck errors"
echo "valgrind: $((pass + asserts)) passed, $fail failed"
[ "$fail" -eq 0 ]
