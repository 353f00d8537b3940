// Persistence of the dispatcher's durable state (SPEC §4 "Storage"): orders with their
// append-only event journal, robots, current assignments (timed plans) and map versions.
//
// `Store` is the interface the server codes against (leveldb's Env idea): SqliteStore is the
// real one, FaultInjectionStore wraps any Store to make chosen writes fail. Records use the
// engine's domain types, never proto messages.
//
// Contract of every implementation:
//  - a write that returns OK is durable (it survives a crash of the process); a write that
//    returns an error changed nothing (each write is atomic);
//  - InsertOrder writes the order and its first journal event atomically, and is
//    idempotent on the order's client_id (see there);
//  - TransitionOrder changes an order's state and journals the change atomically; it allows
//    only engine::CanTransition moves;
//  - journal event ids are strictly increasing in commit order over all orders; events are
//    never changed or deleted;
//  - RunInTransaction makes a group of writes atomic: all or none.
// Errors: kNotFound (unknown id), kInvalidArgument (malformed record, bad page token),
// kFailedPrecondition (conflicting duplicate, forbidden transition), kIoError (the database
// failed; nothing was written). Implementations are thread-safe unless they say otherwise.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/dispatch/assignment.h"
#include "engine/dispatch/robot_commands.h"
#include "engine/fleet/order.h"
#include "engine/fleet/plan.h"
#include "engine/fleet/robot.h"

namespace dispatch::storage {

using engine::Error;
using engine::Result;
using engine::Status;

// An order as stored: the engine order (its `state` is the current state) plus what only
// the service tracks.
struct OrderRecord {
  engine::Order order;
  std::string content_hash;          // OrderContentHash(order) at insertion
  std::vector<std::string> robots;   // robots serving it, leader first; empty before award
  double updated_time = 0.0;         // time of the last state change, seconds
  std::string reason;                // why it failed or was cancelled; empty otherwise
  double distance = 0.0;             // metres its robots drove for it (set when it completes)
};

enum class OrderEventType {
  kCreated,       // the order was accepted (its first event)
  kStateChanged,  // previous_state -> state
  kProgress,      // no state change: a pick/drop done, a re-plan, a note
};
// "created", "state_changed", "progress".
const char* OrderEventTypeName(OrderEventType type);
std::optional<OrderEventType> ParseOrderEventType(std::string_view name);

// One journal entry.
struct OrderEvent {
  std::int64_t id = 0;  // journal position, assigned by the store (> 0 once stored)
  std::string order_id;
  OrderEventType type = OrderEventType::kCreated;
  engine::OrderState state = engine::OrderState::kAccepted;  // order state after the event
  std::optional<engine::OrderState> previous_state;          // kStateChanged only
  double time = 0.0;                                         // seconds
  std::vector<std::string> robots;  // robots serving the order after the event
  std::string detail;               // human-readable
  // Who made the change: the name of the token of the call that made it (issue 18 §2); ""
  // for the dispatcher's own changes (allocation, robots' progress) and without tokens.
  std::string actor;
};

struct InsertOrderResult {
  OrderRecord record;   // the stored order (the earlier one when created = false)
  bool created = true;  // false: the client_id was already stored with the same content
};

// A state change of one order, journaled as a kStateChanged event.
struct OrderTransition {
  std::string order_id;
  engine::OrderState to = engine::OrderState::kAssigned;
  double time = 0.0;
  // Robots serving the order after the change; nullopt keeps the stored ones.
  std::optional<std::vector<std::string>> robots;
  std::string detail;  // journaled; for cancelled/failed also stored as the order's reason
  std::optional<double> distance;  // metres driven for it; nullopt keeps the stored value
  std::string actor;               // OrderEvent::actor
};

struct OrderQuery {
  std::vector<engine::OrderState> states;  // empty = all states
  int page_size = 100;                     // <= 0: 100; above kMaxPageSize: capped
  std::string page_token;                  // next_page_token of the previous page, or empty
};
inline constexpr int kMaxPageSize = 1000;

struct OrderPage {
  std::vector<OrderRecord> orders;  // in insertion order
  std::string next_page_token;      // empty on the last page
};

struct EventQuery {
  std::optional<std::string> order_id;  // only this order's events; nullopt = all orders
  std::int64_t after_id = 0;            // only events with id > after_id
  int limit = 1000;                     // at most this many (>= 1)
};

// A robot as stored: the engine robot plus session bookkeeping.
struct RobotRecord {
  engine::Robot robot;
  std::string kind;                       // drive kinematics, e.g. "differential"
  double last_seen = 0.0;                 // dispatcher seconds of its last message
  std::uint64_t last_acked_sequence = 0;  // server message sequence it acknowledged
  std::uint64_t next_sequence = 1;        // next server message sequence to use
  engine::OperatorMarks marks;            // operator commands in force (issue 18 §4)
};

// A robot's current plan and what it serves (one per robot; saving replaces it): the dispatch
// core's Assignment (engine/dispatch/assignment.h).
using AssignmentRecord = engine::Assignment;

struct MapVersion {
  std::int64_t version = 0;  // increasing, assigned by the store
  std::string name;          // map name, e.g. "chu2024"
  std::string content_hash;  // identifies the content; equal hash = same map
  std::string source;        // where it came from, e.g. "builtin:chu2024" or a file path
  double recorded_time = 0.0;
  // RecordMapVersion only (not stored): other hashes of the same content (an older hash
  // function's). A latest version stored under one of them is re-tagged with content_hash.
  std::vector<std::string> also_known_as;
};

class Store {
 public:
  virtual ~Store() = default;

