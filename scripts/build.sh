#!/usr/bin/env bash
# Installs the Debian packages (if missing), configures and builds everything into build/. The options are set
# explicitly because build/ may hold scripts/demo.sh's lighter configuration (no service, tests, benchmarks).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/compiler-cache.sh
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release \
  -DK4REG_BUILD_SERVICE=ON -DK4REG_BUILD_TESTS=ON -DK4REG_BUILD_BENCH=ON "$@"
cmake --build build -j"$(nproc)"
