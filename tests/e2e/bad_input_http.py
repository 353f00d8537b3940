#!/usr/bin/env python3
"""Bad input on the REST API (issue 6 §3): a real dispatchd, seeded with good orders, gets
requests a broken or hostile HTTP client might send. Each must be answered with HTTP 4xx and
a JSON body {"error": "..."} naming the problem, never a 500, a hang or a crash:
  - bodies that are not JSON or not an object; fields of the wrong type (picks as a number,
    priority as a string, 2^32 + 1 or 1.5, work_time / release_time / formation / stops /
    client id of the wrong type), each error naming the field;
  - unknown and wrong-kind points, coordinates off the floor, empty and too many picks, a
    negative work time; a client id reused with other content (409);
  - unknown order and robot ids (404), an unknown state filter (400), paths and query values
    that are not UTF-8 (echoed in the error, which must still be JSON), an over-long URI (414);
  - wrong methods (PUT /api/v1/orders and others: 404 or 405 with JSON);
  - a 50 MB body: 413 with JSON, after at most the server's limit of BODY_LIMIT bytes kept
    (cpp-httplib's set_payload_max_length; see the report of issue 6 for server/rest_api.cpp);
  - slow clients: STALLED connections that send half a request (half the headers; the
    headers and half the body) and stall, and STALLED idle keep-alive connections, must not
    keep other clients waiting: /healthz answers from another connection within
    HEALTHZ_DEADLINE, and the server gives up on the stalled ones by its read timeout.
Afterwards the server must still serve (/healthz, a good order accepted) and every order,
read back through ListOrders in small pages and GET /api/v1/orders, must be exactly one that
was acknowledged, also after a restart on the same database.

    bad_input_http.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import http.client
import json
import socket
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from bad_input_common import (Book, Cases, check_intact, check_serving,  # noqa: E402
                              expect_http_error, http_call, json_body, restart, submit_good)
from e2e_harness import Harness, TestFailure, check, common_arguments  # noqa: E402

SERVER_ARGS = ["--time-scale", "10"]
ORDERS = "/api/v1/orders"
BODY_LIMIT = 1 << 20  # bytes: an order of the most picks allowed (100) is ~5 kB of JSON
HEALTHZ_DEADLINE = 2.0  # wall seconds for /healthz while other clients stall
STALLED = 16  # stalled and idle clients each: more than cpp-httplib's default of 8 threads
READ_TIMEOUT_MAX = 15.0  # a stalled request must be given up by then (httplib's default: 5 s)


def stop(spec):
    """A StopSpec in JSON from a point name or an {"x", "y"} dict; anything else as it is."""
    if isinstance(spec, str):
        return {"point_name": spec}
    if isinstance(spec, dict) and set(spec) == {"x", "y"}:
        return {"position": spec}
    return spec


def order(client, **fields):
    """A SubmitOrderRequest's JSON (the REST body is the proto3 JSON mapping)."""
    body = {"client_order_id": client, "picks": [stop("K1-1-1N")], "drop": stop("D-B1")}
    if isinstance(fields.get("picks"), list):
        fields["picks"] = [stop(p) for p in fields["picks"]]
    if "drop" in fields:
        fields["drop"] = stop(fields["drop"])
    body.update(fields)
    return json.dumps(body)


def post_fails(server, status, body, *words):
    return expect_http_error(server, "POST", ORDERS, status, *words, body=body,
                             headers={"Content-Type": "application/json"})


def not_json(server):
    for body in ["{not json", "", "{\"client_order_id\": \"x\",", "\xff\xfe"]:
        post_fails(server, 400, body, "not JSON")
    for body in ["[1, 2]", "null", "\"an order\"", "42"]:
        post_fails(server, 400, body, "JSON object")
    # Issue 18: a body that does not say it is JSON (a browser's cross-origin text/plain or
    # form POST, or none at all) creates nothing.
    for headers in [{"Content-Type": "text/plain"}, {"Content-Type": "application/x-www-form-urlencoded"}, {}]:
        expect_http_error(server, "POST", ORDERS, 415, "Content-Type: application/json", body=order("csrf-1"),
                          headers=headers)


