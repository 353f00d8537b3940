#!/usr/bin/env python3
"""Operators' robot commands in the live web map (issue 18 §4) in a real browser: dispatchd
with bearer tokens (a wms, an operator and a robot token) and robot R1 connected with its own
token; Debian's headless Chromium opens the page and:
  - with the wms token typed in the header, the page says who it is (GET /api/v1/session) and
    offers no robot command (a wms token may not read the fleet: the page shows the 403);
  - with the operator token, R1 is listed; selected, its commands are offered, and clicking
    them pauses and resumes it, takes it out of service and returns it, and sends it to a
    station: each time the REST API (read with the operator token) shows the command in force
    with the operator's token name, and the robots panel says so;
  - no JavaScript error once the operator token is in; the screenshot goes to
    OUT/web_map_commands.png (also on failure).

    web_map_commands.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
                        --out DIR [--chromium BIN]

Exits 77 (skipped) when Chromium or python3-websocket is missing.
"""
import hashlib
import json
import os
import sys
import threading
import urllib.request

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
import grpc  # noqa: E402
from e2e_harness import Harness, RobotStream, check  # noqa: E402
from web_map import WINDOW, browser_arguments, check_browser, in_browser  # noqa: E402
from warehouse.dispatch.v1 import common_pb2, fleet_pb2  # noqa: E402

SECRETS = {"wms-1": ("wms", "wms-secret-7f3a"), "op-1": ("operator", "operator-secret-91c2"),
           "r1": ("robot", "robot-secret-R1-55d0")}
PARK = (30.625, 24.75)  # park-P10


def write_tokens(path):
    tokens = []
    for name, (role, secret) in SECRETS.items():
        t = {"name": name, "role": role, "sha256": hashlib.sha256(secret.encode()).hexdigest()}
        if role == "robot":
            t["robot_id"] = "R1"
        tokens.append(t)
    with open(path, "w") as f:
        json.dump({"tokens": tokens}, f)


def rest(server, path, secret):
    req = urllib.request.Request(f"http://{server.http}{path}", headers={"Authorization": f"Bearer {secret}"})
    with urllib.request.urlopen(req, timeout=10) as resp:
        return json.loads(resp.read().decode())


def type_token(page, secret):
    page.evaluate(f"""(t => {{ const e = document.getElementById('token'); e.value = t;
        e.dispatchEvent(new Event('change')); return true; }})({json.dumps(secret)})""")


def commands(h, server, page, out):
    page.call("Emulation.setDeviceMetricsOverride", {"width": WINDOW[0], "height": WINDOW[1],
                                                     "deviceScaleFactor": 1, "mobile": False})
    page.call("Page.navigate", {"url": f"http://{server.http}/"})
    page.wait("document.readyState === 'complete' && !!window.dispatchMap", 20, "the page to load")
    operator = SECRETS["op-1"][1]

    type_token(page, SECRETS["wms-1"][1])
    page.wait("dispatchMap.session && dispatchMap.session.role === 'wms'", 10, "the page to know the wms token")
    problems = page.wait("dispatchMap.problems.filter(p => p.startsWith('robots:') && p.includes('403')).join()",
                         10, "the page to show that a wms token may not read the fleet")
    h.log(f"wms token: {problems}")
    check(page.evaluate("document.querySelectorAll('#robot-commands button').length") == 0,
          "robot commands offered to a wms token")

    type_token(page, operator)
    page.wait("dispatchMap.session && dispatchMap.session.role === 'operator' && dispatchMap.session.robot_commands",
              10, "the page to know the operator token")
    page.wait("!!document.querySelector('#robot-list li[data-robot-id=\"R1\"]')", 10, "R1 in the robots panel")
    errors_before = len(page.errors)
    page.click('#robot-list li[data-robot-id="R1"]')

    def run(command, field, want, shown):
        selector = f'#robot-commands button[data-command="{command}"]'
        page.wait(f"!!document.querySelector({json.dumps(selector)})", 10, f"the {command} button")
        page.click(selector)
        got = h.wait_for(lambda: (lambda r: r if field(r) == want else None)(rest(server, "/api/v1/robots/R1", operator)),
                         10, f"{command}: the API to show {want!r}")
        text = page.wait(f"""(t => t.includes({json.dumps(shown)}) && t)(
            document.querySelector('#robot-list li[data-robot-id="R1"]').textContent)""" if shown else
                         f"""(t => !/paused|out of service/.test(t) && t)(
            document.querySelector('#robot-list li[data-robot-id="R1"]').textContent)""",
                         10, f"{command}: the robots panel to say so")
        h.log(f"{command}: API {field(got)!r}; panel '{text}'")

    run("pause", lambda r: r.get("paused_by", ""), "op-1", "paused by op-1")
    run("resume", lambda r: r.get("paused_by", ""), "", None)
    run("out_of_service", lambda r: r.get("out_of_service_by", ""), "op-1", "out of service (op-1)")
    run("return_to_service", lambda r: r.get("out_of_service_by", ""), "", None)
    page.wait("!!document.querySelector('#send-station option[value=\"P5\"]')", 10, "station P5 offered")
    page.evaluate("(s => { s.value = 'P5'; return true; })(document.getElementById('send-station'))")
    run("send", lambda r: (r.get("sent_to") or {}).get("point_name", ""), "park-P5", "→ park-P5")

    page.call("Page.captureScreenshot", {"format": "png"})  # drains pending events
    new_errors = page.errors[errors_before:]
    check(not new_errors, "JavaScript errors with the operator token:\n  " + "\n  ".join(new_errors))
    page.screenshot(os.path.join(out, "web_map_commands.png"))


def main():
    args = browser_arguments(__doc__, "web_map_commands.png").parse_args()
    check_browser(args)
    with Harness(args, "webmap-commands") as h:
        tokens = os.path.join(h.work, "tokens.json")
        write_tokens(tokens)
        server = h.start_server(["--auth-tokens", tokens, "--time-scale", "10"])
        channel = grpc.insecure_channel(server.grpc)
        hello = fleet_pb2.RobotMessage(hello=fleet_pb2.Hello(
            robot_id="R1", pose=common_pb2.Pose(x=PARK[0], y=PARK[1], theta=0.0)))
        robot = RobotStream(channel, hello, metadata=[("authorization", f"Bearer {SECRETS['r1'][1]}")])
        welcome = robot.welcome()
        done = threading.Event()

        def heartbeats():  # R1 stays on line (a robot's own heartbeat, not a synchronisation)
            while not done.wait(max(0.1, welcome.welcome.heartbeat_interval / 2)):
                robot.send(fleet_pb2.RobotMessage(heartbeat=fleet_pb2.Heartbeat(robot_unix_ms=0)))
        threading.Thread(target=heartbeats, daemon=True).start()
        try:
            in_browser(h, args, "web_map_commands.png", lambda page: commands(h, server, page, args.out))
        finally:
            done.set()
            robot.close()
            channel.close()


if __name__ == "__main__":
    main()
