#!/usr/bin/env python3
"""The live web map in a real browser (issue 6 §1, SPEC §4): dispatchd (time scale 10) with 18
fleet-sim robots and seed Table 1 submitted; Debian's headless Chromium, driven over the
DevTools protocol, opens the page dispatchd serves at `/` and must show: all 18 robots (DOM
elements with data-robot-id; every second one a four-wheel-steer robot, fleet-sim --kinds, drawn
as its turned footprint rectangle, the others as discs) and then at least one of them at a new
position, a non-empty
floor canvas and zone heat layer, a formation drawn as one, a held intersection, the status
line, every submitted order in the order list; a click on an order opens its allocation
explanation with the same bids, winners and reason as GET /api/v1/orders/{id}, and its
remaining routes when the server sends them. No fetch problem shown, no JavaScript error
or console error logged. The screenshot is written to OUT/web_map.png (also on failure).

    web_map.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
               --out DIR [--chromium BIN] [--web-root DIR]

Exits 77 (skipped) when Chromium or python3-websocket is missing.
"""
import base64
import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from e2e_harness import Harness, TestFailure, check, common_arguments, _die_with_parent  # noqa: E402

SKIP = 77
ROBOTS = 18
WINDOW = (1600, 1000)


class Chromium(contextlib.AbstractContextManager):
    """Headless Chromium in its own process group, killed as a group on exit (also on
    failure; PR_SET_PDEATHSIG covers the test itself being killed)."""

    def __init__(self, binary, work):
        self.profile = tempfile.mkdtemp(prefix="chromium-", dir=work)
        self.log_path = os.path.join(work, "chromium.log")
        self._log = open(self.log_path, "wb")
        argv = [binary, "--headless=new", "--no-sandbox", "--remote-debugging-port=0",
                f"--user-data-dir={self.profile}", f"--window-size={WINDOW[0]},{WINDOW[1]}",
                "--no-first-run", "--no-default-browser-check", "--disable-extensions",
                "--disable-background-networking", "--disable-component-update", "about:blank"]
        print(f"[e2e] start chromium: {' '.join(argv)}", flush=True)

        def child():
            os.setsid()  # its own process group: renderer, GPU and zygote die with it
            _die_with_parent()

        self.popen = subprocess.Popen(argv, stdout=self._log, stderr=subprocess.STDOUT,
                                      stdin=subprocess.DEVNULL, preexec_fn=child)

    def debugger_port(self, timeout=30):
        """The port Chromium chose, from <profile>/DevToolsActivePort once it is written."""
        path = os.path.join(self.profile, "DevToolsActivePort")
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            check(self.popen.poll() is None, f"chromium exited with {self.popen.returncode}")
            with contextlib.suppress(FileNotFoundError, ValueError, IndexError):
                with open(path) as f:
                    return int(f.read().split("\n")[0])
            time.sleep(0.05)  # polling for the file, not a synchronisation
        raise TestFailure(f"chromium wrote no {path} within {timeout} s")

    def __exit__(self, *exc):
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.popen.pid, signal.SIGKILL)
        self.popen.wait(timeout=30)
        self._log.close()
        return False

    def log_tail(self, lines=40):
        with open(self.log_path, "rb") as f:
            return "\n".join(f.read().decode(errors="replace").splitlines()[-lines:])


