#!/usr/bin/env bash
# The formation burst through the service (issue 16 §5): real dispatchd (SQLite on disk) and
# fleet-sim's 18 robots on the Chu2024 floor, seed Tables 1 and 2 submitted REPEAT times each at
# once by wmsctl; prints the order states every POLL wall seconds until none is open or
# WALL_LIMIT wall seconds have passed, then the robots' states and dispatchd's traffic figures.
# Not part of the test suite (minutes of wall time). Extra arguments go to dispatchd, e.g.
#   bash deploy/burst_service.sh --planner time-windows
#   bash deploy/burst_service.sh --formation-max-queue 0 --one-formation-per-pick false
# Environment: REPEAT (10), TIME_SCALE (20), POLL (10), WALL_LIMIT (300).
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/setup.sh build build-release -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_TESTS=OFF >/dev/null
bin=build-release
scenarios=../shared/scenarios
run=$bin/burst
rm -rf "$run" && mkdir -p "$run"
repeat=${REPEAT:-10}
poll=${POLL:-10}
wall_limit=${WALL_LIMIT:-300}

"$bin/server/dispatchd" --map chu2024 --db "$run/dispatch.db" --grpc-port 0 --http-port 0 \
  --ports-file "$run/ports.json" --time-scale "${TIME_SCALE:-20}" --log-level warn "$@" >"$run/dispatchd.log" 2>&1 &
dispatchd=$!
fleet=""
stop_all() {
  [ -n "$fleet" ] && kill "$fleet" 2>/dev/null || true
  kill "$dispatchd" 2>/dev/null || true
  wait 2>/dev/null || true
}
trap stop_all EXIT
for _ in $(seq 1 100); do [ -s "$run/ports.json" ] && break; sleep 0.1; done
port() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$run/ports.json" "$1"; }
grpc=127.0.0.1:$(port grpc_port)
http=http://127.0.0.1:$(port http_port)
"$bin/clients/fleet-sim" --server "$grpc" --robots 18 >"$run/fleet-sim.log" 2>&1 &
fleet=$!
for _ in $(seq 1 100); do
  curl -s "$http/api/v1/status" | grep -q '"connected":18' && break
  sleep 0.1
done
for k in $(seq 1 "$repeat"); do
  "$bin/clients/wmsctl" --server "$grpc" submit "$scenarios/chu2024-table1.csv" --prefix "t1x$k-" >/dev/null
  "$bin/clients/wmsctl" --server "$grpc" submit "$scenarios/chu2024-table2.csv" --prefix "t2x$k-" >/dev/null
done
echo "submitted $((14 * repeat)) orders (Tables 1 and 2 x $repeat), dispatchd $*"
start=$SECONDS
while :; do
  sleep "$poll"
  status=$(curl -s "$http/api/v1/status")
  line=$(echo "$status" | python3 -c "
import json, sys
d = json.load(sys.stdin); o = d['orders']
open_ = o['accepted'] + o['assigned'] + o['in_progress']
print(f\"t = {d['time']:.0f} s: {o['completed']} completed, {o['failed']} failed, {o['cancelled']} cancelled, {open_} open\")")
  echo "$line"
  case "$line" in *", 0 open") break ;; esac
  if [ $((SECONDS - start)) -ge "$wall_limit" ]; then
    echo "(stopped after $wall_limit wall seconds with orders still open)"
    break
  fi
done
curl -s "$http/api/v1/robots" | python3 -c "
import collections, json, sys
d = json.load(sys.stdin); robots = d.get('robots', d)
print('robots:', dict(collections.Counter(r.get('state', '?') for r in robots)))"
