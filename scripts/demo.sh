#!/usr/bin/env bash
# The main job: build, simulate two scans of the lab with ground truth, register them locally and
# print the transform and its error against the ground truth.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
out=${K4REG_DEMO_DIR:-out/demo}
mkdir -p "$out"
bin=build/bin
echo "== simulating two 0.7 M-point scans of the lab (stations 0 and 1)"
"$bin/k4reg-simulate" --scene lab --station 0 --points 700000 --seed 1 --out "$out/lab0.ply" --gt "$out/lab0.gt.txt"
"$bin/k4reg-simulate" --scene lab --station 1 --points 700000 --seed 2 --out "$out/lab1.ply" --gt "$out/lab1.gt.txt"
echo "== registering lab0.ply onto lab1.ply (K-4PCS + ICP, sigma = 0.05 m, overlap 0.8)"
"$bin/k4reg" align "$out/lab0.ply" "$out/lab1.ply" --min-scale 0.05 --overlap 0.8 \
  --gt-source "$out/lab0.gt.txt" --gt-target "$out/lab1.gt.txt" --out "$out/lab0_to_lab1.txt"
echo "== transform written to $out/lab0_to_lab1.txt"
