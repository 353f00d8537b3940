#!/usr/bin/env python3
"""Raw garbage on dispatchd's ports (issue 6 §3): with good orders stored, connections to the
gRPC port and to the HTTP port send what is not their protocol: random bytes, a TLS
ClientHello, an HTTP/1.1 request to the gRPC port, an HTTP/2 connection preface (what a gRPC
client sends first) followed by junk to both, 100 kB of zeros, and a connection that sends
nothing (HTTP port only, see PAYLOADS). While all of them are open, both services must answer
(/healthz, and ListOrders on the gRPC port) within SERVE_DEADLINE; each garbage connection
must be answered (the HTTP port: a 4xx with a JSON body, if anything) or closed by the server
within GIVE_UP_DEADLINE; then the same again (nothing left over from the first round).
Afterwards the server must still serve (/healthz, a good order accepted) and every order must
read back as acknowledged, also after a restart on the same database.

    garbage_bytes.py --stubs DIR --dispatchd BIN --fleet-sim BIN --wmsctl BIN --scenarios DIR
"""
import random
import socket
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, sys.argv[sys.argv.index("--stubs") + 1])
from bad_input_common import (Book, Cases, check_intact, check_serving, http_call,  # noqa: E402
                              restart, submit_good)
from e2e_harness import Harness, TestFailure, check, common_arguments  # noqa: E402
from warehouse.dispatch.v1 import orders_pb2  # noqa: E402

SERVER_ARGS = ["--time-scale", "10"]
SERVE_DEADLINE = 2.0  # wall seconds for /healthz and ListOrders while the garbage is open
GIVE_UP_DEADLINE = 15.0  # a garbage connection must be answered or closed by then

_rng = random.Random(6)
# A TLS 1.2 ClientHello for "example.ulfheim.net" (the ulfheim.net walk-through), random fixed.
TLS_CLIENT_HELLO = (
    bytes.fromhex("16030100a5010000a10303") + bytes(_rng.getrandbits(8) for _ in range(32))
    + bytes.fromhex("000020cca8cca9c02fc030c02bc02cc013c009c014c00a009c009d002f0035c012000a"
                    "010000580000001800160000136578616d706c652e756c666865696d2e6e6574000500"
                    "050100000000000a000a0008001d001700180019000b00020100000d00120010040104"
                    "0305010503060106030201020300120000ff01000100"))
H2_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n"
BOTH = ("gRPC", "HTTP")
PAYLOADS = [  # (what, bytes, the ports it is garbage for)
    ("random bytes", bytes(_rng.getrandbits(8) for _ in range(4096)), BOTH),
    ("a TLS ClientHello", TLS_CLIENT_HELLO, BOTH),
    ("an HTTP/1.1 request", b"GET /healthz HTTP/1.1\r\nHost: test\r\n\r\n", ("gRPC",)),
    ("an HTTP/2 preface and junk", H2_PREFACE + bytes(_rng.getrandbits(8) for _ in range(512)),
     BOTH),
    ("100 kB of zeros", bytes(100_000), BOTH),
    # gRPC waits for a silent client's preface as long as its handshake timeout (120 s,
    # GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS) without blocking anyone: HTTP port only.
    ("nothing (half-open)", b"", ("HTTP",)),
]


class Garbage:
    """One connection that sent a payload; a thread records how the server dealt with it."""

    def __init__(self, port, port_name, what, payload):
        self.what = f"{what} to the {port_name} port"
        self.http = port_name == "HTTP"
        self.payload = payload
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=GIVE_UP_DEADLINE)
        self.answer = b""
        self.outcome = None  # "closed" / "answered" / "still open" / an error
        self.t0 = time.monotonic()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        try:
            if self.payload:
                self.sock.sendall(self.payload)
            while True:
                part = self.sock.recv(65536)
                if not part:
                    self.outcome = "closed"
                    return
                self.answer += part
                head, _, body = self.answer.partition(b"\r\n\r\n")
                if self.http and body:  # the HTTP port may keep the connection alive
                    self.outcome = "answered"
                    return
        except socket.timeout:
            self.outcome = "still open"
        except OSError as err:  # a reset instead of a close: also giving up
            reset = isinstance(err, ConnectionResetError)
            self.outcome = "closed" if self.answer or reset else repr(err)
        finally:
            self.took = time.monotonic() - self.t0

    def check(self):
        self.thread.join(GIVE_UP_DEADLINE + 5)
        self.sock.close()
        check(self.outcome in ("closed", "answered"),
              f"{self.what}: {self.outcome} after {self.took:.1f} s (want an answer or a close "
              f"within {GIVE_UP_DEADLINE} s)")
        if self.http and self.answer:
            head, _, body = self.answer.partition(b"\r\n\r\n")
            check(head.startswith(b"HTTP/1.1 4"),
                  f"{self.what}: answered {head[:40]!r}, want a 4xx")
            check(b"application/json" in head and body.startswith(b"{\"error\""),
                  f"{self.what}: the 4xx is not a JSON error: {self.answer[:200]!r}")
        print(f"[e2e] {self.what}: {self.outcome} after {self.took:.2f} s {self.answer[:40]!r}",
              flush=True)


def both_serve(server, what):
    t0 = time.monotonic()
    status, _, data = http_call(server, "GET", "/healthz", timeout=SERVE_DEADLINE)
    check(status == 200, f"/healthz {what}: HTTP {status} {data[:80]!r}")
    server.orders.ListOrders(orders_pb2.ListOrdersRequest(page_size=1), timeout=SERVE_DEADLINE)
    took = time.monotonic() - t0
    check(took <= SERVE_DEADLINE, f"/healthz and ListOrders {what} took {took:.2f} s")


def garbage_on_ports(server):
    conns = [Garbage(port, name, what, payload)
             for port, name in ((server.grpc_port, "gRPC"), (server.http_port, "HTTP"))
             for what, payload, ports in PAYLOADS if name in ports]
    both_serve(server, f"while {len(conns)} garbage connections are open")
    failures = []
    for c in conns:
        try:
            c.check()
        except TestFailure as err:
            failures.append(str(err))
    check(not failures, "; ".join(failures))
    both_serve(server, "after the garbage")


def main():
    args = common_arguments(__doc__).parse_args()
    with Harness(args, "garbage-bytes") as h:
        server = h.start_server(SERVER_ARGS)
        book = Book()
        submit_good(h, server, book, "garbage")
        cases = Cases(h, server)
        cases.run("garbage on the gRPC and HTTP ports", garbage_on_ports, server)
        cases.run("the same again (nothing left over from the first round)", garbage_on_ports,
                  server)

        check_serving(h, server, book, "garbage")
        check_intact(h, server, book, "after the garbage")
        server = restart(h, server, SERVER_ARGS)
        check_intact(h, server, book, "after a restart on the same database")
        check_serving(h, server, book, "garbage-restarted")
        cases.finish()


if __name__ == "__main__":
    main()
