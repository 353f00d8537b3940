#include "server/watch_hub.h"

namespace dispatch::server {

std::uint64_t WatchHub::Subscribe(std::shared_ptr<OrderEventSink> sink) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!closed_) {
      const std::uint64_t id = next_id_++;
      sinks_.emplace(id, std::move(sink));
      return id;
    }
  }
  sink->OnClose();
  return 0;
}

void WatchHub::Unsubscribe(std::uint64_t id) {
  std::lock_guard<std::mutex> lock(mu_);
  sinks_.erase(id);
}

std::vector<std::shared_ptr<OrderEventSink>> WatchHub::Sinks() {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<std::shared_ptr<OrderEventSink>> out;
  out.reserve(sinks_.size());
  for (auto& [id, sink] : sinks_) out.push_back(sink);
  return out;
}

void WatchHub::Publish(const storage::OrderEvent& event) {
  for (auto& sink : Sinks()) sink->OnEvent(event);
}

void WatchHub::CloseAll() {
  std::vector<std::shared_ptr<OrderEventSink>> sinks;
  {
    std::lock_guard<std::mutex> lock(mu_);
    closed_ = true;
    for (auto& [id, sink] : sinks_) sinks.push_back(sink);
    sinks_.clear();
  }
  for (auto& sink : sinks) sink->OnClose();
}

}  // namespace dispatch::server
