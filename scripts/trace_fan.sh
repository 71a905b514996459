#!/bin/sh
# Set everything up, then trace a fan of rays through the default lens
# (biconvex N-BK7, R1 = 50, R2 = -50, t = 8, D = 25 mm) with lenstrace and
# print, for each ray height, the transmitted ray: where it crosses the
# axis (spherical aberration shows as the focus moving in), its power and
# the reflected power.
set -eu
cd "$(dirname "$0")/.."
[ -x build/bin/lenstrace ] || sh scripts/setup.sh build
LENS="R1=50,R2=-50,t=8,D=25,glass=N-BK7"
echo "lens $LENS, lambda 587.56 nm, s-polarized rays parallel to the axis"
printf '%8s %14s %12s %12s %12s\n' "h/mm" "axis cross/mm" "I(depth 2)" "R(depth 1)" "rim"
for h in 0.5 2 4 6 8 10 11 12; do
    build/bin/lenstrace --lens "$LENS" --ray "o=0,$h,-20 d=0,0,1 lambda=587.56 vp=1,0,0" |
    awk -v h="$h" '
        function field(line, key,   s) {
            s = substr(line, index(line, "\"" key "\":") + length(key) + 3)
            sub(/[],}].*/, "", s); return s
        }
        function arr(line, key, out,   s) {
            s = substr(line, index(line, "\"" key "\":[") + length(key) + 4)
            sub(/].*/, "", s); split(s, out, ",")
        }
        /"depth":1,/ { r = field($0, "I") }
        /"depth":2,"kind":"transmit"/ {
            arr($0, "o", o); arr($0, "d", d); i2 = field($0, "I")
            z = (d[2] != 0) ? o[3] - o[2] * d[3] / d[2] : "inf"
        }
        /"summary"/ { rim = field($0, "absorbed_rim") }
        END { printf "%8s %14.6g %12.6g %12.6g %12.6g\n", h, z, i2, r, rim }'
done
