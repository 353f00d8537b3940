"""Shared by the bad-input end-to-end tests (issue 6 §3 "Bad input on every door"):
bad_input_grpc.py, bad_input_fleet.py, bad_input_http.py and garbage_bytes.py.

Each of them seeds dispatchd with GOOD_ORDERS, attacks one door with bad input and then
checks, with the helpers here, that
  - every attack got a clear error (expect_rpc_error / expect_http_error: the status code and
    words of the message that name the problem);
  - the server still serves (check_serving: /healthz answers and a good order is accepted);
  - nothing stored was damaged (check_intact: EVERY order read back through ListOrders with
    small pages and through GET /api/v1/orders equals what SubmitOrder acknowledged, no order
    added), also after a restart on the same database (restart).
Attacks run as named cases (Cases): one failing case does not hide the others, and a case
after which dispatchd is no longer running fails at once, naming the case.
"""
import contextlib
import http.client
import json
import subprocess
import time

import grpc
from google.protobuf import json_format
from e2e_harness import CANCELLED, FAILED, RANK, TestFailure, check, state_name
from warehouse.dispatch.v1 import common_pb2, orders_pb2

# A mix of what a WMS sends: point names, coordinates (seed Table 1 rows), several picks,
# priorities (negative and the int32 maximum), work time and a release time in the past.
GOOD_ORDERS = [
    dict(picks=["K1-1-1N"], drop="D-B1"),
    dict(picks=[(5.5, 13), (9, 9)], drop=(6.5, 2.75)),
    dict(picks=[(10.5, 13), (10.5, 9)], drop=(11.5, 2.75), priority=3),
    dict(picks=[(29, 13), (30.5, 13), (29, 10.5)], drop=(32.25, 5), work_time=2.5),
    dict(picks=["K1-2-1N", "K1-3-2N"], drop="D-T1", priority=-2),
    dict(picks=[(19, 17)], drop=(6.5, 2.75), release_time=0.0),
    dict(picks=["K1-1-2N", (20.5, 10.5)], drop="D-L1"),
    dict(picks=["K1-4-1N"], drop="D-R1", priority=2**31 - 1),
]
PAGE = 3  # ListOrders page size for the read-back: several pages, tokens followed


def stop(spec):
    """A StopSpec from a point name or an (x, y) pair."""
    if isinstance(spec, str):
        return orders_pb2.StopSpec(point_name=spec)
    return orders_pb2.StopSpec(position=common_pb2.Vec2(x=spec[0], y=spec[1]))


def order_request(client_id, picks, drop, **fields):
    return orders_pb2.SubmitOrderRequest(client_order_id=client_id, picks=[stop(p) for p in picks],
                                         drop=stop(drop), **fields)


def content(o):
    """What must never change about a stored order (gRPC Order)."""
    return dict(id=o.id, client=o.client_order_id, priority=o.priority,
                picks=[p.point_id for p in o.picks], drop=o.drop.point_id, formation=o.formation,
                work_time=o.work_time, created=o.created_time,
                release=o.release_time if o.HasField("release_time") else None)


def rest_content(j):
    """content() of a REST order: its JSON is the gRPC Order's proto3 JSON mapping."""
    return content(json_format.ParseDict(j, orders_pb2.Order()))


class Book:
    """The orders the server acknowledged, by client id: what a read-back must return."""

    def __init__(self):
        self.orders = {}  # client id -> content()
        self.cancelled = set()  # client ids cancelled on purpose
        self.states = {}  # client id -> state at the last check_intact

    def add(self, order):
        self.orders[order.client_order_id] = content(order)


def submit_good(h, server, book, tag):
    """Submits GOOD_ORDERS (client ids '<tag>-good-<i>'); all must be created."""
    for i, o in enumerate(GOOD_ORDERS, 1):
        o = dict(o)
        request = order_request(f"{tag}-good-{i}", o.pop("picks"), o.pop("drop"), **o)
        r = server.orders.SubmitOrder(request, timeout=10)
        check(r.created, f"good order {tag}-good-{i} was not created")
        book.add(r.order)
    h.log(f"{len(GOOD_ORDERS)} good orders stored: "
          + ", ".join(f"{c}={v['id']}" for c, v in book.orders.items()))


