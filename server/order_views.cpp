#include "server/order_views.h"

#include <algorithm>
#include <unordered_set>
#include <utility>

namespace dispatch::server {

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

std::shared_ptr<const Snapshot::OrderIndex> OrderViews::Index() {
  if (!published_ || published_generation_ != generation_) {
    published_ = std::make_shared<const Snapshot::OrderIndex>(Snapshot::OrderIndex{by_id_, by_client_id_});
    published_generation_ = generation_;
  }
  return published_;
}

}  // namespace dispatch::server
