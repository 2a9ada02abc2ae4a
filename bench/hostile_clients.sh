#!/usr/bin/env bash
# bench/hostile_clients.sh
# Issue 47's hostile sequences against the release k4reg-server with --memory-budget-mb 512 and a token
# (HostileClientsBench.Sequences in tests/integration/grpc_hostile_clients_test.cpp): header floods, oversized and
# chunked bodies, multipart junk, 50 slow HTTP clients with 50 idle gRPC connections, 4 concurrent large
# unauthenticated gRPC messages (200 MB and 900 MB). Per sequence: the server's peak resident set (VmHWM, reset
# before each through /proc/PID/clear_refs), the worst latency of GET /healthz on the health listener (every
# 100 ms) and what the clients got, as the Markdown table of bench/RESULTS.md's "Hostile clients (issue 47)".
# Build directory: $K4REG_BENCH_BUILD_DIR (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${K4REG_BENCH_BUILD_DIR:-build}

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" -j"$(nproc)" --target grpc_hostile_clients_test k4reg-server
echo "$(date -u +%Y-%m-%d), $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start"
K4REG_HOSTILE_BENCH=1 "$build/tests/grpc_hostile_clients_test" --gtest_filter='HostileClientsBench.*' \
  | grep -E '^\||^overall|^\[  (PASSED|FAILED)'
echo "load average $(cut -d' ' -f1-3 /proc/loadavg) at the end"