class DevTools:
    """A DevTools protocol session with one page: commands, and the events that mean an
    error (uncaught exceptions, console.error, error log entries) collected on the way."""

    def __init__(self, port, timeout=30):
        import websocket  # python3-websocket
        deadline = time.monotonic() + timeout
        url = None
        while url is None:
            with contextlib.suppress(OSError, ValueError):
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=5) as r:
                    pages = [t for t in json.loads(r.read()) if t.get("type") == "page"]
                if pages:
                    url = pages[0]["webSocketDebuggerUrl"]
                    break
            check(time.monotonic() < deadline, f"no page target on DevTools port {port}")
            time.sleep(0.05)  # polling for the target, not a synchronisation
        self.ws = websocket.create_connection(url, timeout=timeout, suppress_origin=True)
        self.next_id = 0
        self.errors = []
        for domain in ("Page", "Runtime", "Log"):
            self.call(f"{domain}.enable")

    def call(self, method, params=None, timeout=20):
        self.next_id += 1
        mid = self.next_id
        self.ws.send(json.dumps({"id": mid, "method": method, "params": params or {}}))
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            check(left > 0, f"DevTools: no answer to {method} within {timeout} s")
            self.ws.settimeout(left)
            msg = json.loads(self.ws.recv())
            if msg.get("id") == mid:
                check("error" not in msg, f"DevTools {method}: {msg.get('error')}")
                return msg.get("result", {})
            self._event(msg)

    def _event(self, msg):
        method, p = msg.get("method"), msg.get("params", {})
        if method == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            text = d.get("exception", {}).get("description") or d.get("text")
            self.errors.append(f"uncaught: {text} ({d.get('url', '')}:{d.get('lineNumber')})")
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            args = " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", []))
            self.errors.append(f"console.{p['type']}: {args}")
        elif method == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            e = p["entry"]
            self.errors.append(f"log ({e.get('source')}): {e.get('text')} {e.get('url', '')}")

    def evaluate(self, expression):
        r = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                           "awaitPromise": True})
        if "exceptionDetails" in r:
            d = r["exceptionDetails"]
            raise TestFailure(f"evaluating {expression[:80]!r}: "
                              f"{d.get('exception', {}).get('description') or d.get('text')}")
        return r.get("result", {}).get("value")

    def wait(self, expression, timeout, what, interval=0.1):
        """Evaluates `expression` until it is truthy (returns its value) or the deadline."""
        deadline = time.monotonic() + timeout
        last = None
        while time.monotonic() < deadline:
            last = self.evaluate(expression)
            if last:
                return last
            time.sleep(interval)  # poll interval of a page condition, not a synchronisation
        raise TestFailure(f"timed out after {timeout} s waiting for {what} (last: {last!r}); "
                          f"page problems: {self.evaluate(PROBLEMS)}")

    def click(self, selector):
        """A real mouse click (press and release) at the centre of the element."""
        box = self.evaluate(f"""(() => {{ const e = document.querySelector({json.dumps(selector)});
            if (!e) return null; e.scrollIntoView({{block: 'center'}});
            const r = e.getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]; }})()""")
        check(box, f"nothing to click: {selector}")
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", {"type": kind, "x": box[0], "y": box[1],
                                                   "button": "left", "clickCount": 1})

    def screenshot(self, path):
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))
        print(f"[e2e] screenshot: {path}", flush=True)


PROBLEMS = "window.dispatchMap ? dispatchMap.problems : 'no window.dispatchMap'"
DRAWN = """[...document.querySelectorAll('#robots [data-robot-id]')]
             .map(e => [e.dataset.robotId, +e.dataset.x, +e.dataset.y])"""
# Of every 7th pixel of a canvas: the share painted, the share painted in a warm tint (red
# well above blue: the density heat), and how many distinct colours (a crude but real
# "something was drawn" measure).
CANVAS_INK = """(id => { const c = document.getElementById(id); if (!c || !c.width) return [0, 0, 0];
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let ink = 0, warm = 0; const colours = new Set();
  for (let i = 0; i < d.length; i += 4 * 7) {
    if (!d[i + 3]) continue;
    ink++; if (d[i] - d[i + 2] > 20) warm++;
    colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]); }
  const n = d.length / (4 * 7); return [ink / n, warm / n, colours.size]; })"""


