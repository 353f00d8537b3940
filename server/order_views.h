// OrderViews: the dispatcher's order book as operators read it - every open order and the
// newest `retained` finished ones, in submission order, indexed by server id and client id
// (the rest stay in the store: DispatcherOptions::finished_retained). The dispatch core keeps
// the open orders' dispatch state; these are the views the snapshot publishes.
//
// Not thread-safe: the dispatcher's loop owns it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/common/result.h"
#include "engine/dispatch/dispatch_core.h"
#include "engine/fleet/order.h"
#include "server/snapshot.h"
#include "storage/store.h"

namespace dispatch::server {

// What recovery learnt from the stored orders besides the book.
struct LoadedOrders {
  double latest_time = 0.0;             // the latest creation or update time stored
  std::int64_t last_order_number = 0;  // of the "ord-N" ids
};

// The view of an order as stored, before any change follows it: finished at its last update
// when it is terminal.
std::shared_ptr<OrderView> StoredView(storage::OrderRecord record);

class OrderViews {
 public:
  explicit OrderViews(std::size_t retained) : retained_(retained) {}

  // Recovery: every stored order, in submission order, the finished ones trimmed to the
  // retention page by page (a long history never passes through memory whole), each with its
  // latest allocation explanation from the journal.
  engine::Result<LoadedOrders> Load(storage::Store& store);

  // An order as the store has it (one that left memory): by server id, or with by_client_id
  // by client order id; with `explain` its latest allocation explanation from its journal.
  // nullptr when there is none.
  static engine::Result<std::shared_ptr<const OrderView>> FromStore(storage::Store& store, const std::string& key,
                                                                    bool by_client_id, bool explain);

  std::shared_ptr<const OrderView> Find(const std::string& order_id) const;
  std::shared_ptr<const OrderView> FindClient(const std::string& client_id) const;
  // Replaces (or adds, at the end) an order; a finished one joins the finished list.
  void Put(std::shared_ptr<OrderView> view);
  // The views follow a committed core change: per order line the state, robots, distance,
  // finish time, reason and the members that dropped; with `records` (per award of the
  // change's round) the allocation explanation.
  void Follow(const engine::Change& change, const std::vector<AllocationRecord>* records);
  // Once more than retained + slack finished orders are in memory, the oldest finished ones
  // leave it down to `retained` (counted in finished_in_store). True when some left.
  bool Retire(std::size_t slack);
  // Recovery loads orders in submission order: the finished list is put in finish order.
  void SortFinished();

  const std::vector<std::shared_ptr<const OrderView>>& all() const { return orders_; }
  // Finished orders that left memory, by state.
  const std::map<engine::OrderState, std::uint64_t>& finished_in_store() const { return finished_in_store_; }
  // The indexes as the snapshot shares them (a new copy only after orders joined or left).
  std::shared_ptr<const Snapshot::OrderIndex> Index();

 private:
  const std::size_t retained_;
  std::vector<std::shared_ptr<const OrderView>> orders_;
  std::unordered_map<std::string, std::size_t> by_id_;
  std::unordered_map<std::string, std::size_t> by_client_id_;
  std::deque<std::string> finished_;  // the finished orders in memory, in finish order
  std::map<engine::OrderState, std::uint64_t> finished_in_store_;
  std::uint64_t generation_ = 0;  // changes when orders join or leave
  std::uint64_t published_generation_ = static_cast<std::uint64_t>(-1);
  std::shared_ptr<const Snapshot::OrderIndex> published_;
};

}  // namespace dispatch::server
