#!/usr/bin/env python3
"""Robot streams dropped and reconnected mid-route (issue 5 §5): seed Table 1 on 18 robots
while fleet-sim drops one robot's stream every DROP_EVERY wall seconds (--drop-every, round
robin) and, through its --control-fd, also drops the stream of every robot of an order at
the moment the order starts (so each order's robots lose their stream at least once while
they are on its route). Every order must complete, and the server must have seen the drops
(streams closed) and the reconnections.

    reconnect_mid_route.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import (COMPLETED, IN_PROGRESS, TERMINAL, Harness, check,  # noqa: E402
                         common_arguments, state_name)

ROBOTS = 18
DROP_EVERY = 0.3  # wall seconds: with 18 robots, each stream drops every ~5.4 s


def main():
    args = common_arguments(__doc__).parse_args()
    table = os.path.join(args.scenarios, "chu2024-table1.csv")
    with Harness(args, "reconnect") as h:
        server = h.start_server(["--time-scale", "10"])
        fleet = h.start_fleet(server, ROBOTS, ["--drop-every", str(DROP_EVERY)], control=True)
        rows = h.submit_file(server, table)
        check(len(rows) == 6, f"wmsctl acknowledged {len(rows)} orders of Table 1, not 6")
        ids = [order for _, order, _, _ in rows]

        dropped_on_route = set()

        def drop_when_started(event, orders):
            if event.state == IN_PROGRESS and event.order_id not in dropped_on_route:
                dropped_on_route.add(event.order_id)
                for robot in event.robot_ids:
                    fleet.command(f"drop {robot}")

        try:
            final = h.watch(server, lambda o: len(o) == len(ids) and
                            all(e.state in TERMINAL for e in o.values()),
                            timeout=60, what="every order to finish", order_ids=ids,
                            on_event=drop_when_started)
        except Exception:
            for robot, line in sorted(server.rest("/api/v1/traffic")["robots"].items()):
                h.log(f"traffic {robot}: {line}")
            raise
        bad = {i: f"{state_name(e.state)}: {e.detail}" for i, e in final.items()
               if e.state != COMPLETED}
        check(not bad, f"orders that did not complete with dropped streams: {bad}")
        check(dropped_on_route == set(ids),
              f"orders whose robots were not dropped mid-route: {sorted(set(ids) - dropped_on_route)}")

        fleet_log = fleet.log_text()
        server_log = server.log_text()
        drops = fleet_log.count("fault: dropping")
        closed = server_log.count("offline: stream closed")
        connects = server_log.count(" connected at ")
        h.log(f"fleet-sim dropped {drops} streams; dispatchd saw {closed} closed streams and "
              f"{connects} connections ({ROBOTS} first ones)")
        check(drops >= 10, f"only {drops} streams were dropped")
        check(closed >= 1 and connects > ROBOTS,
              "dispatchd did not see the drops and reconnections (log lines "
              "'offline: stream closed' / 'connected at')")
        # The run, drops and reconnections included, replays through a fresh dispatch core.
        h.replay(args.dispatch_sim, os.path.join(h.work, "dispatch.db"), 1)


if __name__ == "__main__":
    main()
