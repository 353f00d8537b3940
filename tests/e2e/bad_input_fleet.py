#!/usr/bin/env python3
"""Bad input on FleetService.Connect (issue 6 §3): dispatchd with fleet-sim's robots R1 and
R2 serving the good orders, while streams opened by this test send what a broken or hostile
robot might. Each must end its stream with a clear status (fleet.proto: INVALID_ARGUMENT for
a first message that is not a Hello or a bad Hello, ALREADY_EXISTS for a robot id that has a
live stream) or be ignored harmlessly:
  - a first message that is not a Hello, or without a body; a Hello twice on one stream;
  - robot ids that are empty, too long (also 100 kB: the status must stay short) or not
    [A-Za-z0-9_.-] (the service takes any well-formed id: it has no list of robots);
  - Hello poses that are NaN, 1e300 or far off the floor; a negative diameter; a
    last_acked_sequence no server can have sent;
  - a Hello as R1 while fleet-sim's R1 is connected (an impostor must not take it over);
  - on a live stream: waypoints and task events for waypoints and orders never sent to it
    (one of them claims to have dropped an order of R1), state reports with NaN, 1e300 and
    off-floor poses, an infinite heading, a battery of 87 (percent, not a fraction), an
    unknown state and arc, an Ack of a sequence never sent; afterwards the robot's state is
    its last sane one, and it can connect again (a bad report must not lock it out);
  - a task event without a type; bytes that are not protobuf (gRPC's callback API ends such a
    stream without an error status, see the report of issue 6; only "the stream ends and the
    service goes on" is checked); a message over 4 MiB.
A formation order with only 2 robots connected must stay accepted (not fail, not error): an
allocation round after it (a later single order being assigned) leaves it unassigned.
Throughout, fleet-sim's robots must stay connected and keep working (an order completes after
the attacks), /healthz answers, a good order is accepted, and every stored order reads back as
acknowledged, also after a restart on the same database.

    bad_input_fleet.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
import grpc  # noqa: E402
from bad_input_common import (GOOD_ORDERS, Book, Cases, check_intact,  # noqa: E402
                              check_serving, http_call, json_body, order_request, restart,
                              submit_good)
from e2e_harness import (ACCEPTED, ASSIGNED, CANCELLED, COMPLETED, Harness,  # noqa: E402
                         RobotStream, TestFailure, check, common_arguments, state_name)
from warehouse.dispatch.v1 import common_pb2, fleet_pb2, orders_pb2  # noqa: E402

SERVER_ARGS = ["--time-scale", "10"]
ROBOTS = 2  # fleet-sim's R1 (park-P1) and R2 (park-P2): fewer than a formation needs
PARK = (30.625, 24.75)  # park-P10, far from fleet-sim's robots: where the test's robots stand
CONNECT = "/warehouse.dispatch.v1.FleetService/Connect"
Code = grpc.StatusCode
Msg = fleet_pb2.RobotMessage


def hello(robot_id, x=PARK[0], y=PARK[1], theta=0.0, **fields):
    return Msg(hello=fleet_pb2.Hello(robot_id=robot_id, pose=common_pb2.Pose(x=x, y=y, theta=theta),
                                     **fields))


def report(x=PARK[0], y=PARK[1], theta=0.0, **fields):
    pose = common_pb2.Pose(x=x, y=y, theta=theta)
    return Msg(state_report=fleet_pb2.StateReport(pose=pose, **fields))


def task(order_id, kind=fleet_pb2.TASK_EVENT_TYPE_DROPPED, **fields):
    return Msg(task_event=fleet_pb2.TaskEvent(order_id=order_id, type=kind, **fields))


def robot(server, robot_id):
    status, ctype, data = http_call(server, "GET", f"/api/v1/robots/{robot_id}")
    check(status == 200, f"GET /api/v1/robots/{robot_id}: HTTP {status}: {data[:200]!r}")
    return json_body(status, ctype, data, f"GET /api/v1/robots/{robot_id}")


def rejected(server, code, first, *words, max_len=None):
    RobotStream(server, first).expect_end(code, *words, max_len=max_len)


def not_a_hello(server):
    bad = Code.INVALID_ARGUMENT
    rejected(server, bad, Msg(heartbeat=fleet_pb2.Heartbeat(robot_unix_ms=1)),
             "first message", "Hello")
    rejected(server, bad, report(), "first message", "Hello")
    rejected(server, bad, Msg(), "without a body")
    s = RobotStream(server, hello("RX-twice"))
    s.welcome()
    s.send(hello("RX-twice"))
    s.expect_end(bad, "Hello sent twice")


def bad_ids(server):
    bad = Code.INVALID_ARGUMENT
    for rid in ["", "R 1", "R1;DROP TABLE robots", "\u00e9", "r" * 65]:
        rejected(server, bad, hello(rid), "robot id", "invalid")
    rejected(server, bad, hello("r" * 100_000), "robot id", max_len=2000)


def bad_hellos(server):
    bad = Code.INVALID_ARGUMENT
    rejected(server, bad, hello("RX-nan", x=math.nan), "RX-nan", "not finite")
    rejected(server, bad, hello("RX-theta", theta=math.inf), "RX-theta", "not finite")
    rejected(server, bad, hello("RX-huge", x=1e300, y=1e300), "RX-huge", "not on the map",
             max_len=2000)
    rejected(server, bad, hello("RX-far", x=500, y=500), "RX-far", "not on the map", "nearest")
    rejected(server, bad, hello("RX-diam", diameter=-1), "diameter")
    rejected(server, bad, hello("RX-seq", last_acked_sequence=2**64 - 1), "last_acked_sequence")


def impostor(server):
    """A Hello as fleet-sim's live R1 is refused, and R1 keeps its stream."""
    rejected(server, Code.ALREADY_EXISTS, hello("R1"), "R1", "live stream")
    check(robot(server, "R1")["connected"], "R1 lost its stream to an impostor's Hello")


