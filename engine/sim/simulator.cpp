#include "engine/sim/simulator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>

#include "engine/common/numbers.h"
#include "engine/traffic/intersection_grants.h"

namespace dispatch::engine {
namespace {

struct GuardRun {
  std::size_t guard = 0;
  Movement movement;
  double start_s = 0, end_s = 0;
  std::size_t first = 0, last = 0;  // waypoint indices of the guard run
};

struct ZoneState {
  bool requested = false, granted = false, done = false;
  std::string agent;
};

struct Block {  // one formation task
  std::string order_id;
  std::array<std::size_t, 3> members{};  // robot indices, leader first
  std::array<std::size_t, 3> start{};    // first formation waypoint per member
  std::array<std::size_t, 3> end{};      // drop waypoint per member
  bool active = false, finished = false;
};

struct Cursor {
  std::size_t index = 0;  // last waypoint reached
  double tau = 0;         // time moved on segment index -> index + 1
  double dwell_left = 0;  // work left at `index`
  bool at_slot = false;   // waiting in a rendezvous slot
  bool finished = false;
};

struct RobotRt {
  const SimRobot* in = nullptr;
  std::vector<Eigen::Vector2d> ref;  // agent reference point per waypoint
  std::vector<double> s;             // cumulative reference path length
  std::vector<double> dur;           // segment durations
  std::vector<int> task_of;          // queue task per waypoint (-1: none)
  std::vector<int> slot_block;       // block whose slot this waypoint is, or -1
  std::vector<int> block_at;         // block whose formation part holds this waypoint, or -1
  std::vector<GuardRun> zones;
  std::vector<ZoneState> zstate;
  Cursor c;
  int split = -1;       // block this robot just left, until it is eps1 from its mates
  int split_rank = 0;   // leaving order within that split (front member first)
  double waited = 0;  // continuous traffic wait
  bool was_moving = false;
};

struct Event {
  std::size_t index;
  double offset;
};

class Sim {
 public:
  Sim(const WarehouseMap& map, const std::vector<SimRobot>& robots, const SimConfig& config)
      : map_(map), config_(config), guards_(BuildTrafficGuards(map, config.traffic.guard_merges)),
        grants_(guards_.guards.size()) {
    for (const SimRobot& r : robots) {
      RobotRt x;
      x.in = &r;
      rt_.push_back(std::move(x));
    }
  }

  Status Prepare();
  SimResult Run();

 private:
  const std::vector<Waypoint>& W(std::size_t r) const { return rt_[r].in->plan.waypoints; }
  bool Formation(std::size_t r) const {
    const int b = rt_[r].block_at[std::min(rt_[r].c.index + (rt_[r].c.dwell_left > 0 ? 0 : 1),
                                            W(r).size() - 1)];
    return b >= 0 && blocks_[static_cast<std::size_t>(b)].active;
  }
  // Robots of one group are exempt from each other: the members of an active formation,
  // members gathering within `gather_radius` of their rendezvous, and members splitting up
  // after a formation's drop (among those only the later-ranked one yields).
  std::string Group(std::size_t r) const;
  // Reference point of robot r as (part of) its current agent.
  Eigen::Vector2d AgentRef(std::size_t r, const Cursor& c, bool formation) const {
    return formation ? Ref(r, c) : Pos(r, c);
  }
  Eigen::Vector2d Pos(std::size_t r, const Cursor& c) const;
  Eigen::Vector2d Ref(std::size_t r, const Cursor& c) const;
  double S(std::size_t r, const Cursor& c) const;
  // `block` >= 0: the formation part of that block, moved as one agent by its leader `r`.
  Cursor Advance(std::size_t r, Cursor c, double budget, int block, bool allow_motion,
                 std::vector<Event>* events) const;
  // The cursor of robot `m` of an agent whose controller moved to `c`.
  Cursor MemberCursor(std::size_t m, const Cursor& c, int block) const;
  bool SegmentMoves(std::size_t r, std::size_t i, bool formation, int block) const;
  void Sample(double t, SimResult& out);

