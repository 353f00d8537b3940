#include "server/order_views.h"

#include <cstdlib>

#include <algorithm>
#include <unordered_set>
#include <utility>

#include "server/json_convert.h"

namespace dispatch::server {

std::shared_ptr<OrderView> StoredView(storage::OrderRecord record) {
  auto view = std::make_shared<OrderView>();
  view->record = std::move(record);
  if (engine::IsTerminal(view->record.order.state)) view->finished_time = view->record.updated_time;
  return view;
}

std::shared_ptr<const OrderView> OrderViews::Find(const std::string& order_id) const {
  auto it = by_id_.find(order_id);
  return it == by_id_.end() ? nullptr : orders_[it->second];
}

std::shared_ptr<const OrderView> OrderViews::FindClient(const std::string& client_id) const {
  auto it = by_client_id_.find(client_id);
  return it == by_client_id_.end() ? nullptr : orders_[it->second];
}

void OrderViews::Put(std::shared_ptr<OrderView> view) {
  const std::string id = view->record.order.id;
  const bool finished = engine::IsTerminal(view->record.order.state);
  auto it = by_id_.find(id);
  if (it == by_id_.end()) {
    by_id_.emplace(id, orders_.size());
    by_client_id_.emplace(view->record.order.client_id, orders_.size());
    orders_.push_back(std::move(view));
    ++generation_;
    if (finished) finished_.push_back(id);
  } else {
    if (finished && !engine::IsTerminal(orders_[it->second]->record.order.state)) finished_.push_back(id);
    orders_[it->second] = std::move(view);
  }
}

engine::Result<std::shared_ptr<const OrderView>> OrderViews::FromStore(storage::Store& store, const std::string& key,
                                                                       bool by_client_id, bool explain) {
  auto record = by_client_id ? store.GetOrderByClientId(key) : store.GetOrder(key);
  if (!record.ok()) {
    if (record.error().code == engine::ErrorCode::kNotFound) return std::shared_ptr<const OrderView>();
    return record.error();
  }
  auto view = StoredView(std::move(record).value());
  if (explain) {  // the latest allocation detail in its journal
    storage::EventQuery events;
    events.order_id = view->record.order.id;
    for (;;) {
      auto batch = store.ListEvents(events);
      if (!batch.ok()) return batch.error();
      for (const auto& event : *batch) {
        events.after_id = event.id;
        if (auto explanation = ParseAllocationDetail(event.detail)) view->explanation = std::move(explanation);
      }
      if (batch->size() < static_cast<std::size_t>(events.limit)) break;
    }
  }
  return std::shared_ptr<const OrderView>(std::move(view));
}

void OrderViews::Follow(const engine::Change& change, const std::vector<AllocationRecord>* records) {
  for (const engine::OrderChange& line : change.orders) {
    auto found = Find(line.order_id);
    if (!found) continue;
    auto view = std::make_shared<OrderView>(*found);
    if (auto d = change.dropped_by.find(line.order_id); d != change.dropped_by.end()) view->dropped_by = d->second;
    if (line.to) {
      const engine::OrderState to = *line.to;
      view->record.order.state = to;
      view->record.updated_time = change.time;
      if (line.robots) view->record.robots = *line.robots;
      if (line.distance) view->record.distance = *line.distance;
      if (engine::IsTerminal(to)) view->finished_time = change.time;
      if (to == engine::OrderState::kCancelled || to == engine::OrderState::kFailed) view->record.reason = line.detail;
      if (records && line.award < records->size()) view->explanation = (*records)[line.award];
    }
    Put(std::move(view));
  }
}

bool OrderViews::Retire(std::size_t slack) {
  if (finished_.size() <= retained_ + slack) return false;
  std::unordered_set<std::string> leaving;
  while (finished_.size() > retained_) {
    leaving.insert(std::move(finished_.front()));
    finished_.pop_front();
  }
  std::vector<std::shared_ptr<const OrderView>> kept;
  kept.reserve(orders_.size() - leaving.size());
  for (auto& view : orders_) {
    if (leaving.count(view->record.order.id)) {
      ++finished_in_store_[view->record.order.state];
    } else {
      kept.push_back(std::move(view));
    }
  }
  orders_ = std::move(kept);
  by_id_.clear();
  by_client_id_.clear();
  for (std::size_t i = 0; i < orders_.size(); ++i) {
    by_id_.emplace(orders_[i]->record.order.id, i);
    by_client_id_.emplace(orders_[i]->record.order.client_id, i);
  }
  ++generation_;
  return true;
}

void OrderViews::SortFinished() {
  std::stable_sort(finished_.begin(), finished_.end(), [this](const std::string& a, const std::string& b) {
    return Find(a)->finished_time.value_or(0.0) < Find(b)->finished_time.value_or(0.0);
  });
}

engine::Result<LoadedOrders> OrderViews::Load(storage::Store& store) {
  LoadedOrders out;
  auto keep_newest = [this](std::size_t slack) {
    SortFinished();  // they load in submission order
    Retire(slack);
  };
  storage::OrderQuery query;
  query.page_size = storage::kMaxPageSize;
  for (;;) {
    auto page = store.ListOrders(query);
    if (!page.ok()) return page.error();
    for (const auto& record : page->orders) {
      auto view = StoredView(record);
      out.latest_time = std::max({out.latest_time, record.updated_time, record.order.created_time});
      const std::string& id = record.order.id;
      if (id.rfind("ord-", 0) == 0) {
        out.last_order_number = std::max<std::int64_t>(out.last_order_number, std::atoll(id.c_str() + 4));
      }
      Put(std::move(view));
    }
    if (page->next_page_token.empty()) break;
    query.page_token = page->next_page_token;
    keep_newest(storage::kMaxPageSize);
  }
  keep_newest(0);
  // Allocation explanations from the journal (the latest per order wins).
  storage::EventQuery events;
  events.limit = 1000;
  for (;;) {
    auto batch = store.ListEvents(events);
    if (!batch.ok()) return batch.error();
    for (const auto& event : *batch) {
      events.after_id = event.id;
      auto explanation = ParseAllocationDetail(event.detail);
      if (!explanation) continue;
      if (auto view = Find(event.order_id)) {
        auto copy = std::make_shared<OrderView>(*view);
        copy->explanation = std::move(*explanation);
        Put(std::move(copy));
      }
    }
    if (batch->size() < static_cast<std::size_t>(events.limit)) break;
  }
  return out;
}

std::shared_ptr<const Snapshot::OrderIndex> OrderViews::Index() {
  if (!published_ || published_generation_ != generation_) {
    published_ = std::make_shared<const Snapshot::OrderIndex>(Snapshot::OrderIndex{by_id_, by_client_id_});
    published_generation_ = generation_;
  }
  return published_;
}

}  // namespace dispatch::server
