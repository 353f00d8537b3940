#!/usr/bin/env python3
"""A four-wheel-steer robot through the service (issue 17 §3): dispatchd on a JSON map with a
free-space region (bay_map.json: a 1.4 m wide dead-end bay, its pick K at the closed end, the
drop outside), fleet-sim with two robots, R1 saying in its Hello that it is four-wheel steer
(--kinds) and R2 a differential drive; REST lists them so. An order asking to reach K facing
the bay's mouth (heading pi, a stop with a heading) goes to R1, the only robot that can be
planned into it: the order (REST) shows the heading; the route the service shows for it (GET
/api/v1/orders/{id}) holds poses with a heading and a motion mode inside the bay, a turn among
them, the pick's waypoint facing pi; fleet-sim drives them. Then a plain order into the bay
goes to R2: R1 is nearer by the lanes, but the bids price its route through the bay (it turns
round there, where the lanes just drive back). Both orders complete with the robots never
closer than eps1 (a free-space region holds one robot at a time: the traffic controller keeps
the other out while one is in it). A heading at the drop (on the lanes) is INVALID_ARGUMENT. A
second dispatcher, running the time-window planner, serves the order with a heading by a posed
route too (a refined segment keeps its route and is reserved as it is). (That a differential robot keeps
its lanes is the core test's,
FreeSpaceRound; two robots picking at the closed end of one bay lock each other up, see the
closing note of 2026-12-06.)

    free_space_robot.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import math
import os
import sys
import uuid

import grpc

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import (ASSIGNED, COMPLETED, IN_PROGRESS, Harness, check,  # noqa: E402
                         common_arguments, state_name)
from warehouse.dispatch.v1 import common_pb2, orders_pb2  # noqa: E402

MAP = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bay_map.json")
PICK, DROP = (6.5, 0.8), (1.5, 2.8)  # K at the bay's end, D outside
TURNS = {"MOTION_MODE_SPIN_LEFT", "MOTION_MODE_SPIN_RIGHT", "MOTION_MODE_REVERSE",
         "MOTION_MODE_ARC_REVERSE_LEFT", "MOTION_MODE_ARC_REVERSE_RIGHT"}


def submit(server, tag, pick_heading=None, drop_heading=None):
    pick = orders_pb2.StopSpec(position=common_pb2.Vec2(x=PICK[0], y=PICK[1]))
    drop = orders_pb2.StopSpec(position=common_pb2.Vec2(x=DROP[0], y=DROP[1]))
    if pick_heading is not None:
        pick.heading = pick_heading
    if drop_heading is not None:
        drop.heading = drop_heading
    r = orders_pb2.SubmitOrderRequest(client_order_id=f"bay-{tag}-{uuid.uuid4().hex[:8]}", picks=[pick], drop=drop)
    return server.orders.SubmitOrder(r, timeout=10).order.id


def refused(server, code, text, **headings):
    """SubmitOrder with these headings fails with `code`, its message holding `text`."""
    try:
        submit(server, "refused", **headings)
    except grpc.RpcError as err:
        check(err.code() == code and text in err.details(), f"refused with {err.code()}: {err.details()}")
        return
    check(False, f"an order with {headings} was accepted")


def route_of(server, order_id):
    """(robot, waypoints) of the order's remaining route, once it has one."""
    routes = server.rest(f"/api/v1/orders/{order_id}").get("routes") or {}
    return next(((robot, route.get("waypoints", [])) for robot, route in routes.items()), None)


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "freespace") as h:
        server = h.start_server(["--map", MAP, "--time-scale", "2"])
        h.start_fleet(server, 2, ["--kinds", "four_wheel_steer,differential"])
        kinds = h.wait_for(lambda: (lambda k: len(k) == 2 and k)(
            {r["id"]: r.get("kind") for r in server.rest("/api/v1/robots")["robots"]}), 10, "both robots listed")
        check(kinds == {"R1": "ROBOT_KIND_FOUR_WHEEL_STEER", "R2": "ROBOT_KIND_DIFFERENTIAL"},
              f"robot kinds listed: {kinds}")

        # A stop with a heading: K reached facing the bay's mouth (the lanes arrive facing east).
        # Only R1 can be planned into it: its route holds poses with a heading and a motion mode
        # inside the bay, a turn among them, and the pick's waypoint faces pi.
        refused(server, grpc.StatusCode.INVALID_ARGUMENT, "inside a free-space region", drop_heading=0.0)
        posed_order = submit(server, "1", pick_heading=math.pi)
        heading = server.rest(f"/api/v1/orders/{posed_order}")["order"]["picks"][0].get("heading")  # OrderDetail
        check(heading is not None and abs(abs(heading) - math.pi) < 1e-9, f"the order shows pick heading {heading}")
        h.watch(server, lambda o: posed_order in o and o[posed_order].state in (ASSIGNED, IN_PROGRESS),
                timeout=20, what="the order with a heading assigned", order_ids=[posed_order])
        robot, waypoints = h.wait_for(lambda: route_of(server, posed_order), 10, "the posed order's route")
        check(robot == "R1", f"the order with a heading went to {robot}, not the four-wheel-steer R1")
        posed = [w for w in waypoints if "heading" in w]
        modes = {w.get("motion_mode", "MOTION_MODE_UNSPECIFIED") for w in posed} - {"MOTION_MODE_UNSPECIFIED"}
        h.log(f"{posed_order} on {robot}: {len(waypoints)} waypoints left, {len(posed)} posed, modes {sorted(modes)}")
        check(len(posed) >= 5 and modes, f"poses with a heading: {len(posed)}, modes {sorted(modes)}")
        check(modes & TURNS, f"no turn in the bay among {sorted(modes)}")
        for w in posed:  # inside the bay
            x, y = w["position"].get("x", 0.0), w["position"].get("y", 0.0)
            check(2.0 <= x <= 8.0 and 0.1 <= y <= 1.5, f"a pose at ({x}, {y}) is outside the bay")
        at_pick = [w for w in waypoints if w.get("action") == "WAYPOINT_ACTION_PICK"]
        check(len(at_pick) == 1 and abs(abs(at_pick[0].get("heading", 0.0)) - math.pi) < 1e-6,
              f"the pick waypoint: {at_pick}")
        h.watch(server, lambda o: posed_order in o and o[posed_order].state == COMPLETED,
                timeout=60, what="the order with a heading completed", order_ids=[posed_order])

        # A plain order into the bay: by the lanes R1 (at the drop D) is nearer, but its route
        # through the bay (turning round at K, where the lanes just drive back) costs it more;
        # the bids price it, so R2 takes it, on its lanes.
        plain = submit(server, "2")
        robot, waypoints = h.wait_for(lambda: route_of(server, plain), 20, "the plain order's route")
        check(robot == "R2", f"the plain order went to {robot}, not R2 (R1's turn in the bay is priced)")
        check(not any("heading" in w for w in waypoints), "a differential robot's route has poses")
        done = h.watch(server, lambda o: plain in o and o[plain].state == COMPLETED,
                       timeout=60, what="the plain order completed", order_ids=[plain])
        h.log("states: " + ", ".join(f"{k}={state_name(v.state)}" for k, v in sorted(done.items())))
        h.check_min_distance(server)

        # The time-window planner keeps the refined segment and plans round it: the same order
        # with a heading, served by a posed route.
        planned = h.start_server(["--map", MAP, "--planner", "time-windows", "--time-scale", "2"],
                                 db=os.path.join(h.work, "tw.db"))
        h.start_fleet(planned, 1, ["--kinds", "four_wheel_steer"])
        h.wait_for(lambda: len(planned.rest("/api/v1/robots")["robots"]) == 1, 10, "the robot listed")
        windowed = submit(planned, "3", pick_heading=math.pi)
        robot, waypoints = h.wait_for(lambda: route_of(planned, windowed), 20, "the order's route (time windows)")
        at_pick = [w for w in waypoints if w.get("action") == "WAYPOINT_ACTION_PICK"]
        check(robot == "R1" and sum("heading" in w for w in waypoints) >= 5, f"{robot}'s route: {waypoints}")
        check(len(at_pick) == 1 and abs(abs(at_pick[0].get("heading", 0.0)) - math.pi) < 1e-6,
              f"the pick waypoint (time windows): {at_pick}")
        h.watch(planned, lambda o: windowed in o and o[windowed].state == COMPLETED,
                timeout=60, what="the order with a heading completed (time windows)", order_ids=[windowed])


if __name__ == "__main__":
    main()
