#!/usr/bin/env bash
# Memory soak (issue 15 §3b): dispatchd on the Chu2024 floor with fleet-sim's 18 robots, the web
# map's order list polled once a second over REST, and BATCHES batches of 10 orders (seed 000
# Table 1 and the single-robot tasks of Table 2) submitted through wmsctl, each batch waited
# for. After every batch it prints dispatchd's resident memory (VmRSS) against the orders
# finished so far, then restarts dispatchd on the same database and runs 3 batches more.
# A flat line is the target: memory must not grow with the number of orders ever served.
# Not part of the test suite (minutes of wall time). Environment: BATCHES (default 20),
# BIN (default build-release, built when missing), POLL (default 1: poll GET /api/v1/orders),
# RETAINED (default 1000: dispatchd --finished-retained, the finished orders kept in memory).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BIN:-build-release}
if [ ! -x "$bin/server/dispatchd" ]; then
  bash deploy/setup.sh build "$bin" -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_TESTS=OFF >/dev/null
fi
batches=${BATCHES:-20}
poll=${POLL:-1}
retained=${RETAINED:-1000}
run=$(mktemp -d /tmp/dispatch-soak.XXXXXX)
scenarios=$(cd .. && pwd)/shared/scenarios
{
  echo "task,formation,picks,drop"
  grep -E '^[0-9]+,' "$scenarios/chu2024-table1.csv"
  grep -E '^[0-9]+,0,' "$scenarios/chu2024-table2.csv" | awk -F, 'BEGIN{OFS=","} {$1 = $1 + 6; print}'
} >"$run/batch.csv"

server_pid="" fleet_pid="" poll_pid=""
stop_all() {
  for p in $poll_pid $fleet_pid $server_pid; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  return 0
}
trap stop_all EXIT

start_server() {  # start_server GRPC_PORT HTTP_PORT: sets grpc, http, server_pid
  rm -f "$run/ports.json"
  "$bin/server/dispatchd" --bind 127.0.0.1 --grpc-port "$1" --http-port "$2" --db "$run/dispatch.db" \
    --map chu2024 --time-scale 10 --finished-retained "$retained" --log-level warn --ports-file "$run/ports.json" >>"$run/dispatchd.log" 2>&1 &
  server_pid=$!
  for _ in $(seq 300); do [ -s "$run/ports.json" ] && break; sleep 0.1; done
  [ -s "$run/ports.json" ] || { echo "soak: dispatchd did not start" >&2; cat "$run/dispatchd.log" >&2; exit 1; }
  grpc=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['grpc_port'])" "$run/ports.json")
  http=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['http_port'])" "$run/ports.json")
}

finished=0
sample() {  # sample LABEL
  printf "%-12s orders finished %4d   dispatchd VmRSS %6d kB\n" "$1" "$finished" \
    "$(awk '/^VmRSS/ {print $2}' "/proc/$server_pid/status")"
}

run_batches() {  # run_batches FROM TO
  for b in $(seq "$1" "$2"); do
    timeout 300 "$bin/clients/wmsctl" --server "127.0.0.1:$grpc" --timeout 30 submit "$run/batch.csv" \
      --prefix "soak$b-" --wait >"$run/wmsctl.$b.txt" 2>&1 || true
    finished=$((finished + $(grep -cE '^ord-[0-9]+ .* (completed|failed|cancelled) ' "$run/wmsctl.$b.txt" || true)))
    sample "batch $b"
  done
}

start_server 0 0
mkfifo "$run/fleet-ready"
"$bin/clients/fleet-sim" --server "127.0.0.1:$grpc" --robots 18 --ready-fd 4 4>"$run/fleet-ready" \
  >"$run/fleet-sim.log" 2>&1 &
fleet_pid=$!
read -r -t 60 _ <"$run/fleet-ready" || { echo "soak: fleet-sim did not connect" >&2; exit 1; }
if [ "$poll" = 1 ]; then
  python3 - "http://127.0.0.1:$http/api/v1/orders" <<'PY' &
import sys, time, urllib.request
for _ in range(3600):  # at most an hour, as the web map does: once a second
    try:
        urllib.request.urlopen(sys.argv[1], timeout=5).read()
    except OSError:
        pass
    time.sleep(1)
PY
  poll_pid=$!
fi
sample "start"
run_batches 1 "$batches"
kill -TERM "$server_pid"; wait "$server_pid" 2>/dev/null || true
start_server "$grpc" "$http"
sleep 5
sample "restarted"
run_batches $((batches + 1)) $((batches + 3))
echo "soak: logs and results in $run"
