// The order-stream simulator's state, shared by order_stream.cpp (the loop, allocation, single
// robots, sampling) and order_stream_teams.cpp (formations). Internal; see order_stream.h.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "engine/dispatch/strategy.h"
#include "engine/sim/order_stream.h"

namespace dispatch::engine::stream_sim {

inline constexpr double kTiny = 1e-9;
inline constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

struct Task {
  std::size_t order = 0;  // index into the outcomes
  std::vector<PointId> picks;
  PointId drop = kNoPoint;
  double work = 0.0;
  std::size_t next_stop = 0;  // 0..picks.size(); picks.size() = the drop
  int team = -1;              // a member's part of a formation order: the team (teams_ index)
  int member = -1;            // and its slot there (0 = the front vertex, the leader)
  PointId Stop() const { return next_stop < picks.size() ? picks[next_stop] : drop; }
};

// A member's place in its formation (Chu2024 §3.2).
enum class Slot {
  kNone,    // on its own (approaching the rendezvous, or no formation at all)
  kToSlot,  // joined: driving straight into its slot around the rendezvous point
  kInSlot,  // in its slot: moves with the team agent (rigid triangle, eq. (9))
  kOut,     // leaving: driving from its slot to the point it was placed at
};

// A robot, or a formation's agent (agent = true): every Bot is the controller agent of the
// same index.
struct Bot {
  std::string id;
  PointId home = kNoPoint;
  std::deque<Task> tasks;
  double dwell = 0.0;  // work left at the current stop
  bool moving = false;
  Eigen::Vector2d from = Eigen::Vector2d::Zero(), to = Eigen::Vector2d::Zero();
  double s = 0.0, len = 0.0, speed = 1.0;
  bool waiting = false;
  bool removed = false;       // faulted (or a pooled agent): off the floor
  bool parked_aside = false;  // idle and already sent to a siding once
  bool left_start = false;    // past the clearance on the current arc
  // Formations.
  bool agent = false;  // a formation's agent, not a robot
  int team = -1;       // the team whose task it works on (approach, slot, leaving)
  int former = -1;     // the team it left, until it is point_clearance from its mates
  int member = -1;     // its slot (0 = the front vertex, the leader)
  Slot slot = Slot::kNone;
  double join_wait = 0.0;  // s waited at the rendezvous point for the agent to be placed
  // kToSlot: from the point before P along its arc to `via` (D_f short of P), then into the
  // slot; via_s = that first leg's length (0: straight from `from` to `to`).
  Eigen::Vector2d via = Eigen::Vector2d::Zero();
  double via_s = 0.0;
  // Agents: the structure's heading and its turn in place before the current arc.
  double heading = 0.0, turn_from = 0.0, turn_s = 0.0, turn_len = 0.0;
};

struct Team {
  enum class Phase { kGathering, kMoving, kLeaving, kDone };
  std::size_t order = 0;             // outcome index
  std::vector<std::size_t> members;  // bots, leader first
  Task task;                         // the order's stops, driven by the agent
  int group = 0;                     // controller group of the members and the agent
  Phase phase = Phase::kGathering;
  std::size_t agent = kNone;  // its agent's bot index (kNone: not on the floor)
  double heading0 = 0.0;      // structure heading at the rendezvous: its first arc's
  // The rendezvous is called once every member is free for it (the order first in its queue):
  // each then leaves for P when it would arrive with the slowest (depart[i]); until then it
  // waits like an idle robot, so a formation does not hold P while one member is still busy.
  bool called = false;
  std::vector<double> depart;
  PointId leave_at = kNoPoint;  // where members go back to the controller (drop; P if broken)
  double leave_wait = 0.0;      // s leaving without progress (no member placed or driving out)
  bool apart = false;           // done, and every former member is eps1 from its mates
};

class StreamSim {
 public:
  StreamSim(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
            const StreamConfig& config, TrafficController ctl);

  Status Init(const std::vector<FleetRobot>& robots, std::vector<Order> orders);
  StreamResult Run();

