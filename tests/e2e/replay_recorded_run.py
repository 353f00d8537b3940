#!/usr/bin/env python3
"""Replay of recorded service runs (issue 15 §4). Run 1: dispatchd with 18 fleet-sim robots
serves seed Table 1 and then a random stream of 12 orders, a quarter formations (seeded; pick and
drop points drawn from the seed tables' coordinates, releases spread over a minute); dispatchd
stops. Run 2: dispatchd starts again on the same database (it recovers the robots and the
finished orders), now routing by hub labels (--route-table hub_labels, recorded in the run's
setup), and serves a random stream of 36 single-robot orders within 10 s. `dispatch-sim replay
--db` feeds each run's journal through a fresh dispatch core and must reproduce every award,
grant, hold and order state (exit 0, "matched"). A what-if of run 2 with 3 robots fewer, on
the simulator's motion model, completes every order later than the same orders with the whole
fleet. (Run 1's formations are not used for the what-if: on the simulator's motion model the
dispatch core still freezes with formation orders queued behind each other, README
"Formations on the dispatch core".)

    replay_recorded_run.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN
                           --scenarios DIR --dispatch-sim BIN
"""
import csv
import os
import random
import re
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import COMPLETED, TERMINAL, Harness, check, common_arguments, state_name  # noqa: E402


def table_points(paths):
    """Pick and drop coordinates ("x y") of the seed tables: points the floor is known to have."""
    picks, drops = [], []
    for path in paths:
        with open(path) as f:
            rows = [line for line in f if not line.startswith("#")]
        for r in csv.DictReader(rows):
            picks += [p.strip() for p in r["picks"].split(";")]
            drops.append(r["drop"].strip())
    return sorted(set(picks)), sorted(set(drops))


def write_random_stream(path, picks, drops, count, seed, formations, now, spread):
    """`count` orders released over the `spread` seconds after dispatcher time `now`."""
    rng = random.Random(seed)
    with open(path, "w") as f:
        f.write("task,formation,picks,drop,release\n")
        for i in range(1, count + 1):
            formation = 1 if rng.random() < formations else 0
            chosen = rng.sample(picks, rng.choice((1, 2)))
            f.write(f"{i},{formation},{';'.join(chosen)},{rng.choice(drops)},{now + rng.uniform(0, spread):.1f}\n")


def serve(h, server, path):
    """Submits a task table and waits until every order of it is finished; their states."""
    rows = h.submit_file(server, path)
    ids = [order for _, order, _, _ in rows]
    check(ids, f"{path}: nothing submitted")
    final = h.watch(server, lambda o: len(o) == len(ids) and all(e.state in TERMINAL for e in o.values()),
                    timeout=240, what=f"every order of {os.path.basename(path)} to finish", order_ids=ids)
    states = {i: state_name(e.state) for i, e in final.items()}
    h.log(f"{os.path.basename(path)}: {states}")
    return {i: e.state for i, e in final.items()}


def row(output, name):
    """The cells of a row of the what-if table."""
    for line in output.splitlines():
        if line.strip().startswith(name):
            return line.strip()[len(name):].split()
    raise AssertionError(f"no row {name!r} in the what-if table")


def main():
    args = common_arguments(__doc__).parse_args()
    tables = [os.path.join(args.scenarios, t) for t in ("chu2024-table1.csv", "chu2024-table2.csv")]
    with Harness(args, "replay") as h:
        db = os.path.join(h.work, "recorded.db")
        picks, drops = table_points(tables)
        # Run 1: Table 1, then a random stream with formations.
        server = h.start_server(["--time-scale", "10"], db=db)
        fleet = h.start_fleet(server, 18)
        states = serve(h, server, tables[0])
        check(all(s == COMPLETED for s in states.values()), f"Table 1 orders that did not complete: {states}")
        stream = os.path.join(h.work, "stream-formations.csv")
        write_random_stream(stream, picks, drops, 12, seed=7, formations=0.25,
                            now=server.rest("/api/v1/status")["time"], spread=60)
        serve(h, server, stream)
        fleet.stop()
        check(server.stop() == 0, "dispatchd did not stop cleanly")
        # Run 2: a restart on the same database, single-robot orders, another route table.
        server = h.start_server(["--time-scale", "10", "--route-table", "hub_labels"], db=db)
        fleet = h.start_fleet(server, 18)
        stream = os.path.join(h.work, "stream-single.csv")
        # Twice as many orders as robots, nearly at once: a fleet 3 robots smaller takes longer.
        write_random_stream(stream, picks, drops, 36, seed=11, formations=0.0,
                            now=server.rest("/api/v1/status")["time"], spread=10)
        states = serve(h, server, stream)
        check(all(s == COMPLETED for s in states.values()), f"run 2 orders that did not complete: {states}")
        fleet.stop()
        check(server.stop() == 0, "dispatchd did not stop cleanly")

        for run_number, orders in ((1, 18), (2, 36)):
            out = h.replay(args.dispatch_sim, db, run_number)
            check(re.search(rf"replay of run {run_number} matched: \d+ entries, {orders} orders", out),
                  f"the replay of run {run_number} did not report {orders} matched orders")

        # Run 2's orders with the whole fleet and with 3 robots fewer (exit 0: all completed).
        out = h.replay(args.dispatch_sim, db, 2, "--what-if", "--robots", "15")
        completed = row(out, "completed")
        makespan = [float(x) for x in row(out, "makespan (s)")]
        robots = row(out, "robots")
        check(robots[1:] == ["18", "15"], f"robots row {robots}")
        check(completed[1] == completed[2] and completed[2].split("/")[0] == completed[2].split("/")[1],
              f"completed row {completed}")
        check(makespan[2] > makespan[1],
              f"15 robots should finish later than 18: makespan {makespan[2]} vs {makespan[1]} s")
        h.log(f"what-if: makespan {makespan[1]:.1f} s with 18 robots, {makespan[2]:.1f} s with 15")
    print("replay_recorded_run: OK")


if __name__ == "__main__":
    main()
