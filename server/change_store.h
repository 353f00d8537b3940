// StoreChange: what one change of the dispatch core (engine::Change) writes to the store, in
// one transaction - each order line as a transition or a progress note (with an award's
// allocation explanation after it), the new plans, and the records of the robots it touches
// (their queues, and the message sequences its messages will use, reserved before they are
// sent). On failure nothing is written.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "engine/common/result.h"
#include "engine/dispatch/dispatch_core.h"
#include "storage/store.h"

namespace dispatch::server {

// `award_details`: per award of the change's round, its explanation as journaled (null: not
// a round). `record_of`: a robot's record as it stands before the change. Returns the journal
// events written, in order. `actor`: who made the change (its state changes' actor: the token
// name of a cancel, "" for the dispatcher's own changes).
engine::Result<std::vector<storage::OrderEvent>> StoreChange(
    storage::Store& store, const engine::Change& change, const std::vector<std::string>* award_details,
    const std::function<storage::RobotRecord(const std::string&)>& record_of, const std::string& actor = "");

}  // namespace dispatch::server
