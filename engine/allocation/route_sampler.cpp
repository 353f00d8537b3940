#include "engine/allocation/route_sampler.h"

#include <algorithm>
#include <limits>

namespace dispatch::engine {
namespace {
constexpr ArcId kUnknown = -2;
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

RouteSampler::RouteSampler(const WarehouseMap& map, const RouteTable& routes, double speed,
                           double step)
    : map_(map), routes_(routes), speed_(speed), step_(step), memo_(map.point_count(), kUnknown) {}

double RouteSampler::ArcTime(const Arc& arc) const {
  return arc.length / (arc.max_speed > 0.0 ? std::min(speed_, arc.max_speed) : speed_);
}

ArcId RouteSampler::NextArc(PointId p) {
  ArcId& slot = memo_[static_cast<std::size_t>(p)];
  if (slot != kUnknown) return slot;
  touched_.push_back(p);
  const PointId q = routes_.NextHop(p, memo_target_);
  slot = -1;
  if (q == kNoPoint) return slot;
  // The fastest arc p -> q (maps may hold parallel arcs).
  double best = kInf;
  for (ArcId a : map_.out_arcs(p)) {
    const Arc& arc = map_.arc(a);
    if (arc.to == q && ArcTime(arc) < best) {
      best = ArcTime(arc);
      slot = a;
    }
  }
  return slot;
}

double RouteSampler::AppendLeg(PointId from, PointId to, double depart,
                               std::vector<RouteSample>& out) {
  if (to != memo_target_) {
    for (PointId p : touched_) memo_[static_cast<std::size_t>(p)] = kUnknown;
    touched_.clear();
    memo_target_ = to;
  }
  double t = depart;
  double s0 = 0.0;      // distance driven at the start of the current arc
  double next_s = 0.0;  // distance of the next sample
  PointId p = from;
  std::size_t hops = 0;
  while (p != to) {
    const ArcId a = NextArc(p);
    if (a < 0 || ++hops > map_.point_count()) return kInf;
    const Arc& arc = map_.arc(a);
    const Eigen::Vector2d& xa = map_.point(p).position;
    const Eigen::Vector2d& xb = map_.point(arc.to).position;
    const double dt = ArcTime(arc);
    const double s1 = s0 + arc.length;
    // Samples strictly inside the leg; the arrival point belongs to the next stop.
    const double last = arc.to == to ? s1 - 1e-9 : s1;
    while (next_s < last) {
      const double f = (next_s - s0) / arc.length;
      out.push_back({xa + f * (xb - xa), t + f * dt});
      next_s += step_;
    }
    t += dt;
    s0 = s1;
    p = arc.to;
  }
  return t;
}

double RouteSampler::AppendTask(const PlanTask& task, double arrival,
                                std::vector<RouteSample>& out) {
  if (task.picks.empty()) return kInf;
  double t = arrival;
  PointId at = task.picks.front();
  auto stop = [&](PointId p) {
    out.push_back({map_.point(p).position, t});
    t += task.work_time;
    at = p;
  };
  stop(at);
  for (std::size_t k = 1; k <= task.picks.size(); ++k) {
    const PointId next = k < task.picks.size() ? task.picks[k] : task.drop;
    t = AppendLeg(at, next, t, out);
    if (t == kInf) return kInf;
    stop(next);
  }
  return t;
}

}  // namespace dispatch::engine
