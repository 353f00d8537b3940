// One simulated robot of fleet-sim (SPEC §5): the robot side of FleetService.Connect without
// the network, so it is tested on its own.
//
// Model. The robot stands on or drives between the waypoints of its current plan, in
// dispatcher time (seconds; the server's clock). It drives straight towards the next
// waypoint at up to `speed` m/s, never past the last released waypoint (VDA 5050 horizon),
// and never leaves a waypoint before that waypoint's planned departure (eta + dwell): ahead
// of plan it waits, behind plan it goes at full speed. At pick and drop waypoints it stands
// `dwell` seconds after arriving, then reports the TaskEvent (picked / dropped). It reports
// WaypointReached once per waypoint, in order.
//
// Server messages (Apply): a message whose sequence is not above the last applied one is
// ignored (repeats after a reconnect are harmless); Assignment replaces the plan; PlanUpdate
// replaces its tail; Grant and Resume raise the release horizon; Hold stops the robot at once
// (or at a waypoint) until Resume; Cancel voids the named orders' waypoints (all when none
// are named): the robot stops at its next waypoint and keeps what remains.
//
// Lost events. The server does not acknowledge robot messages, so an event sent just before
// a stream broke (or a server crash) may be lost. A lost drop would leave its order open for
// ever, so when the server sends a plan (Assignment or PlanUpdate) that still holds a drop
// waypoint this robot has already finished for the same order, the robot reports that
// TaskEvent again (from the next Step). The server ignores repeats. Lost WaypointReached and
// picked events need no repeat: state reports carry the last waypoint, and a drop starts an
// order that missed its pick.
//
// Turning (set_turn_time, fleet-sim --turn-time): before each leg whose heading differs from
// the one it drove last it turns in place, turn_time seconds per 90 degrees (Wang2019's t_c;
// none before its first move), as the engine's simulated robot (engine/sim/waypoint_robot.h)
// and the dispatcher's --turn-time plans it.
//
// Four-wheel-steer motion (a waypoint with a heading and a motion mode: the dispatcher plans
// such robots by the hybrid A* inside free-space regions, engine/motion/free_space_plan.h;
// reached, any waypoint with a heading sets the robot's): the robot drives the
// leg without turning first and without facing along it — a crab keeps its heading, an arc
// or a spin turns it evenly over the leg (a spin, a leg of no length, at once) — and reaches
// the waypoint with the planned heading.
//
// Faults for tests of the server: a stalled robot does not move (it still talks); a slow
// robot drives at speed * slow_factor; a muted robot is dead: it neither moves nor produces
// events from then on (fleet-sim also stops sending anything for it, see fleet_sim.cpp).
//
// Not thread-safe: one owner (fleet-sim's loop) drives it.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "warehouse/dispatch/v1/fleet.pb.h"

namespace dispatch::clients {

namespace v1 = ::warehouse::dispatch::v1;

class SimRobot {
 public:
  SimRobot(std::string id, const Eigen::Vector2d& position, double speed);

  const std::string& id() const { return id_; }
  const Eigen::Vector2d& position() const { return position_; }
  double heading() const { return heading_; }
  double speed() const { return current_speed_; }
  std::uint64_t last_applied_sequence() const { return last_applied_; }
  bool held() const { return held_; }
  // Set while the robot stands ready to drive on (arrived, its planned departure passed, not
  // held) and only the release horizon keeps it: the dispatcher time it became ready. A Hold
  // clears it (a traffic wait the server announced is not release latency); so does the
  // release that lets it go (Apply returns the wait it ended through `released_after`).
  std::optional<double> waiting_for_release_since() const { return ready_since_; }
  // No plan left: standing on its last waypoint (or never given one), not working.
  bool idle() const;
  std::size_t pending_waypoints() const { return waypoints_.size(); }

  void set_stalled(bool stalled) { stalled_ = stalled; }
  void set_slow_factor(double factor) { slow_factor_ = factor; }
  void set_turn_time(double seconds_per_90) { turn_time_ = seconds_per_90; }
  // What its Hello says it is (differential by default; four-wheel steer: see above).
  void set_kind(v1::RobotKind kind) { kind_ = kind; }
  // Permanent: a muted robot stands still and Step produces nothing.
  void set_muted() { muted_ = true; }
  bool muted() const { return muted_; }

  // The first message of a stream.
  v1::RobotMessage Hello() const;
  // Applies one server message (see the file comment). Returns false for a message it
  // ignored as already applied. `now` (dispatcher time the message arrived, or < 0 when
  // unknown): when the message releases a robot that stood waiting for it, *released_after
  // gets how long it waited (dispatcher seconds).
  bool Apply(const v1::ServerMessage& message, double now = -1.0, std::optional<double>* released_after = nullptr);
  // Advances to dispatcher time `now` (>= the previous call's); appends the events that
  // happened (WaypointReached, TaskEvent) to `out`.
  void Step(double now, std::vector<v1::RobotMessage>& out);
  // A state report for now.
  v1::RobotMessage Report() const;

 private:
  struct Waypoint {
    v1::TimedWaypoint wp;
    bool arrived = false;
    double reported = 0.0;  // the step (dispatcher time) whose events reported the arrival
  };
  void AdoptWaypoints(const google::protobuf::RepeatedPtrField<v1::TimedWaypoint>& wps);
  void ArriveAt(Waypoint& w, double time, std::vector<v1::RobotMessage>& out);
  // A pick or drop finished: reports it (and remembers drops, see "Lost events").
  void Finished(const v1::TimedWaypoint& w, std::vector<v1::RobotMessage>& out);
  bool MayDriveTo(const Waypoint& w) const;
  // Queues drop events to report again for finished drops that `wps` still holds.
  void RepeatFinishedDrops(const google::protobuf::RepeatedPtrField<v1::TimedWaypoint>& wps);

  std::string id_;
  Eigen::Vector2d position_;
  double heading_ = 0.0;
  double speed_;
  double current_speed_ = 0.0;
  double now_ = 0.0;
  bool started_ = false;

  std::uint64_t last_applied_ = 0;
  std::deque<Waypoint> waypoints_;  // the front is the one being driven to (or stood on)
  std::uint64_t released_up_to_ = 0;
  std::uint64_t last_reached_ = 0;
  bool held_ = false;
  std::uint64_t hold_at_ = 0;  // stop at this waypoint (0: at once)
  std::optional<double> ready_since_;  // see waiting_for_release_since()
  bool dwelling_ = false;
  double dwell_until_ = 0.0;
  v1::TimedWaypoint dwell_wp_;
  bool stalled_ = false;
  double slow_factor_ = 1.0;
  double turn_time_ = 0.0;          // s per 90 degrees
  v1::RobotKind kind_ = v1::ROBOT_KIND_DIFFERENTIAL;
  bool has_heading_ = false;        // it has moved (before, its heading is not known)
  std::uint64_t turning_to_ = 0;    // the waypoint (sequence) it turned, or turns, towards
  double turn_end_ = 0.0;           // when that turn is done
  Eigen::Vector2d leg_from_ = Eigen::Vector2d::Zero();  // where the leg being driven began
  double leg_from_heading_ = 0.0;   // and the heading it began with
  bool muted_ = false;
  // Drops finished (waypoint sequence -> order id), the most recent kMaxFinishedDrops.
  std::deque<std::pair<std::uint64_t, std::string>> finished_drops_;
  std::vector<v1::RobotMessage> repeats_;  // events to report again at the next Step
};

}  // namespace dispatch::clients