def browser_checks(h, server, page, base_url, orders, out):
    """All checks on the page at base_url; `orders` = the submitted order ids."""
    page.call("Emulation.setDeviceMetricsOverride", {"width": WINDOW[0], "height": WINDOW[1],
                                                     "deviceScaleFactor": 1, "mobile": False})
    page.call("Page.navigate", {"url": base_url + "/"})
    page.wait("document.readyState === 'complete' && !!window.dispatchMap", 20, "the page to load")

    drawn = page.wait(f"(d => d.length === {ROBOTS} && d)({DRAWN})", 20, f"all {ROBOTS} robots drawn")
    ids = sorted(r[0] for r in drawn)
    check(ids == sorted(f"R{k}" for k in range(1, ROBOTS + 1)), f"robots drawn: {ids}")
    api = page.evaluate("dispatchMap.robots().map(r => r.id).sort().join()")
    check(api == ",".join(ids), f"dispatchMap.robots() = {api}, DOM has {ids}")
    # Kinds from the robots' Hellos: R2, R4, ... are four-wheel steer, drawn as footprints.
    kinds = page.evaluate("""[...document.querySelectorAll('#robots [data-robot-id]')].map(e => {
        const f = e.querySelector('rect.footprint'), b = e.querySelector('circle.body');
        return [e.dataset.robotId, e.dataset.kind, f.style.display !== 'none', b.style.display !== 'none',
                f.getAttribute('transform') || '', +f.getAttribute('width') > +f.getAttribute('height')]; })""")
    h.log("footprints drawn: " + " ".join(k[0] for k in kinds if k[2]))
    for rid, kind, footprint, disc, turn, long_side in kinds:
        steer = int(rid[1:]) % 2 == 0
        check(kind == ("four_wheel_steer" if steer else "differential"), f"{rid} drawn as kind {kind}")
        check(footprint == steer and disc != steer, f"{rid} ({kind}): footprint shown {footprint}, disc {disc}")
        if steer:
            check(turn.startswith("rotate(") and long_side, f"{rid}: footprint transform {turn!r}")
    frames0 = page.evaluate("dispatchMap.frames")
    first = {r[0]: (r[1], r[2]) for r in drawn}
    h.log(f"{len(first)} robots drawn after {frames0} live updates")
    moved = page.wait(f"""(first => {DRAWN}.filter(([id, x, y]) => first[id] &&
        Math.hypot(x - first[id][0], y - first[id][1]) > 0.05).map(r => r[0]))({json.dumps(first)})
        .join(' ')""", 30, "a robot drawn at a new position")
    h.log(f"moved on the page: {moved}")
    frames = page.wait(f"dispatchMap.frames >= {frames0 + 5} && dispatchMap.frames", 10,
                       "five more live updates")
    h.log(f"live updates applied: {frames}")

    floor_ink, _, floor_colours = page.evaluate(f"{CANVAS_INK}('floor')")
    check(floor_ink > 0.05 and floor_colours >= 6,
          f"floor canvas looks empty: {floor_ink:.0%} painted, {floor_colours} colours")
    heat = page.wait(f"(([, warm]) => warm > 0.005 && warm)({CANVAS_INK}('heat'))", 10,
                     "the zone density heat layer")
    h.log(f"floor canvas {floor_ink:.0%} painted in {floor_colours} colours; density heat on {heat:.0%}")

    status = page.wait("(t => t.includes('chu2024') && t.includes('18/18') && t)"
                       "(document.getElementById('status').textContent)", 10, "the status line")
    h.log(f"status line: {status}")
    listed = page.wait(f"""(l => {json.dumps(orders)}.every(id => l.includes(id)) && l)(
        [...document.querySelectorAll('#orders li[data-order-id]')].map(e => e.dataset.orderId))""",
                       10, "every submitted order in the order list")
    h.log(f"order list: {listed}")
    formation = page.wait("[...document.querySelectorAll('#formations polygon.formation')]"
                          ".map(e => e.dataset.orderId).join(' ')", 30, "a formation drawn as one")
    h.log(f"formations drawn: {formation}")
    grant = page.wait("[...document.querySelectorAll('#grants polygon.grant')]"
                      ".map(e => e.dataset.intersectionId + ':' + e.dataset.holders).join(' ')",
                      30, "an intersection drawn held")
    h.log(f"intersections drawn held: {grant}")

    # Click an allocated order still under way (its routes are left), formation preferred.
    def pick():
        active = [server.rest(f"/api/v1/orders/{o}") for o in orders]
        active = [o for o in active if o.get("allocation")
                  and o["order"]["state"] in ("ORDER_STATE_ASSIGNED", "ORDER_STATE_IN_PROGRESS")]
        return sorted(active, key=lambda o: (not o["order"]["formation"], o["order"]["id"]))
    chosen = h.wait_for(pick, 20, "an allocated order under way")[0]
    oid = chosen["order"]["id"]
    page.click(f'#orders li[data-order-id="{oid}"]')
    shown = page.wait(f"""(() => {{ const p = document.getElementById('detail-panel');
        if (p.hidden || document.getElementById('detail-title').textContent !== {json.dumps(oid)}) return null;
        const rows = t => [...document.querySelectorAll('#detail table.bids')][t];
        const table = rows(0); if (!table) return null;
        const tr = [...table.querySelectorAll('tbody tr')];
        return {{bids: tr.map(r => r.dataset.robot), winners: tr.filter(r => r.classList.contains('winner'))
                 .map(r => r.dataset.robot), reason: document.querySelector('#detail .reason').textContent,
                 cells: tr.length ? tr[0].children.length : 0,
                 companions: rows(1) ? rows(1).querySelectorAll('tbody tr').length : 0}}; }})()""",
                      10, f"the explanation of {oid} after the click")
    alloc = chosen["allocation"]
    h.log(f"clicked {oid}: {len(shown['bids'])} bids shown, winners {shown['winners']}")
    check(sorted(shown["bids"]) == sorted(b["robot_id"] for b in alloc["bids"]),
          f"{oid}: bids shown {shown['bids']}, REST has {[b['robot_id'] for b in alloc['bids']]}")
    check(shown["cells"] == 7, f"{oid}: a bid row has {shown['cells']} cells, want robot T_t T_d T_w F bid win")
    check(shown["winners"] and set(shown["winners"]) <= set(alloc["winner_ids"]),
          f"{oid}: winners marked {shown['winners']}, REST winners {alloc['winner_ids']}")
    check(shown["reason"] == alloc["reason"], f"{oid}: reason shown {shown['reason']!r}, REST {alloc['reason']!r}")
    check(shown["companions"] == len(alloc.get("companion_bids") or []),
          f"{oid}: {shown['companions']} companion bids shown, REST has {len(alloc.get('companion_bids') or [])}")
    check(page.evaluate(f"document.querySelector('#orders li.selected').dataset.orderId") == oid,
          f"{oid} is not marked selected in the order list")
    routes = server.rest(f"/api/v1/orders/{oid}").get("routes")
    if routes is None:
        h.log(f"GET /api/v1/orders/{oid} has no 'routes' (not served yet): no route check")
    elif any(routes.values()):
        drawn_routes = page.wait("[...new Set([...document.querySelectorAll('#routes polyline')]"
                                 ".map(e => e.dataset.routeOf))].sort().join(' ')", 10,
                                 f"the remaining routes of {oid}")
        h.log(f"routes drawn for {drawn_routes}")
        robots = chosen["order"]["robot_ids"]
        check(set(drawn_routes.split()) <= set(robots), f"routes of {drawn_routes}, order has {robots}")

    page.screenshot(os.path.join(out, "web_map.png"))
    problems = page.evaluate(PROBLEMS)
    check(not problems, f"the page shows fetch problems: {problems}")
    check(not page.errors, "JavaScript errors or error log entries:\n  " + "\n  ".join(page.errors))