# --- gRPC -------------------------------------------------------------------------------
def expect_rpc_error(call, code, *words, max_len=None):
    """call() must fail with `code` and a message containing every word (case-insensitive);
    returns the message."""
    try:
        result = call()
    except grpc.RpcError as err:
        got, details = err.code(), err.details() or ""
        check(got == code, f"expected {code.name}, got {got.name}: '{details[:300]}'")
        missing = [w for w in words if w.lower() not in details.lower()]
        check(not missing, f"{code.name} message '{details[:300]}' does not name {missing}")
        check(max_len is None or len(details) <= max_len,
              f"{code.name} message of {len(details)} bytes (want <= {max_len})")
        return details
    raise TestFailure(f"expected {code.name}, but the call succeeded: {str(result)[:200]!r}")


def list_pages(h, server, page_size=PAGE):
    """Every order through ListOrders, page_size at a time; checks the paging itself."""
    out, token, pages = [], "", 0
    while True:
        page = server.orders.ListOrders(
            orders_pb2.ListOrdersRequest(page_size=page_size, page_token=token), timeout=10)
        pages += 1
        check(len(page.orders) <= page_size,
              f"a page of {len(page.orders)} orders (page size {page_size})")
        check(page.orders or not page.next_page_token, "an empty page with a next_page_token")
        out.extend(page.orders)
        token = page.next_page_token
        if not token:
            break
        check(pages < 10000, "ListOrders keeps returning next_page_token")
    ids = [o.id for o in out]
    check(len(set(ids)) == len(ids), f"ListOrders pages repeat orders: {ids}")
    check(ids == sorted(ids), f"ListOrders not in submission order: {ids}")
    return out


# --- REST -------------------------------------------------------------------------------
def http_call(server, method, path, body=None, headers=None, timeout=10):
    """One request on a fresh connection: (status, content type, body bytes)."""
    conn = http.client.HTTPConnection("127.0.0.1", server.http_port, timeout=timeout)
    try:
        conn.request(method, path, body=body, headers=headers or {})
        resp = conn.getresponse()
        return resp.status, resp.getheader("Content-Type") or "", resp.read()
    finally:
        conn.close()


def json_body(status, content_type, data, what):
    check(content_type.startswith("application/json"),
          f"{what}: HTTP {status} with Content-Type '{content_type}', not JSON: {data[:200]!r}")
    try:
        return json.loads(data.decode())
    except ValueError as err:
        raise TestFailure(f"{what}: HTTP {status} body is not JSON ({err}): {data[:200]!r}")


def expect_http_error(server, method, path, statuses, *words, body=None, headers=None):
    """The request must get one of `statuses` (int or tuple) with a JSON {"error": "..."}
    naming every word (case-insensitive); returns the message."""
    statuses = (statuses,) if isinstance(statuses, int) else tuple(statuses)
    what = f"{method} {path[:80]}" + (f" {body[:60]!r}" if body else "")
    status, ctype, data = http_call(server, method, path, body, headers)
    check(status in statuses, f"{what}: HTTP {status}, want {statuses}: {data[:300]!r}")
    j = json_body(status, ctype, data, what)
    check(isinstance(j, dict) and isinstance(j.get("error"), str) and j["error"],
          f"{what}: HTTP {status} body is not {{\"error\": \"...\"}}: {j!r:.300}")
    missing = [w for w in words if w.lower() not in j["error"].lower()]
    check(not missing, f"{what}: error '{j['error'][:300]}' does not name {missing}")
    return j["error"]


def rest_orders(server):
    status, ctype, data = http_call(server, "GET", "/api/v1/orders")
    check(status == 200, f"GET /api/v1/orders: HTTP {status}: {data[:200]!r}")
    return json_body(status, ctype, data, "GET /api/v1/orders")["orders"]


