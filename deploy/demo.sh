#!/usr/bin/env bash
# The main job: the dispatch service on the built-in Chu2024 floor. Builds everything, shows
# the engine's seed reproductions briefly, then starts dispatchd (SQLite file on disk),
# fleet-sim with 18 robots in the parking stations, submits seed 000 Table 1 and then Table 2
# through wmsctl, prints the results, and keeps the service and its live web map up until
# Ctrl-C (the map's URL is printed as soon as dispatchd listens: open it to watch the run).
#
# Environment: TIME_SCALE (dispatcher seconds per wall second, default 5), GRPC_PORT and
# HTTP_PORT (default 0: any free port), BIND (default 127.0.0.1; 0.0.0.0 to open the map from
# another machine or from outside a container), DEMO_EXIT=1 (stop after the results instead
# of serving until Ctrl-C), SECURE (default 1: TLS, robots' client certificates and bearer
# tokens made by deploy/dev_certs.sh in build-release/demo/pki; 0: plaintext, no tokens).
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/setup.sh build build-release -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_TESTS=OFF \
  >/dev/null
bin=build-release
scenarios=../shared/scenarios
run=build-release/demo
rm -rf "$run"
mkdir -p "$run"

echo "== The Chu2024 floor (seed 000 §4.1, reconstructed: engine/map/chu2024_floor.md) =="
"$bin/engine/cli/dispatch-map" summary --map chu2024
"$bin/engine/cli/dispatch-map" svg --map chu2024 --out "$run/chu2024.svg" >/dev/null
echo "(rendered to $run/chu2024.svg)"
if [ ! -f "$scenarios/chu2024-table1.csv" ]; then
  echo "demo: the seed task tables are missing: $scenarios (../shared beside the repository)" >&2
  exit 1
fi
echo
echo "== Engine: seed 000 Tables 3 and 4, the auction on Table 2 without and with traffic prediction =="
"$bin/engine/cli/dispatch-alloc" --table "$scenarios/chu2024-table2.csv"
echo
echo "== Engine: seed 000 Fig. 8, Table 1 simulated with traffic rules off and on =="
"$bin/engine/cli/dispatch-sim" plan --table "$scenarios/chu2024-table1.csv" --rules both \
  --csv "$run/fig8.csv" | grep -E "^Rules|makespan|min pairwise" || true
echo "(minimum distance over time: $run/fig8.csv)"
echo
echo "== Engine: seed 004 §4.3, a head-on conflict on a single lane: wait or re-plan =="
"$bin/engine/cli/dispatch-sim" headon

echo
echo "== The service: dispatchd + fleet-sim (18 robots) + wmsctl =="
server_pid="" fleet_pid=""
stop() {
  [ -n "$fleet_pid" ] && kill "$fleet_pid" 2>/dev/null || true
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null || true
  wait 2>/dev/null || true
}
# dispatchd journals every call of its dispatch core (README "Replay"): once it has stopped,
# the run is fed through a fresh core again and must give the same awards, grants, holds and
# order states.
replay() {
  stop
  server_pid="" fleet_pid=""
  echo
  echo "== Replay: the recorded run through a fresh dispatch core (dispatch-sim replay --db $run/dispatch.db) =="
  local out rc=0
  out=$("$bin/engine/cli/dispatch-sim" replay --db "$run/dispatch.db") || rc=$?
  if [ "$rc" -ne 0 ]; then
    echo "$out"
    echo "demo: the replay did not match (exit $rc)" >&2
    return 1
  fi
  tail -n 1 <<<"$out"
}
trap stop EXIT
trap 'echo; echo "demo: stopping"; replay; exit $?' INT TERM
mkfifo "$run/ready" "$run/fleet-ready"
# Issue 18: TLS for gRPC and REST, a client certificate and a token per robot, a token for the
# WMS (wmsctl) and one for the operator (the web map, the status below).
server_tls=() fleet_tls=() wms_tls=() curl_pki=() scheme=http host=127.0.0.1
if [ "${SECURE:-1}" = 1 ]; then
  pki=$run/pki
  bash deploy/dev_certs.sh "$pki" 18 >/dev/null
  server_tls=(--tls-cert "$pki/server.crt" --tls-key "$pki/server.key" --tls-client-ca "$pki/ca.crt"
              --auth-tokens "$pki/tokens.json")
  fleet_tls=(--tls-ca "$pki/ca.crt" --robot-tokens "$pki/secrets/robot-tokens.json" --robot-certs "$pki/robots")
  wms_tls=(--tls-ca "$pki/ca.crt" --token-file "$pki/secrets/wms.token")
  curl_pki=("$pki/ca.crt" "$pki/secrets/operator.token")
  scheme=https host=localhost
