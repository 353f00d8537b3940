#!/usr/bin/env bash
# The main job: builds the engine and shows the built-in Chu2024 floor: its summary, a sample
# of Floyd routes with lengths and travel times, and an SVG rendering of the floor.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/setup.sh build build-release -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_TESTS=OFF \
  >/dev/null
bin=build-release/engine/cli/dispatch-map
echo "== The Chu2024 floor (seed 000 §4.1, reconstructed: engine/map/chu2024_floor.md) =="
"$bin" summary --map chu2024
echo
echo "== Floyd routes (seed 000 §3.1), speed 1 m/s =="
"$bin" routes --map chu2024
echo
"$bin" svg --map chu2024 --out build-release/chu2024.svg
echo "Open build-release/chu2024.svg in a browser to see the floor."
