#!/usr/bin/env bash
# The container end to end (SPEC §1 "it ships as a container"; ../shared/CONTAINERS.md):
#  1. builds deploy/Dockerfile with podman (no Docker engine here; the Dockerfile is standard);
#  2. runs dispatchd from the image with its default flags (TLS, robots' client certificates
#     and tokens from deploy/dev_certs.sh mounted at /etc/dispatch; database in a host folder
#     mounted as its volume) and fleet-sim (3 robots, each with its certificate and token)
#     from the same image in a second container;
#  3. submits an order with the image's wmsctl and the WMS token and waits until it is done;
#  4. stops dispatchd with SIGTERM (it must exit 0), starts it again on the same volume and
#     checks that the completed order is still there.
# Installs podman, runc and debootstrap (apt-get, idempotent). With no registry reachable it
# makes the debian:bookworm-slim base image from Debian's archive once (about 2 minutes).
# The image build compiles the service: 10-15 minutes on 2 cores the first time.
# Usage: deploy/container_test.sh            IMAGE=name:tag to choose the image's name
set -euo pipefail
cd "$(dirname "$0")/.."
IMAGE=${IMAGE:-warehouse-dispatch:test}
BASE=docker.io/library/debian:bookworm-slim
work=$(mktemp -d /tmp/dispatch-container.XXXXXX)
server=dispatchd-test-$$
fleet=fleet-sim-test-$$

log() { echo "container_test: $*"; }
fail() {
  echo "container_test: FAILED: $*" >&2
  podman logs "$server" 2>&1 | tail -40 >&2 || true
  exit 1
}
cleanup() {
  podman rm -f "$fleet" "$server" >/dev/null 2>&1 || true
  rm -rf "$work"
}
trap cleanup EXIT

missing=()
for p in podman runc debootstrap python3; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  log "installing ${missing[*]}"
  sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  { "${sudo[@]}" apt-get update -qq &&
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
  } >"$work/apt.log" 2>&1 || { tail -20 "$work/apt.log" >&2; fail "apt-get install"; }
fi

# This sandbox: no default rlimits, runc instead of crun (CONTAINERS.md).
cat >"$work/containers.conf" <<'CONF'
[containers]
default_ulimits = []
[engine]
runtime = "runc"
CONF
export CONTAINERS_CONF=$work/containers.conf

if ! podman image exists "$BASE"; then
  log "making $BASE from Debian's archive"
  debootstrap --variant=minbase bookworm "$work/rootfs" >"$work/debootstrap.log" 2>&1 ||
    { tail -20 "$work/debootstrap.log" >&2; fail "debootstrap"; }
  tar -C "$work/rootfs" -cf "$work/rootfs.tar" .
  podman import "$work/rootfs.tar" "$BASE" >/dev/null
  rm -rf "$work/rootfs" "$work/rootfs.tar"
fi

log "building $IMAGE (deploy/Dockerfile)"
start=$(date +%s)
podman build --pull=never --network host -f deploy/Dockerfile -t "$IMAGE" . >"$work/build.log" 2>&1 ||
  { tail -40 "$work/build.log" >&2; fail "podman build"; }
log "built in $(( $(date +%s) - start )) s, $(podman image inspect --format '{{.Size}}' "$IMAGE") bytes"

# The image runs as uid 10001; the volume is a host folder it owns, and so is the PKI.
mkdir -p "$work/data"
chown 10001:10001 "$work/data"
bash deploy/dev_certs.sh "$work/pki" 3 >/dev/null
chown -R 10001:10001 "$work/pki"
pki=(-v "$work/pki:/etc/dispatch:ro")
tls=(--tls-ca /etc/dispatch/ca.crt)

