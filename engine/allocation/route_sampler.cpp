#include "engine/allocation/route_sampler.h"

#include <algorithm>
#include <limits>

#include "engine/common/numbers.h"

namespace dispatch::engine {

RouteSampler::RouteSampler(const WarehouseMap& map, const RouteTable& routes, double speed,
                           double step) {
  Bind(map, routes, speed, step);
}

void RouteSampler::Bind(const WarehouseMap& map, const RouteTable& routes, double speed,
                        double step) {
  for (PointId p : touched_) memo_[static_cast<std::size_t>(p)] = Hop{};
  touched_.clear();
  memo_target_ = kNoPoint;
  if (memo_.size() != map.point_count()) memo_.assign(map.point_count(), Hop{});
  map_ = &map;
  routes_ = &routes;
  speed_ = speed;
  step_ = step;
}

double RouteSampler::ArcTime(const Arc& arc) const {
  return arc.length / (arc.max_speed > 0.0 ? std::min(speed_, arc.max_speed) : speed_);
}

const RouteSampler::Hop& RouteSampler::FindHop(PointId p) {
  Hop& hop = memo_[static_cast<std::size_t>(p)];
  touched_.push_back(p);
  hop.arc = -1;
  const PointId q = routes_->NextHop(p, memo_target_);
  if (q == kNoPoint) return hop;
  // The fastest arc p -> q (maps may hold parallel arcs).
  double best = kInf;
  for (ArcId a : map_->out_arcs(p)) {
    const Arc& arc = map_->arc(a);
    if (arc.to == q && ArcTime(arc) < best) {
      best = ArcTime(arc);
      hop.arc = a;
    }
  }
  if (hop.arc >= 0) {
    const Arc& arc = map_->arc(hop.arc);
    hop.to = arc.to;
    hop.length = arc.length;
    hop.dt = ArcTime(arc);
  }
  return hop;
}

void RouteSampler::SetTarget(PointId to) {
  if (to == memo_target_) return;
  for (PointId p : touched_) memo_[static_cast<std::size_t>(p)] = Hop{};
  touched_.clear();
  memo_target_ = to;
}

double RouteSampler::AppendLeg(PointId from, PointId to, double depart,
                               std::vector<RouteSample>& out) {
  return ForEachLegSample(from, to, depart,
                          [&out](ArcId, const Eigen::Vector2d& xa, const Eigen::Vector2d& xb,
                                 double f, double t) { out.push_back({xa + f * (xb - xa), t}); });
}

double RouteSampler::TimeToTarget(PointId from, PointId to) {
  SetTarget(to);
  // Forward to the target or to a point whose time to go is known, then back along the walk.
  walk_.clear();
  const std::size_t n_points = map_->point_count();
  double to_go = 0.0;
  for (PointId p = from; p != to;) {
    const Hop& hop = NextHop(p);
    if (hop.to_go >= 0.0) {
      to_go = hop.to_go;
      break;
    }
    if (hop.arc < 0 || walk_.size() >= n_points) {  // unreachable, or a loop of next hops
      to_go = kInf;
      break;
    }
    walk_.push_back(p);
    p = hop.to;
  }
  for (auto it = walk_.rbegin(); it != walk_.rend(); ++it) {
    Hop& hop = memo_[static_cast<std::size_t>(*it)];
    to_go += hop.dt;
    hop.to_go = to_go;
  }
  return to_go;
}

double RouteSampler::AppendTask(const PlanTask& task, double arrival,
                                std::vector<RouteSample>& out) {
  if (task.picks.empty()) return kInf;
  double t = arrival;
  PointId at = task.picks.front();
  auto stop = [&](PointId p, double work) {
    out.push_back({map_->point(p).position, t});
    t += work;
    at = p;
  };
  stop(at, task.work_time);
  for (std::size_t k = 1; k <= task.picks.size(); ++k) {
    const bool drop = k == task.picks.size();
    const PointId next = drop ? task.drop : task.picks[k];
    t = AppendLeg(at, next, t, out);
    if (t == kInf) return kInf;
    stop(next, drop ? task.drop_time : task.work_time);
  }
  return t;
}

}  // namespace dispatch::engine
