#!/usr/bin/env bash
# Issue 23's measurement: one project through 1 replica and through a coordinator with 3 local replicas as peers
# (k4reg-server --peers). Prints, per run, the wall time, where the pairs ran (per replica, from /metrics), the
# per-pair and per-stage costs the scaling model in bench/RESULTS.md is built from, and checks that the poses are
# bit-identical. On a 2-core machine three replicas share the same two cores: the speed-up is bounded by 2.
#
#   bench/fanout.sh BUILD_DIR SCAN_DIR SCAN... [-- REGISTER_PROJECT_FLAGS...]
# e.g. bench/fanout.sh build build-bench/bench-cache hall-layout3-station{0,1,2,4}-700000-seed*.ply \
#        -- --min-scale 0.1 --overlap 0.4 --seed 1
set -euo pipefail
build=$(realpath "$1") data=$(realpath "$2")
shift 2
scans=()
while (($#)) && [[ $1 != -- ]]; do scans+=("$1"); shift; done
[[ ${1:-} == -- ]] && shift
flags=("$@")
work=$(mktemp -d)
trap 'kill $(cat "$work"/*.pid 2>/dev/null) 2>/dev/null || true; rm -rf "$work"' EXIT

# start NAME EXTRA_FLAGS...: a replica on ephemeral ports; its gRPC and HTTP ports land in $work/NAME.port/.http
start() {
  local name=$1
  shift
  "$build/bin/k4reg-server" --grpc-listen "127.0.0.1:${port:-0}" --port-file "$work/$name.port" --http-listen 127.0.0.1:0 \
    --http-port-file "$work/$name.http" --data-root "$data" --workers 1 --pair-workers 1 --job-threads 1 \
    --spool-dir "$work/spool-$name" --server-id "$name" "$@" 2>"$work/$name.log" &
  echo $! >"$work/$name.pid"
  for _ in $(seq 300); do [[ -s $work/$name.port ]] && return; sleep 0.1; done
  echo "replica $name did not start" >&2
  exit 1
}
stop_all() {
  kill $(cat "$work"/*.pid) 2>/dev/null || true
  wait 2>/dev/null || true
  rm -f "$work"/*.pid "$work"/*.port "$work"/*.http
}
pairs_received() { curl -s "http://127.0.0.1:$(cat "$work/$1.http")/metrics" |
  awk '/^k4reg_pair_jobs_received_total\{code="OK"\}/ {n += $2} END {print n + 0}'; }
bytes_sent() { curl -s "http://127.0.0.1:$(cat "$work/$1.http")/metrics" |
  awk '/^k4reg_peer_pair_bytes_sent_total\{/ {n += $2} END {printf "%.1f MB", n / 1e6}'; }

run() {  # run LABEL REPLICA...: the project through the first replica
  local label=$1 coordinator=$2
  shift 2
  local t0 t1
  t0=$(date +%s.%N)
  "$build/bin/k4reg" register-project --server "127.0.0.1:$(cat "$work/$coordinator.port")" --ref --json \
    "${flags[@]}" "${scans[@]}" >"$work/$label.json"
  t1=$(date +%s.%N)
  local received=()
  for r in "$coordinator" "$@"; do received+=("$r=$(pairs_received "$r")"); done
  received+=("sent $(bytes_sent "$coordinator")")
  /usr/bin/python3 - "$work/$label.json" "$label" "$(echo "$t1 - $t0" | bc)" "${received[*]}" <<'EOF'
import json, statistics, sys
j = json.load(open(sys.argv[1]))
label, wall, received = sys.argv[2], float(sys.argv[3]), sys.argv[4]
pairs = [l["seconds"] for l in j["links"]]
stages = {t["stage"]: t["seconds"] for t in j["timings"]}
server = j["server_timings"]
print(f"{label}: wall {wall:.1f} s, {len(j['scans'])} scans, {len(pairs)} pairs "
      f"(on peers {j['pairs_on_peers']}, here {j['pairs_local']}, retries {j['pair_retries']}); pair jobs per "
      f"replica: {received}; pair seconds median {statistics.median(pairs):.2f}, min {min(pairs):.2f}, "
      f"max {max(pairs):.2f}, sum {sum(pairs):.1f}; selection {stages.get('selection', 0):.3f} s, refinement "
      f"{stages.get('refinement', 0):.3f} s; server load {server.get('load_s', 0):.2f} s; "
      f"registered {j['scans_registered']}")
EOF
}

start solo
run one-replica solo
stop_all

start peer-b
start peer-c
# As in a deployment (the headless Service lists every replica), the coordinator is one of its own peers.
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
port=$port start coord --peers "ipv4:127.0.0.1:$port,127.0.0.1:$(cat "$work/peer-b.port"),127.0.0.1:$(cat "$work/peer-c.port")"
run three-replicas coord peer-b peer-c
stop_all

/usr/bin/python3 - "$work/one-replica.json" "$work/three-replicas.json" <<'EOF'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
same = [s["pose"] for s in a["scans"]] == [s["pose"] for s in b["scans"]]
print("poses bit-identical with and without peers:", "yes" if same else "NO")
sys.exit(0 if same else 1)
EOF
