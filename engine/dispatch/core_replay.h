// CoreReplay: a recorded run fed through a fresh dispatch core again (issue 15 §4), one
// journal entry at a time (engine/dispatch/core_journal.h). Each entry makes the same call the
// recording made; an allocation round is run again here by the same strategy on the inputs the
// core makes now, and its awards replace the recorded ones. Feed returns what the call gave
// back, described as the recording describes it: equal lines, entry after entry, mean the
// core decided the same awards, grants, holds and order states.
//
// It also keeps what a reader of the run wants: every order's robots and times, and the
// robot-seconds spent on hold (from each Hold to the next Grant or Resume of that robot).
//
// Not thread-safe.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "engine/allocation/allocation_config.h"
#include "engine/common/result.h"
#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/core_journal.h"
#include "engine/dispatch/dispatch_core.h"

namespace dispatch::engine {

// What a run was started with: what a replay needs to build the same core.
struct ReplaySetup {
  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
  CoreOptions core;
  std::string strategy = "auction";  // MakeAllocator's names
  AllocationConfig allocation;
};

// One order as the run dispatched it.
struct OrderTrace {
  std::string id;
  bool formation = false;
  double created = 0.0;
  std::optional<double> assigned, started, finished;
  OrderState state = OrderState::kAccepted;
  std::vector<std::string> robots;
  std::string reason;  // cancelled / failed
};

class CoreReplay {
 public:
  // Errors: those of DispatchCore::Create and MakeAllocator.
  static Result<std::unique_ptr<CoreReplay>> Create(const ReplaySetup& setup);

  // Makes the entry's call; returns its output line. Errors: an entry that refers to a change
  // or round the replay does not have, or that lacks what its kind needs (kInvalidArgument).
  Result<std::string> Feed(const JournalEntry& entry);

  const DispatchCore& core() const { return *core_; }
  // Every order seen, in the order they entered the core.
  const std::vector<OrderTrace>& orders() const { return orders_; }
  double hold_seconds() const { return hold_seconds_; }

 private:
  CoreReplay(std::unique_ptr<DispatchCore> core, std::unique_ptr<RoundRunner> rounds);
  struct Round {
    std::optional<RoundInput> input;
    RoundCommit commit;
  };
  Round* FindRound(std::uint64_t seq);
  void Observe(const Change& change);
  void Observe(const std::vector<RobotCommand>& messages, double now);

  std::unique_ptr<DispatchCore> core_;
  std::unique_ptr<RoundRunner> rounds_;
  std::map<std::uint64_t, Change> changes_;  // by the entry that made them, until applied
  std::set<std::uint64_t> award_changes_;    // those of PlanAwards (kept until Committed)
  std::map<std::uint64_t, Round> round_;     // by their MakeRound entry
  std::vector<OrderTrace> orders_;
  std::map<std::string, std::size_t> order_index_;
  std::map<std::string, double> held_since_;
  double hold_seconds_ = 0.0;
};

}  // namespace dispatch::engine
