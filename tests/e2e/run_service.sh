#!/usr/bin/env bash
# Runs one end-to-end check against real processes: dispatchd (fresh SQLite file, loopback,
# ephemeral ports) and fleet-sim with N robots, then COMMAND; stops both afterwards.
#   run_service.sh DISPATCHD FLEET_SIM ROBOTS [DISPATCHD_ARGS...] -- COMMAND [ARGS...]
# In COMMAND, {grpc} becomes the server's HOST:PORT and {http} its REST HOST:PORT.
# dispatchd reports its ports through --ready-fd (a FIFO here), so nothing polls or sleeps.
# Exit status: COMMAND's. Logs are printed when it fails.
set -euo pipefail
dispatchd=$1 fleet_sim=$2 robots=$3
shift 3
server_args=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do server_args+=("$1"); shift; done
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || { echo "usage: $0 DISPATCHD FLEET_SIM ROBOTS [ARGS..] -- COMMAND.." >&2; exit 2; }

work=$(mktemp -d)
server_pid="" fleet_pid=""
cleanup() {
  [ -n "$fleet_pid" ] && kill "$fleet_pid" 2>/dev/null && wait "$fleet_pid" 2>/dev/null || true
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

mkfifo "$work/ready" "$work/fleet-ready"
"$dispatchd" --bind 127.0.0.1 --grpc-port 0 --http-port 0 --db "$work/dispatch.db" \
  --ready-fd 3 "${server_args[@]}" 3>"$work/ready" >"$work/server.log" 2>&1 &
server_pid=$!
ports=""
read -r -t 60 ports <"$work/ready" || true
if [ -z "$ports" ]; then
  echo "dispatchd did not become ready" >&2
  cat "$work/server.log" >&2
  exit 1
fi
grpc_port=$(sed -E 's/.*"grpc_port": *([0-9]+).*/\1/' <<<"$ports")
http_port=$(sed -E 's/.*"http_port": *([0-9]+).*/\1/' <<<"$ports")

"$fleet_sim" --server "127.0.0.1:$grpc_port" --robots "$robots" --ready-fd 4 4>"$work/fleet-ready" \
  >"$work/fleet.log" 2>&1 &
fleet_pid=$!
connected=""
read -r -t 60 connected <"$work/fleet-ready" || true
case "$connected" in connected*) ;; *) connected="" ;; esac
if [ -z "$connected" ]; then
  echo "fleet-sim did not connect its robots" >&2
  cat "$work/fleet.log" "$work/server.log" >&2
  exit 1
fi

cmd=()
for a in "$@"; do
  a=${a//\{grpc\}/127.0.0.1:$grpc_port}
  cmd+=("${a//\{http\}/127.0.0.1:$http_port}")
done
rc=0
"${cmd[@]}" || rc=$?
if [ "$rc" -ne 0 ]; then
  echo "---- command failed ($rc): ${cmd[*]}" >&2
  echo "---- dispatchd log (tail)" >&2; tail -n 60 "$work/server.log" >&2
  echo "---- fleet-sim log (tail)" >&2; tail -n 30 "$work/fleet.log" >&2
fi
exit "$rc"