fi
"$bin/server/dispatchd" --bind "${BIND:-127.0.0.1}" --grpc-port "${GRPC_PORT:-0}" --http-port "${HTTP_PORT:-0}" \
  --db "$run/dispatch.db" --map chu2024 --time-scale "${TIME_SCALE:-5}" "${server_tls[@]}" \
  --ready-fd 3 3>"$run/ready" >"$run/dispatchd.log" 2>&1 &
server_pid=$!
ports=""
read -r -t 60 ports <"$run/ready" || true
if [ -z "$ports" ]; then
  echo "demo: dispatchd did not start; its log:" >&2
  cat "$run/dispatchd.log" >&2
  exit 1
fi
grpc=$host:$(sed -E 's/.*"grpc_port": *([0-9]+).*/\1/' <<<"$ports")
http=$host:$(sed -E 's/.*"http_port": *([0-9]+).*/\1/' <<<"$ports")
echo "dispatchd: gRPC $grpc, REST $scheme://$http/api/v1/status, database $run/dispatch.db"
echo "           (log $run/dispatchd.log, time scale ${TIME_SCALE:-5}x)"
echo "Live web map: $scheme://$http/"
if [ "${SECURE:-1}" = 1 ]; then
  echo "  TLS with the development CA $pki/ca.crt (your browser will not know it: accept it, or"
  echo "  import it); paste the operator token from $pki/secrets/operator.token into the map's token field."
fi

"$bin/clients/fleet-sim" --server "$grpc" --robots 18 "${fleet_tls[@]}" --ready-fd 4 4>"$run/fleet-ready" \
  >"$run/fleet-sim.log" 2>&1 &
fleet_pid=$!
connected=""
read -r -t 60 connected <"$run/fleet-ready" || true
case "$connected" in connected*) ;; *) connected="" ;; esac
if [ -z "$connected" ]; then
  echo "demo: fleet-sim did not connect its robots; its log:" >&2
  cat "$run/fleet-sim.log" >&2
  exit 1
fi
echo "fleet-sim: 18 robots at their parking stations, $connected"

for table in 1 2; do
  echo
  echo "-- seed 000 Table $table --"
  "$bin/clients/wmsctl" --server "$grpc" "${wms_tls[@]}" submit "$scenarios/chu2024-table$table.csv" --wait
done
echo
# The traffic layer's account (dispatchd's /api/v1/status): the closest two robots of different
# agents it saw (formation members of one team are one agent), grants, holds, re-plans.
python3 - "$scheme://$http/api/v1/status" "${curl_pki[@]}" <<'PY'
import json, ssl, sys, urllib.request
request, context = urllib.request.Request(sys.argv[1]), None
if len(sys.argv) > 2:  # TLS with the demo's CA, the operator's token
    context = ssl.create_default_context(cafile=sys.argv[2])
    request.add_header("Authorization", "Bearer " + open(sys.argv[3]).read().strip())
t = json.load(urllib.request.urlopen(request, timeout=10, context=context))["traffic"]
d = t.get("min_robot_distance")  # absent until two robots were seen
if d:
    print(f"Minimum robot distance seen: {d['distance']:.3f} m ({' and '.join(d['robot_ids'])} at t = {d['time']:.1f} s; eps1 = 0.6 m)")
print(f"Traffic control: {t['grants']} grants, {t['holds']} holds, {t['replans']} re-planned legs, "
      f"{t['deadlocks_resolved']} deadlocks resolved")
PY
echo
echo "Live web map: $scheme://$http/  (metrics: $scheme://$http/metrics)"
curl_args=""
[ "${SECURE:-1}" = 1 ] && curl_args="--cacert $pki/ca.crt -H \"Authorization: Bearer \$(cat $pki/secrets/operator.token)\" "
echo "Orders, robots, traffic and the service status: curl $curl_args$scheme://$http/api/v1/orders, .../api/v1/robots,"
echo "  .../api/v1/traffic, .../api/v1/zones, .../api/v1/intersections, .../api/v1/status"
echo "An allocation's reasons: $bin/clients/wmsctl --server $grpc ${wms_tls[*]} explain <order id>"
if [ "${DEMO_EXIT:-0}" = 1 ]; then
  replay
  exit $?
fi
echo "Serving the web map until Ctrl-C (then the run is replayed)."
wait "$server_pid"
