#!/usr/bin/env bash
# Installs the Debian 12 packages k4reg needs. Idempotent and non-interactive: packages already present are skipped.
#   install-deps.sh           everything: build, every test suite, sanitizers, fuzzing, benchmarks (CI, development)
#   install-deps.sh --image   only what k4reg-server, k4reg and the unit tests need to compile (the image's build
#                             stage, cmake -DK4REG_BUILD_BENCH=OFF): no PCL (VTK, Qt, MPI, a JDK), clang, prometheus
#   install-deps.sh --demo    only what scripts/demo.sh builds (library, CLI without its remote commands, simulator):
#                             no gRPC, no test frameworks, so a fresh machine reaches its first registration quickly
set -euo pipefail

# The image's build stage; tests/docker/deployment_check.py reads this list (and its apt closure) from here.
IMAGE_PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libtbb-dev libpugixml-dev
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc grpc-proto
  libspdlog-dev libfmt-dev libcli11-dev nlohmann-json3-dev libcpp-httplib-dev libssl-dev
  libjs-three  # three.js r111, compiled into the QA report and the server's page (web/)
  libgtest-dev libgmock-dev
)
# scripts/demo.sh: cmake -DK4REG_BUILD_SERVICE=OFF -DK4REG_BUILD_TESTS=OFF -DK4REG_BUILD_BENCH=OFF.
DEMO_PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libtbb-dev libpugixml-dev
  libspdlog-dev libfmt-dev libcli11-dev nlohmann-json3-dev
  libjs-three  # the QA report (--report) is compiled into the CLI
)
PACKAGES=(
  "${IMAGE_PACKAGES[@]}" git ca-certificates
  libpcl-dev libbenchmark-dev  # the benchmarks (bench/): PCL is the reference they compare with
  python3 python3-grpcio python3-protobuf
  prometheus
  gnuplot-nox yamllint python3-yaml docker-compose curl openssl ccache
  clang libclang-rt-14-dev llvm  # sanitizer and fuzz builds; llvm has llvm-symbolizer for their reports
  chromium chromium-driver python3-selenium  # tests/browser: the report and the page in headless Chromium
)

case "${1:-}" in
  --image) PACKAGES=("${IMAGE_PACKAGES[@]}") ;;
  --demo) PACKAGES=("${DEMO_PACKAGES[@]}") ;;
  "") ;;
  *) echo "usage: $0 [--image | --demo]" >&2; exit 2 ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
