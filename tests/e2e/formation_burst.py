#!/usr/bin/env python3
"""The formation burst through the service (issue 16 §5): seed Tables 1 and 2 submitted ten
times each at once (140 orders, 70 of them formations) to the real dispatchd with 18 fleet-sim
robots on the Chu2024 floor. The service must not freeze: every order ends (completed, or
failed saying why) before the deadline, the robots' last states show none left in fault, and
the closest approach the dispatcher saw between robots of different agents stays >= eps1.
With --min-completed N at least N of the 140 complete.

    formation_burst.py [--planner P] [--min-completed N] --stubs DIR --dispatchd BIN
                       --fleet-sim BIN --wmsctl BIN --scenarios DIR --dispatch-sim BIN
"""
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import COMPLETED, FAILED, TERMINAL, Harness, check, common_arguments, state_name  # noqa: E402

EPS1 = 0.6
REPEAT = 10


def main():
    p = common_arguments(__doc__)
    p.add_argument("--planner", default="rules")
    p.add_argument("--min-completed", type=int, default=0)
    p.add_argument("--time-scale", default="20")
    p.add_argument("--timeout", type=float, default=420.0, help="wall seconds for every order to end")
    args = p.parse_args()
    with Harness(args, "burst") as h:
        server = h.start_server(["--time-scale", args.time_scale, "--planner", args.planner])
        h.start_fleet(server, 18)
        ids = []
        for k in range(1, REPEAT + 1):
            for n, table in ((1, "chu2024-table1.csv"), (2, "chu2024-table2.csv")):
                rows = h.submit_file(server, os.path.join(args.scenarios, table), prefix=f"t{n}x{k}-")
                check(all(created for _, _, _, created in rows), f"{table} x{k}: not every order was created")
                ids += [order for _, order, _, _ in rows]
        check(len(ids) == 14 * REPEAT, f"{len(ids)} orders submitted, want {14 * REPEAT}")
        final = h.watch(server, lambda o: len(o) == len(ids) and all(e.state in TERMINAL for e in o.values()),
                        timeout=args.timeout, what="every order of the burst to end", order_ids=ids)
        completed = [i for i, e in final.items() if e.state == COMPLETED]
        failed = {i: e.detail for i, e in final.items() if e.state == FAILED}
        other = {i: state_name(e.state) for i, e in final.items() if e.state not in (COMPLETED, FAILED)}
        h.log(f"burst ({args.planner}): {len(completed)} completed, {len(failed)} failed, {len(other)} other")
        for i, why in sorted(failed.items()):
            h.log(f"failed {i}: {why}")
        check(not other, f"orders neither completed nor failed: {other}")
        for i, why in failed.items():
            check("blocked" in why, f"{i} failed without saying it was blocked: {why}")
        check(len(completed) >= args.min_completed,
              f"{len(completed)} of {len(ids)} completed, want at least {args.min_completed}")
        # A robot blocked near the end is back in service blocked_recovery (60 s) later.
        def none_in_fault():
            robots = server.rest("/api/v1/robots")["robots"]
            return all("FAULT" not in str(r.get("state", "")).upper() for r in robots)
        h.wait_for(none_in_fault, timeout=60, what="every robot back in service")
        h.log(f"status: {server.rest('/api/v1/status')}")
        h.check_min_distance(server, EPS1)


if __name__ == "__main__":
    main()
