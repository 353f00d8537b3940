#include "engine/traffic/intersection_grants.h"

#include <algorithm>
#include <tuple>

namespace dispatch::engine {
namespace {

bool Before(const GrantRequest& a, const GrantRequest& b) {
  return std::tie(a.time, b.priority, a.agent) < std::tie(b.time, a.priority, b.agent);
}

}  // namespace

IntersectionGrants::IntersectionGrants(std::size_t guard_count) : guards_(guard_count) {}

Status IntersectionGrants::Request(std::size_t guard, const GrantRequest& request) {
  if (guard >= guards_.size()) return NotFound("grant request: unknown guard");
  if (request.agent.empty()) return InvalidArgument("grant request: empty agent id");
  Guard& g = guards_[guard];
  for (const auto* list : {&g.holders, &g.queue}) {
    for (const GrantRequest& r : *list) {
      if (r.agent != request.agent) continue;
      if (!(r.movement == request.movement)) {
        return InvalidArgument("grant request: agent " + request.agent +
                               " already requested another movement");
      }
      return Ok{};
    }
  }
  auto at = std::upper_bound(g.queue.begin(), g.queue.end(), request, Before);
  g.queue.insert(at, request);
  Promote(g);
  return Ok{};
}

Status IntersectionGrants::Occupy(std::size_t guard, const std::string& agent) {
  if (guard >= guards_.size()) return NotFound("grant occupy: unknown guard");
  if (agent.empty()) return InvalidArgument("grant occupy: empty agent id");
  Guard& g = guards_[guard];
  auto same = [&](const GrantRequest& r) { return r.agent == agent; };
  if (std::any_of(g.holders.begin(), g.holders.end(), same)) return Ok{};
  g.queue.erase(std::remove_if(g.queue.begin(), g.queue.end(), same), g.queue.end());
  g.holders.push_back({agent, Movement{}, 0.0, 0});
  Promote(g);  // the head may share the occupier's movement
  return Ok{};
}

void IntersectionGrants::Promote(Guard& g) {
  while (!g.queue.empty()) {
    const GrantRequest& head = g.queue.front();
    for (const GrantRequest& h : g.holders) {
      if (!(h.movement == head.movement)) return;  // crossing movements: exclusive
    }
    g.holders.push_back(head);
    g.queue.erase(g.queue.begin());
    ++grants_issued_;
  }
}

bool IntersectionGrants::Granted(std::size_t guard, const std::string& agent) const {
  if (guard >= guards_.size()) return false;
  for (const GrantRequest& r : guards_[guard].holders) {
    if (r.agent == agent) return true;
  }
  return false;
}

bool IntersectionGrants::Waiting(std::size_t guard, const std::string& agent) const {
  if (guard >= guards_.size()) return false;
  for (const GrantRequest& r : guards_[guard].queue) {
    if (r.agent == agent) return true;
  }
  return false;
}

Status IntersectionGrants::Release(std::size_t guard, const std::string& agent) {
  if (guard >= guards_.size()) return NotFound("grant release: unknown guard");
  Guard& g = guards_[guard];
  for (auto* list : {&g.holders, &g.queue}) {
    auto it = std::find_if(list->begin(), list->end(),
                           [&](const GrantRequest& r) { return r.agent == agent; });
    if (it != list->end()) {
      list->erase(it);
      Promote(g);
      return Ok{};
    }
  }
  return NotFound("grant release: agent " + agent + " holds no grant here");
}

std::vector<std::string> IntersectionGrants::Holders(std::size_t guard) const {
  std::vector<std::string> out;
  if (guard < guards_.size()) {
    for (const GrantRequest& r : guards_[guard].holders) out.push_back(r.agent);
  }
  return out;
}

std::vector<std::string> IntersectionGrants::Queue(std::size_t guard) const {
  std::vector<std::string> out;
  if (guard < guards_.size()) {
    for (const GrantRequest& r : guards_[guard].queue) out.push_back(r.agent);
  }
  return out;
}

TrafficGuards BuildTrafficGuards(const WarehouseMap& map, bool guard_merges) {
  TrafficGuards out;
  out.guard_of_point.assign(map.point_count(), -1);
  for (std::size_t w = 0; w < map.intersections().size(); ++w) {
    const Intersection& in = map.intersections()[w];
    out.guards.push_back({in.name, in.inner, static_cast<int>(w)});
    for (PointId p : in.inner) out.guard_of_point[static_cast<std::size_t>(p)] = static_cast<int>(w);
  }
  if (guard_merges) {
    for (PointId p = 0; p < static_cast<PointId>(map.point_count()); ++p) {
      if (map.IntersectionOf(p) >= 0 || map.in_arcs(p).size() < 2) continue;
      out.guard_of_point[static_cast<std::size_t>(p)] = static_cast<int>(out.guards.size());
      out.guards.push_back({"merge " + map.point(p).name, {p}, -1});
    }
  }
  return out;
}

}  // namespace dispatch::engine
