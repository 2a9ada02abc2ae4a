#!/usr/bin/env bash
# k4reg's project registration (`k4reg align-project`) side by side with Open3D's multiway registration recipe
# (bench/open3d_project.py) on the same projects, every scan scored against the ground truth.
#
#   bench/project_vs_open3d.sh [PROJECT ...]     (from the repository root; default: every project below)
#
# Per project, one after the other on the same files: k4reg align-project SCANS --min-scale S --overlap O
# --seed 1 --threads 2 --json, then open3d_project.py --voxel S (OMP_NUM_THREADS=2); wall time of each as
# measured here. Each scan's error: RMS over its points (a fixed stride sample of <= 20 000) of
# |pose_rel p - gt_rel p|, gt_rel = inv(GT_ref) GT_scan, pose_rel = inv(pose_ref) pose_scan (reference = the
# first scan). Correct under the project's limit; a k4reg scan with "registered": false is "not registered".
# Prints a Markdown table; per-scan errors go to bench/results/project-vs-open3d.csv (rewritten each run).
# Environment: CSV (default above), K4REG (binary), CACHE (simulated scans, NAME.ply + NAME.gt.txt), DATA (shared/data), WORK
# (scratch: results JSON, logs, the bunny's moved scans).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
K4REG=${K4REG:-$ROOT/build/bin/k4reg}
CACHE=${CACHE:-$ROOT/build-bench/bench-cache}
DATA=${DATA:-$ROOT/../shared/data}
WORK=${WORK:-${TMPDIR:-/tmp}/project-vs-open3d}
PY=/usr/bin/python3  # system Python: python3-open3d, numpy
CSV=${CSV:-$ROOT/bench/results/project-vs-open3d.csv}
ROWS=$WORK/table-rows.md
mkdir -p "$WORK" "$(dirname "$CSV")"
echo "project,tool,scan,file,status,error_m,limit_m" >"$CSV"
: >"$ROWS"
now() { date +%s.%N; }

