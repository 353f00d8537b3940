// BuildSnapshot: the Snapshot (server/snapshot.h) of the dispatcher loop's state - the order
// views, the core's robots with their sessions and traffic state, the live zone densities, the
// gate's intersections and counters. Called on the loop thread; the result is immutable.
#pragma once

#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "engine/dispatch/journaled_core.h"
#include "server/order_views.h"
#include "server/robot_sessions.h"
#include "server/snapshot.h"

namespace dispatch::server {

// What the snapshot holds besides the book, the core and the sessions.
struct SnapshotFacts {
  std::uint64_t version = 0;
  double time = 0.0;  // dispatcher seconds
  std::string map_version;
  std::string strategy;
  double time_scale = 1.0;
  std::uint64_t implausible_reports = 0;
  const std::set<std::string>* awaiting_reconnect = nullptr;  // robots the restart wait is for
  engine::MinDistance min_distance;
};

std::shared_ptr<Snapshot> BuildSnapshot(const engine::WarehouseMap& map, const engine::JournaledCore& core,
                                        const RobotSessions& sessions, OrderViews& book, const SnapshotFacts& facts);

}  // namespace dispatch::server
