#!/usr/bin/env python3
"""Traffic rules through the service (issue 5 §5, SPEC §3.5): seed Table 1, then Table 2, on
18 robots with the traffic controller releasing waypoints point by point. Every order
completes; formation orders are carried by 3 distinct robots that the traffic controller
treats as one agent (seen in /api/v1/traffic during the run); waypoints were released by
Grants; and the minimum centre distance the dispatcher saw between robots of different agents
(formation members of one team excluded) never dropped below eps1 = 0.6 m.

    traffic_rules.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import csv
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import COMPLETED, TERMINAL, Harness, check, common_arguments, state_name  # noqa: E402

EPS1 = 0.6


def formation_tasks(path):
    with open(path) as f:
        rows = [line for line in f if not line.startswith("#")]
    return {f"{os.path.splitext(os.path.basename(path))[0]}-{r['task']}"
            for r in csv.DictReader(rows) if r["formation"].strip() == "1"}


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "traffic") as h:
        server = h.start_server(["--time-scale", "10"])
        h.start_fleet(server, 18)
        for table in ("chu2024-table1.csv", "chu2024-table2.csv"):
            path = os.path.join(args.scenarios, table)
            rows = h.submit_file(server, path)
            ids = [order for _, order, _, _ in rows]
            # Formations move as one: at some event of each formation order all three members
            # show up in /api/v1/traffic as members of one team agent.
            as_one = set()

            def look(event, orders):
                if event.order_id in as_one or event.state in TERMINAL:
                    return
                lines = server.rest("/api/v1/traffic")["robots"]
                agents = {line.split(": ", 1)[1].split(" ")[0] for line in lines.values()
                          if line.split(" ")[1:4] == ["in", "formation", event.order_id + ":"]}
                members = [r for r, line in lines.items() if f"in formation {event.order_id}:" in line]
                if len(members) == 3 and len(agents) == 1:
                    as_one.add(event.order_id)

            final = h.watch(server, lambda o: len(o) == len(ids) and
                            all(e.state in TERMINAL for e in o.values()),
                            timeout=120, what=f"every order of {table} to finish", order_ids=ids,
                            on_event=look)
            bad = {i: f"{state_name(e.state)}: {e.detail}" for i, e in final.items() if e.state != COMPLETED}
            check(not bad, f"{table}: orders that did not complete: {bad}")
            teams = formation_tasks(path)
            for client, order, _, _ in rows:
                robots = server.rest(f"/api/v1/orders/{order}")["order"]["robot_ids"]
                want = 3 if client in teams else 1
                check(len(set(robots)) == want, f"{client} ({order}) carried by {robots}, want {want} robots")
                if want == 3:
                    check(order in as_one, f"{client} ({order}): its 3 robots were never seen as one agent")
        traffic = server.rest("/api/v1/status")["traffic"]
        h.log(f"traffic: {traffic}")
        check(traffic["control"], "traffic control is off")
        check(int(traffic["grants"]) > 100, f"only {traffic['grants']} grants: waypoints were not released by the controller")
        h.check_min_distance(server, EPS1)


if __name__ == "__main__":
    main()
