#!/usr/bin/env python3
"""Issue 18 §1-3: dispatchd with TLS, robots' client certificates (mTLS) and bearer tokens with
roles, as deploy/dev_certs.sh makes them, against real clients:
  - a plaintext gRPC client and a plaintext HTTP client are refused (the TLS handshake fails);
  - over TLS without a token: UNAUTHENTICATED / HTTP 401 (with WWW-Authenticate: Bearer), an
    unknown token too; /healthz stays open;
  - a wms token submits orders and reads them, but may not read the fleet (403), connect as a
    robot (PERMISSION_DENIED) or POST a body that is not JSON (415);
  - an operator token reads the fleet but may not submit (PERMISSION_DENIED);
  - robot streams: without a client certificate UNAUTHENTICATED; R1's certificate and token
    saying Hello as R2 PERMISSION_DENIED; R3's credentials saying Hello as R1 while R1 works
    (a hijack) PERMISSION_DENIED, and R1's order completes untouched;
  - fleet-sim with per-robot tokens and certificates and wmsctl with a wms token run an order
    to completion;
  - order events name who made them (the wms token's name on the created event, the
    operator's on a cancel);
  - an operator pauses R1 over REST and resumes it over gRPC: R1 stands held "paused by
    operator-dev" meanwhile, the core's journal names the operator for both, and an order
    then completes; a wms token may not pause (403 / PERMISSION_DENIED);
  - SIGHUP re-reads the token file: a revoked token is refused from then on.

    tls_and_tokens.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR ...
"""
import http.client
import json
import os
import signal
import sqlite3
import ssl
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
import grpc  # noqa: E402
from e2e_harness import COMPLETED, Harness, RobotStream, TestFailure, check, common_arguments  # noqa: E402
from warehouse.dispatch.v1 import (common_pb2, fleet_pb2, operator_pb2,  # noqa: E402
                                   operator_pb2_grpc, orders_pb2, orders_pb2_grpc)

HERE = os.path.dirname(os.path.abspath(__file__))
DEV_CERTS = os.path.join(HERE, "..", "..", "deploy", "dev_certs.sh")
Code = grpc.StatusCode
PARK = (30.625, 24.75)  # park-P10, away from fleet-sim's robots


def read(path):
    with open(path, "rb") as f:
        return f.read()


class Credentials:
    def __init__(self, folder):
        self.folder = folder
        self.ca = read(os.path.join(folder, "ca.crt"))
        self.secrets = {role: read(os.path.join(folder, "secrets", f"{role}.token")).decode().strip()
                        for role in ("wms", "operator", "admin")}
        with open(os.path.join(folder, "secrets", "robot-tokens.json")) as f:
            self.robot_secrets = json.load(f)

    def channel(self, server, robot=None):
        """A TLS channel to the server (with robot's client certificate when given)."""
        key = cert = None
        if robot:
            key = read(os.path.join(self.folder, "robots", f"{robot}.key"))
            cert = read(os.path.join(self.folder, "robots", f"{robot}.crt"))
        creds = grpc.ssl_channel_credentials(root_certificates=self.ca, private_key=key, certificate_chain=cert)
        return grpc.secure_channel(f"localhost:{server.grpc_port}", creds)


def bearer(secret):
    return [("authorization", f"Bearer {secret}")] if secret else []


def expect_rpc_error(what, code, call, *words):
    try:
        call()
    except grpc.RpcError as err:
        check(err.code() == code, f"{what}: {err.code().name} '{err.details()}', want {code.name}")
        missing = [w for w in words if w.lower() not in (err.details() or "").lower()]
        check(not missing, f"{what}: '{err.details()}' does not name {missing}")
        print(f"[e2e] {what}: {code.name} '{err.details()}'", flush=True)
        return
    raise TestFailure(f"{what}: succeeded, want {code.name}")


def https(server, creds, method, path, secret=None, body=None, content_type="application/json"):
    context = ssl.create_default_context(cadata=creds.ca.decode())
    conn = http.client.HTTPSConnection("localhost", server.http_port, context=context, timeout=10)
    headers = {}
    if secret:
        headers["Authorization"] = f"Bearer {secret}"
    if body is not None:
        headers["Content-Type"] = content_type
    try:
        conn.request(method, path, body=body, headers=headers)
        resp = conn.getresponse()
        return resp.status, resp.getheader("WWW-Authenticate") or "", resp.read()
    finally:
        conn.close()


def robot_stream(channel, secret, robot_id):
    """A Connect call on `channel` with `secret`'s token that says Hello as `robot_id`."""
    pose = common_pb2.Pose(x=PARK[0], y=PARK[1], theta=0.0)
    hello = fleet_pb2.RobotMessage(hello=fleet_pb2.Hello(robot_id=robot_id, pose=pose))
    return RobotStream(channel, hello, metadata=bearer(secret))


