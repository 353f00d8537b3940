// Intersection grants: the crossing rule of Chu2024 §3.3 (eqs. (13)-(15); SPEC §3.5).
//
// An agent (a robot, or a whole formation as one agent) enters an intersection's inner region
// I_w only while it holds a grant; without one it stops before the approach points O_w. A
// grant is for one Movement (the points before and after the traversal of I_w). Grants are
// exclusive between different movements; agents with the same movement may hold grants
// together (they follow each other; the rear-end rule keeps them apart). Requests are served
// strictly FIFO by request time, ties by higher priority, then by agent id (deterministic):
// the head of the queue is granted when it is compatible with every current holder, and
// nothing behind a waiting head is granted (no starvation). A grant is released by the
// simulator the moment the agent (all its members) has left I_w.
//
// "Guards" generalise intersections: every map intersection is one guard, and (optionally)
// every merge point outside intersections (>= 2 incoming arcs) is a one-point guard.
//
// Pure state machine, no clocks: time is passed in. Not thread-safe (one owner mutates it).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

// How an agent passes a guard: the point before it enters and the point after it leaves
// (kNoPoint when its path starts or ends inside).
struct Movement {
  PointId entry = kNoPoint;
  PointId exit = kNoPoint;
  bool operator==(const Movement&) const = default;
};

struct GrantRequest {
  std::string agent;
  Movement movement;
  double time = 0.0;  // when the agent reached the stop line
  int priority = 0;   // higher first among equal times
};

class IntersectionGrants {
 public:
  explicit IntersectionGrants(std::size_t guard_count);

  std::size_t guard_count() const { return guards_.size(); }
  // Queues a request (idempotent: a repeated request of a waiting or holding agent with the
  // same movement keeps its place) and grants what FIFO allows. Errors: guard out of range,
  // empty agent id, a repeated request with another movement.
  Status Request(std::size_t guard, const GrantRequest& request);
  bool Granted(std::size_t guard, const std::string& agent) const;
  bool Waiting(std::size_t guard, const std::string& agent) const;
  // An agent found standing inside the guard (placed there: a restart, a formation broken up
  // on it) holds a grant at once, whatever the holders' movements (it is inside already), with
  // the movement {kNoPoint, kNoPoint}: no crossing movement is granted until it has left. A
  // request it had queued is withdrawn. Errors: guard out of range, empty agent id.
  Status Occupy(std::size_t guard, const std::string& agent);
  // Ends the agent's grant (or withdraws its request) and grants what FIFO then allows.
  // Error when the agent neither holds nor requested it.
  Status Release(std::size_t guard, const std::string& agent);

  std::vector<std::string> Holders(std::size_t guard) const;
  std::vector<std::string> Queue(std::size_t guard) const;  // waiting agents, FIFO order
  std::size_t grants_issued() const { return grants_issued_; }

 private:
  struct Guard {
    std::vector<GrantRequest> holders;
    std::vector<GrantRequest> queue;  // sorted by (time, -priority, agent)
  };
  void Promote(Guard& g);
  std::vector<Guard> guards_;
  std::size_t grants_issued_ = 0;
};

// A guarded region: a map intersection (inner = I_w) or a merge point.
struct TrafficGuard {
  std::string name;
  std::vector<PointId> inner;
  int intersection = -1;  // map intersection index, -1 for a merge point
};

struct TrafficGuards {
  std::vector<TrafficGuard> guards;
  std::vector<int> guard_of_point;  // per point: guard index or -1
};

// Guards of a map: intersections first (guard i = intersection i), then, when
// `guard_merges`, one per point outside every I_w with at least two incoming arcs.
TrafficGuards BuildTrafficGuards(const WarehouseMap& map, bool guard_merges);

}  // namespace dispatch::engine