  // --- Orders -------------------------------------------------------------------------
  // Stores a new order (state must be kAccepted; id and client_id non-empty) together with
  // its kCreated event at order.created_time. Idempotent on client_id: if the client_id is
  // already stored with the same OrderContentHash, returns the stored order with
  // created = false and writes nothing; with different content (or when order.id already
  // belongs to another client_id) the error is kFailedPrecondition naming both orders.
  // `actor`: who submitted it (its kCreated event's actor).
  virtual Result<InsertOrderResult> InsertOrder(const engine::Order& order, const std::string& actor) = 0;
  virtual Result<OrderRecord> GetOrder(const std::string& order_id) = 0;
  virtual Result<OrderRecord> GetOrderByClientId(const std::string& client_id) = 0;
  // Orders in insertion order, filtered by state, one page at a time. Pages are stable under
  // concurrent inserts (keyset paging): every order present before the first page is
  // returned exactly once.
  virtual Result<OrderPage> ListOrders(const OrderQuery& query) = 0;
  // Changes the state (engine::CanTransition, else kFailedPrecondition naming both states)
  // and journals it; returns the stored event.
  virtual Result<OrderEvent> TransitionOrder(const OrderTransition& transition) = 0;
  // Journals a kProgress event (the order's state is unchanged); returns the stored event.
  virtual Result<OrderEvent> AppendProgress(const std::string& order_id, double time,
                                            const std::string& detail) = 0;
  virtual Result<std::vector<OrderEvent>> ListEvents(const EventQuery& query) = 0;

  // --- Robots -------------------------------------------------------------------------
  virtual Status UpsertRobot(const RobotRecord& robot) = 0;
  virtual Result<RobotRecord> GetRobot(const std::string& robot_id) = 0;
  virtual Result<std::vector<RobotRecord>> ListRobots() = 0;  // by id

  // --- Assignments (current plan per robot) -------------------------------------------
  virtual Status SaveAssignment(const AssignmentRecord& assignment) = 0;
  virtual Result<AssignmentRecord> GetAssignment(const std::string& robot_id) = 0;
  virtual Result<std::vector<AssignmentRecord>> ListAssignments() = 0;  // by robot id
  // Removes the robot's assignment; kNotFound if it has none.
  virtual Status DeleteAssignment(const std::string& robot_id) = 0;

  // --- Map versions -------------------------------------------------------------------
  // Records the map in use. If the latest version has the same name and content_hash it is
  // returned unchanged; otherwise a new version is stored and returned.
  virtual Result<MapVersion> RecordMapVersion(const MapVersion& map) = 0;
  // The latest recorded version; kNotFound when none was recorded.
  virtual Result<MapVersion> LatestMapVersion() = 0;

  // --- Transactions -------------------------------------------------------------------
  // Runs `body` with this store; every write it makes commits together when body returns
  // OK, and none does when it returns an error (that error is returned) or when the commit
  // fails. Other threads' writes wait until it ends. Nesting is allowed (an inner failure
  // undoes only the inner writes if the outer body goes on). The body must use only the
  // Store it is given, on the calling thread.
  virtual Status RunInTransaction(const std::function<Status(Store&)>& body) = 0;
};

// Hash of an order's content as submitted: client_id, priority, picks, drop, formation,
// work_time and release_time (not id, created_time or state). Two submissions with one
// client_id count as "the same" when their hashes are equal. 16 hex digits: FNV-1a 64 of a
// canonical encoding, a change detector (up to 64-bit collisions), not a cryptographic hash.
std::string OrderContentHash(const engine::Order& order);

}  // namespace dispatch::storage
