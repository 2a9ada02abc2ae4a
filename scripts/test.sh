#!/usr/bin/env bash
# The one test command (CI runs it and nothing else): install dependencies, build, run every test suite; then the
# tests again under AddressSanitizer + UndefinedBehaviorSanitizer (scripts/sanitize.sh, own build folder) and every
# fuzzer for a bounded time (scripts/fuzz.sh, own build folder). Each step fails the run.
# Quick local run: K4REG_SKIP_SANITIZERS=1 and/or K4REG_SKIP_FUZZ=1 (K4REG_FUZZ_SECONDS sets the fuzzing time).
set -euo pipefail
cd "$(dirname "$0")/.."
step() { echo "==== scripts/test.sh: $1 ($(date -u +%H:%M:%S))"; }

step "build"
bash scripts/build.sh
step "tests"
(cd build && ctest --output-on-failure --timeout 600 -j"$(nproc)")
if [ "${K4REG_SKIP_SANITIZERS:-0}" = 1 ]; then
  step "sanitizer tests skipped (K4REG_SKIP_SANITIZERS=1)"
else
  step "sanitizer tests: ASan + UBSan build and ctest (scripts/sanitize.sh)"
  bash scripts/sanitize.sh
fi
if [ "${K4REG_SKIP_FUZZ:-0}" = 1 ]; then
  step "fuzzing skipped (K4REG_SKIP_FUZZ=1)"
else
  step "fuzzing: every fuzzer for ${K4REG_FUZZ_SECONDS:-45} s (scripts/fuzz.sh)"
  bash scripts/fuzz.sh
fi
step "all passed"
