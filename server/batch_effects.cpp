#include "server/batch_effects.h"

#include <algorithm>
#include <utility>

namespace dispatch::server {

void BatchEffects::Defer(std::function<void()> effect, bool after_publish) {
  deferred_.push_back(std::move(effect));
  need_publish_ = need_publish_ || after_publish;
}

bool BatchEffects::PublishDue(Clock::time_point now) const {
  return changed_ && (need_publish_ || now - last_publish_ >= kPublishEvery);
}

void BatchEffects::Published(Clock::time_point now) {
  changed_ = false;
  last_publish_ = now;
}

BatchEffects::Clock::time_point BatchEffects::WakeBy(Clock::time_point next_tick) const {
  return changed_ ? std::min(next_tick, last_publish_ + kPublishEvery) : next_tick;
}

void BatchEffects::RunDeferred() {
  need_publish_ = false;
  std::vector<std::function<void()>> effects;
  effects.swap(deferred_);
  for (auto& effect : effects) effect();
}

}  // namespace dispatch::server
