"""Shared orchestration for the Python end-to-end tests (tests/e2e/*.py): real dispatchd and
fleet-sim processes on loopback with ephemeral ports, a gRPC client (stubs generated from
proto/ at build time) and the REST API.

Rules the tests keep (issue 5 §5): loopback only; the first start of dispatchd takes any
free port (--grpc-port 0 --http-port 0) and reports it through --ready-fd, fleet-sim reports
"connected N" through its --ready-fd, so nothing sleeps to synchronise; other waits poll a real
condition (a journal event, a REST field) against a deadline. Every process started here is
stopped when the Harness exits, also on failure (and, through PR_SET_PDEATHSIG, when the test
itself is killed, e.g. by a CTest timeout). A process that ends with a non-zero status (other
than by the test's own kill -9) fails the test too. On failure the logs of every process are
printed and kept, with the database, in the work directory named last.

    with Harness(args, "name") as h:
        server = h.start_server(["--time-scale", "10"])
        fleet = h.start_fleet(server, 18)
        ...
"""
import argparse
import contextlib
import ctypes
import json
import os
import queue
import re
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import urllib.request

import grpc  # noqa: F401  (the caller put the stubs directory on sys.path first)
from warehouse.dispatch.v1 import common_pb2, fleet_pb2_grpc, orders_pb2, orders_pb2_grpc  # noqa: F401

ACCEPTED = common_pb2.ORDER_STATE_ACCEPTED
ASSIGNED = common_pb2.ORDER_STATE_ASSIGNED
IN_PROGRESS = common_pb2.ORDER_STATE_IN_PROGRESS
COMPLETED = common_pb2.ORDER_STATE_COMPLETED
CANCELLED = common_pb2.ORDER_STATE_CANCELLED
FAILED = common_pb2.ORDER_STATE_FAILED
TERMINAL = (COMPLETED, CANCELLED, FAILED)
# Lifecycle order, for "never went backwards" checks (re-allocation aside).
RANK = {ACCEPTED: 0, ASSIGNED: 1, IN_PROGRESS: 2, COMPLETED: 3, CANCELLED: 3, FAILED: 3}


def state_name(state):
    return common_pb2.OrderState.Name(state).replace("ORDER_STATE_", "").lower()


class TestFailure(Exception):
    pass


def check(condition, message):
    if not condition:
        raise TestFailure(message)