# Waits for the ports file dispatchd writes once it listens, then for /readyz.
ready() {
  local ports=""
  for _ in $(seq 600); do
    [ -s "$work/data/ports.json" ] && ports=$(cat "$work/data/ports.json") && break
    [ "$(podman inspect --format '{{.State.Running}}' "$server")" = true ] || fail "dispatchd exited"
    sleep 0.1
  done
  [ -n "$ports" ] || fail "dispatchd wrote no ports file"
  grpc=$(python3 -c 'import json,sys; print(json.loads(sys.argv[1])["grpc_port"])' "$ports")
  http=$(python3 -c 'import json,sys; print(json.loads(sys.argv[1])["http_port"])' "$ports")
  python3 - "$http" "$work/pki/ca.crt" <<'PY' || fail "/readyz"
import ssl, sys, time, urllib.request
context = ssl.create_default_context(cafile=sys.argv[2])
deadline = time.time() + 30
while True:
    try:
        with urllib.request.urlopen(f"https://localhost:{sys.argv[1]}/readyz", timeout=2, context=context) as r:
            if r.status == 200:
                break
    except OSError:
        pass
    if time.time() > deadline:
        sys.exit(1)
    time.sleep(0.2)
PY
}

start_server() {
  rm -f "$work/data/ports.json"
  podman start "$server" >/dev/null
  ready
  log "dispatchd listening: gRPC $grpc, REST $http"
}

# Loopback ports chosen by dispatchd (port 0): no clash with anything else on this machine.
# The image's TLS and token flags, as its default command has them.
podman create --name "$server" --ulimit host --network host -v "$work/data:/var/lib/dispatch" "${pki[@]}" "$IMAGE" \
  --bind 127.0.0.1 --grpc-port 0 --http-port 0 --ports-file /var/lib/dispatch/ports.json \
  --db /var/lib/dispatch/dispatch.db --map chu2024 --time-scale 10 \
  --tls-cert /etc/dispatch/server.crt --tls-key /etc/dispatch/server.key \
  --tls-client-ca /etc/dispatch/ca.crt --auth-tokens /etc/dispatch/tokens.json >/dev/null
start_server

podman run -d --name "$fleet" --ulimit host --network host "${pki[@]}" --entrypoint fleet-sim "$IMAGE" \
  --server "localhost:$grpc" --robots 3 "${tls[@]}" --robot-tokens /etc/dispatch/secrets/robot-tokens.json \
  --robot-certs /etc/dispatch/robots >/dev/null
log "fleet-sim: 3 robots"

log "submitting an order with wmsctl and waiting for it"
timeout 300 podman run --rm --ulimit host --network host "${pki[@]}" --entrypoint wmsctl "$IMAGE" \
  --server "localhost:$grpc" "${tls[@]}" --token-file /etc/dispatch/secrets/wms.token \
  submit --id container-test-1 --pick "19 17" --drop "6.5 2.75" --wait ||
  fail "the order did not complete"

completed() {
  python3 - "$http" "$work/pki" <<'PY'
import json, ssl, sys, urllib.request
context = ssl.create_default_context(cafile=sys.argv[2] + "/ca.crt")
request = urllib.request.Request(f"https://localhost:{sys.argv[1]}/api/v1/orders?state=completed")
request.add_header("Authorization", "Bearer " + open(sys.argv[2] + "/secrets/operator.token").read().strip())
with urllib.request.urlopen(request, timeout=5, context=context) as r:
    orders = json.load(r)["orders"]
print(len(orders))
PY
}
[ "$(completed)" = 1 ] || fail "REST does not list the order as completed"

log "stopping dispatchd (SIGTERM)"
podman stop -t 15 "$server" >/dev/null
code=$(podman inspect --format '{{.State.ExitCode}}' "$server")
[ "$code" = 0 ] || fail "dispatchd exited with $code on SIGTERM"
[ -s "$work/data/dispatch.db" ] || fail "no database in the volume"

log "starting dispatchd again on the same volume"
start_server
[ "$(completed)" = 1 ] || fail "the completed order is gone after the restart"
log "passed: image $IMAGE built, TLS and tokens, order completed, SIGTERM exit 0, order kept across a restart"
