#include "server/rest_handlers.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>

#include "engine/common/text.h"
#include "engine/io/map_json.h"
#include "server/dispatcher.h"
#include "server/metrics.h"
#include "server/proto_convert.h"
#include "server/rest_views.h"

namespace dispatch::server {

int HttpStatus(StatusCode code) {
  switch (code) {
    case StatusCode::kOk: return 200;
    case StatusCode::kInvalidArgument: return 400;
    case StatusCode::kNotFound: return 404;
    case StatusCode::kAlreadyExists: return 409;
    case StatusCode::kFailedPrecondition: return 409;
    case StatusCode::kUnavailable: return 503;
    case StatusCode::kInternal: return 500;
    case StatusCode::kUnauthenticated: return 401;
    case StatusCode::kPermissionDenied: return 403;
    case StatusCode::kDeadlineExceeded: return 408;
  }
  return 500;
}

namespace {

RestReply Json(int status, const google::protobuf::Message& body) { return {status, ToJson(body)}; }
RestReply Error(int status, const std::string& message) { return {status, ErrorJson(message)}; }
RestReply Error(const ServiceStatus& s) { return Error(HttpStatus(s.code), s.message); }

// A state filter: the lower-case name (in_progress) or the enum's (ORDER_STATE_IN_PROGRESS).
std::optional<engine::OrderState> StateFilter(const std::string& name) {
  if (auto state = engine::ParseOrderState(name)) return state;
  pb::OrderState value = pb::ORDER_STATE_UNSPECIFIED;
  if (!pb::OrderState_Parse(name, &value)) return std::nullopt;
  return OrderStateFromProto(value);
}

}  // namespace

RestHandlers::RestHandlers(Dispatcher& dispatcher, ServiceMetrics* metrics,
                           std::function<std::optional<std::string>()> store_health)
    : dispatcher_(dispatcher),
      metrics_(metrics),
      store_health_(std::move(store_health)),
      map_json_(std::make_shared<const std::string>(engine::WriteMapJson(dispatcher.map()))) {}

std::string RestHandlers::ErrorBody(const std::string& message) { return ErrorJson(message); }

RestReply RestHandlers::Session(const Principal& who, bool tokens_required) {
  pb::Session out;
  out.set_name(who.name);
  out.set_role(RoleName(who.role));
  out.set_robot_commands(Permits(who.role, Access::kRobotCommand));
  out.set_tokens_required(tokens_required);
  return Json(200, out);
}

RestReply RestHandlers::Map() const { return {200, *map_json_}; }

RestReply RestHandlers::Zones() const {
  pb::ZoneList out;
  ZonesToProto(*dispatcher_.snapshot(), dispatcher_.map(), &out);
  return Json(200, out);
}

RestReply RestHandlers::Intersections(const std::optional<std::string>& active) const {
  bool only_active = false;
  if (active) {
    if (*active == "1" || *active == "true") {
      only_active = true;
    } else if (*active != "0" && *active != "false") {
      return Error(400, "active must be 1, true, 0 or false");
    }
  }
  pb::IntersectionList out;
  IntersectionsToProto(*dispatcher_.snapshot(), dispatcher_.map(), only_active, &out);
  return Json(200, out);
}

RestReply RestHandlers::Metrics() const {
  if (!metrics_) return Error(404, "metrics are not enabled");
  return {200, metrics_->Render(*dispatcher_.snapshot()), "text/plain; version=0.0.4; charset=utf-8"};
}

RestReply RestHandlers::Health() const {
  pb::Health out;
  out.set_status("ok");
  return Json(200, out);
}

RestReply RestHandlers::Ready() const {
  auto snap = dispatcher_.snapshot();
  if (!snap) return Error(503, "dispatcher not ready");
  pb::Readiness out;
  out.set_snapshot(snap->version);
  if (auto why = store_health_ ? store_health_() : std::nullopt) {
    out.set_ready(false);
    out.set_reason(*why);
    return Json(503, out);
  }
  out.set_ready(true);
  return Json(200, out);
}

RestReply RestHandlers::Status() const {
  pb::ServiceState out;
  StatusToProto(*dispatcher_.snapshot(), &out);
  return Json(200, out);
}

RestReply RestHandlers::Traffic() {
  using Lines = std::vector<std::pair<std::string, std::string>>;
  Lines lines = dispatcher_.Call<Lines>([this](std::function<void(Lines)> done) {
    done(dispatcher_.TrafficLines());
  });
  pb::TrafficReport out;
  for (auto& [id, line] : lines) (*out.mutable_robots())[id] = std::move(line);
  return Json(200, out);
}

RestReply RestHandlers::Robots() const {
  auto snap = dispatcher_.snapshot();
  pb::RobotList out;
  for (const auto& [id, r] : snap->robots) RobotToProto(r, dispatcher_.map(), out.add_robots());
  return Json(200, out);
}

RestReply RestHandlers::Robot(const std::string& id) const {
  auto snap = dispatcher_.snapshot();
  auto it = snap->robots.find(id);
  if (it == snap->robots.end()) return Error(404, "no robot with id '" + id + "'");
  pb::RobotInfo out;
  RobotToProto(it->second, dispatcher_.map(), &out);
  return Json(200, out);
}

RestReply RestHandlers::CommandRobot(engine::RobotCommandKind kind, const std::string& id, const std::string& actor) {
  return Command(kind, id, "", actor);
}

RestReply RestHandlers::SendRobot(const std::string& id, const std::string& body, const std::string& actor) {
  pb::SendRobotRequest parsed;
  if (auto read = FromJson(body, &parsed); !read.ok()) return Error(FromEngineError(read.error()));
  if (!parsed.robot_id().empty() && parsed.robot_id() != id) {
    return Error(400, "robot_id in the body ('" + engine::Clipped(parsed.robot_id()) + "') is not the path's ('" +
                          engine::Clipped(id) + "')");
  }
  if (parsed.station().empty()) return Error(400, "station is required");
  return Command(engine::RobotCommandKind::kSend, id, parsed.station(), actor);
}

RestReply RestHandlers::Command(engine::RobotCommandKind kind, const std::string& id, const std::string& station,
                                const std::string& actor) {
  const ServiceStatus status = dispatcher_.Call<ServiceStatus>([this, kind, id, station, actor](
                                                                   std::function<void(ServiceStatus)> done) {
    dispatcher_.CommandRobot(kind, id, station, actor, std::move(done));
  });
  if (!status.ok()) return Error(status);
  return Robot(id);
}

RestReply RestHandlers::Orders(const std::optional<std::string>& state,
                               const std::optional<std::string>& finished) const {
  std::optional<engine::OrderState> filter;
  if (state) {
    filter = StateFilter(*state);
    if (!filter) {
      return Error(400, "unknown state '" + *state +
                            "' (accepted, assigned, in_progress, completed, cancelled, failed, or "
                            "ORDER_STATE_ACCEPTED ... ORDER_STATE_FAILED)");
    }
  }
  std::size_t keep = kListedFinished;
  if (finished) {
    const std::string& f = *finished;
    const bool digits = !f.empty() && f.size() <= 4 && std::all_of(f.begin(), f.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c));
    });
    if (!digits || std::stoul(f) > kMaxListedFinished) {
      return Error(400, "finished must be a whole number from 0 to " + std::to_string(kMaxListedFinished));
    }
    keep = std::stoul(f);
  }
  auto snap = dispatcher_.snapshot();
  std::vector<std::size_t> open, done;  // indexes into the snapshot's orders
  for (std::size_t i = 0; i < snap->orders.size(); ++i) {
    const auto& o = snap->orders[i];
    if (filter && o->record.order.state != *filter) continue;
    (engine::IsTerminal(o->record.order.state) ? done : open).push_back(i);
  }
  pb::OrderList out;
  std::uint64_t finished_total = done.size();  // with those only in the store
  for (const auto& [s, n] : snap->finished_in_store) finished_total += !filter || s == *filter ? n : 0;
  out.set_finished_total(static_cast<std::uint32_t>(finished_total));
  if (done.size() > keep) {  // the newest finished: by finished time, then submission
    auto newer = [&](std::size_t a, std::size_t b) {
      const double ta = snap->orders[a]->finished_time.value_or(0.0), tb = snap->orders[b]->finished_time.value_or(0.0);
      return ta != tb ? ta > tb : a > b;
    };
    std::nth_element(done.begin(), done.begin() + static_cast<std::ptrdiff_t>(keep), done.end(), newer);
    done.resize(keep);
  }
  std::vector<std::size_t> listed = open;
  listed.insert(listed.end(), done.begin(), done.end());
  std::sort(listed.begin(), listed.end());
  for (const std::size_t i : listed) OrderToProto(*snap->orders[i], dispatcher_.map(), out.add_orders());
  return Json(200, out);
}

