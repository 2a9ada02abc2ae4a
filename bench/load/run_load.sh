#!/usr/bin/env bash
# Load test of k4reg-server on loopback with `k4reg load`: calls/s and p50/p99 latency of a small pair (the
# Stanford bunny, ~40 k points per scan, by reference) at several concurrencies, against one server and through
# three replicas behind the client's round-robin list; plus the service overhead from the servers' own timings
# (request to job start without queue wait, plus job end to reply), which must stay under 5 ms at p99.
#
#   bench/load/run_load.sh                 # writes bench/load/RESULTS-load.md
#
# Environment: K4REG_BIN (folder of k4reg and k4reg-server, default build/bin), LEVELS (concurrencies,
# default "1 2 4 8"), REQUESTS (calls per level, default 100), FLAGS (registration flags, default
# "--min-scale 0.002 --overlap 0.9": a correct registration of the pair in ~0.2 s on one core),
# SINGLE_WORKERS (workers of the single server, default: cores), REPLICA_WORKERS (per replica, default 1),
# OUT (default bench/load/RESULTS-load.md).
# Bounded: every level is a fixed number of calls with a 120 s deadline each; servers are stopped on exit.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${K4REG_BIN:-$root/build/bin}
levels=${LEVELS:-"1 2 4 8"}
requests=${REQUESTS:-100}
read -r -a flags <<<"${FLAGS:---min-scale 0.002 --overlap 0.9}"
cores=$(nproc)
single_workers=${SINGLE_WORKERS:-$cores}
replica_workers=${REPLICA_WORKERS:-1}
out=${OUT:-$here/RESULTS-load.md}
overhead_limit_ms=5
load_before=$(cut -d' ' -f1-3 /proc/loadavg)  # other work on the machine skews every figure: recorded

for tool in "$bin/k4reg" "$bin/k4reg-server"; do
  [[ -x $tool ]] || { echo "run_load.sh: $tool not found (build it, or set K4REG_BIN)" >&2; exit 2; }
done
command -v jq >/dev/null || { echo "run_load.sh: needs jq" >&2; exit 2; }

work=$(mktemp -d)
server_pids=()
stop_servers() {
  for pid in "${server_pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${server_pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  server_pids=()
}
trap 'stop_servers; rm -rf "$work"' EXIT

# start_server NAME WORKERS: a server on an ephemeral loopback port; sets $address.
start_server() {
  local name=$1 workers=$2
  "$bin/k4reg-server" --grpc-listen 127.0.0.1:0 --port-file "$work/$name.port" --http-listen '' --spool-dir "$work" \
    --data-root "$root/tests/data/bunny" --workers "$workers" --queue-size 64 --server-id "$name" \
    --log-level warn 2>"$work/$name.log" &
  server_pids+=($!)
  for _ in $(seq 300); do
    [[ -s $work/$name.port ]] && break
    sleep 0.1
  done
  [[ -s $work/$name.port ]] || { echo "run_load.sh: $name did not start: $(cat "$work/$name.log")" >&2; exit 1; }
  address=127.0.0.1:$(cat "$work/$name.port")
}

load() {  # load SERVERS CONCURRENCY CALLS -> JSON report on stdout
  "$bin/k4reg" load --server "$1" --pair bun045.ply bun000.ply --concurrency "$2" --requests "$3" \
    --deadline 120 --json "${flags[@]}"
}

rows=()
worst_overhead_ms=0
# measure TOPOLOGY SERVERS: one table row per concurrency level.
measure() {
  local topology=$1 servers=$2
  load "$servers" 2 4 >/dev/null  # warm-up: connections, page cache, first-call allocations
  for c in $levels; do
    echo "run_load.sh: $topology, concurrency $c, $requests calls" >&2
    local report
    report=$(load "$servers" "$c" "$requests")
    rows+=("$(jq -r --arg topology "$topology" '
      def ms: . * 1000 | . * 10 | round / 10;
      [$topology, .concurrency, .calls, (.status_counts.OK // 0),
       (.calls_per_s * 100 | round / 100),
       (.latency_s.p50 | ms), (.latency_s.p99 | ms),
       (.server_timings_s.queue_wait.p50 | ms), (.server_timings_s.registration.p50 | ms),
       "\(.server_timings_s.overhead.p50 * 1000 | . * 100 | round / 100) / \(.server_timings_s.overhead.p99 * 1000 | . * 100 | round / 100)",
       (.client_cpu_percent | . * 10 | round / 10),
       ([.replies_per_server | to_entries[] | .value | tostring] | join(" / "))]
      | "| " + (map(tostring) | join(" | ")) + " |"' <<<"$report")")
    worst_overhead_ms=$(jq -r --argjson worst "$worst_overhead_ms" \
      '[$worst, .server_timings_s.overhead.p99 * 1000] | max' <<<"$report")
  done
}

start_server single "$single_workers"
measure "1 server × $single_workers workers" "$address"
stop_servers

replicas=()
for name in replica-a replica-b replica-c; do
  start_server "$name" "$replica_workers"
  replicas+=("$address")
done
measure "3 replicas × $replica_workers worker" "$(IFS=,; echo "${replicas[*]}")"
stop_servers

load_after=$(cut -d' ' -f1-3 /proc/loadavg)
verdict=$(jq -rn --argjson worst "$worst_overhead_ms" --argjson limit "$overhead_limit_ms" \
  'if $worst < $limit then "under" else "OVER" end')
{
  echo "# k4reg load test (loopback)"
  echo
  echo "\`bench/load/run_load.sh\` on $(date -u +%Y-%m-%d), commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)," \
       "$cores cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'))."
  echo "Pair: bun045.ply onto bun000.ply by reference (~40 k points each), flags \`${flags[*]}\`;" \
       "closed loop, $requests calls per row; client and servers share the machine" \
       "(load average before the run: $load_before, after: $load_after; the run itself keeps about $cores cores busy)."
  echo
  echo "| topology | concurrency | calls | OK | calls/s | p50 ms | p99 ms | queue wait p50 ms | registration p50 ms | server overhead p50 / p99 ms | client CPU % | OK calls per server |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"
  printf '%s\n' "${rows[@]}"
  echo
  echo "Server overhead = request to job start without the queue wait (and upload), plus job end to reply, from the"
  echo "servers' own ServerTimings. Worst p99 over all rows: $(printf '%.2f' "$worst_overhead_ms") ms," \
       "$verdict the ${overhead_limit_ms} ms limit."
  echo "Latency is measured by the client from call start to reply (OK calls only). The three replicas share the"
  echo "same $cores cores, so they show the round-robin spread and its cost, not more capacity."
} >"$out"
cat "$out"
