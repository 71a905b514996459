#!/bin/sh
# Every test program under valgrind memcheck; any error or leak fails it.
#   sh scripts/valgrind.sh       -> one line per test, then "N passed, N failed"
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
for t in build-vg/bin/test_*; do
    n=$(basename "$t")
    if (cd build-vg/tests && valgrind --quiet --leak-check=full \
            --errors-for-leak-kinds=definite,indirect,possible --error-exitcode=99 \
            "../bin/$n" >"../valgrind/$n.log" 2>&1); then
        pass=$((pass + 1)); echo "valgrind: $n ok"
    else
        fail=$((fail + 1)); echo "valgrind: $n FAILED (build-vg/valgrind/$n.log)"
    fi
done
echo "valgrind: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
