#include "server/change_store.h"

#include <map>
#include <set>

namespace dispatch::server {

engine::Result<std::vector<storage::OrderEvent>> StoreChange(
    storage::Store& store, const engine::Change& change, const std::vector<std::string>* award_details,
    const std::function<storage::RobotRecord(const std::string&)>& record_of, const std::string& actor) {
  const double now = change.time;
  const std::map<std::string, std::uint64_t> messages = change.MessageCounts();
  std::set<std::string> robots;  // records to store: new plans (their queue), reserved sequences
  for (const auto& [id, plan] : change.plans) robots.insert(id);
  for (const auto& [id, n] : messages) robots.insert(id);
  for (const auto& [id, marks] : change.marks) robots.insert(id);
  std::vector<storage::OrderEvent> events;
  auto committed = store.RunInTransaction([&](storage::Store& s) -> engine::Status {
    events.clear();
    for (const engine::OrderChange& line : change.orders) {
      if (line.to) {
        const storage::OrderTransition t{line.order_id, *line.to, now, line.robots, line.detail, line.distance, actor};
        auto e = s.TransitionOrder(t);
        if (!e.ok()) return e.error();
        events.push_back(*e);
      } else {
        auto e = s.AppendProgress(line.order_id, now, line.detail);
        if (!e.ok()) return e.error();
        events.push_back(*e);
      }
      if (award_details && line.award < award_details->size()) {
        auto e = s.AppendProgress(line.order_id, now, (*award_details)[line.award]);
        if (!e.ok()) return e.error();
        events.push_back(*e);
      }
    }
    for (const auto& [id, plan] : change.plans) {
      if (auto saved = s.SaveAssignment(plan); !saved.ok()) return saved.error();
    }
    for (const auto& id : robots) {
      storage::RobotRecord rec = record_of(id);
      if (auto plan = change.plans.find(id); plan != change.plans.end()) rec.robot.task_queue = plan->second.order_ids;
      if (auto n = messages.find(id); n != messages.end()) rec.next_sequence += n->second;
      if (auto m = change.marks.find(id); m != change.marks.end()) rec.marks = m->second;
      if (auto saved = s.UpsertRobot(rec); !saved.ok()) return saved.error();
    }
    return engine::Ok{};
  });
  if (!committed.ok()) return committed.error();
  return events;
}

}  // namespace dispatch::server
