#!/usr/bin/env python3
"""Writes the seed corpora of fuzz/corpus/ (run from the repository root; protoc encodes the
binary ones from text format). The fuzzers grow the corpora from these; what they keep is
committed beside them.

    python3 fuzz/seeds.py
"""
import os
import struct
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")
PROTO = os.path.join(ROOT, "proto")


def write(harness, name, data):
    folder = os.path.join(CORPUS, harness)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def encode(message, text, proto):
    return subprocess.run(["protoc", "-I", PROTO, f"--encode=warehouse.dispatch.v1.{message}",
                           f"warehouse/dispatch/v1/{proto}"], input=text.encode(), capture_output=True,
                          check=True, cwd=ROOT).stdout


TINY_MAP = """{
  "format": "warehouse-map", "version": 1, "name": "tiny",
  "floor": {"min": [0, 0], "max": [10, 10]},
  "zones": [{"id": "z", "polygon": [[0, 0], [10, 0], [10, 10], [0, 10]]}],
  "points": [{"id": "p", "x": 1, "y": 1, "kind": "pick"},
             {"id": "q", "x": 4, "y": 5, "kind": "drop"},
             {"id": "r", "x": 4, "y": 1, "kind": "lane"}],
  "paths": [{"from": "p", "to": "q", "bidirectional": true},
            {"from": "p", "to": "r"}, {"from": "r", "to": "q", "max_speed": 0.5}]
}
"""
write("map_json", "tiny.json", TINY_MAP)
write("map_json", "not-an-object.json", "[1, 2, {\"a\": null}]")
write("movingai_map", "tiny.map", "type octile\nheight 3\nwidth 5\nmap\n.....\n.@@..\n.....\n")
write("movingai_map", "stations.map", "type octile\nheight 2\nwidth 3\nmap\n.S.\nE@.\n")
with open(os.path.join(ROOT, "..", "shared", "scenarios", "chu2024-table1.csv"), "rb") as f:
    write("order_file", "table1.csv", b"\x00" + f.read())
write("order_file", "orders.json", "\x01" + """[{"picks": ["K3-2-3N", {"x": 19, "y": 17}], "drop": "D-B2",
  "formation": true, "priority": 2, "work_time": 5, "release_time": 3}]""")
ORDER = """{"client_order_id": "wms-1", "picks": [{"point_name": "K3-2-3N"}, {"position": {"x": 19, "y": 17}}],
 "drop": {"point_name": "D-B2"}, "priority": 1, "formation": false, "work_time": 5.0, "release_time": 2.5}"""
write("rest_body", "order.json", ORDER)
write("rest_body", "formation.json", ORDER.replace('"formation": false', '"formation": true'))

submit = encode("SubmitOrderRequest", 'client_order_id: "g-1" picks { point_name: "K3-2-3N" } '
                'drop { point_name: "D-B2" } work_time: 5', "orders.proto")
write("grpc_requests", "submit.bin", b"\x00" + submit)
write("grpc_requests", "list.bin", b"\x01" + encode("ListOrdersRequest", "states: ORDER_STATE_COMPLETED page_size: 3",
                                                   "orders.proto"))
hello = encode("RobotMessage", 'hello { robot_id: "R9" pose { x: 30.625 y: 24.75 } }', "fleet.proto")
write("grpc_requests", "hello.bin", b"\x02" + hello)
write("grpc_requests", "cancel.bin", b"\x03" + encode("CancelOrderRequest", 'order_id: "ord-1" reason: "x"',
                                                     "orders.proto"))


def stream(*messages):
    return b"".join(struct.pack("<H", len(m)) + m for m in messages)


def robot(text):
    return encode("RobotMessage", text, "fleet.proto")


write("robot_stream", "reports.bin", stream(
    robot('state_report { pose { x: 1.0 y: 1.0 } last_waypoint_sequence: 1 battery: 0.5 }'),
    robot('waypoint_reached { sequence: 2 pose { x: 1.0 y: 1.0 } }'),
    robot('task_event { order_id: "ord-1" type: TASK_EVENT_TYPE_PICKED }'),
    robot('task_event { order_id: "ord-1" type: TASK_EVENT_TYPE_DROPPED }'),
    robot('heartbeat { robot_unix_ms: 5 }')))
write("robot_stream", "hello-then-reports.bin", stream(
    robot('hello { robot_id: "R3" pose { x: 30.625 y: 24.75 } }'),
    robot('state_report { pose { x: 30.6 y: 24.7 } }'),
    robot('waypoint_reached { sequence: 1 }')))
# rest_paths: method byte (0 GET, 1 POST, 2 DELETE), request target, newline, body.
REST = [
    ("get-orders", 0, "/api/v1/orders?state=in_progress&finished=5", ""),
    ("get-orders-enum", 0, "/api/v1/orders?state=ORDER_STATE_FAILED&finished=-1", ""),
    ("get-order", 0, "/api/v1/orders/ord-000001", ""),
    ("get-order-escaped", 0, "/api/v1/orders/%00%ff%2F..%2f", ""),
    ("post-order", 1, "/api/v1/orders", ORDER),
    ("cancel", 2, "/api/v1/orders/ord-000001?reason=operator%20asked", ""),
    ("robot", 0, "/api/v1/robots/R1", ""),
    ("robots", 0, "/api/v1/robots", ""),
    ("pause", 1, "/api/v1/robots/R1/pause", ""),
    ("out-of-service", 1, "/api/v1/robots/R1/out-of-service", "{}"),
    ("send", 1, "/api/v1/robots/R1/send", '{"station": "P5"}'),
    ("clear", 1, "/api/v1/robots/R%201/clear", ""),
    ("intersections", 0, "/api/v1/intersections?active=1", ""),
    ("zones", 0, "/api/v1/zones", ""),
    ("status", 0, "/api/v1/status", ""),
    ("traffic", 0, "/api/v1/traffic", ""),
    ("session", 0, "/api/v1/session", ""),
    ("map", 0, "/api/v1/map", ""),
    ("readyz", 0, "/readyz", ""),
    ("metrics", 0, "/metrics", ""),
    ("web", 0, "/../../etc/passwd", ""),
    ("app", 0, "/app.js?x=%zz", ""),
]
for name, method, target, body in REST:
    write("rest_paths", name, bytes([method]) + (target + "\n" + body).encode())
print("seed corpora written to", CORPUS)
