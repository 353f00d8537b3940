#!/usr/bin/env bash
# The whole test suite: installs what it needs, builds (warnings are errors) and runs CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
DISPATCH_TEST_DEPS=1 bash deploy/setup.sh build build -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDISPATCH_BUILD_TESTS=ON \
  -DDISPATCH_WERROR=ON
ctest --test-dir build --output-on-failure -j "$(nproc)" "$@"
