// Test support for the server tests: a temporary directory, an in-process dispatchd on
// 127.0.0.1 with ephemeral ports, a WatchOrders follower and a minimal fake robot on a real
// gRPC channel. Everything waits on stream messages with generous timeouts, never on sleeps.
#pragma once

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>

#include "server/config.h"
#include "server/server.h"
#include "warehouse/dispatch/v1/fleet.grpc.pb.h"
#include "warehouse/dispatch/v1/map.grpc.pb.h"
#include "warehouse/dispatch/v1/orders.grpc.pb.h"

namespace dispatch::server::testing {

namespace pb = ::warehouse::dispatch::v1;
using namespace std::chrono_literals;
inline constexpr auto kTimeout = 10s;

class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("dispatch_server_test_" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// A queue one thread fills and a test thread pops with a timeout.
template <class T>
class BlockingQueue {
 public:
  void Push(T value) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      items_.push_back(std::move(value));
    }
    cv_.notify_all();
  }
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      closed_ = true;
    }
    cv_.notify_all();
  }
  // nullopt on timeout or when closed and empty.
  std::optional<T> Pop(std::chrono::milliseconds timeout = kTimeout) {
    std::unique_lock<std::mutex> lock(mu_);
    if (!cv_.wait_for(lock, timeout, [&] { return !items_.empty() || closed_; })) return std::nullopt;
    if (items_.empty()) return std::nullopt;
    T v = std::move(items_.front());
    items_.pop_front();
    return v;
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<T> items_;
  bool closed_ = false;
};

inline ServerConfig TestConfig(const std::string& db) {
  ServerConfig c;
  c.bind = "127.0.0.1";
  c.grpc_port = 0;
  c.http_port = 0;
  c.db = db;
  c.map = "chu2024";
  c.log_level = "warn";
  return c;
}

inline std::shared_ptr<grpc::Channel> ChannelTo(const DispatchServer& server) {
  return grpc::CreateChannel("127.0.0.1:" + std::to_string(server.ports().grpc),
                             grpc::InsecureChannelCredentials());
}

inline grpc::ClientContext* WithDeadline(grpc::ClientContext& ctx) {
  ctx.set_deadline(std::chrono::system_clock::now() + kTimeout);
  return &ctx;
}

inline pb::SubmitOrderRequest OrderRequest(const std::string& client_id,
                                           const std::vector<std::string>& picks,
                                           const std::string& drop, bool formation = false) {
  pb::SubmitOrderRequest r;
  r.set_client_order_id(client_id);
  for (const auto& p : picks) r.add_picks()->set_point_name(p);
  r.mutable_drop()->set_point_name(drop);
  r.set_formation(formation);
  return r;
}

// Follows WatchOrders on a reader thread.
class OrderWatcher {
 public:
  explicit OrderWatcher(std::shared_ptr<grpc::Channel> channel,
                        pb::WatchOrdersRequest request = pb::WatchOrdersRequest())
      : stub_(pb::OrderService::NewStub(channel)) {
    reader_ = stub_->WatchOrders(&ctx_, request);
    thread_ = std::thread([this] {
      pb::OrderEvent e;
      while (reader_->Read(&e)) events_.Push(e);
      events_.Close();
    });
  }
  ~OrderWatcher() {
    ctx_.TryCancel();
    thread_.join();
    reader_->Finish();
  }
  // The next event of `order_id` reaching `state` (events of other orders are skipped).
  std::optional<pb::OrderEvent> WaitForState(const std::string& order_id, pb::OrderState state) {
    const auto deadline = std::chrono::steady_clock::now() + kTimeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      auto e = events_.Pop(left);
      if (!e) return std::nullopt;
      if (e->order_id() == order_id && e->state() == state &&
          e->type() != pb::ORDER_EVENT_TYPE_PROGRESS) {
        return e;
      }
    }
  }
  std::optional<pb::OrderEvent> Next() { return events_.Pop(); }

 private:
  std::unique_ptr<pb::OrderService::Stub> stub_;
  grpc::ClientContext ctx_;
  std::unique_ptr<grpc::ClientReader<pb::OrderEvent>> reader_;
  BlockingQueue<pb::OrderEvent> events_;
  std::thread thread_;
};

// A robot that connects, says Hello, and can follow its plan by reporting each waypoint,
// picks and drops at once (the server checks progress, not timing).
class FakeRobot {
 public:
  FakeRobot(std::shared_ptr<grpc::Channel> channel, std::string id)
      : stub_(pb::FleetService::NewStub(channel)), id_(std::move(id)) {}
  ~FakeRobot() { Disconnect(); }

