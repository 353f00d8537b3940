#!/usr/bin/env bash
# The main job: builds the engine and shows the built-in Chu2024 floor: its summary, a sample
# of Floyd routes with lengths and travel times, an SVG rendering of the floor, and the
# auction's allocation of the seed's task tables.
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
scenarios=../shared/scenarios
if [ -f "$scenarios/chu2024-table2.csv" ]; then
  echo
  echo "== Auction allocation of seed 000 Table 2, without and with traffic prediction (Tables 3, 4) =="
  build-release/engine/cli/dispatch-alloc --table "$scenarios/chu2024-table2.csv"
  echo
  echo "== Table 1 (mixed single and formation tasks), auction vs. greedy nearest-idle =="
  build-release/engine/cli/dispatch-alloc --table "$scenarios/chu2024-table1.csv" --zeta 100
  build-release/engine/cli/dispatch-alloc --table "$scenarios/chu2024-table1.csv" --strategy greedy --zeta 0
else
  echo "(no $scenarios beside the repository: the seed task tables are skipped)"
fi
