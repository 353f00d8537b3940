#include "engine/fleet/order.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/common/text.h"
#include "engine/fleet/formation.h"

namespace dispatch::engine {
namespace {

std::string Xy(const Eigen::Vector2d& p) { return "(" + Number(p.x()) + ", " + Number(p.y()) + ")"; }

Result<PointId> SnapCoordinate(const WarehouseMap& map, const Eigen::Vector2d& xy, PointKind kind,
                               const SnapOptions& options) {
  if (!xy.allFinite()) return InvalidArgument("coordinate " + Xy(xy) + " is not finite");
  PointId best = kNoPoint;
  PointId second = kNoPoint;
  double best_d = std::numeric_limits<double>::infinity();
  double second_d = best_d;
  for (std::size_t i = 0; i < map.point_count(); ++i) {
    const Point& p = map.points()[i];
    if (p.kind != kind) continue;
    const double d = (p.position - xy).norm();
    if (d < best_d) {
      second = best;
      second_d = best_d;
      best = static_cast<PointId>(i);
      best_d = d;
    } else if (d < second_d) {
      second = static_cast<PointId>(i);
      second_d = d;
    }
  }
  const std::string kind_name = PointKindName(kind);
  if (best == kNoPoint) {
    return NotFound("no " + kind_name + " point on map '" + map.name() + "' to snap " + Xy(xy) +
                    " to");
  }
  if (best_d > options.tolerance) {
    return InvalidArgument("coordinate " + Xy(xy) + " is not at a " + kind_name +
                           " point: nearest is '" + map.point(best).name + "' " +
                           Xy(map.point(best).position) + " at " + Number(best_d) +
                           " m, tolerance " + Number(options.tolerance) + " m");
  }
  if (second != kNoPoint && second_d <= options.tolerance) {
    return InvalidArgument("coordinate " + Xy(xy) + " is ambiguous: " + kind_name + " points '" +
                           map.point(best).name + "' (" + Number(best_d) + " m) and '" +
                           map.point(second).name + "' (" + Number(second_d) +
                           " m) are both within tolerance " + Number(options.tolerance) + " m");
  }
  return best;
}

}  // namespace

const char* OrderStateName(OrderState state) {
  switch (state) {
    case OrderState::kAccepted: return "accepted";
    case OrderState::kAssigned: return "assigned";
    case OrderState::kInProgress: return "in_progress";
    case OrderState::kCompleted: return "completed";
    case OrderState::kCancelled: return "cancelled";
    case OrderState::kFailed: return "failed";
  }
  return "unknown";
}

std::optional<OrderState> ParseOrderState(std::string_view name) {
  for (OrderState s : {OrderState::kAccepted, OrderState::kAssigned, OrderState::kInProgress,
                       OrderState::kCompleted, OrderState::kCancelled, OrderState::kFailed}) {
    if (name == OrderStateName(s)) return s;
  }
  return std::nullopt;
}

bool IsTerminal(OrderState state) {
  return state == OrderState::kCompleted || state == OrderState::kCancelled ||
         state == OrderState::kFailed;
}

bool CanTransition(OrderState from, OrderState to) {
  switch (from) {
    // An order can be cancelled or fail before it starts (an operator cancel, no robot can
    // reach it); an assigned order goes back to accepted when its robot is lost and it is
    // re-allocated.
    case OrderState::kAccepted:
      return to == OrderState::kAssigned || to == OrderState::kCancelled ||
             to == OrderState::kFailed;
    case OrderState::kAssigned:
      return to == OrderState::kInProgress || to == OrderState::kAccepted ||
             to == OrderState::kCancelled || to == OrderState::kFailed;
    case OrderState::kInProgress: return IsTerminal(to);
    case OrderState::kCompleted:
    case OrderState::kCancelled:
    case OrderState::kFailed: return false;
  }
  return false;
}

std::string DescribeStop(const StopSpec& stop) {
  if (const auto* xy = std::get_if<Eigen::Vector2d>(&stop)) return Xy(*xy);
  return "'" + std::get<std::string>(stop) + "'";
}

Result<PointId> ResolveStop(const WarehouseMap& map, const StopSpec& stop, PointKind kind,
                            const SnapOptions& options) {
  if (const auto* xy = std::get_if<Eigen::Vector2d>(&stop)) {
    return SnapCoordinate(map, *xy, kind, options);
  }
  const std::string& name = std::get<std::string>(stop);
  const std::optional<PointId> id = map.FindPoint(name);
  if (!id) return NotFound("unknown point '" + name + "' on map '" + map.name() + "'");
  const PointKind actual = map.point(*id).kind;
  if (actual != kind) {
    return InvalidArgument("point '" + name + "' is a " + PointKindName(actual) + " point, not a " +
                           PointKindName(kind) + " point");
  }
  return *id;
}

Result<Order> ResolveOrder(const WarehouseMap& map, const OrderRequest& request,
                           const SnapOptions& options) {
  const std::string what = "order '" + request.id + "': ";
  if (request.picks.empty()) return InvalidArgument(what + "no pick points");
  if (!std::isfinite(request.work_time) || request.work_time <= 0.0) {
    return InvalidArgument(what + "work time t_w must be > 0 s, got " + Number(request.work_time));
  }
  if (request.work_time > kMaxWorkTime) {
    return InvalidArgument(what + "work time t_w must be at most " + Number(kMaxWorkTime) + " s (a day), got " +
                           Number(request.work_time));
  }
  if (request.release_time &&
      (!std::isfinite(*request.release_time) || std::abs(*request.release_time) > kMaxReleaseTime)) {
    return InvalidArgument(what + "release time must be finite and within +-" + Number(kMaxReleaseTime) +
                           " s of the dispatcher's epoch, got " + Number(*request.release_time));
  }
  Order order;
  order.id = request.id;
  order.client_id = request.client_id;
  order.priority = request.priority;
  order.formation = request.formation;
  order.work_time = request.work_time;
  order.created_time = request.created_time;
  order.release_time = request.release_time;
  for (std::size_t i = 0; i < request.picks.size(); ++i) {
    Result<PointId> pick = ResolveStop(map, request.picks[i], PointKind::kPick, options);
    if (!pick.ok()) {
      return Error{pick.error().code,
                   what + "pick " + std::to_string(i + 1) + ": " + pick.error().message};
    }
    order.picks.push_back(*pick);
  }
  Result<PointId> drop = ResolveStop(map, request.drop, PointKind::kDrop, options);
  if (!drop.ok()) return Error{drop.error().code, what + "drop: " + drop.error().message};
  order.drop = *drop;
  // Headings: only a free-space region lets a robot choose its pose (hybrid A*); on a lane
  // the arc decides it. A formation keeps its members' lanes.
  for (const auto& [k, heading] : request.stop_headings) {
    const std::string stop = k < order.picks.size() ? "pick " + std::to_string(k + 1) : "drop";
    if (k > order.picks.size()) {
      return InvalidArgument(what + "a heading for stop " + std::to_string(k + 1) + " of " +
                             std::to_string(order.picks.size() + 1));
    }
    if (!std::isfinite(heading)) return InvalidArgument(what + stop + ": heading must be finite, got " + Number(heading));
    if (request.formation) return InvalidArgument(what + stop + ": a formation order's stops cannot ask for a heading");
    const PointId p = k < order.picks.size() ? order.picks[k] : order.drop;
    const auto& regions = map.free_spaces();
    const bool in_region = std::any_of(regions.begin(), regions.end(), [&](const FreeSpace& f) {
      return std::binary_search(f.points.begin(), f.points.end(), p);
    });
    if (!in_region) {
      return InvalidArgument(what + stop + ": a heading can only be given at a point inside a free-space region; '" +
                             map.point(p).name + "' is on the lanes, where its arc decides the heading");
    }
    order.stop_headings[k] = WrapAngle(heading);
  }
  return order;
}

}  // namespace dispatch::engine
