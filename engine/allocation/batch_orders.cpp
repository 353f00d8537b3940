#include "engine/allocation/batch_orders.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace dispatch::engine {

BatchSingles TakeSingles(const std::vector<const Order*>& orders, FleetState& state,
                         Allocator& formations, const AwardSink& sink) {
  BatchSingles out;
  for (const Order* o : orders) {
    if (o->formation) {
      sink(*o, formations.Allocate(*o, state));
      continue;
    }
    Result<PlanTask> task = PrepareOrder(*o, state);
    if (!task.ok()) {
      sink(*o, task.error());
      continue;
    }
    if (!task->stop_headings.empty()) {  // only some robots can serve it: the auction's bids say which
      sink(*o, formations.Allocate(*o, state));
      continue;
    }
    out.orders.push_back(o);
    out.tasks.push_back(std::move(task).value());
  }
  return out;
}

std::vector<std::size_t> SoonestRobots(const FleetState& state, const PlanTask& task, std::size_t count) {
  std::vector<std::pair<double, std::size_t>> ranked;
  for (std::size_t i = 0; i < state.robot_count(); ++i) {
    if (!state.HasRoom(i) || !state.CanServe(i, task)) continue;
    const QueueSummary& s = state.summary(i);
    const double start = s.end_time + state.routes().Cost(s.end_point, task.picks.front());
    if (std::isfinite(start)) ranked.emplace_back(start, i);
  }
  const std::size_t keep = std::min(count, ranked.size());
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep), ranked.end());
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < keep; ++k) out.push_back(ranked[k].second);
  std::sort(out.begin(), out.end());
  return out;
}

Result<AwardExplanation> AllocateAsBatch(Allocator& batch, const Order& order, FleetState& state) {
  std::optional<Result<AwardExplanation>> out;
  batch.AllocateBatch({&order}, state, [&](const Order&, Result<AwardExplanation> award) { out.emplace(std::move(award)); });
  return std::move(*out);  // every order of a batch reaches the sink once
}

}  // namespace dispatch::engine
