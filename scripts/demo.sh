#!/usr/bin/env bash
# The main job: build what the demo runs, simulate two scans of the lab with ground truth, register them locally
# and print the transform and its error against the ground truth. It installs and builds only the library, the
# CLI (local commands) and the simulator, so a fresh machine gets its first result quickly; scripts/test.sh
# installs and builds everything else (service, tests, benchmarks) into the same build/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/compiler-cache.sh
bash scripts/install-deps.sh --demo
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release \
  -DK4REG_BUILD_SERVICE=OFF -DK4REG_BUILD_TESTS=OFF -DK4REG_BUILD_BENCH=OFF
cmake --build build -j"$(nproc)" --target k4reg k4reg-simulate
out=${K4REG_DEMO_DIR:-out/demo}
mkdir -p "$out"
bin=build/bin
echo "== simulating two 0.7 M-point scans of the lab (stations 0 and 2)"
"$bin/k4reg-simulate" --scene lab --station 0 --points 700000 --seed 1 --out "$out/lab0.ply" --gt "$out/lab0.gt.txt"
"$bin/k4reg-simulate" --scene lab --station 2 --points 700000 --seed 2 --out "$out/lab2.ply" --gt "$out/lab2.gt.txt"
echo "== registering lab0.ply onto lab2.ply (K-4PCS + ICP, sigma = 0.05 m, overlap 0.8)"
"$bin/k4reg" align "$out/lab0.ply" "$out/lab2.ply" --min-scale 0.05 --overlap 0.8 \
  --gt-source "$out/lab0.gt.txt" --gt-target "$out/lab2.gt.txt" --out "$out/lab0_to_lab2.txt"
echo "== transform written to $out/lab0_to_lab2.txt"
