#!/usr/bin/env python3
"""The disk fills up mid-run (issue 18 §5): dispatchd takes orders; then its file-size limit
(RLIMIT_FSIZE, set on the running process with prlimit: every file it writes, the SQLite
database and its WAL included, stops growing, as on a full disk or quota) is lowered to the
size its files have. Then:
  - SubmitOrder fails with UNAVAILABLE naming the storage failure (within a few hundred
    submits: SQLite first fills pages it already has), /readyz says 503 and why, and the
    service keeps answering reads (GetOrder, /healthz);
  - no acknowledged order is lost: each one reads back;
  - once the limit is lifted ("the disk has room again") the next submits succeed and /readyz
    is 200 again, without a restart;
  - after a restart on the same database every order acknowledged before, during and after the
    fault is there, exactly once, and no refused one is.

    disk_full.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import os
import resource
import sys
import urllib.error
import urllib.request

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
import grpc  # noqa: E402
from e2e_harness import Harness, check, common_arguments  # noqa: E402
from warehouse.dispatch.v1 import orders_pb2  # noqa: E402

MAX_TRIES = 2000


def request(client_id):
    r = orders_pb2.SubmitOrderRequest(client_order_id=client_id)
    r.picks.add().point_name = "K3-2-3N"
    r.drop.point_name = "D-B2"
    return r


def readyz(server):
    try:
        with urllib.request.urlopen(f"http://{server.http}/readyz", timeout=10) as resp:
            return resp.status, resp.read().decode()
    except urllib.error.HTTPError as err:
        return err.code, err.read().decode()


def submit(server, client_id):
    """(order id, None) when acknowledged, (None, the RpcError) when refused."""
    try:
        return server.orders.SubmitOrder(request(client_id), timeout=10).order.id, None
    except grpc.RpcError as err:
        return None, err


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "disk-full") as h:
        server = h.start_server()
        db = os.path.join(h.work, "dispatch.db")
        acked = {}  # client id -> order id
        for i in range(20):
            oid, err = submit(server, f"before-{i}")
            check(err is None, f"submit before the fault: {err}")
            acked[f"before-{i}"] = oid

        files = [p for p in (db, db + "-wal", db + "-shm") if os.path.exists(p)]
        limit = max(os.path.getsize(p) for p in files)
        h.log(f"file sizes {[(os.path.basename(p), os.path.getsize(p)) for p in files]}: limit {limit} bytes")
        soft, hard = resource.prlimit(server.pid, resource.RLIMIT_FSIZE)
        resource.prlimit(server.pid, resource.RLIMIT_FSIZE, (limit, hard))
        refused = None
        for i in range(MAX_TRIES):
            cid = f"during-{i}"
            oid, err = submit(server, cid)
            if err is None:
                acked[cid] = oid
                continue
            refused = (cid, err)
            break
        check(refused is not None, f"{MAX_TRIES} orders acknowledged past the file-size limit")
        cid, err = refused
        h.log(f"refused after {len(acked) - 20} more orders: {err.code().name} '{err.details()}'")
        check(err.code() == grpc.StatusCode.UNAVAILABLE, f"a full disk answered {err.code().name}, want UNAVAILABLE")
        check("stor" in err.details().lower(), f"'{err.details()}' does not say the storage failed")
        status, body = readyz(server)
        check(status == 503, f"/readyz with a full disk: {status} {body}")
        h.log(f"/readyz: {status} {body.strip()}")
        for c, oid in acked.items():
            got = server.orders.GetOrder(orders_pb2.GetOrderRequest(order_id=oid), timeout=10)
            check(got.client_order_id == c, f"{oid} reads back as {got.client_order_id}, want {c}")
        with urllib.request.urlopen(f"http://{server.http}/healthz", timeout=10) as resp:
            check(resp.status == 200, f"/healthz with a full disk: {resp.status}")

        resource.prlimit(server.pid, resource.RLIMIT_FSIZE, (soft, hard))  # room again
        oid, err = submit(server, cid)
        check(err is None, f"the refused order again once there is room: {err}")
        acked[cid] = oid
        for i in range(5):
            oid, err = submit(server, f"after-{i}")
            check(err is None, f"submit after the fault: {err}")
            acked[f"after-{i}"] = oid
        status, body = readyz(server)
        check(status == 200, f"/readyz once there is room: {status} {body}")
        h.log(f"recovered without a restart: {len(acked)} orders acknowledged, /readyz {status}")

        check(server.stop() == 0, "dispatchd did not stop cleanly")
        server = h.start_server(db=db)
        stored = {o.client_order_id: o.id for o in h.list_orders(server)}
        check(stored == acked, f"after the restart: {len(stored)} orders stored, {len(acked)} acknowledged; "
                               f"missing {sorted(set(acked) - set(stored))[:5]}, extra {sorted(set(stored) - set(acked))[:5]}")
        h.log(f"after a restart: all {len(stored)} acknowledged orders, and only those")


if __name__ == "__main__":
    main()
