#!/usr/bin/env python3
"""Issue 18 §3: idle connections must not lock the service out. Measured before: with a
256-descriptor limit, 300 idle connections left gRPC refusing every new connection for good.
dispatchd started with a soft limit of 256 (its hard limit as this test's) must raise it to the
hard limit, and with 300 idle TCP connections on its gRPC port and 100 on its HTTP port a real
client still submits and reads orders; once the idle connections are gone nothing is left
broken. (dispatchd also closes connections that never finish their handshake within 10 s and
HTTP/2 connections idle for 2 minutes; those times are not waited for here.)

    descriptor_limits.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR ...
"""
import resource
import socket
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import Harness, check, common_arguments  # noqa: E402
from warehouse.dispatch.v1 import orders_pb2  # noqa: E402


def open_files_limit(pid):
    with open(f"/proc/{pid}/limits") as f:
        for line in f:
            if line.startswith("Max open files"):
                return int(line.split()[3])
    return None


def main():
    args = common_arguments(__doc__).parse_args()
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    check(hard == resource.RLIM_INFINITY or hard >= 1024, f"this machine's hard descriptor limit is {hard}")
    with Harness(args, "descriptor-limits") as h:
        resource.setrlimit(resource.RLIMIT_NOFILE, (256, hard))
        try:
            server = h.start_server(["--time-scale", "10"])  # inherits the soft limit of 256
        finally:
            resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))
        raised = open_files_limit(server.pid)
        h.log(f"dispatchd's descriptor limit: {raised} (started with 256, hard {hard})")
        check(raised is not None and raised > 256, f"dispatchd kept a descriptor limit of {raised}")
        idle = []
        try:
            for port, count in ((server.grpc_port, 300), (server.http_port, 100)):
                for _ in range(count):
                    s = socket.create_connection(("127.0.0.1", port), timeout=10)
                    idle.append(s)
            h.log(f"{len(idle)} idle connections open")
            r = server.orders.SubmitOrder(orders_pb2.SubmitOrderRequest(
                client_order_id="fd-1", picks=[orders_pb2.StopSpec(point_name="K3-2-3N")],
                drop=orders_pb2.StopSpec(point_name="D-B2")), timeout=10)
            check(r.order.id, "no order id")
            status = server.rest("/healthz")
            check(status.get("status") == "ok", f"/healthz: {status}")
        finally:
            for s in idle:
                s.close()
        listed = server.orders.ListOrders(orders_pb2.ListOrdersRequest(), timeout=10)
        check(len(listed.orders) == 1, f"{len(listed.orders)} orders listed, want 1")
        h.log("idle connections did not lock the service out")


if __name__ == "__main__":
    main()
