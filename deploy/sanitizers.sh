#!/usr/bin/env bash
# The sanitizer runs of the test command (issue 18 §5; deploy/test.sh runs this after the
# suite):
#  1. ASan + UBSan (build-asan/, -O1): every GoogleTest test and the fuzz corpus replays
#     (every input ever kept or found by deploy/fuzz.sh), any report fatal;
#  2. TSan (build-tsan/): the service's tests (tests/server: in-process dispatchd with real gRPC
#     and REST, the dispatcher loop, its workers) and the dispatch core's
#     (tests/engine/dispatch), run directly.
# The end-to-end tests (separate processes, Python) run in the plain build only.
#   deploy/sanitizers.sh [asan|tsan]...      (default: both)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=("$@")
[ ${#runs[@]} -gt 0 ] || runs=(asan tsan)
jobs=$(nproc)
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/deploy/sanitizers/lsan.supp}
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/deploy/sanitizers/tsan.supp}
flags=(-DCMAKE_BUILD_TYPE=None "-DCMAKE_CXX_FLAGS=-O1 -g1" -DDISPATCH_BUILD_TESTS=ON)
for run in "${runs[@]}"; do
  start=$(date +%s)
  case "$run" in
    asan)
      cmake -S . -B build-asan "${flags[@]}" -DDISPATCH_SANITIZE=address,undefined >/dev/null
      cmake --build build-asan -j "$jobs"
      ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE e2e
      ;;
    tsan)
      cmake -S . -B build-tsan "${flags[@]}" -DDISPATCH_SANITIZE=thread >/dev/null
      mapfile -t targets < <(sed -nE 's/^dispatch_add_test\(([a-z_]+) .*/\1/p' \
        tests/server/CMakeLists.txt tests/engine/dispatch/CMakeLists.txt)
      cmake --build build-tsan -j "$jobs" --target "${targets[@]}"
      for t in "${targets[@]}"; do
        bin=$(find build-tsan/tests -type f -name "$t" -perm -u+x | head -n 1)
        echo "tsan: $t"
        "$bin" --gtest_brief=1
      done
      ;;
    *) echo "usage: $0 [asan|tsan]..." >&2; exit 2 ;;
  esac
  echo "sanitizers: $run clean in $(( $(date +%s) - start )) s"
done
