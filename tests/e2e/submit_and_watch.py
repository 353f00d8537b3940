#!/usr/bin/env python3
"""A second-language client (issue 5): submits one order through the gRPC API with stubs
generated from proto/ by protoc's Python and gRPC-Python plugins, and watches it complete.

    submit_and_watch.py STUBS_DIR HOST:PORT
Exit status 0 when the order completes, 1 otherwise."""
import sys
import uuid

sys.path.insert(0, sys.argv[1])
import grpc  # noqa: E402
from warehouse.dispatch.v1 import common_pb2, orders_pb2, orders_pb2_grpc  # noqa: E402


def main() -> int:
    channel = grpc.insecure_channel(sys.argv[2])
    grpc.channel_ready_future(channel).result(timeout=30)
    orders = orders_pb2_grpc.OrderServiceStub(channel)
    # Seed Table 1, task 4: three picks, then the drop (coordinates snap to map points).
    request = orders_pb2.SubmitOrderRequest(
        client_order_id="python-" + uuid.uuid4().hex,
        picks=[orders_pb2.StopSpec(position=common_pb2.Vec2(x=x, y=y))
               for x, y in ((29, 13), (30.5, 13), (29, 10.5))],
        drop=orders_pb2.StopSpec(position=common_pb2.Vec2(x=32.25, y=5)))
    response = orders.SubmitOrder(request, timeout=10)
    order_id = response.order.id
    print(f"submitted {request.client_order_id} as {order_id}: "
          f"{common_pb2.OrderState.Name(response.order.state)}")
    # A bad order gets a clear status, not a crash.
    try:
        orders.SubmitOrder(orders_pb2.SubmitOrderRequest(client_order_id="python-bad"), timeout=10)
        print("an order without picks was accepted")
        return 1
    except grpc.RpcError as e:
        print(f"empty order rejected: {e.code().name}: {e.details()}")
        if e.code() != grpc.StatusCode.INVALID_ARGUMENT:
            return 1
    watch = orders.WatchOrders(
        orders_pb2.WatchOrdersRequest(order_ids=[order_id], from_start=True), timeout=300)
    for event in watch:
        state = common_pb2.OrderState.Name(event.state)
        print(f"  event {event.event_id}: {state} {list(event.robot_ids)} {event.detail[:100]}")
        if event.state == common_pb2.ORDER_STATE_COMPLETED:
            watch.cancel()
            final = orders.GetOrder(orders_pb2.GetOrderRequest(order_id=order_id), timeout=10)
            print(f"completed by {list(final.robot_ids)} at t={final.finished_time:.2f} s")
            return 0
        if event.state in (common_pb2.ORDER_STATE_CANCELLED, common_pb2.ORDER_STATE_FAILED):
            print(f"order ended {state}: {event.detail}")
            return 1
    print("the watch ended before the order completed")
    return 1


if __name__ == "__main__":
    sys.exit(main())
