#!/usr/bin/env bash
# bench/soak.sh [SECONDS]
# The service soak test (tests/integration/service_soak_test.cpp) for longer than in CI: one k4reg-server on
# loopback, 4 client threads sending valid, invalid, cancelled and short-deadline calls for SECONDS (default 600),
# then the health, spool, thread and RSS checks. Appends the run's summary line to the soak block of
# bench/RESULTS.md. Build directory: $K4REG_BENCH_BUILD_DIR (default build, the one scripts/build.sh makes).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
build=${K4REG_BENCH_BUILD_DIR:-build}

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" -j"$(nproc)" --target service_soak_test k4reg-server
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
K4REG_SOAK_SECONDS=$seconds "$build/tests/service_soak_test" | tee "$log" || status=$?
summary=$(grep '^soak:' "$log" || echo "soak: no summary (the test stopped early)")
result=$([ $status -eq 0 ] && echo passed || echo FAILED)

markdown=bench/RESULTS.md
line="- $(date -u +%Y-%m-%d) ($(nproc) cores, load average $(cut -d' ' -f1 /proc/loadavg) at the end): $result — ${summary#soak: }"
if ! grep -q '<!-- soak:begin -->' "$markdown"; then
  cat >> "$markdown" <<'HEADER'

## Service soak (issue 9)

`bench/soak.sh SECONDS` runs `tests/integration/service_soak_test.cpp` for longer than CI does (CI: 20 s). Each
line: one run; counts are `kind:grpc status code` (0 OK, 1 CANCELLED, 3 INVALID_ARGUMENT, 4 DEADLINE_EXCEEDED,
5 NOT_FOUND, 7 PERMISSION_DENIED, 8 RESOURCE_EXHAUSTED, 15 DATA_LOSS). RSS and threads are the server's, from
/proc/<pid>/status: baseline after a warm-up, peak during the soak, after it; threads above the baseline are gRPC's
executor threads, which grow on demand up to 2 x cores and stay (the test allows only those).

<!-- soak:begin -->
<!-- soak:end -->
HEADER
fi
awk -v line="$line" '$0 == "<!-- soak:end -->" { print line } { print }' "$markdown" > "$markdown.tmp"
mv "$markdown.tmp" "$markdown"
echo "bench/soak.sh: $result; summary added to $markdown"
exit $status
