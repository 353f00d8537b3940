// A simulated robot that follows the dispatch core's messages (issue 15 §3: the simulator is
// the core plus a motion model): it stands on or drives between the waypoints of its current
// plan, straight towards the next one at up to `speed` m/s, never past the last released
// waypoint, never leaving a waypoint before its planned departure (eta + dwell: ahead of plan
// it waits, behind plan it goes at full speed), turning in place first where its heading
// changes (`turn_time` seconds per 90 degrees, as BuildPlan times it; none before its first
// move). At a waypoint with a dwell it stands that long;
// at a pick or drop it then reports the pick or drop. Every waypoint reached is reported once,
// in order.
//
// Messages (Apply): an Assignment replaces the plan, a PlanUpdate its tail from from_sequence;
// Grant and Resume raise the release horizon; Hold stops it at once (or at a waypoint) until
// Resume; Cancel voids the named orders' waypoints (it stops at its next waypoint).
//
// The same rules as the wire robot of fleet-sim (clients/sim_robot.h), on the engine's values
// and in process. Not thread-safe: one owner.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "engine/dispatch/robot_message.h"

namespace dispatch::engine {

struct RobotEvent {
  enum class Kind { kReached, kPicked, kDropped };
  Kind kind = Kind::kReached;
  std::uint64_t sequence = 0;  // the waypoint
  std::string order_id;        // kPicked, kDropped
};

class alignas(64) WaypointRobot {
 public:
  WaypointRobot(std::string id, const Eigen::Vector2d& xy, double speed, double turn_time = 0.0);

  const std::string& id() const { return id_; }
  const Eigen::Vector2d& xy() const { return xy_; }
  double heading() const { return heading_; }
  std::uint64_t last_reached() const { return last_reached_; }
  bool moving() const { return moving_; }
  bool working() const { return dwelling_; }
  // No plan left: standing on its last waypoint (or never given one), not working.
  bool idle() const;
  double driven() const { return driven_; }  // metres so far

  void Apply(const RobotMessage& message);
  // Advances to `now` (>= the previous call's), appending what happened to `out`.
  void Step(double now, std::vector<RobotEvent>& out);

 private:
  struct Stop {
    Waypoint wp;
    std::string order_id;
    bool arrived = false;
  };
  void Adopt(const std::vector<MessageWaypoint>& wps);
  void Arrive(Stop& s, double t, std::vector<RobotEvent>& out);
  void Finish(const Stop& s, std::vector<RobotEvent>& out) const;
  bool Released(const Stop& s) const { return static_cast<std::uint64_t>(s.wp.seq) <= released_up_to_; }

  // The stops ahead, the front first: a vector read from `head` (the stops driven past are
  // dropped in batches), so a step reads its front without a deque's chunk bookkeeping.
  struct StopQueue {
    std::vector<Stop> items;
    std::size_t head = 0;
    bool empty() const { return head == items.size(); }
    std::size_t size() const { return items.size() - head; }
    Stop& front() { return items[head]; }
    const Stop& front() const { return items[head]; }
    const Stop& operator[](std::size_t i) const { return items[head + i]; }
    const Stop& back() const { return items.back(); }
    std::vector<Stop>::const_iterator begin() const { return items.begin() + static_cast<std::ptrdiff_t>(head); }
    std::vector<Stop>::const_iterator end() const { return items.end(); }
    void push_back(Stop s) { items.push_back(std::move(s)); }
    void pop_back() { items.pop_back(); }  // not empty
    void pop_front() {                     // not empty
      if (++head == items.size()) {
        clear();
      } else if (head >= 32 && 2 * head >= items.size()) {
        items.erase(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(head));
        head = 0;
      }
    }
    void clear() {
      items.clear();
      head = 0;
    }
  };

  // What every step reads first, together in the first cache line (the stops' vector in the
  // second): 500 robots' steps do not fit in a core's cache.
  double now_ = 0.0;
  bool started_ = false;
  bool moving_ = false;
  bool held_ = false;
  bool dwelling_ = false;
  bool has_heading_ = false;  // it has moved (before, its heading is not known)
  Eigen::Vector2d xy_;
  std::uint64_t released_up_to_ = 0;
  std::uint64_t hold_at_ = 0;  // stop at this waypoint (0: at once)
  double dwell_until_ = 0.0;
  double speed_;
  StopQueue stops_;  // the front is the one driven to (or stood on)
  double heading_ = 0.0;
  double turn_time_;            // s per 90 degrees
  int turning_to_ = -1;         // the waypoint (seq) it turned, or turns, towards
  double turn_end_ = 0.0;       // when that turn is done
  double driven_ = 0.0;
  std::uint64_t last_reached_ = 0;
  std::string id_;
  Stop dwell_stop_;
};

}  // namespace dispatch::engine