def wrong_types(server):
    post_fails(server, 400, order("t-1", picks=5), "picks")
    post_fails(server, 400, order("t-2", picks="K1-1-1N"), "picks")
    post_fails(server, 400, order("t-3", picks=[7]), "picks[0]")
    post_fails(server, 400, order("t-4", picks=[{"position": {"x": "nineteen", "y": 17}}]), "picks[0].position.x")
    post_fails(server, 400, order("t-4b", picks=[{}]), "pick 1", "neither point_name nor position")
    post_fails(server, 400, order("t-4c", picks=[{"x": 19, "y": 17, "z": 0}]), "picks[0]", "cannot find field")
    post_fails(server, 400, order("t-5", drop=None), "drop")
    post_fails(server, 400, order("t-6", drop=[6.5, 2.75]), "drop")
    post_fails(server, 400, order("t-7", priority="high"), "priority")
    post_fails(server, 400, order("t-8", priority=2**32 + 1), "priority")  # not wrapped to 1
    post_fails(server, 400, order("t-9", priority=1.5), "priority")
    post_fails(server, 400, order("t-10", priority=True), "priority")
    post_fails(server, 400, order("t-11", work_time="five"), "work_time")
    post_fails(server, 400, order("t-12", formation="maybe"), "formation")
    post_fails(server, 400, order("t-13", formation=1), "formation")
    post_fails(server, 400, order("t-14", release_time="soon"), "release_time")
    post_fails(server, 400, '{"client_order_id": "t-15", "picks": [{"point_name": "K1-1-1N"}], '
                            '"drop": {"point_name": "D-B1"}, '
                            '"release_time": 1e999}', "1e999")  # a JSON parse error, no field
    post_fails(server, 400, json.dumps({"client_order_id": 5, "picks": [stop("K1-1-1N")],
                                        "drop": stop("D-B1")}), "client_order_id")
    post_fails(server, 400, json.dumps({"picks": [stop("K1-1-1N")], "drop": stop("D-B1")}), "client_order_id")
    # The old REST shape (stops as bare names) is not a SubmitOrderRequest.
    post_fails(server, 400, json.dumps({"client_order_id": "t-16", "picks": ["K1-1-1N"], "drop": "D-B1"}),
               "StopSpec")
    post_fails(server, 400, order("t-17", relase_time=60), "relase_time")


def bad_orders(server, book):
    post_fails(server, 400, order("o-1", picks=["NO-SUCH-POINT"]), "unknown point", "NO-SUCH-POINT")
    post_fails(server, 400, order("o-2", picks=["D-B1"]), "not a pick point")
    post_fails(server, 400, order("o-3", picks=[{"x": 1e6, "y": -1e6}]), "not at a pick point")
    post_fails(server, 400, order("o-4", drop={"x": -40, "y": 3}), "drop")
    post_fails(server, 400, order("o-5", picks=[]), "no pick points")
    post_fails(server, 400, order("o-6", picks=["K1-1-1N"] * 101), "101 picks", "at most 100")
    post_fails(server, 400, order("o-7", work_time=-1), "work time")
    post_fails(server, 400, order("c" * 129), "longer than 128")
    first = next(iter(book.orders))  # <tag>-good-1: picks K1-1-1N, drop D-B1
    post_fails(server, 409, order(first, drop="D-B2"), first, book.orders[first]["id"])
    status, ctype, data = http_call(server, "POST", ORDERS, order(first), headers={"Content-Type": "application/json"})
    j = json_body(status, ctype, data, "the same submission again")
    check(status == 200 and j["created"] is False and j["order"]["id"] == book.orders[first]["id"],
          f"the same submission again: HTTP {status} {j}")


def unknown_ids(server):
    expect_http_error(server, "GET", f"{ORDERS}/ord-999999", 404, "ord-999999")
    expect_http_error(server, "GET", "/api/v1/robots/R404", 404, "R404")
    expect_http_error(server, "DELETE", f"{ORDERS}/ord-999999", 404, "ord-999999")
    expect_http_error(server, "GET", f"{ORDERS}?state=bogus", 400, "unknown state", "bogus")
    expect_http_error(server, "GET", f"{ORDERS}?state=", 400, "unknown state")
    expect_http_error(server, "GET", "/api/v1/" + "a" * 9000, 414)


def not_utf8(server):
    """Echoed bytes that are not UTF-8 must not turn the JSON error into a 500 (or worse)."""
    expect_http_error(server, "GET", f"{ORDERS}/%FF%FE", 404, "no order")
    expect_http_error(server, "DELETE", f"{ORDERS}/%C3%28", 404, "no order")
    expect_http_error(server, "GET", "/api/v1/robots/%FF", 404, "no robot")
    expect_http_error(server, "GET", f"{ORDERS}?state=%FF", 400, "unknown state")
    expect_http_error(server, "GET", "/no/such/path/%FF", 404, "no such endpoint")


def wrong_methods(server):
    for method, path in [("PUT", ORDERS), ("PATCH", f"{ORDERS}/ord-000001"), ("DELETE", ORDERS),
                         ("POST", "/healthz"), ("PUT", "/api/v1/robots/R1"),
                         ("GET", "/api/v2/orders")]:
        expect_http_error(server, method, path, (404, 405), body="{}" if method != "GET" else None)


