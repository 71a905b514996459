#!/bin/sh
# Run one fuzz target with the project's settings.
#   fuzz/run.sh TARGET [SECONDS [BUILD_DIR]]
# TARGET: scene, lenstrace_args or agf; SECONDS default 600; BUILD_DIR
# default build-fuzz (see fuzz/setup.sh).  New inputs go to
# BUILD_DIR/fuzz-work/TARGET (the seeds in fuzz/corpus/TARGET stay as they
# are); a crash, leak, timeout (10 s) or allocation over 512 MB is written
# to BUILD_DIR/fuzz-artifacts/TARGET/ and stops the run.  The statistics
# (executions, executions per second) are printed at the end.
set -eu
cd "$(dirname "$0")/.."
t=${1:?usage: fuzz/run.sh scene|lenstrace_args|agf [SECONDS [BUILD_DIR]]}
secs=${2:-600}
build=${3:-build-fuzz}
mkdir -p "$build/fuzz-work/$t" "$build/fuzz-artifacts/$t"
exec "$build/bin/fuzz_$t" "$build/fuzz-work/$t" "fuzz/corpus/$t" \
    -dict="fuzz/$t.dict" -max_total_time="$secs" -timeout=10 \
    -rss_limit_mb=1024 -malloc_limit_mb=512 -max_len=8192 \
    -print_final_stats=1 -artifact_prefix="$build/fuzz-artifacts/$t/"
