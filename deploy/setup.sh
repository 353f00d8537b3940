#!/usr/bin/env bash
# Installs the Debian packages the build needs (idempotent: apt-get runs only when a package
# is missing) and configures + builds the project into a build folder.
#   deploy/setup.sh packages            install packages only
#   deploy/setup.sh build DIR [ARGS..]  packages, then configure DIR with ARGS and build it
# With DISPATCH_TEST_DEPS=1 it also installs what only the tests use (deploy/test.sh sets it):
# headless Chromium and python3-websocket for the web map's browser test; with
# DISPATCH_FUZZ_DEPS=1 (deploy/fuzz.sh) clang and its runtime libraries (libFuzzer).
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  g++ cmake make ninja-build pkg-config lld
  libeigen3-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libsqlite3-dev
  libspdlog-dev libcpp-httplib-dev prometheus-cpp-dev libssl-dev openssl
  python3 python3-grpcio python3-protobuf
)
if [ "${DISPATCH_TEST_DEPS:-0}" = 1 ]; then
  PACKAGES+=(chromium python3-websocket)
fi
if [ "${DISPATCH_FUZZ_DEPS:-0}" = 1 ]; then  # deploy/fuzz.sh: clang's libFuzzer and sanitizers
  PACKAGES+=(clang libclang-rt-dev)
fi

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "setup: installing ${missing[*]}"
  local sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# A new build folder is configured for Ninja: it keeps both cores busy across targets, where
# Make compiles none of a target's files before its libraries are built (the ASan build of
# deploy/sanitizers.sh: 15 min with Ninja, 21.5 with Make, measured 2026-12-06). A folder
# configured before keeps its generator.
generator() { [ -f "$1/CMakeCache.txt" ] || ! command -v ninja >/dev/null || echo "-GNinja"; }

build() {
  local dir=$1; shift
  cmake -S . -B "$dir" $(generator "$dir") "$@" >/dev/null
  cmake --build "$dir" -j "$(nproc)"
}

case "${1:-packages}" in
  packages) install_packages ;;
  build) shift; install_packages; build "$@" ;;
  *) echo "usage: $0 packages | build DIR [CMAKE_ARGS...]" >&2; exit 2 ;;
esac
