#!/usr/bin/env python3
"""Heartbeat loss -> offline -> re-allocation (issue 5 §5, server/dispatcher.h "Robots").

Deterministic set-up: a first fleet-sim runs R1 alone, so both orders submitted go to R1:
A (Table 1 task 6) first, B (Table 1 task 5) queued after it. A second fleet-sim then brings
R2 and R3, idle (assigned orders are not auctioned again). When A goes in_progress (R1 at A's
first pick), the test tells the first fleet-sim (--control-fd) to mute R1: it stops moving
and sending anything but keeps its stream open. dispatchd must then
  - mark R1 offline by the heartbeat timeout ("no message for ..."), not by a closed stream;
  - after --offline-grace, fail A (in progress: the load is on the lost robot, by design) and
    put B (assigned, not started) back to accepted;
  - re-allocate B to R2 or R3, which completes it;
and R1 stays offline. Finally a new order goes to a live robot and completes.

    heartbeat_loss.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import os
import sys
import time
import uuid

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import (ACCEPTED, ASSIGNED, COMPLETED, FAILED, IN_PROGRESS,  # noqa: E402
                         TERMINAL, Harness, check, common_arguments, state_name)
from warehouse.dispatch.v1 import common_pb2, orders_pb2  # noqa: E402

HEARTBEAT_INTERVAL = 0.5  # wall seconds
HEARTBEAT_TIMEOUT = 3.0
OFFLINE_GRACE = 1.0
SERVER_ARGS = ["--time-scale", "10", "--heartbeat-interval", str(HEARTBEAT_INTERVAL),
               "--heartbeat-timeout", str(HEARTBEAT_TIMEOUT), "--offline-grace", str(OFFLINE_GRACE)]

# Seed Table 1 rows (picks, drop), near the first parking stations.
TASK_6 = ([(5.5, 13), (9, 9)], (6.5, 2.75))
TASK_5 = ([(10.5, 13), (10.5, 9)], (11.5, 2.75))
TASK_4 = ([(29, 13), (30.5, 13), (29, 10.5)], (32.25, 5))


def request(tag, task):
    picks, drop = task
    return orders_pb2.SubmitOrderRequest(
        client_order_id=f"hb-{tag}-{uuid.uuid4().hex[:8]}",
        picks=[orders_pb2.StopSpec(position=common_pb2.Vec2(x=x, y=y)) for x, y in picks],
        drop=orders_pb2.StopSpec(position=common_pb2.Vec2(x=drop[0], y=drop[1])))


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "heartbeat") as h:
        server = h.start_server(SERVER_ARGS)
        first = h.start_fleet(server, 1, control=True)  # R1
        a = server.orders.SubmitOrder(request("A", TASK_6), timeout=10).order.id
        b = server.orders.SubmitOrder(request("B", TASK_5), timeout=10).order.id
        h.log(f"submitted A = {a}, B = {b}")
        h.watch(server, lambda o: all(i in o and o[i].state in (ASSIGNED, IN_PROGRESS)
                                      for i in (a, b)),
                timeout=10, what="A and B assigned", order_ids=[a, b])
        for i in (a, b):
            o = server.orders.GetOrder(orders_pb2.GetOrderRequest(order_id=i), timeout=10)
            check(list(o.robot_ids) == ["R1"], f"{i} went to {list(o.robot_ids)}, not R1 (alone)")
        h.start_fleet(server, 2, ["--first", "2"])  # R2, R3: idle, connected

        muted_at = []
        seen_before = set()  # events up to the mute

        def mute_on_start(event, orders):
            seen_before.add(event.event_id)
            if event.order_id == a and event.state == IN_PROGRESS and not muted_at:
                first.command("mute R1")
                muted_at.append(time.monotonic())

        h.watch(server, lambda o: bool(muted_at), timeout=20, what="A in progress",
                order_ids=[a, b], on_event=mute_on_start)

        # B: assigned to R1 -> accepted (re-allocated) -> assigned to R2/R3 -> completed;
        # A: in progress on R1 -> failed.
        history = {a: [], b: []}
        released_at = []  # when the release (A failed / B back to accepted) was seen

        def record(event, orders):
            history[event.order_id].append(event)
            if not released_at and event.event_id not in seen_before and (
                    event.state == FAILED or (event.order_id == b and event.state == ACCEPTED)):
                released_at.append(time.monotonic())

        final = h.watch(server, lambda o: all(i in o and o[i].state in TERMINAL for i in (a, b)),
                        timeout=30, what="A and B to finish", order_ids=[a, b], on_event=record)
        check(bool(released_at), "no release event (A failed / B accepted) was seen")
        lost_after = released_at[0] - muted_at[0]
        h.log(f"R1's orders released {lost_after:.2f} s after it went silent (heartbeat timeout "
              f"{HEARTBEAT_TIMEOUT} s + offline grace {OFFLINE_GRACE} s)")

        a_end, b_end = final[a], final[b]
        check(a_end.state == FAILED,
              f"A (in progress on the lost robot) ended {state_name(a_end.state)}, not failed")
        a_order = server.orders.GetOrder(orders_pb2.GetOrderRequest(order_id=a), timeout=10)
        check("R1" in a_order.reason and "offline" in a_order.reason,
              f"A's failure reason does not name R1 offline: '{a_order.reason}'")
        check(b_end.state == COMPLETED,
              f"B ended {state_name(b_end.state)} ({b_end.detail}), not completed")
        b_order = server.orders.GetOrder(orders_pb2.GetOrderRequest(order_id=b), timeout=10)
        check(len(b_order.robot_ids) == 1 and b_order.robot_ids[0] in ("R2", "R3"),
              f"B was completed by {list(b_order.robot_ids)}, not by R2 or R3")
        b_states = [e.state for e in history[b]]
        back = [k for k, e in enumerate(history[b])
                if e.type == orders_pb2.ORDER_EVENT_TYPE_STATE_CHANGED
                and e.previous_state == ASSIGNED and e.state == ACCEPTED]
        check(len(back) == 1, f"B went from assigned back to accepted {len(back)} times, not once")
        check(ASSIGNED in b_states[back[0]:], "B was not assigned again after going back to accepted")
        check(IN_PROGRESS not in b_states[:back[0]],
              "B had started on R1 before it was re-allocated (the test wants a queued order)")
        h.log(f"B re-allocated: '{history[b][back[0]].detail}'")
        check(lost_after >= HEARTBEAT_TIMEOUT + OFFLINE_GRACE * 0.9,
              f"the orders were released {lost_after:.2f} s after the mute, sooner than the "
              f"heartbeat timeout + grace ({HEARTBEAT_TIMEOUT + OFFLINE_GRACE} s)")

        log = server.log_text()
        check("robot R1 offline: no message for" in log,
              "dispatchd did not log R1 offline by heartbeat timeout ('no message for ...')")
        check("robot R1 offline: stream closed" not in log,
              "R1's stream was closed by the client: the test wants the heartbeat path")
        r1 = server.rest("/api/v1/robots/R1")
        check(not r1["connected"] and r1["state"] == "ROBOT_STATE_OFFLINE",
              f"R1 after the loss: connected={r1['connected']} state={r1['state']}")
        check(r1["order_ids"] == [], f"R1 still holds orders: {r1['order_ids']}")
        check("the server closed its stream" in first.log_text(),
              "fleet-sim did not see the server close the silent robot's stream")

        # The fleet goes on without R1.
        c = server.orders.SubmitOrder(request("C", TASK_4), timeout=10).order.id
        final = h.watch(server, lambda o: c in o and o[c].state in TERMINAL,
                        timeout=30, what="C to finish", order_ids=[c])
        c_order = server.orders.GetOrder(orders_pb2.GetOrderRequest(order_id=c), timeout=10)
        check(final[c].state == COMPLETED and "R1" not in c_order.robot_ids,
              f"C ended {state_name(final[c].state)} on {list(c_order.robot_ids)}")

        # The run (a robot lost, its orders re-allocated) replays through a fresh core.
        h.replay(args.dispatch_sim, os.path.join(h.work, "dispatch.db"), 1)


if __name__ == "__main__":
    main()
