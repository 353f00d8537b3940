#!/usr/bin/env bash
# Benchmarks (Release, Google Benchmark). Extra arguments go to every benchmark binary,
# e.g. deploy/bench.sh --benchmark_filter=Floyd
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/setup.sh build build-bench -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_TESTS=OFF \
  -DDISPATCH_BUILD_BENCHMARKS=ON >/dev/null
for b in routing_bench allocation_bench sim_bench planning_bench; do build-bench/tests/benchmarks/$b "$@"; done
