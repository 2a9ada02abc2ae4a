#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang++, ASan + UBSan) into their own build folder and runs each
# for a bounded time, $(nproc) at once. Fails on any crash, leak, timeout (one input over 5 s), out-of-memory
# (RSS over 2 GiB, or one allocation over 256 MiB: a reader allocating per a header's claim instead of the
# input's size) or sanitizer report. Findings (the inputs that triggered them) stay in <build>/findings/<target>/;
# reproduce one with <build>/fuzz/<target> <file>.
#
# Environment: K4REG_FUZZ_SECONDS per target (default 45), K4REG_FUZZ_TARGETS (space-separated subset, default
# all), K4REG_FUZZ_BUILD_DIR (default build-fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/compiler-cache.sh
build=${K4REG_FUZZ_BUILD_DIR:-build-fuzz}
seconds=${K4REG_FUZZ_SECONDS:-45}

# -O1 without NDEBUG: fast enough to fuzz, and assertions (ours, Eigen's) stay on.
cmake -S . -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DK4REG_BUILD_FUZZERS=ON -DK4REG_BUILD_TESTS=OFF -DK4REG_BUILD_BENCH=OFF
cmake --build "$build" -j"$(nproc)" --target fuzzers

targets=${K4REG_FUZZ_TARGETS:-$(ls "$build/fuzz")}
mkdir -p "$build/logs"
rm -f "$build"/logs/*.failed

# One target: the corpus grows in <build>/corpus/<target> (new inputs go to the first folder), seeded from
# tests/fuzz/corpus/<target>.
run_target() {
  local target=$1 log="$build/logs/$1.log"
  mkdir -p "$build/corpus/$target" "$build/findings/$target"
  if ! ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0 UBSAN_OPTIONS=print_stacktrace=1 \
      "$build/fuzz/$target" -max_total_time="$seconds" -timeout=5 -rss_limit_mb=2048 -malloc_limit_mb=256 \
      -max_len=65536 -print_final_stats=1 -artifact_prefix="$build/findings/$target/" \
      "$build/corpus/$target" "tests/fuzz/corpus/$target" >"$log" 2>&1; then
    touch "$build/logs/$target.failed"
  fi
}
export -f run_target
export build seconds
printf '%s\n' $targets | xargs -P "$(nproc)" -I{} bash -c 'run_target {}'

status=0
printf '%-24s %12s %8s  %s\n' target executions exec/s result
for target in $targets; do
  log="$build/logs/$target.log"
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  result=ok
  if [ -e "$build/logs/$target.failed" ]; then
    result="FAILED (log: $log, findings: $build/findings/$target/)"
    status=1
  fi
  printf '%-24s %12s %8s  %s\n' "$target" "${runs:-?}" "${speed:-?}" "$result"
done
for target in $targets; do
  if [ -e "$build/logs/$target.failed" ]; then
    echo "---- $target: last lines of $build/logs/$target.log"
    tail -n 60 "$build/logs/$target.log"
  fi
done
exit $status
