#!/usr/bin/env bash
# The League of Robot Runners 2024 instances (issue 19 §3) through the product's allocation and
# planning (dispatch-sim lorr), each output replayed by the project's checker (lorr-check), and
# one table: tasks finished against the start kit's defaults measured on this kind of machine
# and the best published figures, planning time per step, wall time and peak memory.
# Release build; not part of the test suite (the long instances take minutes).
# Environment: INSTANCES (default "random sortation warehouse"), WAREHOUSE_STEPS (default 5000),
# PLAN_MS (default 0: no per-step limit; 100 counts entry timeouts as the competition would),
# ROUTE_TABLE (default floyd: dense on the random floor, the lazy table with a 4 GiB cache on
# the large ones; hub_labels: no cache, a few hundred MB).
# Outputs (the competition's JSON): build-release/bench/lorr_*.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/setup.sh build build-release -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_TESTS=OFF >/dev/null
sim=build-release/engine/cli/dispatch-sim
out=build-release/bench
mkdir -p "$out"
problems=../shared/benchmarks/lorr2024/example_problems
plan_ms=${PLAN_MS:-0}
route_table=${ROUTE_TABLE:-floyd}

# name problem steps start-kit best
declare -A problem=([random]=random.domain/random_32_32_20_100.json
                    [sortation]=warehouse.domain/sortation_large_2000.json
                    [warehouse]=warehouse.domain/warehouse_large_5000.json)
declare -A steps=([random]=500 [sortation]=2000 [warehouse]=${WAREHOUSE_STEPS:-5000})
declare -A start_kit=([random]=896 [sortation]=9361 [warehouse]=27741)
declare -A best=([random]=1186 [sortation]=15508 [warehouse]=94232)
if [ "${WAREHOUSE_STEPS:-5000}" = 1000 ]; then start_kit[warehouse]=4878; best[warehouse]=-; fi

rows=()
for name in ${INSTANCES:-random sortation warehouse}; do
  json=$out/lorr_$name.json
  log=$out/lorr_$name.log
  /usr/bin/time -f "wall %e s, peak %M KB" "$sim" lorr --problem "$problems/${problem[$name]}" \
    --steps "${steps[$name]}" --plan-ms "$plan_ms" --route-table "$route_table" --output "$json" >"$log" 2>&1
  "$sim" lorr-check --problem "$problems/${problem[$name]}" --output "$json" >"$out/lorr_$name.check" 2>&1 ||
    { echo "bench_lorr: $name: the checker refused the output:"; tail -5 "$out/lorr_$name.check"; exit 1; }
  cat "$log"
  finished=$(sed -n 's/^tasks finished \([0-9]*\),.*/\1/p' "$log")
  planning=$(sed -n 's/^planning per step: mean \([0-9.]*\) ms, max \([0-9.]*\) ms.*/\1 \/ \2/p' "$log")
  wall=$(sed -n 's/^wall \(.*\)/\1/p' "$log")
  rows+=("$(printf '| %-36s | %5s | %6s | %6s | %6s | %-20s | %-28s |' "${problem[$name]##*/}" "${steps[$name]}" \
    "$finished" "${start_kit[$name]}" "${best[$name]}" "$planning" "$wall")")
done
echo
echo "| instance                             | steps | tasks  | kit    | best   | plan ms mean / max   | run                          |"
echo "|--------------------------------------|-------|--------|--------|--------|----------------------|------------------------------|"
printf '%s\n' "${rows[@]}"
