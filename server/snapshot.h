// Snapshot: the immutable picture of the dispatcher's state that the loop publishes after
// every batch of commands (SPEC §4 "Concurrency": queues in, snapshots out). Readers (gRPC
// GetOrder/ListOrders, REST) take a shared_ptr<const Snapshot> and never touch the loop's
// state or locks. Orders are shared between consecutive snapshots (copy on write per order).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/allocation/bid.h"
#include "storage/store.h"

namespace dispatch::server {

// An award and the weights it was made with (journaled, so it survives restarts).
struct AllocationRecord {
  engine::AwardExplanation award;
  double alpha = 0.0;
  double beta = 0.0;
  double zeta = 0.0;
  double time = 0.0;  // dispatcher seconds when the auction ran
  // How many bids there were; award.bids / companion_bids keep the best (KeepBestBids).
  std::size_t bids_total = 0;
  std::size_t companion_bids_total = 0;
};

struct OrderView {
  storage::OrderRecord record;  // order (current state), robots, reason, updated_time
  std::optional<AllocationRecord> explanation;  // the auction behind the award
  std::optional<double> finished_time;  // set once terminal
  std::set<std::string> dropped_by;     // team members that reported the drop
};

struct RobotView {
  engine::Robot robot;  // pose, state (offline when not connected), current point, queue
  std::string kind;
  bool connected = false;
  double last_seen = 0.0;  // dispatcher seconds
  std::uint64_t plan_id = 0;
  std::size_t waypoints = 0;  // in its current plan
  bool held = false;          // a traffic Hold is in force
  std::string hold_reason;
  engine::OperatorMarks marks;  // operator commands in force
  engine::PointId sent_to = engine::kNoPoint;  // the station it is sent to, while on its way
  std::string formation;      // the formation order whose team it is in ("": none)
};

// A zone's live density (Chu2024 eq. (7) with the robots there now): robots / area.
struct ZoneView {
  std::vector<std::string> robots;  // connected robots whose position is in the zone
  double density = 0.0;             // robots per m^2
};

// A map intersection's grant: who holds it, who waits (robot ids).
struct IntersectionView {
  std::vector<std::string> holders;
  std::vector<std::string> waiting;
};

// The traffic layer's counters and the closest two robots seen (engine/traffic/traffic_gate.h).
struct TrafficView {
  bool enabled = false;
  std::uint64_t grants = 0;    // releases sent as Grant messages
  std::uint64_t holds = 0;     // Hold messages
  std::uint64_t replans = 0;   // legs re-planned on the controller's word (detours, back-offs)
  std::size_t deadlocks_resolved = 0;
  std::size_t head_on_conflicts = 0;
  std::size_t nudges = 0;
  std::uint64_t implausible_reports = 0;  // robot reports not taken (engine/dispatch/report_check.h)
  double min_distance = -1.0;  // m between robot centres of different agents; < 0: none yet
  std::string min_pair_a, min_pair_b;
  double min_time = 0.0;
  // After a restart: robots the gate waits for before it releases anything (Dispatcher).
  std::vector<std::string> awaiting_reconnect;
};

struct Snapshot {
  std::uint64_t version = 0;  // increases with every publish
  double time = 0.0;          // dispatcher seconds at publish
  std::string map_name;
  std::string map_version;
  std::string strategy;
  double time_scale = 1.0;
  // Every open order and the newest finished ones (DispatcherOptions::finished_retained), in
  // submission order; the older finished ones are only in the store (Dispatcher::FindAnywhere).
  std::vector<std::shared_ptr<const OrderView>> orders;
  // How many finished orders, by state, are only in the store (not in `orders`).
  std::map<engine::OrderState, std::uint64_t> finished_in_store;
  // Order id / client id -> index in `orders`; shared by snapshots until the set changes.
  struct OrderIndex {
    std::unordered_map<std::string, std::size_t> by_id, by_client_id;
  };
  std::shared_ptr<const OrderIndex> index = std::make_shared<const OrderIndex>();
  std::map<std::string, RobotView> robots;                    // by id
  TrafficView traffic;
  std::vector<ZoneView> zones;                  // index = map zone id
  std::vector<IntersectionView> intersections;  // index = map intersection (empty: no control)

  std::shared_ptr<const OrderView> FindOrder(const std::string& id) const {
    auto it = index->by_id.find(id);
    return it == index->by_id.end() ? nullptr : orders[it->second];
  }
  std::shared_ptr<const OrderView> FindClientOrder(const std::string& client_id) const {
    auto it = index->by_client_id.find(client_id);
    return it == index->by_client_id.end() ? nullptr : orders[it->second];
  }
};

}  // namespace dispatch::server