RestReply RestHandlers::Order(const std::string& id) {
  auto found = dispatcher_.FindAnywhere(id, false, true);
  if (found.ok() && !*found) found = dispatcher_.FindAnywhere(id, true, true);
  if (!found.ok()) return Error(FromEngineError(found.error()));
  const std::shared_ptr<const OrderView> order = *found;
  if (!order) return Error(404, "no order with id or client id '" + id + "'");
  pb::OrderDetail out;
  OrderToProto(*order, dispatcher_.map(), out.mutable_order());
  if (order->explanation) AllocationToProto(*order->explanation, dispatcher_.map(), out.mutable_allocation());
  const std::string order_id = order->record.order.id;
  OrderRoutes routes = dispatcher_.Call<OrderRoutes>([this, order_id](std::function<void(OrderRoutes)> done) {
    done(dispatcher_.RoutesOf(order_id));
  });
  RoutesToProto(routes, &out);
  return Json(200, out);
}

RestReply RestHandlers::SubmitOrder(const std::string& body, const std::string& actor) {
  pb::SubmitOrderRequest parsed;
  if (auto read = FromJson(body, &parsed); !read.ok()) return Error(FromEngineError(read.error()));
  auto request = OrderRequestFromProto(parsed);
  if (!request.ok()) return Error(FromEngineError(request.error()));
  SubmitReply reply = dispatcher_.Call<SubmitReply>(
      [this, r = std::move(request).value(), actor](std::function<void(SubmitReply)> done) mutable {
        dispatcher_.SubmitOrder(std::move(r), actor, std::move(done));
      });
  if (!reply.status.ok()) return Error(reply.status);
  pb::SubmitOrderResponse out;
  OrderToProto(*reply.order, dispatcher_.map(), out.mutable_order());
  out.set_created(reply.created);
  return Json(reply.created ? 201 : 200, out);
}

RestReply RestHandlers::CancelOrder(const std::string& id, const std::string& reason, const std::string& actor) {
  // The reason is stored and sent back in Order.reason: a proto string, so UTF-8.
  OrderReply reply = dispatcher_.Call<OrderReply>([this, id, why = ValidUtf8(reason), actor](
                                                      std::function<void(OrderReply)> done) {
    dispatcher_.CancelOrder(id, why, actor, std::move(done));
  });
  if (!reply.status.ok()) return Error(reply.status);
  pb::Order out;
  OrderToProto(*reply.order, dispatcher_.map(), &out);
  return Json(200, out);
}

}  // namespace dispatch::server