  const WarehouseMap& map_;
  const SimConfig& config_;
  TrafficGuards guards_;
  IntersectionGrants grants_;
  std::vector<RobotRt> rt_;
  std::vector<Block> blocks_;
  std::map<std::string, OrderOutcome> outcomes_;
  std::vector<std::string> order_ids_;
};

Status Sim::Prepare() {
  std::map<std::string, std::size_t> index;
  for (std::size_t r = 0; r < rt_.size(); ++r) {
    if (rt_[r].in->plan.waypoints.empty()) {
      return InvalidArgument("simulate: robot " + rt_[r].in->id + " has an empty plan");
    }
    if (!index.emplace(rt_[r].in->id, r).second) {
      return InvalidArgument("simulate: duplicate robot id " + rt_[r].in->id);
    }
  }
  std::map<std::string, std::size_t> block_index;
  for (std::size_t r = 0; r < rt_.size(); ++r) {
    RobotRt& x = rt_[r];
    const auto& w = W(r);
    const std::size_t n = w.size();
    x.task_of.assign(n, -1);
    x.slot_block.assign(n, -1);
    x.block_at.assign(n, -1);
    std::size_t prev = 0, k = 0;
    for (std::size_t i = 1; i < n; ++i) {
      if (w[i].action != WaypointAction::kDrop) continue;
      if (k >= x.in->queue.size()) {
        return InvalidArgument("simulate: robot " + x.in->id + " has more drops than tasks");
      }
      for (std::size_t j = prev + 1; j <= i; ++j) x.task_of[j] = static_cast<int>(k);
      const QueuedTask& q = x.in->queue[k];
      if (outcomes_.find(q.order_id) == outcomes_.end()) {
        order_ids_.push_back(q.order_id);
        outcomes_[q.order_id] = {q.order_id, q.team, false, 0.0, w[i].departure(), ""};
      }
      if (q.team.size() == 3) {
        std::size_t fs = prev + 1;
        while (fs < i && w[fs].action != WaypointAction::kPick) ++fs;
        if (fs == prev + 1 || w[fs - 1].action != WaypointAction::kWait) {
          return InvalidArgument("simulate: robot " + x.in->id + ": formation task " +
                                 q.order_id + " has no rendezvous slot");
        }
        auto [it, fresh] = block_index.emplace(q.order_id, blocks_.size());
        if (fresh) {
          Block b;
          b.order_id = q.order_id;
          for (std::size_t m = 0; m < 3; ++m) {
            auto f = index.find(q.team[m]);
            if (f == index.end()) {
              return InvalidArgument("simulate: order " + q.order_id + " names unknown robot " +
                                     q.team[m]);
            }
            b.members[m] = f->second;
            b.start[m] = b.end[m] = n;  // filled below
          }
          blocks_.push_back(b);
        }
        Block& b = blocks_[it->second];
        for (std::size_t m = 0; m < 3; ++m) {
          if (b.members[m] == r) b.start[m] = fs, b.end[m] = i;
        }
        x.slot_block[fs - 1] = static_cast<int>(it->second);
        for (std::size_t j = fs; j <= i; ++j) x.block_at[j] = static_cast<int>(it->second);
      }
      prev = i;
      ++k;
    }
    if (k != x.in->queue.size()) {
      return InvalidArgument("simulate: robot " + x.in->id + " has fewer drops than tasks");
    }
    x.dur.assign(n, 0.0);
    for (std::size_t i = 0; i + 1 < n; ++i) {
      x.dur[i] = std::max(0.0, w[i + 1].eta - w[i].departure());
    }
    x.ref.resize(n);
    for (std::size_t i = 0; i < n; ++i) x.ref[i] = w[i].xy;
  }
  for (const Block& b : blocks_) {
    for (std::size_t m = 0; m < 3; ++m) {
      if (b.start[m] >= W(b.members[m]).size() ||
          b.end[m] - b.start[m] != b.end[0] - b.start[0]) {
        return InvalidArgument("simulate: formation " + b.order_id + " plans do not align");
      }
    }
    for (std::size_t k = 0; k <= b.end[0] - b.start[0]; ++k) {
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (std::size_t m = 0; m < 3; ++m) c += W(b.members[m])[b.start[m] + k].xy;
      for (std::size_t m = 0; m < 3; ++m) rt_[b.members[m]].ref[b.start[m] + k] = c / 3.0;
    }
  }
  // Reference path lengths and guarded zones.
  for (std::size_t r = 0; r < rt_.size(); ++r) {
    RobotRt& x = rt_[r];
    const auto& w = W(r);
    const std::size_t n = w.size();
    x.s.assign(n, 0.0);
    for (std::size_t i = 1; i < n; ++i) x.s[i] = x.s[i - 1] + (x.ref[i] - x.ref[i - 1]).norm();
    for (std::size_t i = 0; i < n;) {
      const int g = guards_.guard_of_point[static_cast<std::size_t>(w[i].point)];
      if (g < 0) {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j + 1 < n && guards_.guard_of_point[static_cast<std::size_t>(w[j + 1].point)] == g) ++j;
      const double c = config_.traffic.Clearance(x.block_at[i] >= 0);
      GuardRun z{static_cast<std::size_t>(g),
             {i > 0 ? w[i - 1].point : kNoPoint, j + 1 < n ? w[j + 1].point : kNoPoint},
             x.s[i] - c, x.s[j] + c, i, j};
      if (!x.zones.empty() && x.zones.back().guard == z.guard &&
          z.start_s <= x.zones.back().end_s) {
        x.zones.back().end_s = z.end_s;  // back through the same guard (a pick dock)
        x.zones.back().last = j;
        x.zones.back().movement.exit = z.movement.exit;
      } else {
        x.zones.push_back(z);
      }
      i = j + 1;
    }
    for (GuardRun& z : x.zones) {  // released at the first stop after the guard
      for (std::size_t k = z.last + 1; k < n; ++k) {
        if (w[k].dwell > 0 || w[k].action == WaypointAction::kWait || k + 1 == n) {
          z.end_s = std::min(z.end_s, x.s[k]);
          break;
        }
      }
      z.end_s = std::max(z.end_s, x.s[z.last]);
    }
    x.zstate.assign(x.zones.size(), {});
    x.c.dwell_left = std::max(0.0, w[0].eta) + w[0].dwell;
  }
  return Ok{};
}

std::string Sim::Group(std::size_t r) const {
  const RobotRt& x = rt_[r];
  if (x.split >= 0) return "F:" + blocks_[static_cast<std::size_t>(x.split)].order_id;
  const std::size_t i = std::min(x.c.index + (x.c.dwell_left > 0 ? 0 : 1), W(r).size() - 1);
  const int k = x.task_of[i];
  if (k < 0) return x.in->id;
  const QueuedTask& q = x.in->queue[static_cast<std::size_t>(k)];
  if (q.team.size() != 3) return x.in->id;
  const int bi = x.block_at[i];
  if (bi >= 0 && blocks_[static_cast<std::size_t>(bi)].active) return "F:" + q.order_id;
  // Gathering: find this task's block via the slot ahead.
  for (std::size_t j = x.c.index; j < x.slot_block.size(); ++j) {
    if (x.slot_block[j] < 0) continue;
    const Block& b = blocks_[static_cast<std::size_t>(x.slot_block[j])];
    const Eigen::Vector2d centre = x.ref[j + 1];
    if ((Pos(r, x.c) - centre).norm() <= config_.traffic.gather_radius) return "F:" + b.order_id;
    break;
  }
  return x.in->id;
}

Eigen::Vector2d Sim::Pos(std::size_t r, const Cursor& c) const {
  const auto& w = W(r);
  if (c.tau <= 0 || c.index + 1 >= w.size()) return w[c.index].xy;
  const double f = std::clamp(c.tau / rt_[r].dur[c.index], 0.0, 1.0);
  return w[c.index].xy + f * (w[c.index + 1].xy - w[c.index].xy);
}

Eigen::Vector2d Sim::Ref(std::size_t r, const Cursor& c) const {
  const RobotRt& x = rt_[r];
  if (c.tau <= 0 || c.index + 1 >= x.ref.size()) return x.ref[c.index];
  const double f = std::clamp(c.tau / x.dur[c.index], 0.0, 1.0);
  return x.ref[c.index] + f * (x.ref[c.index + 1] - x.ref[c.index]);
}

double Sim::S(std::size_t r, const Cursor& c) const {
  const RobotRt& x = rt_[r];
  if (c.tau <= 0 || c.index + 1 >= x.s.size()) return x.s[c.index];
  const double f = std::clamp(c.tau / x.dur[c.index], 0.0, 1.0);
  return x.s[c.index] + f * (x.s[c.index + 1] - x.s[c.index]);
}

bool Sim::SegmentMoves(std::size_t r, std::size_t i, bool formation, int block) const {
  if (!formation) return (W(r)[i + 1].xy - W(r)[i].xy).norm() > kEps;
  const Block& b = blocks_[static_cast<std::size_t>(block)];
  const std::size_t k = i - (b.start[0] - 1);  // steps from the slot
  for (std::size_t m = 0; m < 3; ++m) {
    const auto& w = W(b.members[m]);
    const std::size_t j = b.start[m] - 1 + k;
    if ((w[j + 1].xy - w[j].xy).norm() > kEps) return true;
  }
  return false;
}

// Moves a cursor by up to `budget` seconds of plan time. Stops at a rendezvous slot (single
// mode), at the end of the formation part (formation mode), or before a segment that moves
// when !allow_motion. Records drop completions with their offset into the step.
Cursor Sim::Advance(std::size_t r, Cursor c, double budget, int block, bool allow_motion,
                    std::vector<Event>* events) const {
  const RobotRt& x = rt_[r];
  const auto& w = W(r);
  const std::size_t n = w.size();
  const bool formation = block >= 0;
  double used = 0;
  while (!c.finished && !c.at_slot) {
    if (c.dwell_left > 0) {
      const double d = std::min(c.dwell_left, budget - used);
      c.dwell_left -= d;
      used += d;
      if (c.dwell_left > kEps) break;
      c.dwell_left = 0;
      if (w[c.index].action == WaypointAction::kDrop) events->push_back({c.index, used});
    }
    // Standing at c.index, work done: decide whether to depart.
    if (c.tau <= 0) {
      if (formation && c.index == blocks_[static_cast<std::size_t>(block)].end[0]) break;
      if (c.index + 1 >= n) {
        c.finished = true;
        break;
      }
      const int sb = x.slot_block[c.index];
      if (!formation && sb >= 0 && !blocks_[static_cast<std::size_t>(sb)].active &&
          !blocks_[static_cast<std::size_t>(sb)].finished) {
        c.at_slot = true;
        break;
      }
    }
    if (used >= budget - kEps) break;
    if (!allow_motion && x.dur[c.index] > 0 && SegmentMoves(r, c.index, formation, block)) break;
    const double step = std::min(x.dur[c.index] - c.tau, budget - used);
    c.tau += step;
    used += step;
    if (c.tau >= x.dur[c.index] - kEps) {
      ++c.index;
      c.tau = 0;
      const bool slot_wait = w[c.index].action == WaypointAction::kWait &&
                             x.slot_block[c.index] >= 0;
      c.dwell_left = slot_wait ? 0.0 : w[c.index].dwell;
      if (c.dwell_left <= 0 && w[c.index].action == WaypointAction::kDrop) {
        events->push_back({c.index, used});
      }
    } else {
      break;
    }
  }
  return c;
}

Cursor Sim::MemberCursor(std::size_t m, const Cursor& c, int block) const {
  Cursor cm = c;
  if (block < 0) return cm;
  const Block& b = blocks_[static_cast<std::size_t>(block)];
  for (std::size_t k = 0; k < 3; ++k) {
    if (b.members[k] == m) cm.index = c.index - b.start[0] + b.start[k];
  }
  return cm;
}

void Sim::Sample(double t, SimResult& out) {
  SafetyFrame frame;
  frame.t = t;
  for (std::size_t r = 0; r < rt_.size(); ++r) {
    if (rt_[r].c.finished && config_.finished_robots_leave_floor) continue;
    const bool f = Formation(r);
    const std::string group = Group(r);
    frame.robots.push_back({rt_[r].in->id, f ? group : rt_[r].in->id, group, f, Pos(r, rt_[r].c)});
  }
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < frame.robots.size(); ++i) {
    for (std::size_t j = i + 1; j < frame.robots.size(); ++j) {
      if (frame.robots[i].group == frame.robots[j].group) continue;
      best = std::min(best, (frame.robots[i].xy - frame.robots[j].xy).norm());
    }
  }
  out.times.push_back(t);
  out.min_distance.push_back(best);
  out.overall_min_distance = std::min(out.overall_min_distance, best);
  if (config_.record_frames) out.frames.push_back(std::move(frame));
}

SimResult Sim::Run() {
  SimResult out;
  const double dt = config_.time_step;
  const bool rules = config_.traffic.rules_enabled;
  Sample(0.0, out);
  std::size_t step = 0;
  double t = 0;
  while (t < config_.max_time) {
    bool all_done = true;
    for (const RobotRt& x : rt_) all_done = all_done && x.c.finished;
    if (all_done) break;
    // Rendezvous: a formation departs when all three members wait in their slots.
    for (Block& b : blocks_) {
      if (b.active || b.finished) continue;
      bool ready = true;
      for (std::size_t m = 0; m < 3; ++m) {
        const Cursor& c = rt_[b.members[m]].c;
        ready = ready && c.at_slot && c.index + 1 == b.start[m];
      }
      if (!ready) continue;
      b.active = true;
      for (std::size_t m = 0; m < 3; ++m) rt_[b.members[m]].c.at_slot = false;
    }
    // A split ends for a robot once it is eps1 from every mate still on the floor.
    for (std::size_t r = 0; r < rt_.size(); ++r) {
      RobotRt& x = rt_[r];
      if (x.split < 0) continue;
      bool apart = true;
      for (std::size_t m : blocks_[static_cast<std::size_t>(x.split)].members) {
        if (m == r || (rt_[m].c.finished && config_.finished_robots_leave_floor)) continue;
        apart = apart && (Pos(m, rt_[m].c) - Pos(r, x.c)).norm() >=
                             config_.traffic.epsilon_single_single;
      }
      if (apart || x.c.finished) x.split = -1;
    }
    // Agents: single robots, and active formations (controlled by their leader).
    struct Agent {
      std::string id;
      bool formation = false;
      std::size_t ctrl = 0;
      int block = -1;
      std::vector<std::size_t> robots;
      Eigen::Vector2d ref;
      std::string group;
    };
    std::vector<Agent> agents;
    std::vector<int> agent_of(rt_.size(), -1);
    for (std::size_t r = 0; r < rt_.size(); ++r) {
      if (agent_of[r] >= 0) continue;
      if (rt_[r].c.finished && config_.finished_robots_leave_floor) continue;
      Agent a;
      a.group = Group(r);
      if (Formation(r)) {
        const RobotRt& x = rt_[r];
        a.block = x.block_at[std::min(x.c.index + (x.c.dwell_left > 0 ? 0 : 1), W(r).size() - 1)];
        const Block& b = blocks_[static_cast<std::size_t>(a.block)];
        a.formation = true;
        a.id = a.group;
        a.ctrl = b.members[0];
        a.robots.assign(b.members.begin(), b.members.end());
      } else {
        a.id = rt_[r].in->id;
        a.ctrl = r;
        a.robots = {r};
      }
      a.ref = AgentRef(a.ctrl, rt_[a.ctrl].c, a.formation);
      for (std::size_t m : a.robots) agent_of[m] = static_cast<int>(agents.size());
      agents.push_back(std::move(a));
    }
    for (Agent& a : agents) {
      RobotRt& x = rt_[a.ctrl];
      if (x.c.finished) continue;
      const Cursor c0 = x.c;
      std::vector<Event> events;
      Cursor c1 = Advance(a.ctrl, c0, dt, a.block, true, &events);
      const Eigen::Vector2d ref1 = AgentRef(a.ctrl, c1, a.formation);
      bool moved = false;
      for (std::size_t m : a.robots) {
        moved = moved || (Pos(m, MemberCursor(m, c1, a.block)) - Pos(m, rt_[m].c)).norm() > kEps;
      }
      std::string why;
      if (rules && moved) {
        const double s1 = S(a.ctrl, c1);
        for (std::size_t z = 0; z < x.zones.size() && why.empty(); ++z) {
          ZoneState& st = x.zstate[z];
          const GuardRun& zone = x.zones[z];
          if (st.done || st.granted) continue;
          if (zone.start_s >= s1 - kEps) break;
          if (!st.requested) {
            (void)grants_.Request(zone.guard, {a.id, zone.movement, t, a.formation ? 1 : 0});
            st.requested = true;
            st.agent = a.id;
          }
          if (grants_.Granted(zone.guard, st.agent)) {
            st.granted = true;
            if (guards_.guards[zone.guard].intersection >= 0) ++out.intersection_grants;
          } else {
            why = "waiting for a grant at " + guards_.guards[zone.guard].name;
            const auto holders = grants_.Holders(zone.guard);
            if (!holders.empty()) why += " held by " + holders.front();
          }
        }
        for (std::size_t o = 0; o < agents.size() && why.empty(); ++o) {
          const Agent& b = agents[o];
          if (&b == &a) continue;
          if (b.group == a.group) {
            // Splitting members: the later-ranked one yields to the earlier ones.
            const RobotRt& xb = rt_[b.ctrl];
            if (x.split < 0 || x.split != xb.split || x.split_rank < xb.split_rank) continue;
          }
          const double eps = config_.traffic.Epsilon(a.formation, b.formation);
          const double d1 = (ref1 - b.ref).norm();
          if (d1 < eps && d1 < (a.ref - b.ref).norm() - kEps) why = "rear-end behind " + b.id;
        }
      }
      if (!why.empty()) {
        events.clear();
        c1 = Advance(a.ctrl, c0, dt, a.block, false, &events);
        x.waited += dt;
        out.total_waiting_time += dt;
        if (x.was_moving) ++out.stops;
        x.was_moving = false;
        if (x.waited > config_.max_wait) {
          char buf[64];
          std::snprintf(buf, sizeof buf, " waited %.0f s at t=%.1f s: ", x.waited, t);
          out.blocked.push_back(a.id + buf + why);
        }
      } else {
        x.waited = 0;
        x.was_moving = moved;
      }
      // Commit: the controller's cursor, and the members' aligned cursors.
      for (std::size_t m : a.robots) {
        const Cursor cm = MemberCursor(m, c1, a.block);
        out.total_distance += (Pos(m, cm) - Pos(m, rt_[m].c)).norm();
        rt_[m].c = cm;
      }
      a.ref = AgentRef(a.ctrl, x.c, a.formation);
      for (const Event& e : events) {
        const int k = x.task_of[e.index];
        if (k < 0) continue;
        OrderOutcome& o = outcomes_[x.in->queue[static_cast<std::size_t>(k)].order_id];
        o.completed = true;
        o.completion_time = t + e.offset;
      }
      if (a.formation) {
        Block& b = blocks_[static_cast<std::size_t>(a.block)];
        if (x.c.index == b.end[0] && x.c.dwell_left <= 0 && x.c.tau <= 0) {
          b.active = false;
          b.finished = true;
          // Members leave the drop front first (by their offset along the last heading).
          Eigen::Vector2d heading = Eigen::Vector2d::UnitX();
          for (std::size_t k = b.end[0]; k > b.start[0]; --k) {
            const Eigen::Vector2d d = x.ref[k] - x.ref[k - 1];
            if (d.norm() > kEps) {
              heading = d.normalized();
              break;
            }
          }
          std::array<std::pair<double, std::size_t>, 3> order;
          for (std::size_t k = 0; k < 3; ++k) {
            const std::size_t m = b.members[k];
            order[k] = {-(Pos(m, rt_[m].c) - x.ref[b.end[0]]).dot(heading) + 1e-9 * k, m};
          }
          std::sort(order.begin(), order.end());
          for (std::size_t k = 0; k < 3; ++k) {
            RobotRt& xm = rt_[order[k].second];
            if (xm.c.index + 1 >= W(order[k].second).size()) xm.c.finished = true;
            xm.was_moving = false;
            xm.split = a.block;
            xm.split_rank = static_cast<int>(k);
          }
        }
      }
      // Release grants behind the reference point (or all, when the plan is done).
      const double s = S(a.ctrl, x.c);
      for (std::size_t z = 0; z < x.zones.size(); ++z) {
        ZoneState& st = x.zstate[z];
        if (st.done) continue;
        if (x.zones[z].end_s <= s + kEps || x.c.finished) {
          if (st.requested) (void)grants_.Release(x.zones[z].guard, st.agent);
          st.done = true;
        }
      }
    }
    ++step;
    t = static_cast<double>(step) * dt;
    Sample(t, out);
    if (!out.blocked.empty()) break;
  }
  out.end_time = t;
  out.grants_issued = grants_.grants_issued();
  std::string reason = out.blocked.empty() ? "simulation time limit reached"
                                           : "blocked: " + out.blocked.front();
  for (const std::string& id : order_ids_) {
    OrderOutcome& o = outcomes_[id];
    if (o.completed) {
      out.makespan = std::max(out.makespan, o.completion_time);
    } else {
      o.failure = reason;
    }
    out.orders.push_back(o);
  }
  return out;
}

}  // namespace

