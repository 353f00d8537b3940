#include "server/batch_effects.h"

#include <algorithm>
#include <utility>

namespace dispatch::server {

void BatchEffects::Defer(std::function<void()> effect, bool after_publish) {
  deferred_.push_back(std::move(effect));
  need_publish_ = need_publish_ || after_publish;
}

void BatchEffects::Announce(std::function<void()> effect) { announced_.push_back(std::move(effect)); }

bool BatchEffects::PublishDue(Clock::time_point now) const {
  return (changed_ || !announced_.empty()) && (need_publish_ || now - last_publish_ >= period_);
}

void BatchEffects::Published(Clock::time_point now, Clock::duration took) {
  changed_ = false;
  last_publish_ = now;
  period_ = std::max<Clock::duration>(kPublishEvery, took * kPublishShare);
  for (auto& effect : announced_) released_.push_back(std::move(effect));
  announced_.clear();
}

BatchEffects::Clock::time_point BatchEffects::WakeBy(Clock::time_point next_tick) const {
  return changed_ || !announced_.empty() ? std::min(next_tick, last_publish_ + period_) : next_tick;
}

void BatchEffects::RunDeferred() {
  need_publish_ = false;
  std::vector<std::function<void()>> effects;
  effects.swap(deferred_);
  for (auto& effect : released_) effects.push_back(std::move(effect));
  released_.clear();
  for (auto& effect : effects) effect();
}

}  // namespace dispatch::server
