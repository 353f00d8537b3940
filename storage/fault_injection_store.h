// FaultInjectionStore: a Store decorator that makes chosen writes fail (leveldb's
// EnvWrapper idea), so tests of the store's callers can prove that a failed write reaches
// the caller as an error and loses nothing that was acknowledged.
//
// Writes are the mutating calls: InsertOrder, TransitionOrder, AppendProgress, UpsertRobot,
// SaveAssignment, DeleteAssignment, RecordMapVersion. They are numbered 1, 2, 3, ... in call
// order (reads are not counted). A failing write returns kIoError "injected failure of write
// N (<method>)" without reaching the wrapped store, so it changes nothing. Writes made inside
// RunInTransaction go through the decorator too (the body is handed this decorator).
// Thread-safe if the wrapped store is; the counters are atomic.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "storage/store.h"

namespace dispatch::storage {

class FaultInjectionStore final : public Store {
 public:
  // `inner` must outlive this decorator.
  explicit FaultInjectionStore(Store& inner) : inner_(inner) {}

  // Write number `n` (counting from 1 over this decorator's life) fails; 0 = none.
  void FailWrite(std::uint64_t n) { fail_at_.store(n); }
  // Every write from number `n` on fails (a disk that stays broken); 0 = none.
  void FailWritesFrom(std::uint64_t n) { fail_from_.store(n); }
  // Writes attempted so far (failed ones included).
  std::uint64_t writes() const { return writes_.load(); }
  // Writes that were made to fail.
  std::uint64_t failures() const { return failures_.load(); }

  Result<InsertOrderResult> InsertOrder(const engine::Order& order, const std::string& actor) override;
  Result<OrderRecord> GetOrder(const std::string& order_id) override {
    return inner_.GetOrder(order_id);
  }
  Result<OrderRecord> GetOrderByClientId(const std::string& client_id) override {
    return inner_.GetOrderByClientId(client_id);
  }
  Result<OrderPage> ListOrders(const OrderQuery& query) override {
    return inner_.ListOrders(query);
  }
  Result<OrderEvent> TransitionOrder(const OrderTransition& transition) override;
  Result<OrderEvent> AppendProgress(const std::string& order_id, double time,
                                    const std::string& detail) override;
  Result<std::vector<OrderEvent>> ListEvents(const EventQuery& query) override {
    return inner_.ListEvents(query);
  }

  Status UpsertRobot(const RobotRecord& robot) override;
  Result<RobotRecord> GetRobot(const std::string& robot_id) override {
    return inner_.GetRobot(robot_id);
  }
  Result<std::vector<RobotRecord>> ListRobots() override { return inner_.ListRobots(); }

  Status SaveAssignment(const AssignmentRecord& assignment) override;
  Result<AssignmentRecord> GetAssignment(const std::string& robot_id) override {
    return inner_.GetAssignment(robot_id);
  }
  Result<std::vector<AssignmentRecord>> ListAssignments() override {
    return inner_.ListAssignments();
  }
  Status DeleteAssignment(const std::string& robot_id) override;

  Result<MapVersion> RecordMapVersion(const MapVersion& map) override;
  Result<MapVersion> LatestMapVersion() override { return inner_.LatestMapVersion(); }

  Status RunInTransaction(const std::function<Status(Store&)>& body) override {
    return inner_.RunInTransaction([&](Store&) { return body(*this); });
  }

 private:
  // Counts one write; an error if it is to fail.
  Status Admit(const char* method);

  Store& inner_;
  std::atomic<std::uint64_t> fail_at_{0};
  std::atomic<std::uint64_t> fail_from_{0};
  std::atomic<std::uint64_t> writes_{0};
  std::atomic<std::uint64_t> failures_{0};
};

}  // namespace dispatch::storage
