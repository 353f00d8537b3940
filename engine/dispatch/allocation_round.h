// Allocation rounds (Chu2024 §2, issue 15 §1): one round of the chosen strategy over the
// robots' current state, the same for the service (on its allocation worker) and the
// simulator.
//
// A round builds a fresh FleetState with every robot at its start point now, replays each
// robot's remaining orders into its queue from its stored plan (ReplayQueue: the stored
// waypoints, re-timed from the queue's end, no routing), so that bids count the whole queue
// (eq. (3)) and the traffic prediction sees every robot's work, then auctions the pending
// orders one at a time in their allocation order (AllocationOrderLess). Each award carries
// the winners' new plan segments, to be spliced into their assignments (AppendOrder).
//
// A replayed queue starts at the first start of a prediction bucket at or after now (at most
// TrafficPredictionConfig::bucket_seconds later): replayed once from time 0, it is then the
// same queue moved by whole buckets in every round until the robot, its start, its progress or
// its orders change. The runner keeps the fleet from one round to the next: a robot's entry
// that the last round did not change (no award) and whose queue and ready bucket are the same
// stays as it is, instead of being replayed and predicted again (a robot reaches a waypoint
// every second or so; rounds come every 0.1 s on a busy floor). Every entry is what a fresh
// fleet would hold, so what a round returns is still a function of its input alone (a test
// runs rounds on one runner and each on a new one). The prediction's buckets start at the
// round's ten-minute step (a whole number of buckets after TrafficPredictionConfig::
// origin_time): a new step builds a new fleet, so the kept counts hold at most ten minutes of
// the past.
//
// RoundRunner is not thread-safe: one round at a time (it keeps the predictor's zone index
// and the replayed queues between rounds). Inputs are values; nothing else is read.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/allocation/allocator.h"
#include "engine/allocation/fleet_state.h"
#include "engine/dispatch/assignment.h"

namespace dispatch::engine {

// "R2" < "R10": letters compare as text, digit runs as numbers (robot bidding order, and the
// tie-break of orders created at the same time: "ord-999999" < "ord-1000000").
bool NaturalLess(const std::string& a, const std::string& b);
// Allocation order: priority descending, then creation time, then id (NaturalLess).
bool AllocationOrderLess(const Order& a, const Order& b);

// A round's view of one robot.
struct RoundRobot {
  std::string id;
  PointId start = kNoPoint;  // where a new plan of it starts (standing or arriving there)
  // Its plan as the round starts (shared, never changed once made); null or no order_ids: no
  // queue.
  std::shared_ptr<const Assignment> assignment;
  bool has_queue() const { return assignment && !assignment->order_ids.empty(); }
  std::uint64_t last_reached = 0;
  std::vector<std::shared_ptr<const Order>> queue;  // the orders of assignment.order_ids
  RobotKind kind = RobotKind::kDifferential;        // four-wheel steer: see FleetState::UseFreeSpace
};

struct RoundInput {
  double now = 0.0;
  std::vector<RoundRobot> robots;                     // bidding order (NaturalLess of ids)
  std::vector<std::shared_ptr<const Order>> pending;  // allocation order
};

struct RoundAward {
  std::string order_id;
  AwardExplanation award;
  // Per winner (award.winners order): the new waypoints (from its start for a robot with no
  // queue), and the departure the first of them follows (robots with a queue).
  std::vector<std::vector<Waypoint>> segments;
  std::vector<double> after_departure;
  double seconds = 0.0;  // the strategy's time for this order (RoundRunner's stopwatch)
};

struct RoundResult {
  std::vector<RoundAward> awards;
  std::vector<std::string> notes;  // orders not allocated and queues not replayed, with why
};

class RoundRunner {
 public:
  // `stopwatch` (optional) reads a clock in seconds, for RoundAward::seconds.
  RoundRunner(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
              AllocationConfig config, std::unique_ptr<Allocator> allocator,
              std::function<double()> stopwatch = {});

  RoundResult Run(const RoundInput& input);
  const Allocator& allocator() const { return *allocator_; }

 private:
  // Appends the robot's remaining orders (the first from the picks it has not reached yet)
  // to its queue in `fleet`, not yet published to its traffic predictor (FleetState::Publish:
  // the caller, once per robot). False (with a note) when a part of the queue could not be
  // replayed.
  bool ReplayQueue(FleetState& fleet, std::size_t index, const RoundRobot& robot,
                   std::vector<std::string>& notes) const;
  // A robot's replayed queue (from ready time 0) with the notes its replay gave, and what it
  // was replayed from.
  struct Replay {
    RoundRobot robot;
    std::shared_ptr<const FleetState::RobotSnapshot> snapshot;  // null: not kept
    std::vector<std::string> notes;
    bool Matches(const RoundRobot& r) const;
  };
  // Replays robot's queue into its entry `index` of `fleet` from ready time 0 and moves it to
  // `bucket` (FleetState::Settle); with a snapshot when `keep`. Null (nothing changed) when the
  // entry cannot be reset to the robot's start.
  std::shared_ptr<const Replay> ReplayAnew(FleetState& fleet, std::size_t index, const RoundRobot& robot,
                                           std::size_t bucket, bool keep);
  // The kept fleet made ready for this round (see above): rebuilt when the robots, their
  // kinds or the prediction's origin step change; each robot's entry its replayed queue from
  // the round's ready bucket or its start now, as a fresh fleet would hold them. Null (with a
  // note) when the fleet cannot be built.
  FleetState* Prepare(const RoundInput& input, std::vector<std::string>& notes);
  // What the kept fleet's entry of a robot holds: its replay (null: its start, published at
  // the round's time) from `bucket`, as of revision `revision`; the rounds in a row it has
  // held that replay.
  struct KeptRobot {
    bool installed = false;
    std::shared_ptr<const Replay> replay;
    std::size_t bucket = 0;
    std::uint64_t revision = 0;
    std::size_t rounds = 0;
  };
  // The map's free-space regions for four-wheel-steer robots (engine/motion/free_space_plan.h),
  // built by the first round that needs them; null on a map without any (or when they cannot
  // be built: a note says why, once).
  std::shared_ptr<const FreeSpaceMotion> FreeSpace(std::vector<std::string>& notes);

  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
  AllocationConfig config_;
  std::unique_ptr<Allocator> allocator_;
  std::function<double()> stopwatch_;
  std::shared_ptr<const ZoneIndex> zone_index_;  // built by the first round, kept
  std::shared_ptr<const FreeSpaceMotion> free_space_;
  bool free_space_tried_ = false;
  std::unordered_map<std::string, std::shared_ptr<const Replay>> replays_;  // the last round's, by robot id
  std::optional<FleetState> kept_;  // the fleet kept from round to round, without its awards
  double kept_origin_ = 0.0;        // its prediction's origin
  std::vector<KeptRobot> kept_robots_;
};

}  // namespace dispatch::engine
