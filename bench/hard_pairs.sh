#!/usr/bin/env bash
# Hard pairs at 1.5 M points as a user runs them (`k4reg align`, no parameters), every scan in an arbitrary frame:
# monument layout 5 (front and back of a gate), the arch plaza, courtyard layout 5. Simulates the scans once, then
# prints per pair: seconds, error against the truth (largest displacement over a 60 x 60 x 10 m box about the
# source scanner), the verdict. Usage: bench/hard_pairs.sh [BIN_DIR=build/bin] [WORK_DIR=/tmp/k4reg-hard]
set -euo pipefail
bin=$(realpath "${1:-build/bin}")
work=${2:-/tmp/k4reg-hard}
mkdir -p "$work" && cd "$work"
simulate() {  # NAME SCENE LAYOUT STATION SEED
  [ -f "$1.ply" ] || "$bin/k4reg-simulate" --scene "$2" --layout "$3" --station "$4" --points 1500000 --seed "$5" \
    --frame arbitrary --out "$1.ply" --gt "$1.gt.txt" >/dev/null
}
for s in 0 1 2 3; do
  simulate "mon5-$s" monument 5 "$s" "5$s"; simulate "arch-$s" arch 0 "$s" "6$s"; simulate "cy5-$s" courtyard 5 "$s" "7$s"
done
echo "pair,seconds,error_m,ambiguous,well_supported,margin,reason"
for p in mon5-0:mon5-1 mon5-0:mon5-3 mon5-3:mon5-2 mon5-1:mon5-2 arch-0:arch-1 arch-1:arch-2 arch-2:arch-3 arch-0:arch-2 \
         cy5-0:cy5-1 cy5-1:cy5-2 cy5-2:cy5-3 cy5-0:cy5-2; do
  s=${p%%:*} t=${p##*:}
  start=$(date +%s.%N)
  rc=0; "$bin/k4reg" align --json "$s.ply" "$t.ply" >"$s-$t.json" 2>"$s-$t.err" || rc=$?
  python3 - "$s" "$t" "$rc" "$start" "$(date +%s.%N)" <<'PY'
import json, math, sys
s, t, rc, a, b = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
def load(f): return [list(map(float, l.split())) for l in open(f) if l.strip()]
def mul(A, B): return [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]
def inv(T):
    R = [[T[j][i] for j in range(3)] for i in range(3)]
    t = [-sum(R[i][k] * T[k][3] for k in range(3)) for i in range(3)]
    return [R[0] + [t[0]], R[1] + [t[1]], R[2] + [t[2]], [0, 0, 0, 1]]
if rc != 0:
    print(f'{s}->{t},{b - a:.2f},,refused,,,"{open(f"{s}-{t}.err").read().strip()[:200]}"'); sys.exit()
d = json.load(open(f'{s}-{t}.json'))
truth = mul(inv(load(t + '.gt.txt')), load(s + '.gt.txt'))
T = d['transform']  # 16 numbers, row by row
T = [T[4 * i:4 * i + 4] for i in range(4)]
c = d['source_scanner_position']['point_m']
err = max(math.sqrt(sum(sum((T[i][k] - truth[i][k]) * p[k] for k in range(4)) ** 2 for i in range(3)))
          for p in ([c[0] + dx, c[1] + dy, c[2] + dz, 1] for dx in (-30, 30) for dy in (-30, 30) for dz in (-5, 5)))
print(f'{s}->{t},{b - a:.2f},{err:.4f},{d["ambiguous"]},{d["well_supported"]},{d["ambiguity_margin"]:.3f},"{d.get("ambiguity_reason", "")[:120]}"')
PY
done