  // Opens the stream and sends Hello at (x, y).
  void Connect(double x, double y, std::uint64_t last_acked = 0) {
    ctx_ = std::make_unique<grpc::ClientContext>();
    stream_ = stub_->Connect(ctx_.get());
    pb::RobotMessage hello;
    hello.mutable_hello()->set_robot_id(id_);
    hello.mutable_hello()->mutable_pose()->set_x(x);
    hello.mutable_hello()->mutable_pose()->set_y(y);
    hello.mutable_hello()->set_last_acked_sequence(last_acked);
    ASSERT_TRUE(stream_->Write(hello));
    reader_ = std::thread([this] {
      pb::ServerMessage m;
      while (stream_->Read(&m)) messages_.Push(m);
      messages_.Close();
    });
  }
  // Sends raw messages (for bad-input tests).
  bool Write(const pb::RobotMessage& m) { return stream_->Write(m); }
  // Half-closes, waits for the server to end the stream, returns its status.
  grpc::Status Finish() {
    stream_->WritesDone();
    return AwaitEnd();
  }
  // Waits for the server to end the stream (without half-closing) and returns its status.
  grpc::Status AwaitEnd() {
    if (reader_.joinable()) reader_.join();
    grpc::Status status = stream_->Finish();
    stream_.reset();
    return status;
  }
  void Disconnect() {
    if (!stream_) return;
    ctx_->TryCancel();
    AwaitEnd();
  }

  // The next message with the given body (others are skipped but remembered in `seen`).
  std::optional<pb::ServerMessage> WaitFor(pb::ServerMessage::BodyCase body,
                                           std::chrono::milliseconds timeout = kTimeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      auto m = messages_.Pop(left);
      if (!m) return std::nullopt;
      last_sequence_ = m->sequence();
      if (m->body_case() == body) return m;
    }
  }

  // Reports every waypoint of `waypoints` in order, with picked/dropped task events, each only
  // once the release horizon covers it: `released_up_to` at first, then raised by the Grant and
  // Resume messages the server sends (traffic control). A state report goes with every
  // waypoint. Returns the Grants received, or -1 when no release came in time.
  int Follow(const google::protobuf::RepeatedPtrField<pb::TimedWaypoint>& waypoints,
             std::uint64_t released_up_to) {
    int grants = 0;
    const auto deadline = std::chrono::steady_clock::now() + kTimeout;
    for (const auto& w : waypoints) {
      while (w.sequence() > released_up_to) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) return -1;
        auto m = messages_.Pop(left);
        if (!m) return -1;
        last_sequence_ = m->sequence();
        if (m->has_grant()) {
          ++grants;
          released_up_to = std::max<std::uint64_t>(released_up_to, m->grant().release_up_to_sequence());
        } else if (m->has_resume()) {
          released_up_to = std::max<std::uint64_t>(released_up_to, m->resume().release_up_to_sequence());
        }
      }
      pb::RobotMessage report;
      auto* r = report.mutable_state_report();
      r->mutable_pose()->set_x(w.x());
      r->mutable_pose()->set_y(w.y());
      r->set_state(pb::ROBOT_STATE_MOVING);
      r->set_last_waypoint_sequence(w.sequence());
      pb::RobotMessage reached;
      reached.mutable_waypoint_reached()->set_sequence(w.sequence());
      reached.mutable_waypoint_reached()->mutable_pose()->set_x(w.x());
      reached.mutable_waypoint_reached()->mutable_pose()->set_y(w.y());
      if (!stream_->Write(reached)) return -1;
      if (w.action() == pb::WAYPOINT_ACTION_PICK || w.action() == pb::WAYPOINT_ACTION_DROP) {
        pb::RobotMessage event;
        auto* e = event.mutable_task_event();
        e->set_order_id(w.order_id());
        e->set_type(w.action() == pb::WAYPOINT_ACTION_PICK ? pb::TASK_EVENT_TYPE_PICKED
                                                           : pb::TASK_EVENT_TYPE_DROPPED);
        e->set_point_id(w.point_id());
        e->set_waypoint_sequence(w.sequence());
        if (!stream_->Write(event)) return -1;
      }
      if (!stream_->Write(report)) return -1;
    }
    return grants;
  }
  void Heartbeat() {
    pb::RobotMessage m;
    m.mutable_heartbeat()->set_robot_unix_ms(0);
    stream_->Write(m);
  }
  std::uint64_t last_sequence() const { return last_sequence_; }

 private:
  std::unique_ptr<pb::FleetService::Stub> stub_;
  std::string id_;
  std::unique_ptr<grpc::ClientContext> ctx_;
  std::unique_ptr<grpc::ClientReaderWriter<pb::RobotMessage, pb::ServerMessage>> stream_;
  BlockingQueue<pb::ServerMessage> messages_;
  std::thread reader_;
  std::uint64_t last_sequence_ = 0;
};

}  // namespace dispatch::server::testing
