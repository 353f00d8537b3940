// TrafficController: creation (config validation, corridors, clearance neighbours) and the
// public interface. Requests (points, corridors, grants, waits) are in
// traffic_controller_requests.cpp, detours, back-off, sidings and deadlocks in
// traffic_controller_deadlocks.cpp, the shared state in traffic_controller_impl.h.
#include "engine/traffic/traffic_controller.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/traffic/traffic_controller_impl.h"

namespace dispatch::engine {

const char* PlanExecutionName(PlanExecution execution) {
  switch (execution) {
    case PlanExecution::kTimes: return "times";
    case PlanExecution::kClaim: return "claim";
    case PlanExecution::kOrder: return "order";
  }
  return "times";
}

std::optional<PlanExecution> ParsePlanExecution(std::string_view name) {
  for (PlanExecution e : {PlanExecution::kTimes, PlanExecution::kClaim, PlanExecution::kOrder}) {
    if (name == PlanExecutionName(e)) return e;
  }
  return std::nullopt;
}

Status TrafficControllerConfig::Validate() const {
  if (!std::isfinite(max_envelope) || max_envelope < 0) {
    return InvalidArgument("traffic controller: max_envelope must be finite and >= 0");
  }
  for (double v : {speed, t_w1, t_w2, blocked_after}) {
    if (!std::isfinite(v) || v <= 0) {
      return InvalidArgument("traffic controller: speed and waits must be finite and > 0");
    }
  }
  if (!std::isfinite(point_clearance) || point_clearance < 0) {
    return InvalidArgument("traffic controller: point_clearance must be finite and >= 0");
  }
  return Ok{};
}

Result<TrafficController> TrafficController::Create(std::shared_ptr<const WarehouseMap> map,
                                                    const TrafficControllerConfig& config) {
  if (!map) return InvalidArgument("traffic controller: no map");
  Status valid = config.Validate();
  if (!valid.ok()) return valid.error();
  auto impl = std::make_unique<Impl>();
  impl->map = std::move(map);
  impl->config = config;
  const WarehouseMap& m = *impl->map;
  impl->lanes = BuildLaneCorridors(m);
  impl->grants = IntersectionGrants(m.intersections().size());
  const std::size_t n = m.point_count();
  impl->holder.assign(n, -1);
  impl->cstate.assign(impl->lanes.corridors.size(), {});
  for (std::size_t c = 0; c < impl->lanes.corridors.size(); ++c) {
    const auto& pts = impl->lanes.corridors[c].points;
    for (std::size_t k = 1; k + 1 < pts.size(); ++k) {
      if (IsServicePoint(m.point(pts[k]).kind)) impl->cstate[c].exclusive = true;
    }
  }
  impl->region_of.assign(n, -1);
  for (std::size_t f = 0; f < m.free_spaces().size(); ++f) {
    for (PointId p : m.free_spaces()[f].points) impl->region_of[static_cast<std::size_t>(p)] = static_cast<int>(f);
  }
  impl->dist.assign(n, kInf);
  impl->via.assign(n, -1);
  impl->seen.assign(n, 0);
  impl->lower_memo.assign(n, kInf);
  impl->lower_seen.assign(n, 0);
  impl->point_xy.reserve(n);
  impl->guard_of.reserve(n);
  impl->search_begin.assign(1, 0);
  for (std::size_t p = 0; p < n; ++p) {
    impl->point_xy.push_back(m.points()[p].position);
    impl->guard_of.push_back(m.IntersectionOf(static_cast<PointId>(p)));
    for (ArcId a : m.out_arcs(static_cast<PointId>(p))) {
      impl->search_arcs.push_back({m.arc(a).to, impl->CorridorOf(a), a, impl->ArcTime(a)});
    }
    impl->search_begin.push_back(static_cast<std::uint32_t>(impl->search_arcs.size()));
  }
  // Clearance neighbours by a uniform grid of cell size point_clearance.
  impl->near.assign(n, {});
  const double cell = config.point_clearance + 2.0 * config.max_envelope;
  if (cell > 0) {
    std::unordered_map<long long, std::vector<PointId>> grid;
    auto key = [&](long long ix, long long iy) { return ix * 1000003LL + iy; };
    auto cell_of = [&](const Eigen::Vector2d& p) {
      return std::pair<long long, long long>{static_cast<long long>(std::floor(p.x() / cell)),
                                             static_cast<long long>(std::floor(p.y() / cell))};
    };
    for (std::size_t p = 0; p < n; ++p) {
      auto [ix, iy] = cell_of(m.points()[p].position);
      grid[key(ix, iy)].push_back(static_cast<PointId>(p));
    }
    for (std::size_t p = 0; p < n; ++p) {
      const Eigen::Vector2d& xy = m.points()[p].position;
      auto [ix, iy] = cell_of(xy);
      for (long long dx = -1; dx <= 1; ++dx) {
        for (long long dy = -1; dy <= 1; ++dy) {
          auto it = grid.find(key(ix + dx, iy + dy));
          if (it == grid.end()) continue;
          for (PointId q : it->second) {
            const double d = (m.points()[static_cast<std::size_t>(q)].position - xy).norm();
            if (static_cast<std::size_t>(q) != p && d < cell - 1e-9) impl->near[p].push_back({q, d});
          }
        }
      }
    }
  }
  return TrafficController(std::move(impl));
}

TrafficController::TrafficController(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TrafficController::TrafficController(TrafficController&&) noexcept = default;
TrafficController& TrafficController::operator=(TrafficController&&) noexcept = default;
TrafficController::~TrafficController() = default;

Result<std::size_t> TrafficController::AddRobot(const std::string& id, PointId at, int group) {
  Impl& s = *impl_;
  if (id.empty()) return InvalidArgument("traffic: empty robot id");
  if (at < 0 || static_cast<std::size_t>(at) >= s.M().point_count()) {
    return NotFound("traffic: robot " + id + " stands at an unknown point");
  }
  if (s.index.count(id)) return InvalidArgument("traffic: duplicate robot id " + id);
  const std::size_t r = s.robots.size();
  ControlledRobot x;
  x.id = id;
  x.at = at;
  x.route = {at};
  s.Touch(x);
  x.group = std::max(0, group);
  s.robots.push_back(std::move(x));
  const int b = s.PointBlocker(at, r);
  if (b >= 0) {
    s.robots.pop_back();
    return InvalidArgument("traffic: robot " + id + " placed at " + s.Name(at) + " held by " +
                           s.robots[static_cast<std::size_t>(b)].id);
  }
  s.holder[static_cast<std::size_t>(at)] = static_cast<int>(r);
  s.index.emplace(id, r);
  s.OccupyGuard(r);
  return r;
}

std::size_t TrafficController::robot_count() const { return impl_->robots.size(); }
const std::string& TrafficController::robot_id(std::size_t r) const { return impl_->robots.at(r).id; }
Status TrafficController::SetRoute(std::size_t r, std::vector<PointId> points) {
  if (r >= impl_->robots.size()) return InvalidArgument("traffic: unknown robot index");
  return impl_->Assign(r, std::move(points));
}
std::vector<PointId> TrafficController::RemainingRoute(std::size_t r) const {
  const ControlledRobot& x = impl_->robots.at(r);
  if (x.route.empty()) return {};
  return {x.route.begin() + static_cast<std::ptrdiff_t>(x.pos), x.route.end()};
}
void TrafficController::SetRouteBound(std::shared_ptr<const RouteTable> routes) {
  impl_->bound_routes.reset();
  impl_->lower_to = kNoPoint;  // the memo was the old table's
  if (!routes || routes->point_count() != impl_->M().point_count()) return;
  const RouteTableBuildInfo info = routes->build_info();
  if (info.turn_expanded || !(info.speed > 0.0)) return;
  // Per arc, the table costs length / min(its speed, max_speed) and ArcTime length /
  // min(config.speed, max_speed): times min(1, table speed / config.speed), never more.
  impl_->bound_scale = std::min(1.0, info.speed / impl_->config.speed);
  impl_->bound_routes = std::move(routes);
}
void TrafficController::CopyRemainingRoute(std::size_t r, std::vector<PointId>& out) const {
  const ControlledRobot& x = impl_->robots.at(r);
  if (x.route.empty()) {
    out.clear();
    return;
  }
  out.assign(x.route.begin() + static_cast<std::ptrdiff_t>(x.pos), x.route.end());
}
bool TrafficController::RemainingRouteIs(std::size_t r, const std::vector<PointId>& route) const {
  const ControlledRobot& x = impl_->robots.at(r);
  if (x.route.empty()) return route.empty();
  return std::equal(x.route.begin() + static_cast<std::ptrdiff_t>(x.pos), x.route.end(), route.begin(), route.end());
}
std::uint64_t TrafficController::RouteEpoch(std::size_t r) const { return impl_->robots.at(r).route_epoch; }
bool TrafficController::InExclusiveCorridor(PointId p) const {
  if (p < 0 || static_cast<std::size_t>(p) >= impl_->lanes.interior_of.size()) return false;
  const int c = impl_->lanes.interior_of[static_cast<std::size_t>(p)];
  return c >= 0 && impl_->cstate[static_cast<std::size_t>(c)].exclusive;
}
bool TrafficController::HasRoute(std::size_t r) const {
  const ControlledRobot& x = impl_->robots.at(r);
  return !x.removed && x.pos + 1 < x.route.size();
}
PointId TrafficController::At(std::size_t r) const { return impl_->robots.at(r).at; }
PointId TrafficController::Next(std::size_t r) const { return impl_->robots.at(r).next; }
void TrafficController::SetWorking(std::size_t r, bool working, double work_end) {
  impl_->robots.at(r).working = working;
  impl_->robots.at(r).work_end = work_end;
}
void TrafficController::SetLoaded(std::size_t r, bool loaded) { impl_->robots.at(r).loaded = loaded; }
void TrafficController::SetRank(std::size_t r, double release_time) { impl_->robots.at(r).rank = release_time; }
void TrafficController::SetIdle(std::size_t r, bool idle) { impl_->robots.at(r).idle = idle; }
void TrafficController::SetGroup(std::size_t r, int group, int second, int third) {
  impl_->robots.at(r).group = std::max(0, group);
  impl_->robots.at(r).group2 = std::max(0, second);
  impl_->robots.at(r).group3 = std::max(0, third);
}
void TrafficController::SetEnvelope(std::size_t r, double extra) {
  impl_->robots.at(r).envelope = std::clamp(extra, 0.0, impl_->config.max_envelope);
}
TrafficDecision TrafficController::Request(std::size_t r, double t) {
  return impl_->Request(r, t);
}
void TrafficController::LeftPoint(std::size_t r) {
  Impl& s = *impl_;
  const ControlledRobot& x = s.robots.at(r);
  if (x.next == kNoPoint) return;
  int& h = s.holder[static_cast<std::size_t>(x.at)];
  if (h == static_cast<int>(r)) h = -1;
}
void TrafficController::Arrived(std::size_t r, double /*t*/) { impl_->Arrived(r); }
void TrafficController::Remove(std::size_t r) { impl_->Remove(r); }
Status TrafficController::Place(std::size_t r, PointId at) {
  Impl& s = *impl_;
  if (r >= s.robots.size()) return InvalidArgument("traffic: unknown robot index");
  ControlledRobot& x = s.robots[r];
  if (!x.removed) return Error{ErrorCode::kFailedPrecondition, "traffic: robot " + x.id + " is on the floor"};
  if (at < 0 || static_cast<std::size_t>(at) >= s.M().point_count()) {
    return NotFound("traffic: robot " + x.id + " placed at an unknown point");
  }
  const int b = s.PointBlocker(at, r);
  if (b >= 0) {
    return InvalidArgument("traffic: robot " + x.id + " placed at " + s.Name(at) + " held by " +
                           s.robots[static_cast<std::size_t>(b)].id);
  }
  x.removed = false;
  x.at = at;
  x.next = kNoPoint;
  x.route = {at};
  x.arcs.clear();
  x.pos = 0;
  s.Touch(x);
  Impl::ForgetProgress(x);
  x.working = x.loaded = false;
  x.idle = true;
  s.ClearWait(x);
  ClearStanding(r);
  s.holder[static_cast<std::size_t>(at)] = static_cast<int>(r);
  s.OccupyGuard(r);
  return Ok{};
}
void TrafficController::HoldGrantAt(std::size_t r, PointId at) {
  Impl& s = *impl_;
  if (r >= s.robots.size() || at < 0 || static_cast<std::size_t>(at) >= s.M().point_count()) return;
  s.OccupyGuard(r, s.M().IntersectionOf(at));
}
void TrafficController::SetStanding(std::size_t r, const Eigen::Vector2d& xy) {
  Impl& s = *impl_;
  if (r >= s.robots.size() || !s.robots[r].removed) return;
  ClearStanding(r);
  s.standing.emplace_back(r, xy);
}
void TrafficController::ClearStanding(std::size_t r) {
  auto& v = impl_->standing;
  v.erase(std::remove_if(v.begin(), v.end(), [&](const auto& e) { return e.first == r; }), v.end());
}
bool TrafficController::removed(std::size_t r) const { return impl_->robots.at(r).removed; }
int TrafficController::HolderOf(PointId p) const { return impl_->holder.at(static_cast<std::size_t>(p)); }
int TrafficController::BlockerOf(PointId p, std::size_t r, double envelope) const {
  return impl_->PointBlocker(p, r, envelope);
}
int TrafficController::WaitsOn(std::size_t r) const {
  const ControlledRobot& x = impl_->robots.at(r);
  return x.wait == WaitKind::kNone ? -1 : x.waits_on;
}
double TrafficController::WaitedFor(std::size_t r, double t) const {
  const ControlledRobot& x = impl_->robots.at(r);
  return x.wait == WaitKind::kNone ? 0.0 : t - x.wait_start;
}
void TrafficController::WaitOn(std::size_t r, int other, double t, const std::string& why) {
  ControlledRobot& x = impl_->robots.at(r);
  if (other < 0 || static_cast<std::size_t>(other) >= impl_->robots.size() || static_cast<std::size_t>(other) == r) {
    if (x.wait != WaitKind::kNone) impl_->ClearWait(x);
    return;
  }
  (void)impl_->Wait(r, WaitKind::kPoint, other, t, why);
}
void TrafficController::RestartWaitClock(std::size_t r, double t) {
  ControlledRobot& x = impl_->robots.at(r);
  Impl::ForgetProgress(x);
  if (x.wait == WaitKind::kNone) return;
  x.wait_start = t;
  x.next_detour_try = 0.0;
}
const std::string& TrafficController::why(std::size_t r) const { return impl_->robots.at(r).why; }
std::string TrafficController::Describe(std::size_t r) const {
  const Impl& s = *impl_;
  const ControlledRobot& x = s.robots.at(r);
  std::string out = x.id + (x.removed ? " (off the floor)" : "") + " at " + s.Name(x.at);
  if (x.next != kNoPoint) out += " -> " + s.Name(x.next);
  out += " route";
  for (std::size_t k = x.pos; k < x.route.size() && k < x.pos + 6; ++k) out += " " + s.Name(x.route[k]);
  if (x.working) out += " working";
  if (x.wait != WaitKind::kNone) {
    out += " waiting on " + (x.waits_on >= 0 ? s.robots[static_cast<std::size_t>(x.waits_on)].id
                                              : std::string("-")) + " (" + x.why + ")";
  }
  return out;
}

bool TrafficController::StepAside(std::size_t r) { return impl_->StepAside(r, {}); }
bool TrafficController::StepAside(std::size_t r, const std::vector<PointId>& keep_clear) {
  return impl_->StepAside(r, keep_clear);
}

std::size_t TrafficController::ResolveDeadlocks(double t) { return impl_->ResolveDeadlocks(t); }
const TrafficStats& TrafficController::stats() const { return impl_->stats; }
const LaneCorridors& TrafficController::corridors() const { return impl_->lanes; }
const IntersectionGrants& TrafficController::grants() const { return impl_->grants; }

}  // namespace dispatch::engine