def junk_on_a_live_stream(server, book):
    # The last good order: queued behind three others on R1 or R2, it cannot complete in the
    # fraction of a second this case takes, unless the junk completes it.
    victim = list(book.orders.values())[len(GOOD_ORDERS) - 1]["id"]
    s = RobotStream(server, hello("RX-junk"))
    s.welcome()
    reached = fleet_pb2.WaypointReached
    s.send(report(state=common_pb2.ROBOT_STATE_IDLE, battery=0.5),  # the last sane report
           Msg(waypoint_reached=reached(sequence=999, pose=common_pb2.Pose(x=1, y=1))),
           Msg(waypoint_reached=reached(sequence=2**64 - 1)),
           task(victim, fleet_pb2.TASK_EVENT_TYPE_PICKED, point_id=-5, waypoint_sequence=77),
           task(victim, point_id=10**6, waypoint_sequence=78),
           task("ord-999999"),
           report(x=math.nan, y=1),
           report(x=1e300, y=-1e300),
           report(x=500, y=-500),
           report(theta=math.inf),
           report(battery=87),
           report(battery=math.nan),
           report(state=42, arc_id=99999, arc_offset=math.nan, speed=-3),
           report(last_waypoint_sequence=10**12),
           Msg(ack=fleet_pb2.Ack(sequence=2**64 - 1)),
           Msg(heartbeat=fleet_pb2.Heartbeat()))
    # The server handles a stream's messages in order: its answer to a second Hello says
    # that everything before it was handled.
    s.send(hello("RX-junk"))
    s.expect_end(Code.INVALID_ARGUMENT, "Hello sent twice")
    r = robot(server, "RX-junk")
    pose = r["pose"]
    check((pose["x"], pose["y"]) == PARK,
          f"RX-junk is at ({pose['x']}, {pose['y']}), not where it last sanely was, {PARK}")
    check(r.get("point") is not None, "RX-junk stands at no map point after its reports")
    check(pose["theta"] == 0.0, f"RX-junk heading {pose['theta']}")
    check(r["battery"] == 0.5, f"RX-junk battery {r['battery']}, not its last sane 0.5")
    after = server.orders.GetOrder(orders_pb2.GetOrderRequest(order_id=victim), timeout=10)
    check(after.state != COMPLETED,
          f"{victim} completed by a robot that never served it ({list(after.robot_ids)})")
    check("RX-junk" not in after.robot_ids, f"{victim} now lists RX-junk: {list(after.robot_ids)}")
    again = RobotStream(server, hello("RX-junk"))  # not locked out by what it sent before
    again.welcome()
    again.close()
    again.expect_end(Code.OK)


