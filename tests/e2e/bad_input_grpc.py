#!/usr/bin/env python3
"""Bad input on OrderService (issue 6 §3): a real dispatchd, seeded with good orders, gets
malformed and nonsense requests; each must end in a gRPC status with a meaningful code and a
message naming the problem (orders.proto: INVALID_ARGUMENT for a malformed order or page
token, NOT_FOUND for an unknown order, ALREADY_EXISTS for a reused client order id,
RESOURCE_EXHAUSTED beyond the server's 4 MiB receive limit, gRPC's default, which
server/server.cpp keeps). Covered: bytes that are not protobuf, an oversized message,
unknown and wrong-kind point names, coordinates off the floor or not finite, missing and
empty stops, empty and too many picks, bad work and release times, client id missing / too
long / reused with other content, GetOrder / CancelOrder / ExplainAllocation of unknown ids,
bad page tokens, sizes and state filters, and messages echoing 100 kB of input. An
unreachable drop is tried when the map has one (the chu2024 floor is strongly connected and
map files must be, engine/io/map_format.md rule 4, so it is skipped with a note). Negative
priorities are valid (int32, higher is more urgent) and must be stored as given.

Afterwards the server must still serve (/healthz, a good order accepted) and every order,
read back through ListOrders in small pages and GET /api/v1/orders, must be exactly one that
was acknowledged, also after a restart on the same database.

    bad_input_grpc.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import random
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
import grpc  # noqa: E402
from bad_input_common import (Book, Cases, check_intact, check_serving, content,  # noqa: E402
                              expect_rpc_error, order_request, restart, stop, submit_good)
from e2e_harness import Harness, TestFailure, check, common_arguments  # noqa: E402
from warehouse.dispatch.v1 import map_pb2, map_pb2_grpc, orders_pb2  # noqa: E402

SERVER_ARGS = ["--time-scale", "10"]
SUBMIT = "/warehouse.dispatch.v1.OrderService/SubmitOrder"
MAX_RECEIVE = 4 * 1024 * 1024  # gRPC's default; server/server.cpp sets no other
MAX_PICKS = 100  # server/dispatcher.cpp kMaxPicksPerOrder
BIG = 100_000  # bytes of echoed input; the status message must stay short anyway
Code = grpc.StatusCode


def not_protobuf(server):
    """Raw bytes to SubmitOrder through identity serializers."""
    raw = server.channel.unary_unary(SUBMIT, request_serializer=None, response_deserializer=None)
    rng = random.Random(6)
    for what, data in [("random bytes", bytes(rng.getrandbits(8) for _ in range(512))),
                       ("a truncated field", b"\x0a\x10only-five"),
                       ("an invalid wire type", b"\x0f\x01\x02"),
                       ("a varint without end", b"\x10" + b"\xff" * 11),
                       ("invalid UTF-8 in a string", b"\x0a\x02\xff\xfe")]:
        try:
            raw(data, timeout=10)
        except grpc.RpcError as err:
            check(err.code() in (Code.INVALID_ARGUMENT, Code.INTERNAL) and err.details(),
                  f"{what}: {err.code().name} '{err.details()}' (want INVALID_ARGUMENT or "
                  "INTERNAL with a message saying the request is not a SubmitOrderRequest)")
            continue
        raise TestFailure(f"{what}: SubmitOrder accepted bytes that are not protobuf")


def oversized(server):
    raw = server.channel.unary_unary(SUBMIT, request_serializer=None, response_deserializer=None)
    # One length-delimited field (client_order_id) just over the limit.
    n = MAX_RECEIVE + 1
    length = bytearray()
    v = n
    while True:
        length.append((v & 0x7F) | (0x80 if v > 0x7F else 0))
        v >>= 7
        if not v:
            break
    expect_rpc_error(lambda: raw(b"\x0a" + bytes(length) + b"x" * n, timeout=30),
                     Code.RESOURCE_EXHAUSTED, "larger than max")


def submit_fails(server, code, request, *words, max_len=None):
    return expect_rpc_error(lambda: server.orders.SubmitOrder(request, timeout=10), code, *words,
                            max_len=max_len)


def bad_points(server):
    bad = Code.INVALID_ARGUMENT
    submit_fails(server, bad, order_request("bad-pt-1", ["NO-SUCH-POINT"], "D-B1"),
                 "pick 1", "unknown point", "NO-SUCH-POINT")
    submit_fails(server, bad, order_request("bad-pt-2", ["K1-1-1N"], "NOWHERE"), "drop", "NOWHERE")
    submit_fails(server, bad, order_request("bad-pt-3", ["D-B1"], "D-B1"),
                 "'D-B1' is a drop point, not a pick point")
    submit_fails(server, bad, order_request("bad-pt-4", ["K1-1-1N"], "K1-1-2N"),
                 "not a drop point")
    submit_fails(server, bad, order_request("bad-pt-5", ["Z" * BIG], "D-B1"), "unknown point",
                 max_len=2000)


def bad_coordinates(server):
    bad = Code.INVALID_ARGUMENT
    submit_fails(server, bad, order_request("bad-xy-1", [(1e6, -1e6)], "D-B1"),
                 "pick 1", "not at a pick point", "nearest")
    submit_fails(server, bad, order_request("bad-xy-2", [(19.5, 17)], "D-B1"),  # 0.5 m off
                 "pick 1", "tolerance")
    submit_fails(server, bad, order_request("bad-xy-3", ["K1-1-1N"], (-500, 900)), "drop")
    submit_fails(server, bad, order_request("bad-xy-4", [(1e300, 1e300)], "D-B1"),
                 "pick 1", "1e+300")
    submit_fails(server, bad, order_request("bad-xy-5", [(float("nan"), 3)], "D-B1"), "not finite")
    submit_fails(server, bad, order_request("bad-xy-6", ["K1-1-1N"], (float("inf"), 3)),
                 "drop", "not finite")


def bad_shapes(server):
    bad = Code.INVALID_ARGUMENT
    submit_fails(server, bad, order_request("bad-shape-1", [], "D-B1"), "no pick points")
    no_drop = orders_pb2.SubmitOrderRequest(client_order_id="bad-shape-2", picks=[stop("K1-1-1N")])
    submit_fails(server, bad, no_drop, "drop is required")
    empty_stop = orders_pb2.SubmitOrderRequest(client_order_id="bad-shape-3",
                                               picks=[orders_pb2.StopSpec()], drop=stop("D-B1"))
    submit_fails(server, bad, empty_stop, "pick 1", "neither point_name nor position")
    submit_fails(server, bad, order_request("", ["K1-1-1N"], "D-B1"), "client_order_id is required")
    submit_fails(server, bad, order_request("c" * 129, ["K1-1-1N"], "D-B1"), "longer than 128")
    for n in (MAX_PICKS + 1, 100_000):
        submit_fails(server, bad, order_request(f"bad-many-{n}", ["K1-1-1N"] * n, "D-B1"),
                     f"{n} picks", f"at most {MAX_PICKS}")


def bad_times(server):
    bad = Code.INVALID_ARGUMENT
    for i, t in enumerate([-1.0, 0.0, float("nan"), float("inf")]):
        submit_fails(server, bad, order_request(f"bad-tw-{i}", ["K1-1-1N"], "D-B1", work_time=t),
                     "work time")
    for i, t in enumerate([float("nan"), float("-inf")]):
        submit_fails(server, bad, order_request(f"bad-rt-{i}", ["K1-1-1N"], "D-B1", release_time=t),
                     "release_time", "finite")
    # Finite but absurd: an order released in 1e300 s (or taking a week per stop) never ends.
    submit_fails(server, bad, order_request("bad-rt-far", ["K1-1-1N"], "D-B1", release_time=1e300),
                 "release time", "1e+300")
    submit_fails(server, bad, order_request("bad-tw-week", ["K1-1-1N"], "D-B1", work_time=604800.0),
                 "work time", "at most")


def negative_priority(server, book):
    """Valid: stored as given (priorities are int32, higher is more urgent)."""
    for client, p in (("prio-neg", -7), ("prio-min", -2**31)):
        r = server.orders.SubmitOrder(order_request(client, ["K1-2-2N"], "D-B3", priority=p),
                                      timeout=10)
        check(r.created and r.order.priority == p, f"priority {p} stored as {r.order.priority}")
        book.add(r.order)


def reused_client_id(server, book):
    first = next(iter(book.orders))  # <tag>-good-1: picks K1-1-1N, drop D-B1
    stored = book.orders[first]
    for what, req in [("other picks", order_request(first, ["K1-1-2N"], "D-B1")),
                      ("other drop", order_request(first, ["K1-1-1N"], "D-B2")),
                      ("other priority", order_request(first, ["K1-1-1N"], "D-B1", priority=5)),
                      ("formation", order_request(first, ["K1-1-1N"], "D-B1", formation=True)),
                      ("other work time", order_request(first, ["K1-1-1N"], "D-B1", work_time=9))]:
        msg = submit_fails(server, Code.ALREADY_EXISTS, req, first, stored["id"])
        check("different content" in msg,
              f"{what}: ALREADY_EXISTS message '{msg}' says nothing about the content")
    again = server.orders.SubmitOrder(order_request(first, ["K1-1-1N"], "D-B1"), timeout=10)
    check(not again.created and content(again.order) == stored,
          f"the same submission again: created={again.created}, {content(again.order)} "
          f"(stored {stored})")


def unknown_ids(server, book):
    o = server.orders

    def get(**key):
        return lambda: o.GetOrder(orders_pb2.GetOrderRequest(**key), timeout=10)

    def cancel(**key):
        return lambda: o.CancelOrder(orders_pb2.CancelOrderRequest(**key), timeout=10)

    def explain(order_id):
        request = orders_pb2.ExplainAllocationRequest(order_id=order_id)
        return lambda: o.ExplainAllocation(request, timeout=10)

    expect_rpc_error(get(order_id="ord-999999"), Code.NOT_FOUND, "ord-999999")
    expect_rpc_error(get(client_order_id="nobody"), Code.NOT_FOUND, "nobody")
    expect_rpc_error(get(order_id="q" * BIG), Code.NOT_FOUND, "no order", max_len=2000)
    expect_rpc_error(get(), Code.INVALID_ARGUMENT, "order_id or client_order_id")
    expect_rpc_error(cancel(order_id="ord-999999"), Code.NOT_FOUND, "ord-999999")
    expect_rpc_error(cancel(), Code.INVALID_ARGUMENT, "order_id is required")
    expect_rpc_error(explain("nope"), Code.NOT_FOUND, "nope")
    accepted = book.orders[next(iter(book.orders))]["id"]  # no robots: never allocated
    expect_rpc_error(explain(accepted), Code.FAILED_PRECONDITION, "not been allocated")


def bad_paging(server, book):
    def page(**fields):
        return lambda: server.orders.ListOrders(orders_pb2.ListOrdersRequest(**fields), timeout=10)

    count = len(book.orders)
    for token in ["x", "p", "P1", "p-1", "p+1", "p 1", "p1x", "p0x10", "p01", "p" + "9" * 30,
                  f"p{count + 1}", "p99999999", "\u00e9", "t" * BIG]:
        expect_rpc_error(page(page_token=token), Code.INVALID_ARGUMENT, "page_token", max_len=2000)
    expect_rpc_error(page(page_size=-1), Code.INVALID_ARGUMENT, "page_size")
    expect_rpc_error(page(states=[99]), Code.INVALID_ARGUMENT, "states", "99")
    first = page(page_size=1)()
    check(first.next_page_token, "a page of 1 of several orders has no next_page_token")
    rest = page(page_size=1000, page_token=first.next_page_token)()
    check(len(rest.orders) == count - 1,
          f"the token of page 1 led to {len(rest.orders)} orders, not {count - 1}")


def unreachable_drop(h, server):
    stub = map_pb2_grpc.MapServiceStub(server.channel)
    m = stub.GetMap(map_pb2.GetMapRequest(), timeout=10).map
    succ = {}
    for a in m.arcs:
        succ.setdefault(a.from_point, []).append(a.to_point)
    picks = [p for p in m.points if p.kind == map_pb2.POINT_KIND_PICK]
    seen, todo = {picks[0].id}, [picks[0].id]
    while todo:
        for q in succ.get(todo.pop(), []):
            if q not in seen:
                seen.add(q)
                todo.append(q)
    cut = [p for p in m.points if p.kind == map_pb2.POINT_KIND_DROP and p.id not in seen]
    if not cut:
        h.log(f"note: no drop unreachable from pick '{picks[0].name}' on map '{m.name}' "
              "(map files must be service-connected): unreachable drop skipped")
        return
    request = order_request("bad-unreachable", [picks[0].name], cut[0].name)
    submit_fails(server, Code.INVALID_ARGUMENT, request, "no route", cut[0].name)


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "bad-input-grpc") as h:
        server = h.start_server(SERVER_ARGS)
        book = Book()
        submit_good(h, server, book, "grpc")
        cases = Cases(h, server)
        cases.run("bytes that are not protobuf", not_protobuf, server)
        cases.run("a message over the 4 MiB receive limit", oversized, server)
        cases.run("unknown and wrong-kind point names", bad_points, server)
        cases.run("coordinates off the floor or not finite", bad_coordinates, server)
        cases.run("missing stops, empty and too many picks, bad client ids", bad_shapes, server)
        cases.run("bad work and release times", bad_times, server)
        cases.run("negative priorities are stored as given", negative_priority, server, book)
        cases.run("a client order id reused with other content", reused_client_id, server, book)
        cases.run("unknown order ids", unknown_ids, server, book)
        cases.run("bad page tokens, page sizes and state filters", bad_paging, server, book)
        cases.run("an unreachable drop", unreachable_drop, h, server)

        check_serving(h, server, book, "grpc")
        check_intact(h, server, book, "after the attacks")
        server = restart(h, server, SERVER_ARGS)
        check_intact(h, server, book, "after a restart on the same database")
        check_serving(h, server, book, "grpc-restarted")
        cases.finish()


if __name__ == "__main__":
    main()
