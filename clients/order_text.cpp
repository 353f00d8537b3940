#include "clients/order_text.h"

#include <chrono>
#include <cstdio>
#include <random>

namespace dispatch::clients {
namespace {

std::string Format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

template <typename List>
std::string Join(const List& items) {
  std::string s;
  for (const auto& item : items) s += (s.empty() ? "" : " ") + item;
  return s.empty() ? "-" : s;
}

std::string Stops(const v1::Order& o) {
  std::string s;
  for (const auto& p : o.picks()) s += (s.empty() ? "" : ", ") + p.point_name();
  return s + " -> " + o.drop().point_name();
}

void AppendBid(std::string& out, const v1::Bid& b) {
  if (b.queue_full()) {
    out += Format("  %-6s has a full queue (does not bid)\n", b.robot_id().c_str());
    return;
  }
  if (!b.reachable()) {
    out += Format("  %-6s cannot reach the order\n", b.robot_id().c_str());
    return;
  }
  if (!b.priced()) {
    out += Format("  %-6s B>=%8.2f  T_t=%7.2f T_d=%7.2f T_w=%6.2f  F>=%.4f (part of the route: could not win)\n",
                  b.robot_id().c_str(), b.total(), b.total_time(), b.travel_time(), b.work_time(),
                  b.traffic_flow());
    return;
  }
  out += Format("  %-6s B=%9.2f  T_t=%7.2f T_d=%7.2f T_w=%6.2f  F=%.4f x=%7.2f%s\n",
                b.robot_id().c_str(), b.total(), b.total_time(), b.travel_time(), b.work_time(),
                b.traffic_flow(), b.traffic_term(), b.winner() ? "  <- awarded" : "");
}

}  // namespace

const char* StateName(v1::OrderState state) {
  switch (state) {
    case v1::ORDER_STATE_ACCEPTED: return "accepted";
    case v1::ORDER_STATE_ASSIGNED: return "assigned";
    case v1::ORDER_STATE_IN_PROGRESS: return "in_progress";
    case v1::ORDER_STATE_COMPLETED: return "completed";
    case v1::ORDER_STATE_CANCELLED: return "cancelled";
    case v1::ORDER_STATE_FAILED: return "failed";
    default: return "unspecified";
  }
}

std::optional<v1::OrderState> ParseStateName(const std::string& name) {
  for (v1::OrderState s : {v1::ORDER_STATE_ACCEPTED, v1::ORDER_STATE_ASSIGNED,
                           v1::ORDER_STATE_IN_PROGRESS, v1::ORDER_STATE_COMPLETED,
                           v1::ORDER_STATE_CANCELLED, v1::ORDER_STATE_FAILED}) {
    if (name == StateName(s)) return s;
  }
  return std::nullopt;
}

bool IsTerminal(v1::OrderState state) {
  return state == v1::ORDER_STATE_COMPLETED || state == v1::ORDER_STATE_CANCELLED ||
         state == v1::ORDER_STATE_FAILED;
}

const char* StatusCodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return "OK";
    case grpc::StatusCode::CANCELLED: return "CANCELLED";
    case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS: return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED: return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED: return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE: return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED: return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL: return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
    default: return "UNKNOWN";
  }
}

std::string DescribeEvent(const v1::OrderEvent& e) {
  std::string s = Format("#%llu t=%.2f %s ", static_cast<unsigned long long>(e.event_id()),
                         e.time(), e.order_id().c_str());
  if (e.type() == v1::ORDER_EVENT_TYPE_STATE_CHANGED) {
    s += std::string(StateName(e.previous_state())) + " -> " + StateName(e.state());
  } else if (e.type() == v1::ORDER_EVENT_TYPE_CREATED) {
    s += std::string("created (") + StateName(e.state()) + ")";
  } else {
    s += StateName(e.state());
  }
  if (!e.robot_ids().empty()) s += " [" + Join(e.robot_ids()) + "]";
  if (!e.detail().empty()) {
    // Long details (e.g. a stored allocation explanation) are cut: `explain` shows those.
    constexpr std::size_t kMax = 120;
    s += " " + (e.detail().size() > kMax ? e.detail().substr(0, kMax) + "..." : e.detail());
  }
  return s;
}

std::string DescribeOrder(const v1::Order& o) {
  std::string s = Format("order %s (client %s): %s\n", o.id().c_str(), o.client_order_id().c_str(),
                         StateName(o.state()));
  s += "  stops     " + Stops(o) + "\n";
  s += Format("  formation %s, priority %d, work time %.1f s\n", o.formation() ? "yes" : "no",
              o.priority(), o.work_time());
  s += "  robots    " + Join(o.robot_ids()) + "\n";
  s += Format("  created   %.2f s", o.created_time());
  if (o.has_finished_time()) s += Format(", finished %.2f s", o.finished_time());
  s += "\n";
  if (!o.reason().empty()) s += "  reason    " + o.reason() + "\n";
  return s;
}

std::string OrderTableHeader() {
  return Format("%-10s %-24s %-12s %-14s %9s %9s %9s %9s", "order", "client id", "state", "robots",
                "created", "finished", "took (s)", "dist (m)");
}

std::string OrderTableRow(const v1::Order& o) {
  std::string finished = "-", took = "-";
  if (o.has_finished_time()) {
    finished = Format("%.2f", o.finished_time());
    took = Format("%.2f", o.finished_time() - o.created_time());
  }
  const std::string distance = o.state() == v1::ORDER_STATE_COMPLETED ? Format("%.1f", o.distance()) : "-";
  return Format("%-10s %-24s %-12s %-14s %9.2f %9s %9s %9s", o.id().c_str(),
                o.client_order_id().c_str(), StateName(o.state()), Join(o.robot_ids()).c_str(),
                o.created_time(), finished.c_str(), took.c_str(), distance.c_str());
}

std::string DescribeExplanation(const v1::AllocationExplanation& ex) {
  std::string s = Format("order %s, strategy %s (alpha %.2f, beta %.2f, zeta %.1f) at t=%.2f\n",
                         ex.order_id().c_str(), ex.strategy().c_str(), ex.alpha(), ex.beta(),
                         ex.zeta(), ex.time());
  s += "awarded to " + Join(ex.winner_ids()) + ": " + ex.reason() + "\n";
  s += "bids (B = alpha T_t + beta T_d + zeta F):\n";
  for (const auto& b : ex.bids()) AppendBid(s, b);
  if (!ex.companion_bids().empty()) {
    s += "costs to reach the first pick (formation companions):\n";
    for (const auto& b : ex.companion_bids()) AppendBid(s, b);
  }
  return s;
}

std::string NewClientId() {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  std::random_device rd;
  return Format("wmsctl-%lld-%04x", static_cast<long long>(ms), rd() & 0xffffu);
}

}  // namespace dispatch::clients
