#!/usr/bin/env bash
# Two builds of `k4reg align`, interleaved on the simulated lab's 15 station pairs (Table 2's scans), in one run:
# the median wall time per pair of each and their ratio, and how many results lie within the paper's threshold
# (RMSE over true correspondences < 0.5 m, from the ground truth). For "no slower than before" checks of a change.
#
#   bench/ab_lab_pairs.sh BEFORE_K4REG AFTER_K4REG SCAN_DIR [POINTS] [SIGMA_M] [SEEDS]
# SCAN_DIR gets lab-station{0..5}-POINTS.ply and .gt.txt (simulated when missing, with the AFTER build's
# k4reg-simulate next to it). Every run: --min-scale SIGMA_M --overlap 0.8 --seed S --threads 2.
set -euo pipefail
before=$1 after=$2 dir=$3 points=${4:-700000} sigma=${5:-0.05} seeds=${6:-2}
simulate="$(dirname "$after")/k4reg-simulate"
mkdir -p "$dir"
for s in 0 1 2 3 4 5; do
  scan="$dir/lab-station$s-$points"
  [[ -f $scan.ply ]] || "$simulate" --scene lab --station "$s" --points "$points" --seed $((s + 1)) \
    --out "$scan.ply" --gt "$scan.gt.txt" >/dev/null
done
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for src in 0 1 2 3 4 5; do
  for tgt in 0 1 2 3 4 5; do
    ((src < tgt)) || continue
    for seed in $(seq "$seeds"); do
      for build in before after; do
        bin=$before
        [[ $build == after ]] && bin=$after
        start=$(date +%s.%N)
        "$bin" align "$dir/lab-station$src-$points.ply" "$dir/lab-station$tgt-$points.ply" --min-scale "$sigma" \
          --overlap 0.8 --seed "$seed" --threads 2 --gt-source "$dir/lab-station$src-$points.gt.txt" \
          --gt-target "$dir/lab-station$tgt-$points.gt.txt" --json >"$out.json" 2>/dev/null || true
        end=$(date +%s.%N)
        echo "$build $src-$tgt $seed $(echo "$end - $start" | bc) $(/usr/bin/python3 -c '
import json, sys
try:
    j = json.load(open(sys.argv[1]))
    print(j.get("truth", j.get("ground_truth", {})).get("success", "?"))
except Exception:
    print("failed")' "$out.json")" >>"$out"
      done
    done
  done
done
/usr/bin/python3 - "$out" <<'EOF'
import statistics, sys
runs = [line.split() for line in open(sys.argv[1])]
median = {}
for build in ("before", "after"):
    times = [float(r[3]) for r in runs if r[0] == build]
    ok = sum(r[4] in ("True", "true") for r in runs if r[0] == build)
    median[build] = statistics.median(times)
    print(f"{build}: {len(times)} runs, median {median[build]:.2f} s, within the threshold {ok}/{len(times)}")
print(f"after / before: {median['after'] / median['before']:.2f}x")
EOF