def huge_body(server):
    """A 50 MB POST: 413 with JSON, and the server keeps serving."""
    size = 50 << 20
    sock = socket.create_connection(("127.0.0.1", server.http_port), timeout=60)
    try:
        sock.sendall(f"POST {ORDERS} HTTP/1.1\r\nHost: test\r\nContent-Type: application/json\r\n"
                     f"Content-Length: {size}\r\nConnection: close\r\n\r\n".encode())
        chunk = b"[" + b"0," * (1 << 19)
        sent = 0
        try:
            while sent < size:
                n = min(len(chunk), size - sent)
                sock.sendall(chunk[:n])
                sent += n
        except OSError:  # the server answered early and closed: fine, read its answer
            pass
        data = b""
        while True:
            part = sock.recv(65536)
            if not part:
                break
            data += part
    except socket.timeout:
        raise TestFailure("no answer to a 50 MB POST within 60 s")
    except ConnectionResetError:
        if not data:
            raise TestFailure("the connection of a 50 MB POST was reset without an answer")
    finally:
        sock.close()
    head, _, body = data.partition(b"\r\n\r\n")
    status = int(head.split(b" ", 2)[1]) if head.startswith(b"HTTP/1.1 ") else None
    check(status == 413,
          f"50 MB POST: {head[:60]!r}, want HTTP 413 (body limit {BODY_LIMIT} bytes)")
    ctype = next((line.split(b":", 1)[1].strip().decode() for line in head.split(b"\r\n")[1:]
                  if line.lower().startswith(b"content-type:")), "")
    j = json_body(status, ctype, body, "50 MB POST")
    check("too large" in j.get("error", "").lower(),
          f"413 error '{j.get('error')}' does not say 'too large'")


def slow_clients(server):
    """STALLED half-requests and STALLED idle keep-alive connections: /healthz still answers at
    once; the server gives up on the half-requests (4xx or close) by its read timeout."""
    stalled = []
    half_body = f"POST {ORDERS} HTTP/1.1\r\nHost: t\r\nContent-Length: 100\r\n\r\n{{\"client"
    for i in range(STALLED):
        s = socket.create_connection(("127.0.0.1", server.http_port), timeout=READ_TIMEOUT_MAX)
        s.sendall(half_body.encode() if i % 2 else b"GET /healthz HTTP/1.1\r\nHo")
        stalled.append(s)
    idle = []
    for i in range(STALLED):  # e.g. browsers polling the web map
        conn = http.client.HTTPConnection("127.0.0.1", server.http_port, timeout=HEALTHZ_DEADLINE)
        try:
            conn.request("GET", "/healthz")
            conn.getresponse().read()
        except OSError as err:  # socket.timeout included
            raise TestFailure(f"GET /healthz on a new connection got no answer within "
                              f"{HEALTHZ_DEADLINE} s ({err!r}) while {STALLED} clients stall and "
                              f"{i} keep idle connections: too few server threads?")
        idle.append(conn)
    t0 = time.monotonic()
    try:
        status, _, data = http_call(server, "GET", "/healthz", timeout=HEALTHZ_DEADLINE)
    except OSError as err:  # socket.timeout included
        raise TestFailure(f"/healthz while {STALLED} clients stall and {STALLED} idle: {err!r}")
    took = time.monotonic() - t0
    for conn in idle:
        conn.close()
    check(status == 200, f"/healthz while clients stall: HTTP {status} {data[:80]!r}")
    check(took <= HEALTHZ_DEADLINE, f"/healthz took {took:.2f} s while clients stall")
    given_up = []
    for s in stalled:
        try:
            s.recv(64)  # blocks until the server answers or closes
            given_up.append(round(time.monotonic() - t0, 2))
        except socket.timeout:
            given_up.append(None)
        finally:
            s.close()
    check(None not in given_up,
          f"the server still waits for stalled clients after {READ_TIMEOUT_MAX} s: {given_up}")


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "bad-input-http") as h:
        server = h.start_server(SERVER_ARGS)
        book = Book()
        submit_good(h, server, book, "http")
        cases = Cases(h, server)
        cases.run("bodies that are not JSON objects", not_json, server)
        cases.run("fields of the wrong type", wrong_types, server)
        cases.run("orders that cannot be served, a reused client id", bad_orders, server, book)
        cases.run("unknown ids and state filters, a long URI", unknown_ids, server)
        cases.run("wrong methods", wrong_methods, server)
        cases.run("slow clients", slow_clients, server)
        cases.run("a 50 MB body", huge_body, server)
        cases.run("paths and queries that are not UTF-8", not_utf8, server)

        check_serving(h, server, book, "http")
        check_intact(h, server, book, "after the attacks")
        server = restart(h, server, SERVER_ARGS)
        check_intact(h, server, book, "after a restart on the same database")
        check_serving(h, server, book, "http-restarted")
        cases.finish()


if __name__ == "__main__":
    main()
