// MeteredStore: a Store decorator that times every write (and every transaction, commit
// included) into ServiceMetrics' dispatch_db_write_seconds{op}. Reads pass through untimed.
// Writes made inside RunInTransaction go through the decorator too (the body is handed this
// decorator), so a transaction shows as its writes plus one "transaction" observation.
// It also remembers whether the last write failed for I/O (read-only or full database),
// until a write succeeds again: readiness (GET /readyz) reads it.
// Thread-safe if the wrapped store is.
#pragma once

#include <mutex>
#include <optional>
#include <string>

#include "server/metrics.h"
#include "storage/store.h"

namespace dispatch::server {

class MeteredStore final : public storage::Store {
 public:
  // `inner` and `metrics` must outlive this decorator.
  MeteredStore(storage::Store& inner, ServiceMetrics& metrics) : inner_(inner), metrics_(metrics) {}

  engine::Result<storage::InsertOrderResult> InsertOrder(const engine::Order& order, const std::string& actor) override;
  engine::Result<storage::OrderRecord> GetOrder(const std::string& order_id) override {
    return inner_.GetOrder(order_id);
  }
  engine::Result<storage::OrderRecord> GetOrderByClientId(const std::string& client_id) override {
    return inner_.GetOrderByClientId(client_id);
  }
  engine::Result<storage::OrderPage> ListOrders(const storage::OrderQuery& query) override {
    return inner_.ListOrders(query);
  }
  engine::Result<storage::OrderEvent> TransitionOrder(const storage::OrderTransition& transition) override;
  engine::Result<storage::OrderEvent> AppendProgress(const std::string& order_id, double time,
                                                     const std::string& detail) override;
  engine::Result<std::vector<storage::OrderEvent>> ListEvents(const storage::EventQuery& query) override {
    return inner_.ListEvents(query);
  }
  engine::Status UpsertRobot(const storage::RobotRecord& robot) override;
  engine::Result<storage::RobotRecord> GetRobot(const std::string& robot_id) override {
    return inner_.GetRobot(robot_id);
  }
  engine::Result<std::vector<storage::RobotRecord>> ListRobots() override { return inner_.ListRobots(); }
  engine::Status SaveAssignment(const storage::AssignmentRecord& assignment) override;
  engine::Result<storage::AssignmentRecord> GetAssignment(const std::string& robot_id) override {
    return inner_.GetAssignment(robot_id);
  }
  engine::Result<std::vector<storage::AssignmentRecord>> ListAssignments() override {
    return inner_.ListAssignments();
  }
  engine::Status DeleteAssignment(const std::string& robot_id) override;
  engine::Result<storage::MapVersion> RecordMapVersion(const storage::MapVersion& map) override;
  engine::Result<storage::MapVersion> LatestMapVersion() override { return inner_.LatestMapVersion(); }
  engine::Status RunInTransaction(const std::function<engine::Status(storage::Store&)>& body) override;

  // Why the last write failed for I/O (nullopt: it did not, or a write has succeeded since).
  std::optional<std::string> WriteFailure() const;

 private:
  template <class Fn>
  auto Timed(const char* op, Fn&& fn);

  storage::Store& inner_;
  ServiceMetrics& metrics_;
  mutable std::mutex mu_;  // guards write_failure_
  std::optional<std::string> write_failure_;
};

}  // namespace dispatch::server
