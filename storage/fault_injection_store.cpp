#include "storage/fault_injection_store.h"

namespace dispatch::storage {

Status FaultInjectionStore::Admit(const char* method) {
  const std::uint64_t n = ++writes_;
  const std::uint64_t at = fail_at_.load();
  const std::uint64_t from = fail_from_.load();
  if ((at != 0 && n == at) || (from != 0 && n >= from)) {
    ++failures_;
    return engine::IoError("injected failure of write " + std::to_string(n) + " (" + method +
                           ")");
  }
  return engine::Ok{};
}

Result<InsertOrderResult> FaultInjectionStore::InsertOrder(const engine::Order& order, const std::string& actor) {
  if (Status s = Admit("InsertOrder"); !s.ok()) return s.error();
  return inner_.InsertOrder(order, actor);
}

Result<OrderEvent> FaultInjectionStore::TransitionOrder(const OrderTransition& transition) {
  if (Status s = Admit("TransitionOrder"); !s.ok()) return s.error();
  return inner_.TransitionOrder(transition);
}

Result<OrderEvent> FaultInjectionStore::AppendProgress(const std::string& order_id, double time,
                                                       const std::string& detail) {
  if (Status s = Admit("AppendProgress"); !s.ok()) return s.error();
  return inner_.AppendProgress(order_id, time, detail);
}

Status FaultInjectionStore::UpsertRobot(const RobotRecord& robot) {
  if (Status s = Admit("UpsertRobot"); !s.ok()) return s;
  return inner_.UpsertRobot(robot);
}

Status FaultInjectionStore::SaveAssignment(const AssignmentRecord& assignment) {
  if (Status s = Admit("SaveAssignment"); !s.ok()) return s;
  return inner_.SaveAssignment(assignment);
}

Status FaultInjectionStore::DeleteAssignment(const std::string& robot_id) {
  if (Status s = Admit("DeleteAssignment"); !s.ok()) return s;
  return inner_.DeleteAssignment(robot_id);
}

Result<MapVersion> FaultInjectionStore::RecordMapVersion(const MapVersion& map) {
  if (Status s = Admit("RecordMapVersion"); !s.ok()) return s.error();
  return inner_.RecordMapVersion(map);
}

}  // namespace dispatch::storage
