#!/usr/bin/env bash
# The one test command: install dependencies, build, run every test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cd build
ctest --output-on-failure --timeout 600 -j"$(nproc)"