# The bunny's ten scans are in one frame (bun.conf): like k4reg-bench-project, move each by a random rigid motion
# (uniform rotation, translation up to 0.2 m per axis, seed 1000 + i) and compose its truth with the inverse
# motion; the truth into bun000's frame is chained through gt_pairs.log as the benchmark does. Written as
# float32 PLY + .gt.txt in $WORK/bunny for both tools.
prepare_bunny() {
  "$PY" - "$DATA/stanford-bunny-scans" "$WORK/bunny" "$@" <<'EOF'
import os, sys
import numpy as np, open3d as o3d
folder, out, files = sys.argv[1], sys.argv[2], sys.argv[3:]
os.makedirs(out, exist_ok=True)
lines = [l for l in open(os.path.join(folder, "gt_pairs.log")) if l.strip() and not l.startswith("#")]
pairs = [(*lines[k].split()[:2], np.loadtxt(lines[k + 1:k + 5])) for k in range(0, len(lines), 5)]
to_first, grew = {files[0]: np.identity(4)}, True
while grew:
    grew = False
    for s, t, T in pairs:  # T maps s into t
        if t in to_first and s not in to_first: to_first[s], grew = to_first[t] @ T, True
        elif s in to_first and t not in to_first: to_first[t], grew = to_first[s] @ np.linalg.inv(T), True
for i, f in enumerate(files):
    rng = np.random.default_rng(1000 + i)
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)  # Eigen::Quaterniond(w, x, y, z), as random_motion.cpp
    m = np.identity(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                 [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                 [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    p = np.asarray(o3d.io.read_point_cloud(os.path.join(folder, f)).points)
    name = os.path.join(out, os.path.splitext(f)[0])
    with open(name + ".ply", "wb") as o:
        o.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                b"property float x\nproperty float y\nproperty float z\nend_header\n" % len(p))
        o.write((p @ m[:3, :3].T + m[:3, 3]).astype("<f4").tobytes())
    np.savetxt(name + ".gt.txt", to_first[f] @ np.linalg.inv(m), fmt="%.17g")
EOF
}

# Scores both tools' results of one project: a CSV line per scan and tool, a Markdown table row.
score() {  # NAME LIMIT K4REG_SECONDS OPEN3D_SECONDS SCAN...
  "$PY" - "$CSV" "$ROWS" "$WORK" "$@" <<'EOF'
import json, math, sys
import numpy as np, open3d as o3d
csv, rows, work, name, limit, k4_s, o3_s, scans = *sys.argv[1:8], sys.argv[8:]
limit = float(limit)
gt = [np.loadtxt(s[:-4] + ".gt.txt") for s in scans]

def sample(path):
    p = np.asarray(o3d.io.read_point_cloud(path).points)
    return p[::max(1, math.ceil(len(p) / 20000))]

pts = [sample(s) for s in scans]

def load(tool):  # [(pose or None if not registered)], reference index; None if the run left no result
    try:
        d = json.load(open(f"{work}/{name}.{tool}.json"))
    except (OSError, ValueError):
        return None, 0
    poses = [np.array(s["pose"]).reshape(4, 4) if s.get("registered", True) else None for s in d["scans"]]
    return poses, d.get("reference", 0)

def errors(tool):  # per scan: (status, error)
    poses, ref = load(tool)
    if poses is None or len(poses) != len(scans):
        return [("failed", math.nan)] * len(scans)
    out = []
    for i, pose in enumerate(poses):
        if pose is None or poses[ref] is None:
            out.append(("not registered", math.nan))
            continue
        d = np.linalg.inv(poses[ref]) @ pose - np.linalg.inv(gt[ref]) @ gt[i]
        e = math.sqrt(np.mean(np.sum((pts[i] @ d[:3, :3].T + d[:3, 3]) ** 2, axis=1)))
        out.append(("correct" if e < limit else "wrong", e))
    return out

cells = [name, str(len(scans))]
with open(csv, "a") as f:
    for tool, secs in (("k4reg", k4_s), ("open3d", o3_s)):
        res = errors(tool)
        for i, (status, e) in enumerate(res):
            f.write(f"{name},{tool},{i},{scans[i].split('/')[-1]},{status},{e:.6g},{limit:g}\n")
        n = {k: sum(s == k for s, _ in res) for k in ("correct", "not registered", "wrong", "failed")}
        errs = [e for i, (s, e) in enumerate(res) if i > 0 and not math.isnan(e)]  # reference left out
        spread = f"{np.median(errs):.3g} / {max(errs):.3g}" if errs else "–"
        counts = [n["correct"]] + ([n["not registered"]] if tool == "k4reg" else [])
        counts.append(n["wrong"] if not n["failed"] else f'{n["wrong"]} (+{n["failed"]} failed)')
        cells += [str(c) for c in counts] + [spread, f"{float(secs):.1f}"]
open(rows, "a").write("| " + " | ".join(cells) + " |\n")
EOF
}

run_project() {  # NAME SIGMA OVERLAP LIMIT SCAN...
  local name=$1 sigma=$2 overlap=$3 limit=$4 t0 t1 t2 rc
  shift 4
  if [[ ${#SELECTED[@]} -gt 0 && " ${SELECTED[*]} " != *" $name "* ]]; then return; fi
  for s in "$@"; do [[ -f $s && -f ${s%.ply}.gt.txt ]] || { echo "$name: missing $s or its .gt.txt, left out" >&2; return; }; done
  echo "== $name: $# scans, sigma $sigma, overlap $overlap, limit $limit" >&2
  rm -f "$WORK/$name.k4reg.json" "$WORK/$name.open3d.json"
  t0=$(now)
  rc=0; "$K4REG" align-project "$@" --min-scale "$sigma" --overlap "$overlap" --seed 1 --threads 2 --json \
    >"$WORK/$name.k4reg.json" 2>"$WORK/$name.k4reg.log" || rc=$?
  t1=$(now)
  [[ $rc == 0 ]] || echo "$name: k4reg exited $rc (see $WORK/$name.k4reg.log)" >&2
  rc=0; OMP_NUM_THREADS=2 "$PY" "$ROOT/bench/open3d_project.py" --voxel "$sigma" --out "$WORK/$name.open3d.json" "$@" \
    2>"$WORK/$name.open3d.log" || rc=$?
  t2=$(now)
  [[ $rc == 0 ]] || echo "$name: open3d_project.py exited $rc (see $WORK/$name.open3d.log)" >&2
  score "$name" "$limit" "$(awk "BEGIN { print $t1 - $t0 }")" "$(awk "BEGIN { print $t2 - $t1 }")" "$@"
  tail -n 1 "$ROWS" >&2
}

SELECTED=("$@")
C=$CACHE
run_project hall-L0-4st 0.1 0.4 0.05 "$C"/hall-station{0-700000-seed1,1-700000-seed2,2-700000-seed3,4-700000-seed5}.ply
run_project hall-L3-4st 0.1 0.4 0.05 "$C"/hall-layout3-station{0-700000-seed1,1-700000-seed2,2-700000-seed3,4-700000-seed5}.ply
run_project monument-L0-3st 0.1 0.4 0.1 "$C"/monument-station{0-700000-seed1,1-700000-seed2,2-700000-seed3}.ply
run_project courtyard-L0-4st 0.1 0.4 0.1 "$C"/courtyard-station{0-700000-seed1,1-700000-seed2,2-700000-seed3,3-700000-seed4}.ply
OBJECT=(); for i in {0..9}; do OBJECT+=("$C/object-layout1-station$i-40000-seed$((i + 1)).ply"); done
run_project object-L1-10st 0.002 0.5 0.001 "${OBJECT[@]}"
BUNNY=(bun000.ply bun045.ply bun090.ply bun180.ply bun270.ply bun315.ply chin.ply ear_back.ply top2.ply top3.ply)
if [[ ${#SELECTED[@]} -eq 0 || " ${SELECTED[*]} " == *" bunny-10 "* ]]; then
  prepare_bunny "${BUNNY[@]}"  # k4reg-bench-project's order
  run_project bunny-10 0.002 0.5 0.001 "${BUNNY[@]/#/$WORK/bunny/}"
fi

echo
echo "| project | scans | k4reg correct | k4reg not registered | k4reg wrong | k4reg error median / worst (m) | k4reg wall s | Open3D correct | Open3D wrong | Open3D error median / worst (m) | Open3D wall s |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
cat "$ROWS"
