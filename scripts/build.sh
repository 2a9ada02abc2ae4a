#!/usr/bin/env bash
# Installs the Debian packages (if missing), configures and builds everything into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/compiler-cache.sh
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j"$(nproc)"