bool SimResult::all_completed() const {
  return std::all_of(orders.begin(), orders.end(),
                     [](const OrderOutcome& o) { return o.completed; });
}

Result<SimResult> Simulate(const WarehouseMap& map, const std::vector<SimRobot>& robots,
                           const SimConfig& config) {
  if (!(config.time_step > 0) || !std::isfinite(config.time_step) || !(config.max_wait > 0) ||
      !(config.max_time > 0)) {
    return InvalidArgument("simulate: time_step, max_wait and max_time must be > 0");
  }
  Status valid = config.traffic.Validate();
  if (!valid.ok()) return valid.error();
  SimConfig run = config;
  run.record_frames = config.record_frames || config.check_safety;
  Sim sim(map, robots, run);
  Status prepared = sim.Prepare();
  if (!prepared.ok()) return prepared.error();
  SimResult out = sim.Run();
  if (config.check_safety) {
    out.safety = CheckSafety(out.frames, map, config.traffic);
    if (!config.record_frames) std::vector<SafetyFrame>().swap(out.frames);
  }
  return out;
}

Result<SimResult> Simulate(const FleetState& state, const SimConfig& config) {
  std::vector<SimRobot> robots;
  for (std::size_t r = 0; r < state.robot_count(); ++r) {
    robots.push_back({state.robot_id(r), state.plan(r), state.queue(r)});
  }
  return Simulate(state.map(), robots, config);
}

}  // namespace dispatch::engine