def common_arguments(description):
    """Command line shared by the tests: the binaries, the stubs and the scenario folder."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--stubs", required=True, help="python_stubs directory (already on sys.path)")
    p.add_argument("--dispatchd", required=True)
    p.add_argument("--fleet-sim", required=True)
    p.add_argument("--wmsctl", required=True)
    p.add_argument("--scenarios", required=True, help="folder of the seed CSV tables")
    p.add_argument("--dispatch-sim", required=True, help="for `dispatch-sim replay` of the recorded runs")
    return p


_prctl = ctypes.CDLL("libc.so.6", use_errno=True).prctl  # loaded before any fork
_PR_SET_PDEATHSIG = 1


def _die_with_parent():
    # In the child between fork and exec: it gets SIGKILL when the test process dies (CTest
    # timeout, Ctrl-C), so no process outlives the test. Only a call of a function loaded
    # beforehand, nothing that could wait for a lock of another (gRPC) thread.
    _prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL))


def _read_line(fd, timeout, what):
    """One line from a pipe (a --ready-fd), or TestFailure after `timeout` seconds / on EOF."""
    deadline = time.monotonic() + timeout
    data = b""
    while b"\n" not in data:
        left = deadline - time.monotonic()
        if left <= 0:
            raise TestFailure(f"{what}: nothing on its ready descriptor within {timeout:.0f} s")
        ready, _, _ = select.select([fd], [], [], left)
        if not ready:
            continue
        chunk = os.read(fd, 4096)
        if not chunk:
            raise TestFailure(f"{what}: closed its ready descriptor without a line (exited?)")
        data += chunk
    return data.split(b"\n", 1)[0].decode()


class Process:
    """A child process with its log file."""

    def __init__(self, harness, name, argv, log_path, pass_fds=()):
        self.name = name
        self.argv = argv
        self.log_path = log_path
        self.killed = False  # by kill9(), on purpose
        self._log = open(log_path, "wb")
        print(f"[e2e] start {name}: {' '.join(argv)}", flush=True)
        self.popen = subprocess.Popen(argv, stdout=self._log, stderr=subprocess.STDOUT,
                                      stdin=subprocess.DEVNULL, pass_fds=pass_fds,
                                      preexec_fn=_die_with_parent)
        harness.processes.append(self)  # stopped by the harness from now on, whatever happens

    @property
    def pid(self):
        return self.popen.pid

    def running(self):
        return self.popen.poll() is None

    def kill9(self):
        """SIGKILL, then reap it."""
        print(f"[e2e] kill -9 {self.name} (pid {self.pid})", flush=True)
        self.killed = True
        self.popen.send_signal(signal.SIGKILL)
        self.popen.wait(timeout=30)

    def stop(self, timeout=10):
        """SIGTERM (graceful), SIGKILL after `timeout` seconds. Returns the exit status."""
        if self.popen.poll() is None:
            self.popen.send_signal(signal.SIGTERM)
            try:
                self.popen.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                print(f"[e2e] {self.name} ignored SIGTERM for {timeout} s: SIGKILL", flush=True)
                self.popen.kill()
                self.popen.wait(timeout=30)
        self._log.close()
        return self.popen.returncode

    def log_text(self):
        with open(self.log_path, "rb") as f:
            return f.read().decode(errors="replace")


class Server(Process):
    """dispatchd, started with --ready-fd; `grpc` and `http` are its HOST:PORT addresses."""

    def __init__(self, harness, index, db, grpc_port, extra):
        r, w = os.pipe()
        argv = [harness.args.dispatchd, "--bind", "127.0.0.1", "--grpc-port", str(grpc_port),
                "--http-port", "0", "--db", db, "--ready-fd", str(w)] + list(extra)
        try:
            super().__init__(harness, f"dispatchd#{index}", argv,
                             os.path.join(harness.work, f"dispatchd-{index}.log"), pass_fds=(w,))
        finally:
            os.close(w)
        try:
            line = _read_line(r, 60, self.name)
        finally:
            os.close(r)
        ports = json.loads(line)
        self.grpc_port = int(ports["grpc_port"])
        self.http_port = int(ports["http_port"])
        self.grpc = f"127.0.0.1:{self.grpc_port}"
        self.http = f"127.0.0.1:{self.http_port}"
        print(f"[e2e] {self.name} ready: gRPC {self.grpc}, REST {self.http}", flush=True)
        self.printed_events = set()  # journal events logged so far
        self.channel = grpc.insecure_channel(self.grpc)
        self.orders = orders_pb2_grpc.OrderServiceStub(self.channel)

    def close_channel(self):
        self.channel.close()

    def rest(self, path, timeout=10):
        with urllib.request.urlopen(f"http://{self.http}{path}", timeout=timeout) as resp:
            return json.loads(resp.read().decode())


class Fleet(Process):
    """fleet-sim with --ready-fd (waited for) and, optionally, a --control-fd pipe."""

    def __init__(self, harness, index, server, robots, extra, control):
        r, w = os.pipe()
        fds = [w]
        argv = [harness.args.fleet_sim, "--server", server.grpc, "--robots", str(robots),
                "--ready-fd", str(w)]
        self._control_w = None
        control_r = None
        if control:
            control_r, self._control_w = os.pipe()
            fds.append(control_r)
            argv += ["--control-fd", str(control_r)]
        argv += list(extra)
        try:
            super().__init__(harness, f"fleet-sim#{index}", argv,
                             os.path.join(harness.work, f"fleet-sim-{index}.log"), pass_fds=fds)
        finally:
            os.close(w)
            if control_r is not None:
                os.close(control_r)
        try:
            line = _read_line(r, 60, self.name)
        finally:
            os.close(r)
        check(line.startswith("connected"), f"{self.name}: unexpected ready line '{line}'")
        print(f"[e2e] {self.name}: {line}", flush=True)

    def command(self, text):
        """Sends one --control-fd command line, e.g. "mute R1"."""
        print(f"[e2e] {self.name} <- '{text}'", flush=True)
        os.write(self._control_w, (text + "\n").encode())

    def stop(self, timeout=10):
        if self._control_w is not None:
            os.close(self._control_w)
            self._control_w = None
        return super().stop(timeout)


class RobotStream:
    """One Connect call driven by the test: send() queues robot messages; a reader thread
    collects the server's messages and, last, the status the stream ended with. `server`: a
    Server (its channel) or a channel; `metadata`: the call's (e.g. a bearer token)."""

    def __init__(self, server, *first, metadata=()):
        self._out = queue.Queue()
        for m in first:
            self._out.put(m)
        self._in = queue.Queue()
        channel = server.channel if hasattr(server, "channel") else server
        stub = fleet_pb2_grpc.FleetServiceStub(channel)
        self.call = stub.Connect(iter(self._out.get, None), timeout=60, metadata=list(metadata))
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        try:
            for m in self.call:
                self._in.put(m)
            self._in.put(("end", self.call.code(), self.call.details() or ""))
        except grpc.RpcError as err:
            self._in.put(("end", err.code(), err.details() or ""))

    def send(self, *messages):
        for m in messages:
            self._out.put(m)

    def close(self):
        self._out.put(None)  # half-close: the server ends the stream

    def next(self, timeout=10):
        try:
            return self._in.get(timeout=timeout)  # a wait for the server's answer, not a sleep
        except queue.Empty:
            raise TestFailure(f"no message or end of stream within {timeout} s")

    def welcome(self):
        m = self.next()
        if isinstance(m, tuple):
            raise TestFailure(f"stream ended instead of a Welcome: {m[1].name} '{m[2]}'")
        check(m.WhichOneof("body") == "welcome", f"first server message is {m.WhichOneof('body')}")
        return m

    def expect_end(self, code, *words, max_len=None):
        """Skips server messages until the end; the status must be `code` naming `words`."""
        while True:
            m = self.next()
            if isinstance(m, tuple):
                break
        _, got, details = m
        check(got == code, f"stream ended with {got.name} '{details[:300]}', want {code.name}")
        missing = [w for w in words if w.lower() not in details.lower()]
        check(not missing, f"{code.name} '{details[:300]}' does not name {missing}")
        check(max_len is None or len(details) <= max_len, f"status message of {len(details)} bytes")
        return details