def bad_bodies(server):
    s = RobotStream(server, hello("RX-type"))
    s.welcome()
    s.send(task("x", fleet_pb2.TASK_EVENT_TYPE_UNSPECIFIED))
    s.expect_end(Code.INVALID_ARGUMENT, "task_event", "type")
    raw = server.channel.stream_stream(CONNECT, request_serializer=None, response_deserializer=None)
    for data in (b"\xff\xff\xff\xff\x0f", b"\x0a\x05R1"):
        call = raw(iter([data]), timeout=10)
        try:
            for _ in call:
                pass
            code, details = call.code(), call.details()
        except grpc.RpcError as err:
            code, details = err.code(), err.details()
        check(code != Code.DEADLINE_EXCEEDED, f"bytes {data!r}: the stream did not end")
        print(f"[e2e] Connect with bytes {data!r} that are not a RobotMessage: {code.name} "
              f"'{details}'", flush=True)
    big = RobotStream(server, Msg(hello=fleet_pb2.Hello(robot_id="R" * (4 * 1024 * 1024 + 10))))
    big.expect_end(Code.RESOURCE_EXHAUSTED, "larger than max")


def formation_with_two_robots(h, server, book):
    """Stays accepted while an allocation round assigns a later single order."""
    request = order_request("fleet-formation", [(19, 17), (20.5, 10.5)], (6.5, 2.75),
                            formation=True)
    f = server.orders.SubmitOrder(request, timeout=10)
    check(f.created and f.order.state == ACCEPTED, f"formation order: {state_name(f.order.state)}")
    book.add(f.order)
    single = server.orders.SubmitOrder(order_request("fleet-single", ["K1-3-1N"], "D-B2"),
                                       timeout=10).order
    book.add(single)
    h.watch(server, lambda o: single.id in o and o[single.id].state == ASSIGNED, timeout=10,
            what="the single order after the formation assigned", order_ids=[single.id])
    got = server.orders.GetOrder(orders_pb2.GetOrderRequest(order_id=f.order.id), timeout=10)
    check(got.state == ACCEPTED and not got.robot_ids,
          f"formation order with {ROBOTS} robots: {state_name(got.state)} on "
          f"{list(got.robot_ids)}, want accepted on none")
    # Cancelled, so that the test's own robots (a third connected robot) never get it.
    for _ in range(2):  # cancelling a cancelled order returns it unchanged
        c = server.orders.CancelOrder(
            orders_pb2.CancelOrderRequest(order_id=f.order.id, reason="test"), timeout=10)
        check(c.state == CANCELLED, f"cancelled formation order is {state_name(c.state)}")
    book.cancelled.add("fleet-formation")


def fleet_sim_still_works(h, server):
    robots = json_body(*http_call(server, "GET", "/api/v1/robots"), "GET /api/v1/robots")["robots"]
    live = sorted(r["id"] for r in robots if r["connected"])
    check(live == ["R1", "R2"],
          f"connected robots after the attacks: {live}, want fleet-sim's R1 and R2")
    done = {o.id for o in h.list_orders(server) if o.state == COMPLETED}
    h.watch(server, lambda o: any(e.state == COMPLETED and i not in done for i, e in o.items()),
            timeout=60, what="an order completed by fleet-sim's robots after the attacks")


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "bad-input-fleet") as h:
        server = h.start_server(SERVER_ARGS)
        h.start_fleet(server, ROBOTS)
        book = Book()
        submit_good(h, server, book, "fleet")
        cases = Cases(h, server)
        cases.run("a formation order with 2 robots stays accepted", formation_with_two_robots,
                  h, server, book)
        cases.run("a first message that is not a Hello", not_a_hello, server)
        cases.run("robot ids that are not ids", bad_ids, server)
        cases.run("Hellos with nonsense poses and sequences", bad_hellos, server)
        cases.run("a Hello as a connected robot", impostor, server)
        cases.run("junk on a live stream", junk_on_a_live_stream, server, book)
        cases.run("bad task events, bytes, an oversized message", bad_bodies, server)
        ours = ("RX-junk", "RX-type", "RX-twice")
        h.wait_for(lambda: not any(robot(server, r)["connected"] for r in ours), 10,
                   "the test's robots to be disconnected")
        cases.run("fleet-sim's robots keep working", fleet_sim_still_works, h, server)

        check_serving(h, server, book, "fleet")
        check_intact(h, server, book, "after the attacks")
        server = restart(h, server, SERVER_ARGS)
        check_intact(h, server, book, "after a restart on the same database")
        check_serving(h, server, book, "fleet-restarted")
        cases.finish()
        # Both runs, attacks included, replay through a fresh dispatch core.
        for run in (1, 2):
            h.replay(args.dispatch_sim, os.path.join(h.work, "dispatch.db"), run)


if __name__ == "__main__":
    main()
