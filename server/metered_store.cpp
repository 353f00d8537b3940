#include "server/metered_store.h"

#include <chrono>

namespace dispatch::server {

template <class Fn>
auto MeteredStore::Timed(const char* op, Fn&& fn) {
  const auto start = std::chrono::steady_clock::now();
  auto result = fn();
  metrics_.ObserveDbWrite(op, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  if (result.ok() || result.error().code == engine::ErrorCode::kIoError) {
    std::lock_guard<std::mutex> lock(mu_);
    if (result.ok()) {
      write_failure_.reset();
    } else {
      write_failure_ = result.error().message;
    }
  }
  return result;
}

std::optional<std::string> MeteredStore::WriteFailure() const {
  std::lock_guard<std::mutex> lock(mu_);
  return write_failure_;
}

engine::Result<storage::InsertOrderResult> MeteredStore::InsertOrder(const engine::Order& order,
                                                                     const std::string& actor) {
  return Timed("insert_order", [&] { return inner_.InsertOrder(order, actor); });
}

engine::Result<storage::OrderEvent> MeteredStore::TransitionOrder(const storage::OrderTransition& transition) {
  return Timed("transition_order", [&] { return inner_.TransitionOrder(transition); });
}

engine::Result<storage::OrderEvent> MeteredStore::AppendProgress(const std::string& order_id, double time,
                                                                 const std::string& detail) {
  return Timed("append_progress", [&] { return inner_.AppendProgress(order_id, time, detail); });
}

engine::Status MeteredStore::UpsertRobot(const storage::RobotRecord& robot) {
  return Timed("upsert_robot", [&] { return inner_.UpsertRobot(robot); });
}

engine::Status MeteredStore::SaveAssignment(const storage::AssignmentRecord& assignment) {
  return Timed("save_assignment", [&] { return inner_.SaveAssignment(assignment); });
}

engine::Status MeteredStore::DeleteAssignment(const std::string& robot_id) {
  return Timed("delete_assignment", [&] { return inner_.DeleteAssignment(robot_id); });
}

engine::Result<storage::MapVersion> MeteredStore::RecordMapVersion(const storage::MapVersion& map) {
  return Timed("record_map_version", [&] { return inner_.RecordMapVersion(map); });
}

engine::Status MeteredStore::RunInTransaction(const std::function<engine::Status(storage::Store&)>& body) {
  return Timed("transaction", [&] { return inner_.RunInTransaction([&](storage::Store&) { return body(*this); }); });
}

}  // namespace dispatch::server
