// Orders (SPEC §2): what the WMS asks for, resolved onto map points.
//
// An `OrderRequest` names its stops either by point name or by coordinate; `ResolveOrder`
// turns it into an `Order` whose stops are PointIds of the right kind (picks on pick points,
// the drop on a drop point). Order states follow
//   accepted -> assigned -> in_progress -> completed | cancelled | failed
// plus cancel/fail before the start and assigned -> accepted for re-allocation;
// `CanTransition` allows nothing else (no skipping ahead, nothing leaves a terminal state).
//
// Invariants of a resolved Order: at least one pick, every pick is a kPick point, the drop
// is a kDrop point, work_time > 0 and finite; a stop's heading (issue 17 §3, "tasks have a
// position and a heading") is finite, in (-pi, pi], at a point inside one of the map's
// free-space regions, and only in a single-robot order. Plain values: not thread-safe to mutate
// concurrently, safe to share once built. All functions here are pure.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

// Robots in a formation (Chu2024 §3.2: a 3-robot virtual structure).
inline constexpr int kFormationTeamSize = 3;

// Work time per task point t_w (Chu2024 eq. (3)). The paper gives no value; 5 s is our
// default for one pick or drop operation.
inline constexpr double kDefaultWorkTime = 5.0;

enum class OrderState { kAccepted, kAssigned, kInProgress, kCompleted, kCancelled, kFailed };

// "accepted", "assigned", "in_progress", "completed", "cancelled", "failed".
const char* OrderStateName(OrderState state);
std::optional<OrderState> ParseOrderState(std::string_view name);
// completed, cancelled and failed are terminal.
bool IsTerminal(OrderState state);
// True exactly for accepted->{assigned, cancelled, failed},
// assigned->{in_progress, accepted, cancelled, failed} and
// in_progress->{completed, cancelled, failed}.
bool CanTransition(OrderState from, OrderState to);

struct Order {
  std::string id;
  std::string client_id;  // idempotency key of the submitting client
  int priority = 0;       // higher = more urgent
  std::vector<PointId> picks;  // visiting order, >= 1
  PointId drop = kNoPoint;
  bool formation = false;  // carried by kFormationTeamSize robots
  double work_time = kDefaultWorkTime;  // t_w, seconds per task point
  double created_time = 0.0;            // seconds
  std::optional<double> release_time;   // earliest start, seconds; none = on acceptance
  OrderState state = OrderState::kAccepted;
  // The heading a robot must have at a stop (radians counter-clockwise from +x, in
  // (-pi, pi]), keyed by the stop's index: the picks 0..picks.size()-1 in order, then the drop.
  // Stops without one are reached with the heading of the arc into them.
  std::map<std::size_t, double> stop_headings{};

  int team_size() const { return formation ? kFormationTeamSize : 1; }
};

// A stop given either as a coordinate (metres) or as a point name.
using StopSpec = std::variant<Eigen::Vector2d, std::string>;

// Order as submitted: like Order, but stops are not yet resolved to points.
struct OrderRequest {
  std::string id;
  std::string client_id;
  int priority = 0;
  std::vector<StopSpec> picks;
  StopSpec drop = Eigen::Vector2d(0.0, 0.0);
  bool formation = false;
  double work_time = kDefaultWorkTime;
  double created_time = 0.0;
  std::optional<double> release_time;
  std::map<std::size_t, double> stop_headings{};  // as Order's, any finite value (ResolveOrder wraps it)
};

// "(19, 16.5)" or "'X3-4'": how a stop is named in error messages.
std::string DescribeStop(const StopSpec& stop);

struct SnapOptions {
  // A coordinate resolves to the nearest point of the required kind when that point lies
  // within `tolerance` metres, and when it is the only such point.
  //
  // Default 0.2 m, the robot radius (diameter 0.4 m): a coordinate farther from a node than
  // a robot's own radius does not describe "standing at" that node. It is also below half
  // the smallest spacing between two distinct points of one kind on the Chu2024 floor (pick
  // docks (14, 16.5) and (19, 16.5) are 0.5 m from the lane picks beside them; other picks
  // are >= 0.75 m apart), so a snap there can never be ambiguous: any coordinate within
  // 0.2 m of one pick is >= 0.3 m from every other. The seed tables' coordinates are exact
  // nodes (distance 0). Larger tolerances are allowed; a coordinate with two candidates
  // within tolerance is then rejected as ambiguous rather than silently picking one.
  double tolerance = 0.2;
};

// Bounds ResolveOrder enforces: a task point's work time (a day), and a release time's
// distance from the dispatcher's epoch (about 31 years: beyond it an order would never start).
inline constexpr double kMaxWorkTime = 86400.0;
inline constexpr double kMaxReleaseTime = 1e9;

// Resolves a request on `map` (state = accepted). Errors:
//  - kInvalidArgument: no picks; work_time not finite, <= 0 or > kMaxWorkTime; a release time
//    not finite or beyond kMaxReleaseTime; a non-finite coordinate; a
//    coordinate farther than the tolerance from every candidate (names the coordinate, the
//    nearest candidate and its distance) or within tolerance of two (names both); a named
//    point of the wrong kind; a stop heading that is not finite, names no stop, is at a point
//    outside every free-space region, or is in a formation order;
//  - kNotFound: an unknown point name; a map without points of the required kind.
Result<Order> ResolveOrder(const WarehouseMap& map, const OrderRequest& request,
                           const SnapOptions& options = {});

// One stop alone: `kind` is kPick or kDrop (any kind is accepted; see ResolveOrder).
Result<PointId> ResolveStop(const WarehouseMap& map, const StopSpec& stop, PointKind kind,
                            const SnapOptions& options = {});

}  // namespace dispatch::engine
