// WatchHub: fans journal events (storage::OrderEvent, already committed) out to the open
// WatchOrders streams. The dispatcher loop publishes; streams subscribe and unsubscribe from
// gRPC threads. Sinks must not block (they queue and write asynchronously).
// Thread-safe: one mutex guards the subscriber list; sinks are called without it held.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "storage/store.h"

namespace dispatch::server {

class OrderEventSink {
 public:
  virtual ~OrderEventSink() = default;
  virtual void OnEvent(const storage::OrderEvent& event) = 0;
  // The server is shutting down: end the stream.
  virtual void OnClose() = 0;
};

class WatchHub {
 public:
  std::uint64_t Subscribe(std::shared_ptr<OrderEventSink> sink);
  void Unsubscribe(std::uint64_t id);
  void Publish(const storage::OrderEvent& event);
  // Calls OnClose on every sink and forgets them; later subscriptions are closed at once.
  void CloseAll();

 private:
  std::vector<std::shared_ptr<OrderEventSink>> Sinks();

  std::mutex mu_;  // guards sinks_, next_id_, closed_
  std::unordered_map<std::uint64_t, std::shared_ptr<OrderEventSink>> sinks_;
  std::uint64_t next_id_ = 1;
  bool closed_ = false;
};

}  // namespace dispatch::server
