#include "engine/traffic/safety_check.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <tuple>
#include <utility>

namespace dispatch::engine {
namespace {

struct Box {
  Eigen::Vector2d min, max;
  bool Contains(const Eigen::Vector2d& p) const {
    return p.x() >= min.x() && p.y() >= min.y() && p.x() <= max.x() && p.y() <= max.y();
  }
};

// One agent's stay inside one intersection box: frames [first, last].
struct Visit {
  std::string agent;
  std::string group, group2, group3;
  int intersection = -1;
  std::size_t first = 0, last = 0;
  PointId entry = kNoPoint, exit = kNoPoint;
};

// True when two robots (or agents' visits) have a group in common ("" is none).
template <typename A, typename B>
bool SharesGroup(const A& a, const B& b) {
  for (const std::string* x : {&a.group, &a.group2, &a.group3}) {
    if (x->empty()) continue;
    for (const std::string* y : {&b.group, &b.group2, &b.group3}) {
      if (*x == *y) return true;
    }
  }
  return false;
}

PointId NearestInner(const WarehouseMap& map, const Intersection& in, const Eigen::Vector2d& p) {
  PointId best = kNoPoint;
  double best_d = std::numeric_limits<double>::infinity();
  for (PointId q : in.inner) {
    const double d = (map.point(q).position - p).squaredNorm();
    if (d < best_d) best_d = d, best = q;
  }
  return best;
}

}  // namespace

const char* ViolationKindName(ViolationKind kind) {
  return kind == ViolationKind::kSpacing ? "spacing" : "crossing";
}

std::string SafetyViolation::Describe() const {
  char buf[256];
  if (kind == ViolationKind::kSpacing) {
    std::snprintf(buf, sizeof buf, "t=%.1f s: %s and %s %.3f m apart (< %.3f m)", t, a.c_str(),
                  b.c_str(), distance, required);
  } else {
    std::snprintf(buf, sizeof buf, "t=%.1f s: %s and %s cross inside intersection %d", t,
                  a.c_str(), b.c_str(), intersection);
  }
  return buf;
}

SafetyReport CheckSafety(const std::vector<SafetyFrame>& frames, const WarehouseMap& map,
                         const TrafficConfig& config, const SafetyCheckOptions& options) {
  SafetyReport report;
  // Spacing (eqs. (10)-(12)), one violation per episode of consecutive frames and pair.
  std::map<std::pair<std::string, std::string>, std::size_t> open;  // pair -> violation index
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const auto& rs = frames[f].robots;
    std::map<std::pair<std::string, std::string>, std::size_t> still_open;
    for (std::size_t i = 0; i < rs.size(); ++i) {
      for (std::size_t j = i + 1; j < rs.size(); ++j) {
        if (SharesGroup(rs[i], rs[j])) continue;
        const double d = (rs[i].xy - rs[j].xy).norm();
        report.min_robot_distance = std::min(report.min_robot_distance, d);
        const double need = config.RobotClearance(rs[i].formation, rs[j].formation);
        if (d >= need - options.tolerance) continue;
        auto key = std::minmax(rs[i].robot, rs[j].robot);
        std::pair<std::string, std::string> k{key.first, key.second};
        auto it = open.find(k);
        if (it == open.end()) {
          report.violations.push_back(
              {ViolationKind::kSpacing, frames[f].t, k.first, k.second, d, need, -1});
          still_open[k] = report.violations.size() - 1;
        } else {
          SafetyViolation& v = report.violations[it->second];
          v.distance = std::min(v.distance, d);
          still_open[k] = it->second;
        }
      }
    }
    open = std::move(still_open);
  }

  // Crossing (eqs. (13)-(15)): agents' reference points (centroid of their robots).
  std::vector<Box> boxes;
  for (const Intersection& in : map.intersections()) {
    Box b{Eigen::Vector2d::Constant(1e300), Eigen::Vector2d::Constant(-1e300)};
    for (PointId p : in.inner) {
      b.min = b.min.cwiseMin(map.point(p).position);
      b.max = b.max.cwiseMax(map.point(p).position);
    }
    b.min.array() -= options.box_margin;
    b.max.array() += options.box_margin;
    boxes.push_back(b);
  }
  std::vector<Visit> visits;
  std::map<std::string, std::size_t> current;  // agent -> open visit index
  for (std::size_t f = 0; f < frames.size(); ++f) {
    std::map<std::string, std::pair<Eigen::Vector2d, int>> refs;
    std::map<std::string, const RobotSample*> group_of;
    for (const RobotSample& r : frames[f].robots) {
      auto& e = refs.try_emplace(r.agent, Eigen::Vector2d::Zero(), 0).first->second;
      e.first += r.xy;
      ++e.second;
      const RobotSample*& g = group_of[r.agent];
      if (g == nullptr || (g->group2.empty() && !r.group2.empty())) g = &r;  // further groups if any member has them
    }
    std::map<std::string, std::size_t> next;
    for (auto& [agent, sum] : refs) {
      const Eigen::Vector2d ref = sum.first / sum.second;
      int inside = -1;
      for (std::size_t w = 0; w < boxes.size() && inside < 0; ++w) {
        if (boxes[w].Contains(ref)) inside = static_cast<int>(w);
      }
      if (inside < 0) continue;
      const Intersection& in = map.intersections()[static_cast<std::size_t>(inside)];
      auto it = current.find(agent);
      if (it != current.end() && visits[it->second].intersection == inside) {
        visits[it->second].last = f;
        visits[it->second].exit = NearestInner(map, in, ref);
        next[agent] = it->second;
      } else {
        const PointId p = NearestInner(map, in, ref);
        const RobotSample& g = *group_of[agent];
        visits.push_back({agent, g.group, g.group2, g.group3, inside, f, f, p, p});
        next[agent] = visits.size() - 1;
      }
    }
    current = std::move(next);
  }
  for (std::size_t i = 0; i < visits.size(); ++i) {
    for (std::size_t j = i + 1; j < visits.size(); ++j) {
      const Visit& a = visits[i];
      const Visit& b = visits[j];
      if (a.intersection != b.intersection || SharesGroup(a, b)) continue;
      if (a.last < b.first || b.last < a.first) continue;
      if (a.entry == b.entry && a.exit == b.exit) continue;  // same movement: may share
      // Through the same entry one behind the other (the spacing rule keeps them apart): the
      // online controller may turn the one ahead off, or back one off the way it came, so their
      // exits can differ without either crossing the other's path.
      if (options.followers_may_diverge && a.entry == b.entry &&
          map.intersections()[static_cast<std::size_t>(a.intersection)].inner.size() > 1) {
        continue;
      }
      SafetyViolation v;
      v.kind = ViolationKind::kCrossing;
      v.t = frames[std::max(a.first, b.first)].t;
      v.a = std::min(a.agent, b.agent);
      v.b = std::max(a.agent, b.agent);
      v.intersection = a.intersection;
      report.violations.push_back(v);
    }
  }
  std::stable_sort(report.violations.begin(), report.violations.end(),
                   [](const SafetyViolation& x, const SafetyViolation& y) { return x.t < y.t; });
  return report;
}

}  // namespace dispatch::engine
