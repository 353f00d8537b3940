#include "engine/sim/random_orders.h"

#include <cmath>
#include <random>
#include <string>

namespace dispatch::engine {

Result<std::vector<Order>> RandomOrders(const WarehouseMap& map, const RandomOrderOptions& options) {
  if (!std::isfinite(options.interval) || options.interval < 0) {
    return InvalidArgument("random orders: interval must be finite and >= 0");
  }
  if (!std::isfinite(options.work_time) || options.work_time <= 0) {
    return InvalidArgument("random orders: work_time must be finite and > 0");
  }
  if (!(options.formation_share >= 0 && options.formation_share <= 1)) {
    return InvalidArgument("random orders: formation_share must be in [0, 1]");
  }
  std::vector<PointId> picks, drops;
  for (std::size_t p = 0; p < map.point_count(); ++p) {
    const PointKind kind = map.points()[p].kind;
    if (kind == PointKind::kPick) picks.push_back(static_cast<PointId>(p));
    if (kind == PointKind::kDrop) drops.push_back(static_cast<PointId>(p));
  }
  if (picks.empty() || drops.empty()) {
    return InvalidArgument("random orders: map '" + map.name() + "' needs pick and drop points");
  }
  std::mt19937_64 rng(options.seed);
  auto below = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
  auto unit = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  std::vector<Order> orders;
  orders.reserve(options.count);
  for (std::size_t i = 0; i < options.count; ++i) {
    Order o;
    o.id = "O" + std::to_string(i + 1);
    o.client_id = o.id;
    o.picks = {picks[below(picks.size())]};
    o.drop = drops[below(drops.size())];
    if (o.drop == o.picks.front() && drops.size() > 1) o.drop = drops[(below(drops.size() - 1) + 1) % drops.size()];
    o.work_time = options.work_time;
    // Drawn only when asked for, so streams without formations stay what they were.
    if (options.formation_share > 0) o.formation = unit() < options.formation_share;
    const double release =
        (static_cast<double>(i) + (options.jitter ? unit() : 0.0)) * options.interval;
    o.created_time = release;
    o.release_time = release;
    orders.push_back(std::move(o));
  }
  return orders;
}

}  // namespace dispatch::engine
