#!/usr/bin/env bash
# The whole test suite: installs what it needs, builds (warnings are errors) and runs CTest
# (unit, fuzz replay and end-to-end tests), then the sanitizer runs (deploy/sanitizers.sh:
# ASan + UBSan, TSan). Arguments go to CTest (e.g. -R Name) and then skip the sanitizer runs;
# DISPATCH_SANITIZERS=0 skips them too.
set -euo pipefail
cd "$(dirname "$0")/.."
# -O2 without debug information: the same code as RelWithDebInfo, compiled and linked faster
# (the sanitizer builds keep -g1 for their reports); the test programs' own files at -O0
# (a third less compile time for them; the code under test keeps -O2).
DISPATCH_TEST_DEPS=1 bash deploy/setup.sh build build -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -DNDEBUG" -DDISPATCH_BUILD_TESTS=ON -DDISPATCH_WERROR=ON \
  -DDISPATCH_TEST_CXX_FLAGS=-O0
ctest --test-dir build --output-on-failure -j "$(nproc)" "$@"
if [ $# -eq 0 ] && [ "${DISPATCH_SANITIZERS:-1}" = 1 ]; then
  bash deploy/sanitizers.sh
fi
