// One robot's FleetService.Connect stream in fleet-sim, on gRPC's callback (reactor) API so
// that hundreds of robots share gRPC's few threads instead of a thread each.
//
// Received server messages are queued for the owner (TakeReceived), stamped with the time
// they arrived (for latency figures: the owner polls at its own tick); writes are queued and
// sent one at a time (gRPC allows one outstanding write per stream). The stream ends when
// the server ends it, on a network error, or on Close(); then done() is true and status()
// says why. A reactor is used for one call only: reconnecting means a new RobotStream.
//
// Thread-safe: gRPC's threads call the On* callbacks, the owner calls the rest.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "warehouse/dispatch/v1/fleet.grpc.pb.h"

namespace dispatch::clients {

namespace v1 = ::warehouse::dispatch::v1;

class RobotStream final : public grpc::ClientBidiReactor<v1::RobotMessage, v1::ServerMessage> {
 public:
  // Starts the call and sends `hello` first. `delay`: every outgoing message waits this long
  // before it is sent (the "delayed messages" fault); zero sends at once. `token`: the
  // bearer token the call carries ("" none).
  RobotStream(v1::FleetService::Stub& stub, const v1::RobotMessage& hello,
              std::chrono::milliseconds delay = std::chrono::milliseconds(0), const std::string& token = "");
  ~RobotStream() override;

  void Send(const v1::RobotMessage& message);
  // Forgets the messages queued and not yet being written (a robot that went silent).
  void DiscardPending();
  // Sends the messages whose delay has passed (call it from the owner's loop).
  void Pump();
  struct Received {
    v1::ServerMessage message;
    std::chrono::steady_clock::time_point time;  // when gRPC handed it over
  };
  std::vector<Received> TakeReceived();
  // Ends the call from the client side (the "dropped stream" fault and shutdown).
  void Close();
  bool done() const;
  grpc::Status status() const;
  // Blocks until the call has ended (OnDone ran); required before destruction.
  void WaitDone();

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnDone(const grpc::Status& status) override;

 private:
  // Starts the next due write if none is in flight (StartWrite outside the lock).
  void MaybeStartWrite();

  grpc::ClientContext context_;
  std::chrono::milliseconds delay_;
  v1::ServerMessage incoming_;
  mutable std::mutex mu_;
  std::condition_variable done_cv_;
  struct Pending {
    v1::RobotMessage message;
    std::chrono::steady_clock::time_point due;
  };
  std::deque<Pending> outgoing_;
  v1::RobotMessage writing_;
  bool write_in_flight_ = false;
  bool closed_ = false;
  bool done_ = false;
  grpc::Status status_;
  std::vector<Received> received_;
};

}  // namespace dispatch::clients