def order_request(client_id, pick="K3-2-3N", drop="D-B2"):
    r = orders_pb2.SubmitOrderRequest(client_order_id=client_id)
    r.picks.add().point_name = pick
    r.drop.point_name = drop
    return r


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "tls-tokens") as h:
        folder = os.path.join(h.work, "pki")
        subprocess.run(["bash", DEV_CERTS, folder, "3"], check=True, timeout=60)
        creds = Credentials(folder)
        tokens = os.path.join(folder, "tokens.json")
        server = h.start_server(["--time-scale", "10", "--tls-cert", os.path.join(folder, "server.crt"),
                                 "--tls-key", os.path.join(folder, "server.key"),
                                 "--tls-client-ca", os.path.join(folder, "ca.crt"), "--auth-tokens", tokens])
        wms, operator = creds.secrets["wms"], creds.secrets["operator"]

        # Plaintext is refused.
        plain = orders_pb2_grpc.OrderServiceStub(grpc.insecure_channel(server.grpc))
        expect_rpc_error("plaintext gRPC", Code.UNAVAILABLE,
                         lambda: plain.ListOrders(orders_pb2.ListOrdersRequest(), timeout=5, metadata=bearer(wms)))
        try:
            conn = http.client.HTTPConnection("127.0.0.1", server.http_port, timeout=5)
            conn.request("GET", "/healthz")
            status = conn.getresponse().status
            raise TestFailure(f"plaintext HTTP answered {status}")
        except (OSError, http.client.HTTPException) as err:
            print(f"[e2e] plaintext HTTP refused: {type(err).__name__}", flush=True)

        # TLS: who may do what.
        orders = orders_pb2_grpc.OrderServiceStub(creds.channel(server))
        expect_rpc_error("no token", Code.UNAUTHENTICATED,
                         lambda: orders.ListOrders(orders_pb2.ListOrdersRequest(), timeout=10), "Bearer")
        expect_rpc_error("unknown token", Code.UNAUTHENTICATED,
                         lambda: orders.ListOrders(orders_pb2.ListOrdersRequest(), timeout=10,
                                                   metadata=bearer("not-a-token")), "unknown")
        expect_rpc_error("operator submits", Code.PERMISSION_DENIED,
                         lambda: orders.SubmitOrder(order_request("op-1"), timeout=10, metadata=bearer(operator)),
                         "operator", "submit")
        status, challenge, _ = https(server, creds, "GET", "/api/v1/orders")
        check(status == 401 and challenge == "Bearer", f"REST without a token: {status} '{challenge}'")
        status, _, _ = https(server, creds, "GET", "/healthz")
        check(status == 200, f"/healthz over HTTPS without a token: {status}")
        status, _, body = https(server, creds, "GET", "/api/v1/robots", wms)
        check(status == 403, f"wms reads the fleet: HTTP {status} {body[:200]!r}")
        status, _, body = https(server, creds, "GET", "/api/v1/robots", operator)
        check(status == 200, f"operator reads the fleet: HTTP {status} {body[:200]!r}")
        status, _, body = https(server, creds, "POST", "/api/v1/orders", wms,
                                body=json.dumps({"client_order_id": "text-1", "picks": [{"point_name": "K3-2-3N"}],
                                                 "drop": {"point_name": "D-B2"}}), content_type="text/plain")
        check(status == 415, f"text/plain POST: HTTP {status} {body[:200]!r}")

        # Robot identity.
        robot_stream(creds.channel(server), creds.robot_secrets["R1"], "R1").expect_end(
            Code.UNAUTHENTICATED, "certificate")
        robot_stream(creds.channel(server, "R1"), wms, "R1").expect_end(
            Code.PERMISSION_DENIED, "wms")
        robot_stream(creds.channel(server, "R1"), creds.robot_secrets["R1"], "R2").expect_end(
            Code.PERMISSION_DENIED, "R2")
        robot_stream(creds.channel(server, "R1"), creds.robot_secrets["R2"], "R2").expect_end(
            Code.PERMISSION_DENIED, "R1")

        # The fleet and a WMS, each with its own credentials, run an order to the end; a
        # hijack of R1 meanwhile is refused.
        h.start_fleet(server, 3, ["--tls-ca", os.path.join(folder, "ca.crt"),
                                  "--robot-tokens", os.path.join(folder, "secrets", "robot-tokens.json"),
                                  "--robot-certs", os.path.join(folder, "robots")])
        submitted = orders.SubmitOrder(order_request("tls-1"), timeout=10, metadata=bearer(wms))
        robot_stream(creds.channel(server, "R3"), creds.robot_secrets["R3"], "R1").expect_end(
            Code.PERMISSION_DENIED, "R1")
        wmsctl = [args.wmsctl, "--server", f"localhost:{server.grpc_port}", "--tls-ca", os.path.join(folder, "ca.crt"),
                  "--token-file", os.path.join(folder, "secrets", "wms.token")]
        r = subprocess.run(wmsctl + ["submit", "--pick", "K3-3-1N", "--drop", "D-B2", "--id", "tls-2", "--wait"],
                           capture_output=True, text=True, timeout=120)
        sys.stdout.write(r.stdout + r.stderr)
        check(r.returncode == 0, f"wmsctl with TLS and a wms token exited {r.returncode}")
        h.wait_for(lambda: orders.GetOrder(orders_pb2.GetOrderRequest(order_id=submitted.order.id), timeout=10,
                                           metadata=bearer(wms)).state == COMPLETED, 120,
                   f"{submitted.order.id} (R1's order during the hijack) completed")

        # Who made each change.
        def events_of(order_id):
            call = orders.WatchOrders(orders_pb2.WatchOrdersRequest(order_ids=[order_id], from_start=True),
                                      timeout=10, metadata=bearer(wms))
            seen = []
            try:
                for e in call:
                    seen.append(e)
                    if e.state in (common_pb2.ORDER_STATE_COMPLETED, common_pb2.ORDER_STATE_CANCELLED):
                        call.cancel()
            except grpc.RpcError as err:
                check(err.code() == Code.CANCELLED, f"WatchOrders: {err.code().name} {err.details()}")
            return seen
        created = events_of(submitted.order.id)[0]
        check(created.actor == "wms-dev", f"created event's actor '{created.actor}', want wms-dev")
        cancel_me = orders.SubmitOrder(order_request("tls-3", "K1-1-1N", "D-B1"), timeout=10, metadata=bearer(wms))
        orders.CancelOrder(orders_pb2.CancelOrderRequest(order_id=cancel_me.order.id, reason="test"), timeout=10,
                           metadata=bearer(operator))
        cancelled = events_of(cancel_me.order.id)[-1]
        check(cancelled.state == common_pb2.ORDER_STATE_CANCELLED and cancelled.actor == "operator-dev",
              f"cancel event: state {cancelled.state} actor '{cancelled.actor}', want operator-dev")

        # Operator commands: pause R1 (REST), resume it (gRPC); a wms token may not.
        status, _, body = https(server, creds, "POST", "/api/v1/robots/R1/pause", wms, body="")
        check(status == 403, f"wms pauses R1: HTTP {status} {body[:200]!r}")
        operators = operator_pb2_grpc.OperatorServiceStub(creds.channel(server))
        expect_rpc_error("wms pauses over gRPC", Code.PERMISSION_DENIED,
                         lambda: operators.PauseRobot(operator_pb2.RobotCommandRequest(robot_id="R1"), timeout=10,
                                                      metadata=bearer(wms)), "robot commands")
        status, _, body = https(server, creds, "POST", "/api/v1/robots/R1/pause", operator, body="")
        check(status == 200 and json.loads(body)["paused_by"] == "operator-dev", f"pause R1: HTTP {status} {body!r}")
        status, _, body = https(server, creds, "POST", "/api/v1/robots/R9/pause", operator, body="")
        check(status == 404, f"pause an unknown robot: HTTP {status} {body!r}")

        def held_paused():
            _, _, b = https(server, creds, "GET", "/api/v1/robots/R1", operator)
            r = json.loads(b)
            return r.get("held") and r.get("hold_reason") == "paused by operator-dev"
        h.wait_for(held_paused, 30, "R1 held, paused by operator-dev")
        resumed = operators.ResumeRobot(operator_pb2.RobotCommandRequest(robot_id="R1"), timeout=10,
                                        metadata=bearer(operator))
        check(resumed.paused_by == "", f"resumed R1 still paused by '{resumed.paused_by}'")
        r = subprocess.run(wmsctl + ["submit", "--pick", "K3-2-1N", "--drop", "D-B2", "--id", "tls-4", "--wait"],
                           capture_output=True, text=True, timeout=120)
        sys.stdout.write(r.stdout + r.stderr)
        check(r.returncode == 0, f"an order after the resume: wmsctl exited {r.returncode}")

        def journaled():
            db = sqlite3.connect(f"file:{os.path.join(h.work, 'dispatch.db')}?mode=ro", uri=True, timeout=5)
            try:
                rows = db.execute("SELECT input FROM core_journal WHERE kind = 'plan_command' ORDER BY seq").fetchall()
            finally:
                db.close()
            commands = [json.loads(r[0]).get("cmd") for r in rows]  # [command, robot, by, point]
            on_r1 = [c[:3] for c in commands if c and c[1] == "R1"]  # R9's refused pause is journaled too
            return on_r1 == [["pause", "R1", "operator-dev"], ["resume", "R1", "operator-dev"]]
        h.wait_for(journaled, 30, "the journal's pause and resume naming operator-dev")

        # SIGHUP: the wms token revoked.
        with open(tokens) as f:
            table = json.load(f)
        table["tokens"] = [t for t in table["tokens"] if t["role"] != "wms"]
        with open(tokens, "w") as f:
            json.dump(table, f)
        server.popen.send_signal(signal.SIGHUP)

        def revoked():
            try:
                orders.ListOrders(orders_pb2.ListOrdersRequest(), timeout=10, metadata=bearer(wms))
                return False
            except grpc.RpcError as err:
                return err.code() == Code.UNAUTHENTICATED
        h.wait_for(revoked, 10, "the wms token refused after SIGHUP")
        orders.ListOrders(orders_pb2.ListOrdersRequest(), timeout=10, metadata=bearer(operator))
        h.log("TLS, mTLS and tokens hold")


if __name__ == "__main__":
    main()
