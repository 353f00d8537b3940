#!/usr/bin/env python3
"""Durability across kill -9 (issue 5 §5): dispatchd (fresh SQLite file) with fleet-sim's 18
robots serves seed Table 1 submitted through wmsctl; once an order is in progress, dispatchd
is killed with SIGKILL and restarted on the same database file and the same gRPC port, so
fleet-sim (which reconnects by itself) finds it again. Then:
  - every order SubmitOrder acknowledged before the kill is there, exactly once per client id
    and under the same server id, none lost, none added, and none went back in its lifecycle
    or changed robots;
  - submitting the same file again returns the same orders (idempotent on client ids);
  - every robot reconnects and every order completes;
  - traffic control released nothing until every robot had reported back, and no two robots
    came closer than eps1 after the restart;
  - both runs replay through a fresh dispatch core (dispatch-sim replay): the killed one up to
    the last batch its journal holds, the restarted one from its recovery on.

    durability_kill9.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
                        --dispatch-sim BIN
"""
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import (ASSIGNED, COMPLETED, IN_PROGRESS, RANK, TERMINAL, Harness,  # noqa: E402
                         check, common_arguments, state_name)
from warehouse.dispatch.v1 import orders_pb2  # noqa: E402

ROBOTS = 18
EPS1 = 0.6
SERVER_ARGS = ["--time-scale", "10"]


def main():
    args = common_arguments(__doc__).parse_args()
    table = os.path.join(args.scenarios, "chu2024-table1.csv")
    with Harness(args, "durability") as h:
        server = h.start_server(SERVER_ARGS)
        db = os.path.join(h.work, "dispatch.db")
        h.start_fleet(server, ROBOTS)

        rows = h.submit_file(server, table)
        check(len(rows) == 6, f"wmsctl acknowledged {len(rows)} orders of Table 1, not 6")
        check(all(created for *_, created in rows), "a first submission was not 'created'")
        acked = {client: order for client, order, _, _ in rows}
        check(len(set(acked.values())) == len(acked), f"two client ids share an order id: {acked}")

        # Kill once the fleet is really working: an order in progress, none finished yet.
        h.watch(server, lambda o: any(e.state == IN_PROGRESS for e in o.values()),
                timeout=30, what="an order in progress", order_ids=list(acked.values()))
        before = {o.id: o for o in h.list_orders(server)}
        h.log("before the kill: " + ", ".join(f"{i}={state_name(o.state)}{list(o.robot_ids)}"
                                             for i, o in sorted(before.items())))
        check(any(o.state not in TERMINAL for o in before.values()),
              "every order finished before the kill; nothing left to recover")
        clock_before = server.rest("/api/v1/status")["time"]
        server.close_channel()
        server.kill9()

        # Same database, same gRPC port (fleet-sim reconnects there), a new REST port. Traffic
        # control waits up to the heartbeat timeout for the fleet: long enough for a slow machine.
        server = h.start_server(SERVER_ARGS + ["--heartbeat-timeout", "15"], db=db, grpc_port=server.grpc_port)
        clock_after = server.rest("/api/v1/status")["time"]
        h.log(f"dispatcher clock: {clock_before:.2f} s just before the kill, "
              f"{clock_after:.2f} s just after the restart")
        after = h.list_orders(server)
        by_client = {}
        for o in after:
            by_client.setdefault(o.client_order_id, []).append(o)
        dups = {c: [o.id for o in os_] for c, os_ in by_client.items() if len(os_) > 1}
        check(not dups, f"client ids stored more than once after the restart: {dups}")
        lost = sorted(set(acked) - set(by_client))
        check(not lost, f"acknowledged orders lost by the restart: {lost}")
        extra = sorted(set(by_client) - set(acked))
        check(not extra, f"orders nobody submitted appeared after the restart: {extra}")
        for client, order_id in acked.items():
            o = by_client[client][0]
            check(o.id == order_id, f"{client} was {order_id} before the kill, {o.id} after")
            b = before[order_id]
            check(RANK[o.state] >= RANK[b.state],
                  f"{order_id} went back from {state_name(b.state)} to {state_name(o.state)}")
            if b.state in (ASSIGNED, IN_PROGRESS) and o.state not in TERMINAL:
                check(list(o.robot_ids) == list(b.robot_ids),
                      f"{order_id} was on {list(b.robot_ids)} before the kill, "
                      f"{list(o.robot_ids)} after")
        h.log(f"after the restart: the {len(acked)} acknowledged orders are there once each")

        again = h.submit_file(server, table)
        check([(c, i) for c, i, _, _ in again] == [(c, i) for c, i, _, _ in rows],
              f"resubmission returned other orders: {again} (first: {rows})")
        check(not any(created for *_, created in again), "a resubmission created an order")
        check(len(h.list_orders(server)) == len(acked), "the resubmission added orders")

        def all_connected():
            robots = server.rest("/api/v1/robots")
            robots = robots.get("robots", robots) if isinstance(robots, dict) else robots
            return sum(1 for r in robots if r.get("connected")) == ROBOTS
        h.wait_for(all_connected, 20, f"all {ROBOTS} robots to reconnect (REST /api/v1/robots)")
        h.log(f"all {ROBOTS} robots reconnected")

        created = {}

        def count_created(event, orders):
            if event.type == orders_pb2.ORDER_EVENT_TYPE_CREATED:
                created[event.order_id] = created.get(event.order_id, 0) + 1

        final = h.watch(server, lambda o: len(o) == len(acked) and
                        all(e.state in TERMINAL for e in o.values()),
                        timeout=60, what="every order to finish", order_ids=list(acked.values()),
                        on_event=count_created)
        check(all(created.get(i) == 1 for i in acked.values()),
              f"journal 'created' entries per order after the restart: {created} (want 1 each)")
        bad = {i: f"{state_name(e.state)}: {e.detail}" for i, e in final.items()
               if e.state != COMPLETED}
        check(not bad, f"orders that did not complete after the restart: {bad}")
        done = h.list_orders(server)
        check(sorted(o.client_order_id for o in done) == sorted(acked),
              "the final order list differs from the acknowledged orders")
        check(all(o.state == COMPLETED for o in done), "ListOrders disagrees with the journal")
        log = server.log_text()
        recovered = [ln for ln in log.splitlines() if "recovered" in ln]
        h.log("dispatchd#2: " + (recovered[0] if recovered else "(no recovery line)"))
        for line in log.splitlines():
            if "traffic control" in line or "formed again" in line:
                h.log("dispatchd#2: " + line)
        # Traffic control waited for the fleet: nothing was released until every robot that
        # was on line had reported, and nobody came closer than eps1 after the restart.
        check("every robot that was on line before the restart has reported" in log,
              "dispatchd#2 never saw the whole fleet report back (or did not wait for it)")
        closest = server.rest("/api/v1/status")["traffic"].get("min_robot_distance")
        check(closest is not None, "no robot distance measured after the restart")
        check(closest["distance"] >= EPS1 - 1e-6,
              f"after the restart robots {closest['robot_ids']} came {closest['distance']:.6f} m close "
              f"(eps1 = {EPS1} m)")

        # The journal: the killed run up to what it had written, the restarted run whole.
        for run in (1, 2):
            h.replay(args.dispatch_sim, db, run)


if __name__ == "__main__":
    main()