 private:
  // order_stream.cpp
  void Release(double t);
  void Enqueue(std::size_t r, std::size_t k);  // orders_[k] to robot r's queue
  void Move(std::size_t r, double t);
  void FinishStop(std::size_t r, double t);
  void FailTasks(std::size_t r, const std::string& why);
  // The PlanTask of `task` from stop `first` on (allocation rounds); false when only the
  // drop's work is left (it is in the ready time).
  static bool Remaining(const Task& task, std::size_t first, PlanTask& out);
  void Complete(std::size_t outcome, double t);
  void Fail(std::size_t outcome, const std::string& why);  // once per order
  Eigen::Vector2d Position(std::size_t r) const;
  bool SameAgent(const Bot& a, const Bot& b) const;
  void Sample(double t);
  void Record(double t);  // a CheckSafety frame

  // order_stream_teams.cpp
  void EnqueueTeam(const std::vector<std::size_t>& members, std::size_t k);
  // Where a member's queue continues and when (allocation rounds).
  void MemberStart(std::size_t r, double t, PointId& start, double& ready) const;
  // The remaining stops of a member's formation task (allocation rounds); false if none.
  bool MemberRemaining(const Task& task, PlanTask& out) const;
  void SyncGroup(std::size_t r);
  void KeepFormer(Bot& b, int team);  // b left `team` (or its formation broke up)
  // Approaching member r at the rendezvous: joins (true) or waits for the point (false).
  bool Join(std::size_t r, double t);
  // A member free for its formation that must not leave for P yet (the rendezvous is not
  // called, or its departure time has not come).
  bool HoldsForRendezvous(const Bot& b, double t) const;
  void CallRendezvous(Team& team, double t);
  // The gathering agent waits (for the controller's deadlock search) on a member whose wait
  // leads back to the agent.
  void AwaitMembers(std::size_t team, double t);
  // It could not join for `budget` seconds more; too long fails the order (blocked).
  void WaitToJoin(std::size_t r, double budget);
  bool PlaceAgent(std::size_t team, PointId p, double t);
  void PoolAgent(Team& team);
  void MoveMember(std::size_t r);
  void TeamDropDone(std::size_t agent, double t);  // the agent finished the drop's work
  void StepTeams(double t);
  void BreakTeam(std::size_t team, const std::string& why);
  // Its agent was blocked on the way: the order has failed, the members leave where it stands.
  void DissolveBlocked(std::size_t agent);
  bool StepLeaving(std::size_t team, double t);
  PointId PlaceOff(std::size_t team, std::size_t member, double t);
  // Sends an idle robot (or a member waiting for its rendezvous call) aside, off keep_clear.
  bool NudgeIdle(std::size_t r, double t, const std::vector<PointId>& keep_clear);
  void CheckApart(std::size_t team);
  Eigen::Vector2d SlotPosition(const Team& team, int member) const;
  double TeamHeading(const Bot& agent) const;

  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
  std::shared_ptr<const ZoneIndex> zone_index_;  // kept between allocation rounds
  const StreamConfig& config_;
  TrafficController ctl_;
  std::vector<Bot> bots_;
  std::vector<Team> teams_;
  std::vector<std::size_t> active_teams_;  // not yet apart
  std::vector<std::size_t> agent_pool_;    // removed agents, reusable
  std::vector<Order> orders_;              // by release time
  std::vector<std::size_t> outcome_of_;    // orders_[k] -> out_.orders index
  std::vector<bool> terminal_of_;          // per outcome: completed or failed
  std::size_t next_release_ = 0;
  double next_allocation_ = 0.0;
  std::size_t terminal_ = 0;
  std::unique_ptr<Allocator> allocator_;  // MakeAllocator (null: preassigned)
  StreamResult out_;
  double clearance_ = 0.6;  // TrafficControllerConfig::point_clearance
  double radius_ = 0.0;     // the formation's D_f
  // Spatial hash for the distance series.
  std::vector<int> head_;
  std::vector<std::uint32_t> head_stamp_;
  std::vector<int> next_in_cell_;
  std::uint32_t stamp_ = 0;
  int cols_ = 1, rows_ = 1;
  std::vector<SafetyFrame> frames_;  // check_safety
};

}  // namespace dispatch::engine::stream_sim
