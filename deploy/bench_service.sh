#!/usr/bin/env bash
# Service benchmarks (issue 6 §4): real dispatchd + fleet-sim + load clients on loopback,
# Release build, SQLite on disk. Not part of the test suite (minutes of wall time).
#   1. Order intake: SubmitOrder throughput and p50/p99 (order-load, 8 calls in flight) with
#      18 robots on the Chu2024 floor and with 500 robots on LoRR sortation_large.
#   2. Streaming: N fleet-sim robots at 10 Hz state reports driving one order each on
#      sortation_large in real time (--time-scale 1) for DURATION s; the release latency
#      fleet-sim measures (ms a robot stood ready at its release horizon until the Grant or
#      Resume arrived; waits announced by a Hold excluded): p50/p99 and dispatchd's CPU share.
#   3. REST: wrk on /api/v1/status at ~200 requests/s (2 connections, 9 ms pacing) while
#      the streaming fleet runs: latency percentiles.
# Environment: FLEETS (default "500": the streaming fleet sizes, e.g. "250 500 1000"), DURATION (default 60),
# INTAKE_ORDERS (default 1000). Results: build-release/bench/*.json and a summary at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/setup.sh build build-release -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_TESTS=OFF >/dev/null
if ! command -v wrk >/dev/null; then
  [ "$(id -u)" -eq 0 ] && sudo=() || sudo=(sudo)
  "${sudo[@]}" apt-get update -qq && DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq wrk
fi
bin=build-release
out=$bin/bench
rm -rf "$out" && mkdir -p "$out"
sortation=../shared/benchmarks/lorr2024/example_problems/warehouse.domain/maps/sortation_large.map
fleets=${FLEETS:-500}
duration=${DURATION:-60}
intake_orders=${INTAKE_ORDERS:-1000}

pids=()
stop_all() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  pids=()
}
trap stop_all EXIT

# start_server NAME MAP ARGS...: sets grpc, http, server_pid.
start_server() {
  local name=$1 map=$2; shift 2
  mkfifo "$out/$name.ready"
  "$bin/server/dispatchd" --bind 127.0.0.1 --grpc-port 0 --http-port 0 --db "$out/$name.db" \
    --map "$map" --log-level warn --ready-fd 3 "$@" 3>"$out/$name.ready" >"$out/$name.dispatchd.log" 2>&1 &
  server_pid=$!
  pids+=("$server_pid")
  local ports=""
  read -r -t 120 ports <"$out/$name.ready" || true
  [ -n "$ports" ] || { echo "bench: dispatchd did not start:" >&2; cat "$out/$name.dispatchd.log" >&2; exit 1; }
  grpc=127.0.0.1:$(sed -E 's/.*"grpc_port": *([0-9]+).*/\1/' <<<"$ports")
  http=127.0.0.1:$(sed -E 's/.*"http_port": *([0-9]+).*/\1/' <<<"$ports")
}

# start_fleet NAME N ARGS...: sets fleet_pid once all N robots are connected.
start_fleet() {
  local name=$1 n=$2; shift 2
  mkfifo "$out/$name.fleet-ready"
  "$bin/clients/fleet-sim" --server "$grpc" --robots "$n" --ready-fd 4 --stats-out "$out/$name.fleet.json" "$@" \
    4>"$out/$name.fleet-ready" >"$out/$name.fleet.log" 2>&1 &
  fleet_pid=$!
  pids+=("$fleet_pid")
  local line=""
  read -r -t 300 line <"$out/$name.fleet-ready" || true
  case "$line" in connected*) ;; *) echo "bench: fleet-sim did not connect:" >&2; cat "$out/$name.fleet.log" >&2; exit 1 ;; esac
}

cpu_ticks() { awk '{print $14 + $15}' "/proc/$1/stat"; }

echo "== Order intake: SubmitOrder, 8 in flight, $intake_orders orders =="
for setup in "18 chu2024" "500 $sortation"; do
  read -r n map <<<"$setup"
  name=intake-$n
  start_server "$name" "$map" --time-scale 1
  start_fleet "$name" "$n"
  "$bin/clients/order-load" --server "$grpc" --orders "$intake_orders" --concurrency 8 --json "$out/$name.json" \
    | sed "s/^/$n robots: /"
  stop_all
done

echo
echo "== Streaming: fleet-sim at 10 Hz reports, real time, ${duration} s per fleet, + REST at 200 req/s =="
cat >"$out/pace.lua" <<'LUA'
function delay() return 9 end
LUA
for n in $fleets; do
  name=stream-$n
  start_server "$name" "$sortation" --time-scale 1
  start_fleet "$name" "$n" --report-hz 10
  "$bin/clients/order-load" --server "$grpc" --orders "$n" --concurrency 8 --json "$out/$name.orders.json" >/dev/null
  hz=$(getconf CLK_TCK)
  c0=$(cpu_ticks "$server_pid"); f0=$(cpu_ticks "$fleet_pid"); t0=$(date +%s.%N)
  wrk -t1 -c2 -d"$((duration / 2))s" --latency -s "$out/pace.lua" "http://$http/api/v1/status" >"$out/$name.wrk.txt" 2>&1 &
  wrk_pid=$!
  sleep "$duration"  # the measurement window (the fleet drives meanwhile); not a synchronisation
  wait "$wrk_pid" || true
  c1=$(cpu_ticks "$server_pid"); f1=$(cpu_ticks "$fleet_pid"); t1=$(date +%s.%N)
  curl -s "http://$http/api/v1/status" >"$out/$name.status.json"
  kill -TERM "$fleet_pid"
  wait "$fleet_pid" || true
  python3 - "$out/$name" "$n" "$c0" "$c1" "$f0" "$f1" "$t0" "$t1" "$hz" <<'PY'
import json, re, sys
base, n, c0, c1, f0, f1, t0, t1, hz = sys.argv[1:]
wall = float(t1) - float(t0)
cpu = lambda a, b: (int(b) - int(a)) / int(hz) / wall * 100
fleet = json.load(open(base + ".fleet.json"))
status = json.load(open(base + ".status.json"))
wrk = open(base + ".wrk.txt").read()
def pct(p):
    m = re.search(r"^\s+%s%%\s+([\d.]+)(us|ms|s)" % p, wrk, re.M)
    if not m: return None
    v, u = float(m.group(1)), m.group(2)
    return v / 1000 if u == "us" else v * 1000 if u == "s" else v
rate = re.search(r"Requests/sec:\s+([\d.]+)", wrk)
r = {"robots": int(n), "dispatchd_cpu_percent": cpu(c0, c1), "fleet_sim_cpu_percent": cpu(f0, f1),
     "release_latency_ms": fleet["release_latency_ms"], "grants": int(status["traffic"]["grants"]),
     "orders": status["orders"], "rest_status_ms": {"p50": pct(50), "p99": pct(99)},
     "rest_requests_per_s": float(rate.group(1)) if rate else None}
json.dump(r, open(base + ".json", "w"), indent=1)
l = r["release_latency_ms"]
print(f"{n} robots: release latency p50 {l['p50']:.1f} ms, p99 {l['p99']:.1f} ms over {l['count']} waits; "
      f"dispatchd {r['dispatchd_cpu_percent']:.0f}% CPU, fleet-sim {r['fleet_sim_cpu_percent']:.0f}%; "
      f"{r['grants']} grants; REST /api/v1/status at {r['rest_requests_per_s'] or 0:.0f} req/s: "
      f"p50 {r['rest_status_ms']['p50']} ms, p99 {r['rest_status_ms']['p99']} ms")
PY
  stop_all
done
echo
echo "(figures: $out/*.json; logs beside them)"