class Harness(contextlib.AbstractContextManager):
    def __init__(self, args, name):
        self.args = args
        self.name = name
        self.work = tempfile.mkdtemp(prefix=f"e2e-{name}-")
        self.processes = []
        self.servers = 0
        self.fleets = 0
        self.t0 = time.monotonic()

    def log(self, text):
        print(f"[e2e {time.monotonic() - self.t0:6.2f}s] {text}", flush=True)

    # --- processes ----------------------------------------------------------------------
    def start_server(self, extra=(), db=None, grpc_port=0):
        self.servers += 1
        db = db or os.path.join(self.work, "dispatch.db")
        return Server(self, self.servers, db, grpc_port, extra)

    def start_fleet(self, server, robots, extra=(), control=False):
        self.fleets += 1
        return Fleet(self, self.fleets, server, robots, extra, control)

    def wmsctl(self, server, *argv, timeout=60):
        cmd = [self.args.wmsctl, "--server", server.grpc] + list(argv)
        self.log("run " + " ".join(cmd))
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        sys.stdout.write(r.stdout)
        sys.stdout.write(r.stderr)
        check(r.returncode == 0, f"wmsctl exited {r.returncode}")
        return r.stdout

    def submit_file(self, server, path, prefix=None):
        """wmsctl submit FILE [--prefix P]; returns [(client id, order id, state, created)] in
        file order."""
        out = self.wmsctl(server, "submit", path, *(["--prefix", prefix] if prefix else []))
        rows = []
        for line in out.splitlines():
            m = re.match(r"^(\S+)\s+->\s+(\S+)\s+(\S+)\s+(created|already submitted)", line)
            if m:
                rows.append((m.group(1), m.group(2), m.group(3), m.group(4) == "created"))
        return rows

    # --- the order API ------------------------------------------------------------------
    def list_orders(self, server):
        out, token = [], ""
        while True:
            page = server.orders.ListOrders(
                orders_pb2.ListOrdersRequest(page_size=1000, page_token=token), timeout=10)
            out.extend(page.orders)
            token = page.next_page_token
            if not token:
                return out

    def watch(self, server, until, timeout, what, order_ids=(), on_event=None):
        """Follows WatchOrders from the start of the journal. `orders` is a dict order id ->
        its latest event; returns once until(orders) is true, after `on_event(event, orders)`
        for each event. TestFailure after `timeout` seconds."""
        orders = {}
        call = server.orders.WatchOrders(
            orders_pb2.WatchOrdersRequest(order_ids=list(order_ids), from_start=True),
            timeout=timeout)
        try:
            for e in call:
                orders[e.order_id] = e
                if e.event_id not in server.printed_events:  # watches replay the journal
                    server.printed_events.add(e.event_id)
                    self.log(f"event {e.event_id} {e.order_id}: {state_name(e.state)} "
                             f"{list(e.robot_ids)} {e.detail[:90]}")
                if on_event:
                    on_event(e, orders)
                if until(orders):
                    return orders
        except grpc.RpcError as err:
            if err.code() == grpc.StatusCode.DEADLINE_EXCEEDED:
                self.log_traffic(server)
                raise TestFailure(f"timed out after {timeout} s waiting for {what}; last states: "
                                  + ", ".join(f"{k}={state_name(v.state)}"
                                              for k, v in sorted(orders.items())))
            raise TestFailure(f"WatchOrders failed while waiting for {what}: "
                              f"{err.code().name}: {err.details()}")
        finally:
            call.cancel()
        raise TestFailure(f"the watch ended before {what}")

    def check_min_distance(self, server, eps1=0.6):
        """The closest approach the dispatcher saw between robots of different agents (REST
        /api/v1/status) is at least eps1."""
        closest = server.rest("/api/v1/status")["traffic"].get("min_robot_distance")
        check(closest is not None, "no minimum distance measured")
        check(closest["distance"] >= eps1 - 1e-6,
              f"robots {closest['robot_ids']} came {closest['distance']:.6f} m close at t = {closest['time']:.1f} s "
              f"(eps1 = {eps1} m)")

    def log_traffic(self, server):
        """Logs every robot's traffic state (REST /api/v1/traffic), for a failure's report."""
        try:
            for robot, line in sorted(server.rest("/api/v1/traffic")["robots"].items()):
                self.log(f"traffic {robot}: {line}")
        except Exception as err:  # the report of a failure must not hide it
            self.log(f"traffic state not readable: {err}")

    def wait_for(self, predicate, timeout, what, interval=0.05):
        """Polls predicate() (a real condition) until true or the deadline."""
        deadline = time.monotonic() + timeout
        last = None
        while time.monotonic() < deadline:
            try:
                last = predicate()
            except Exception as err:  # noqa: BLE001 (the server may not answer yet)
                last = err
            if last is True or (last and not isinstance(last, Exception)):
                return last
            time.sleep(interval)  # poll interval of a condition, not a synchronisation
        raise TestFailure(f"timed out after {timeout} s waiting for {what} (last: {last!r})")

    # --- the dispatch core's journal ---------------------------------------------------
    def replay(self, dispatch_sim, db, run, *extra):
        """Stops every process, then `dispatch-sim replay --db DB --run N [extra]`; fails
        unless it exits 0 (the run matched). Returns its output."""
        for p in self.processes:
            p.stop()
        cmd = [dispatch_sim, "replay", "--db", db, "--run", str(run)] + list(extra)
        self.log("run " + " ".join(cmd))
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        lines = r.stdout.strip().splitlines()
        self.log(f"replay of run {run}: exit {r.returncode}: {lines[-1] if lines else ''} {r.stderr.strip()}")
        check(r.returncode == 0, f"run {run} did not replay (exit {r.returncode}): {r.stdout[-3000:]} {r.stderr}")
        return r.stdout

    # --- lifetime -----------------------------------------------------------------------
    def __exit__(self, exc_type, exc, tb):
        failed = exc_type is not None
        for p in reversed(self.processes):
            if isinstance(p, Server) and hasattr(p, "channel"):
                with contextlib.suppress(Exception):
                    p.close_channel()
            rc = p.stop()
            if not p.killed and rc != 0:
                # A crash, or an unclean exit on SIGTERM: a failure even if the checks passed.
                print(f"[e2e] {p.name} ended with status {rc}", flush=True)
                if not failed:
                    failed, exc_type = True, TestFailure
                    exc = TestFailure(f"{p.name} ended with status {rc}")
        if failed:
            if exc_type is TestFailure:
                print(f"\nFAILED: {exc}", flush=True)
            else:
                traceback.print_exception(exc_type, exc, tb)
            for p in self.processes:
                text = p.log_text().splitlines()
                print(f"---- {p.name} log ({len(text)} lines, last 120): {p.log_path}")
                print("\n".join(text[-120:]), flush=True)
            print(f"[e2e] logs and database kept in {self.work}", flush=True)
            sys.exit(1)
        self.log(f"{self.name}: passed")
        shutil.rmtree(self.work, ignore_errors=True)
        return False
