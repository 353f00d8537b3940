#!/usr/bin/env bash
# The sanitizer runs of the test command (issue 18 §5; deploy/test.sh runs this after the
# suite):
#  1. ASan + UBSan (build-asan/; UBSan without its null and alignment checks; the engine
#     library at -O1, everything else at -O0, which compiles ~40% faster: the build is most
#     of this run's time): every GoogleTest test but six long simulations (below) and the
#     fuzz corpus replays (every input ever kept or found by deploy/fuzz.sh), any report
#     fatal;
#  2. TSan (build-tsan/; the test programs' own files at -O0): the dispatch core's tests
#     (tests/engine/dispatch) and the service's tests that do not serve gRPC (the dispatcher
#     loop and its parts, its worker threads, the order replies, the robot protocol, tokens,
#     config), run directly, no suppressions.
#     The tests that serve gRPC are not run under TSan: Debian's gRPC, abseil and protobuf are
#     not built with it, their own synchronisation is invisible to it, and it reports
#     thousands of races inside them (measured 2026-12-05: 7,500 reports over the seven
#     gRPC test programs, every one with a gRPC, abseil or protobuf frame, none in our code
#     alone); ASan + UBSan and the end-to-end tests cover them.
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
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}
# New build folders use Ninja (deploy/setup.sh says why); an existing one keeps its generator.
generator() { [ -f "$1/CMakeCache.txt" ] || ! command -v ninja >/dev/null || echo "-GNinja"; }
flags=(-DCMAKE_BUILD_TYPE=None "-DCMAKE_CXX_FLAGS=-O1 -g1" -DDISPATCH_BUILD_TESTS=ON)
for run in "${runs[@]}"; do
  start=$(date +%s)
  case "$run" in
    asan)
      # UBSan without its null and alignment checks, which double the engine's compile time at
      # -O1 (measured 2026-12-07): a null dereference still stops the run (ASan reports the
      # SEGV with its stack), and x86 reads misaligned data correctly.
      cmake -S . -B build-asan $(generator build-asan) -DCMAKE_BUILD_TYPE=None "-DCMAKE_CXX_FLAGS=-O0 -g1" \
        -DDISPATCH_ENGINE_CXX_FLAGS=-O1 -DDISPATCH_BUILD_TESTS=ON -DDISPATCH_SANITIZE=address,undefined \
        -DDISPATCH_SANITIZE_SKIP=alignment,null >/dev/null
      # Only what the run executes: every GoogleTest program (with the tools some of them start,
      # their declared dependencies) and the fuzz replays; not the clients nor the tools the
      # end-to-end tests alone use.
      mapfile -t targets < <(find tests -name CMakeLists.txt -exec sed -nE 's/^dispatch_add_test\(([a-z0-9_]+)( .*)?$/\1/p' {} +)
      for h in $(sed -nE 's/^set\(dispatch_fuzz_harnesses (.*)\)/\1/p' fuzz/CMakeLists.txt); do
        targets+=("fuzz_${h}_replay")
      done
      cmake --build build-asan -j "$jobs" --target "${targets[@]}"
      # Six long simulations (30-55 s each under ASan, 4 minutes of CPU in all) run in the plain
      # build only; shorter runs of the same code (teams breaking up, restarts, zone lookups)
      # stay here.
      long='^(CoreStreamTest[.](ABrokenUpFormationHandsItsIntersectionGrantToItsMembers'
      long+='|MembersOnTheirWayStayExemptFromEachOtherWhenTheirTeamBreaksUp'
      long+='|MembersOfABrokenUpTeamStayExemptUntilAllHaveDrivenOff)'
      long+='|TrafficGateTest[.]AFormationOrderCompletesWhateverMomentTheServerRestartsAt'
      long+='|TrafficPredictionZoneAtTest[.]LorrScaleFloorIsFastAndExact'
      long+='|CoreStreamFormationTest[.]RandomStreamsWithFormationsOnChu2024)$'
      ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE e2e -E "$long"
      ;;
    tsan)
      cmake -S . -B build-tsan $(generator build-tsan) "${flags[@]}" -DDISPATCH_SANITIZE=thread \
        -DDISPATCH_TEST_CXX_FLAGS=-O0 >/dev/null
      mapfile -t targets < <(sed -nE 's/^dispatch_add_test\(([a-z_]+) .*/\1/p' tests/engine/dispatch/CMakeLists.txt)
      targets+=(server_dispatcher_parts_test server_worker_thread_test server_order_replies_test
                server_robot_protocol_test server_auth_test server_config_test server_explanation_test)
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