# --- the three after-attack checks ----------------------------------------------------------
def check_serving(h, server, book, tag):
    """/healthz answers and a good order is accepted (and stored in `book`)."""
    status, _, data = http_call(server, "GET", "/healthz", timeout=5)
    check(status == 200, f"/healthz: HTTP {status}: {data[:100]!r}")
    r = server.orders.SubmitOrder(order_request(f"{tag}-after", ["K1-1-3N"], "D-B2"), timeout=10)
    check(r.created, f"the good order {tag}-after was not created")
    book.add(r.order)
    h.log(f"still serving: /healthz ok, {tag}-after accepted as {r.order.id}")
    return r.order


def check_intact(h, server, book, what):
    """EVERY stored order (gRPC, paged, and REST) is exactly one the server acknowledged, with
    its acknowledged content; none missing, none added; none went back in its lifecycle."""
    grpc_orders = list_pages(h, server)
    by_client = {}
    for o in grpc_orders:
        check(o.client_order_id not in by_client,
              f"{what}: client id {o.client_order_id} stored twice")
        by_client[o.client_order_id] = o
    lost = sorted(set(book.orders) - set(by_client))
    added = sorted(set(by_client) - set(book.orders))
    check(not lost, f"{what}: acknowledged orders missing: {lost}")
    check(not added, f"{what}: orders nobody had acknowledged: {added}")
    for client, want in book.orders.items():
        got = content(by_client[client])
        check(got == want, f"{what}: {client} changed: stored {got}, acknowledged {want}")
        state = by_client[client].state
        if client in book.cancelled:
            check(state == CANCELLED, f"{what}: {client} was cancelled, now {state_name(state)}")
        else:
            check(state not in (CANCELLED, FAILED), f"{what}: {client} is {state_name(state)}")
        before = book.states.get(client)
        if before is not None:
            check(RANK[state] >= RANK[before],
                  f"{what}: {client} went back from {state_name(before)} to {state_name(state)}")
        book.states[client] = state
    rest = rest_orders(server)
    check(len(rest) == len(grpc_orders),
          f"{what}: REST lists {len(rest)} orders, gRPC {len(grpc_orders)}")
    for j in rest:
        want = book.orders.get(j["client_order_id"], {})
        check(rest_content(j) == want, f"{what}: REST order {j['id']} is {rest_content(j)}, "
                                       f"acknowledged {want}")
    h.log(f"{what}: all {len(book.orders)} acknowledged orders intact "
          f"(ListOrders in pages of {PAGE}, and REST)")


def restart(h, server, extra):
    """SIGTERM (must exit 0), then dispatchd again on the same database and gRPC port."""
    server.close_channel()
    rc = server.stop()
    check(rc == 0, f"{server.name} exited with status {rc} on SIGTERM after the attacks")
    return h.start_server(extra, grpc_port=server.grpc_port)


class Cases:
    """Runs named attack cases: a TestFailure is recorded and the next case runs; a case
    after which dispatchd is not running ends the test (naming it)."""

    def __init__(self, h, server):
        self.h = h
        self.server = server
        self.failures = []

    def run(self, name, fn, *args):
        t0 = time.monotonic()
        try:
            fn(*args)
            self.h.log(f"ok   {name} ({time.monotonic() - t0:.2f} s)")
        except (TestFailure, OSError, http.client.HTTPException, grpc.RpcError) as err:
            what = str(err) if isinstance(err, TestFailure) else f"{type(err).__name__}: {err}"
            self.failures.append(f"{name}: {what}")
            self.h.log(f"FAIL {name}: {what}")
            if not isinstance(err, TestFailure):  # the server may be going down: let it
                with contextlib.suppress(subprocess.TimeoutExpired):
                    self.server.popen.wait(timeout=2)
        if not self.server.running():
            self.failures.append(f"{name}: dispatchd died (status {self.server.popen.returncode})")
            self.finish()

    def finish(self):
        check(not self.failures,
              f"{len(self.failures)} case(s) failed:\n  " + "\n  ".join(self.failures))