def browser_arguments(description, screenshot):
    """The e2e arguments with --out and --chromium; exits 77 (skipped) without Chromium or
    python3-websocket."""
    p = common_arguments(description)
    p.add_argument("--out", required=True, help=f"folder for {screenshot}")
    p.add_argument("--chromium", default="/usr/bin/chromium")
    return p


def check_browser(args):
    try:
        import websocket  # noqa: F401
    except ImportError:
        print("SKIPPED: python3-websocket is not installed")
        sys.exit(SKIP)
    if not shutil.which(args.chromium):
        print(f"SKIPPED: no Chromium at {args.chromium}")
        sys.exit(SKIP)
    os.makedirs(args.out, exist_ok=True)


def in_browser(h, args, screenshot, checks):
    """Runs checks(page) on a page of a fresh headless Chromium; on a failure the page's
    screenshot (OUT/screenshot), its errors and Chromium's log tail are printed."""
    with Chromium(args.chromium, h.work) as browser:
        page = None
        try:
            page = DevTools(browser.debugger_port())
            checks(page)
        except BaseException:
            if page is not None:
                with contextlib.suppress(Exception):
                    page.screenshot(os.path.join(args.out, screenshot))
                print("---- page errors:\n  " + "\n  ".join(page.errors or ["none"]), flush=True)
            print(f"---- chromium log (last 40 lines): {browser.log_path}\n{browser.log_tail()}", flush=True)
            raise


def main():
    p = browser_arguments(__doc__, "web_map.png")
    p.add_argument("--web-root", help="serve the page from this folder (dispatchd --web-root)")
    args = p.parse_args()
    check_browser(args)
    with Harness(args, "webmap") as h:
        extra = ["--time-scale", "10"] + (["--web-root", args.web_root] if args.web_root else [])
        server = h.start_server(extra)
        h.start_fleet(server, ROBOTS, extra=["--kinds", "differential,four_wheel_steer"])
        rows = h.submit_file(server, os.path.join(args.scenarios, "chu2024-table1.csv"))
        check(len(rows) == 6, f"submitted {len(rows)} orders of Table 1, want 6")
        in_browser(h, args, "web_map.png", lambda page: browser_checks(
            h, server, page, f"http://{server.http}", [r[1] for r in rows], args.out))


if __name__ == "__main__":
    main()
