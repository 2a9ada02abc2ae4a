#!/usr/bin/env bash
# bench/run.sh [--quick] [--table2] [--resume | --progress]
# Builds the benchmarks, runs the voxel grid benchmark (Google Benchmark, 5 repetitions, medians), the read
# throughput of every scan format (k4reg-bench-read, 10 M points, about half a minute) and the K-4PCS / 4PCS
# comparison with PCL 1.13, then rewrites the machine, voxel and read blocks of bench/RESULTS.md, the compare-<mode>
# block of bench/results/comparison-with-pcl.md and the files in bench/results/ (CSV, JSON, gnuplot scripts, PNG
# plots, run log). The full run then also measures the paper's Table 2 for our K-4PCS (k4reg-bench-table2: its
# table2 block of bench/RESULTS.md and results/table2-*.csv).
# --quick: a representative subset (about 20 min on 2 cores; Table 2 is left out to stay within that).
#   Without it: the full suites (hours).
# --resume: continue an interrupted comparison from its journal (bench/results/compare-<mode>-journal.jsonl):
#   the runs already made are kept, only the missing ones run (same build and options).
# --progress: while a comparison runs (or after it was interrupted), write its compare block (in
#   bench/results/comparison-with-pcl.md), CSVs and plots
#   from the journal so far and run nothing; partial rows are marked.
# --table2: only k4reg-bench-table2: with --quick its 0.7M, sigma = 50 mm row (all 15 pairs x 10 seeds, about
#   3 min on 2 cores), without it the full grid of 3 sizes x 3 sigmas (about an hour on 2 cores).
# Not part of the test suite. Build directory: $K4REG_BENCH_BUILD_DIR (default build-bench).
set -euo pipefail
cd "$(dirname "$0")/.."

mode=full
quick_flag=()
resume_flag=()
table2_only=false
progress=false
for arg in "$@"; do
  case "$arg" in
    --quick) mode=quick; quick_flag=(--quick) ;;
    --table2) table2_only=true ;;
    --resume) resume_flag=(--resume) ;;
    --progress) progress=true ;;
    *) echo "usage: bench/run.sh [--quick] [--table2] [--resume | --progress]" >&2; exit 2 ;;
  esac
done
build=${K4REG_BENCH_BUILD_DIR:-build-bench}
results=bench/results
markdown=bench/RESULTS.md
comparison=bench/results/comparison-with-pcl.md   # the compare-<mode> blocks (k4reg-bench-compare's own default is $markdown)
mkdir -p "$results"

# Replaces the lines between "<!-- NAME:begin -->" and "<!-- NAME:end -->" of FILE by CONTENT_FILE
# (appends the block when the markers are missing).
replace_block() {
  local file=$1 name=$2 content=$3
  touch "$file"
  if grep -q "<!-- $name:begin -->" "$file"; then
    awk -v b="<!-- $name:begin -->" -v e="<!-- $name:end -->" -v c="$content" '
      $0 == b { print; while ((getline line < c) > 0) print line; skip = 1; next }
      $0 == e { skip = 0 }
      !skip { print }' "$file" > "$file.tmp"
    mv "$file.tmp" "$file"
  else
    { echo; echo "<!-- $name:begin -->"; cat "$content"; echo "<!-- $name:end -->"; } >> "$file"
  fi
}

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DK4REG_BUILD_BENCH=ON -DK4REG_BUILD_SERVICE=OFF \
  -DK4REG_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j"$(nproc)" --target voxel_grid_bench k4reg-bench-compare k4reg-bench-read \
  k4reg-bench-table2
compare="$build/bin/k4reg-bench-compare"

# Shares the cache of simulated scans with the comparison; rebuilds the table2 block after every row.
table2() {
  "$build/bin/k4reg-bench-table2" "${quick_flag[@]}" --cache-dir "$build/bench-cache" --results-dir "$results" \
    --markdown "$markdown" 2>&1 | tee "$results/table2-$mode.log"
}
# The comparison's gnuplot scripts carry their data: each writes its PNG next to itself.
plots() {
  if command -v gnuplot > /dev/null; then
    for plot in "$results"/compare-"$mode"-*.gp; do
      (cd "$results" && gnuplot "$(basename "$plot")")
    done
  else
    echo "gnuplot not found: plots not made" >&2
  fi
}
if $progress; then
  "$compare" "${quick_flag[@]}" --resume --report-only --cache-dir "$build/bench-cache" --results-dir "$results" \
    --markdown "$comparison"
  plots
  exit 0
fi
if $table2_only; then
  table2
  echo "bench/run.sh: done (Table 2, $mode); see $markdown and $results/"
  exit 0
fi

machine=$(mktemp)
trap 'rm -f "$machine"' EXIT
{
  echo "### Machine and how to reproduce"
  echo
  echo "- Date: $(date -u '+%Y-%m-%d %H:%M UTC') ($mode run)"
  echo "- CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//'), nproc = $(nproc)"
  echo "- Memory: $(free -g | awk '/^Mem:/ {print $2}') GB; OS: $(. /etc/os-release && echo "$PRETTY_NAME"), kernel $(uname -r)"
  echo "- Compiler: $(c++ --version | head -1); PCL $(dpkg-query -W -f '${Version}' libpcl-dev 2>/dev/null || echo '?')," \
       "Google Benchmark $(dpkg-query -W -f '${Version}' libbenchmark-dev 2>/dev/null || echo '?'), Release build"
  echo "- Source: commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- core tools bench 2>/dev/null || echo ' with uncommitted changes in core/, tools/ or bench/')"
  echo "- Load average when starting: $(cut -d' ' -f1-3 /proc/loadavg) – the machine is shared with other work," \
       "so absolute times are noisy; compare the columns of one run with each other."
  echo "- Reproduce: \`bench/run.sh${quick_flag:+ --quick}\` (builds into \`$build\`, runs" \
       "\`voxel_grid_bench --benchmark_repetitions=5\`, \`k4reg-bench-read\` and \`k4reg-bench-compare${quick_flag:+ --quick}\`)."
} > "$machine"
replace_block "$markdown" machine "$machine"

read_table=$(mktemp)
trap 'rm -f "$machine" "$read_table"' EXIT
{
  echo "### Read throughput: one 10 M-point cloud in every format"
  echo
  echo "Random points with intensity in a 200 m block at 500 000 E / 5 240 000 N, written by the core's writers, read"
  echo "with \`read_cloud\` from the page cache (median of 3 after one warm-up read; load average $(cut -d' ' -f1 /proc/loadavg))."
  echo
  "$build/bin/k4reg-bench-read" --repeats 3
} > "$read_table"
replace_block "$markdown" read "$read_table"

"$build/bin/voxel_grid_bench" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out="$results/voxel_grid_bench.json" --benchmark_out_format=json
"$compare" voxel-report --json "$results/voxel_grid_bench.json" --markdown "$markdown" > /dev/null

"$compare" "${quick_flag[@]}" "${resume_flag[@]}" --cache-dir "$build/bench-cache" --results-dir "$results" \
  --markdown "$comparison" 2>&1 | tee ${resume_flag:+-a} "$results/compare-$mode.log"

plots
if [[ $mode == full ]]; then table2; fi
echo "bench/run.sh: done ($mode); see $markdown, $comparison and $results/"
