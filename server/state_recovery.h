// RecoverState: the dispatcher loop's state at start-up, read back from the store
// (dispatcher.h, "Durability" and "Restart"):
// - the order views (OrderViews::Load), each open order entered in the core with its robots;
// - every stored robot, in the core with its stored plan and operator marks and in the sessions (its message
//   sequences), offline until it reconnects;
// - with traffic control, the robots that were on line when the old process stopped are
//   awaited by the restart wait (where they are now is known when they report); the others
//   are placed in the gate at their stored points at once.
// Called on the loop's state before the loop starts; logs what it recovered.
#pragma once

#include <cstdint>

#include "engine/common/result.h"
#include "engine/dispatch/journaled_core.h"
#include "server/order_views.h"
#include "server/restart_wait.h"
#include "server/robot_sessions.h"
#include "storage/store.h"

namespace dispatch::server {

struct RecoveredState {
  double latest_time = 0.0;  // the latest time stored (0 at least): the dispatcher's clock goes on from it
  std::int64_t last_order_number = 0;  // of the "ord-N" ids
};

// Errors: the store cannot be read.
engine::Result<RecoveredState> RecoverState(storage::Store& store, bool traffic_control, OrderViews& book,
                                            engine::JournaledCore& core, RobotSessions& sessions,
                                            RestartWait& restart_wait);

}  // namespace dispatch::server
