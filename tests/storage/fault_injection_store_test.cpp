// FaultInjectionStore: a failed write is an error to the caller and changes nothing, other
// writes and all reads go through, and writes inside a transaction are counted too.
#include "storage/fault_injection_store.h"

#include <gtest/gtest.h>

#include "storage/sqlite_store.h"
#include "tests/storage/temp_dir.h"

namespace dispatch::storage {
namespace {

using engine::ErrorCode;
using engine::OrderState;
using testing::FastOptions;

engine::Order MakeOrder(const std::string& id) {
  engine::Order o;
  o.id = id;
  o.client_id = "client-" + id;
  o.picks = {1};
  o.drop = 2;
  return o;
}

class FaultInjectionStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto opened = SqliteStore::Open(dir_.File("dispatch.db"), FastOptions());
    ASSERT_TRUE(opened.ok()) << opened.error().message;
    sqlite_ = std::move(opened).value();
    store_ = std::make_unique<FaultInjectionStore>(*sqlite_);
  }
  testing::TempDir dir_;
  std::unique_ptr<SqliteStore> sqlite_;
  std::unique_ptr<FaultInjectionStore> store_;
};

TEST_F(FaultInjectionStoreTest, TheNthWriteFailsAndChangesNothing) {
  store_->FailWrite(2);
  ASSERT_TRUE(store_->InsertOrder(MakeOrder("o1"), "").ok());
  auto failed = store_->InsertOrder(MakeOrder("o2"), "");
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ErrorCode::kIoError);
  EXPECT_EQ(failed.error().message, "injected failure of write 2 (InsertOrder)");
  EXPECT_EQ(store_->GetOrder("o2").error().code, ErrorCode::kNotFound);  // reads pass through
  EXPECT_TRUE(store_->GetOrder("o1").ok());
  // Only write 2 fails: the retry (write 3) succeeds.
  ASSERT_TRUE(store_->InsertOrder(MakeOrder("o2"), "").ok());
  EXPECT_EQ(store_->writes(), 3u);
  EXPECT_EQ(store_->failures(), 1u);
  EXPECT_EQ(sqlite_->ListOrders({}).value().orders.size(), 2u);
  EXPECT_EQ(sqlite_->ListEvents({}).value().size(), 2u);
}

TEST_F(FaultInjectionStoreTest, EveryKindOfWriteCanFail) {
  ASSERT_TRUE(store_->InsertOrder(MakeOrder("o1"), "").ok());  // write 1
  store_->FailWritesFrom(2);
  EXPECT_FALSE(store_->TransitionOrder({"o1", OrderState::kAssigned, 1, {}, "", {}, ""}).ok());
  EXPECT_FALSE(store_->AppendProgress("o1", 1, "x").ok());
  RobotRecord robot;
  robot.robot.id = "R1";
  EXPECT_FALSE(store_->UpsertRobot(robot).ok());
  AssignmentRecord assignment;
  assignment.robot_id = "R1";
  EXPECT_FALSE(store_->SaveAssignment(assignment).ok());
  EXPECT_FALSE(store_->DeleteAssignment("R1").ok());
  EXPECT_FALSE(store_->RecordMapVersion({0, "m", "h", "s", 0, {}}).ok());
  EXPECT_EQ(store_->failures(), 6u);
  // Nothing reached the database.
  EXPECT_EQ(sqlite_->GetOrder("o1")->order.state, OrderState::kAccepted);
  EXPECT_EQ(sqlite_->ListEvents({}).value().size(), 1u);
  EXPECT_TRUE(sqlite_->ListRobots().value().empty());
  EXPECT_TRUE(sqlite_->ListAssignments().value().empty());
  EXPECT_EQ(sqlite_->LatestMapVersion().error().code, ErrorCode::kNotFound);
  store_->FailWritesFrom(0);
  EXPECT_TRUE(store_->TransitionOrder({"o1", OrderState::kAssigned, 1, {}, "", {}, ""}).ok());
}

TEST_F(FaultInjectionStoreTest, AFailureInsideATransactionUndoesItsEarlierWrites) {
  store_->FailWrite(2);
  Status status = store_->RunInTransaction([](Store& tx) -> Status {
    auto order = tx.InsertOrder(MakeOrder("o1"), "");  // write 1: succeeds inside the transaction
    if (!order.ok()) return order.error();
    auto assigned = tx.TransitionOrder({"o1", OrderState::kAssigned, 1, std::vector<std::string>{"R1"}, "", {}, ""});  // fails
    if (!assigned.ok()) return assigned.error();
    return engine::Ok{};
  });
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("write 2 (TransitionOrder)"), std::string::npos);
  EXPECT_EQ(sqlite_->GetOrder("o1").error().code, ErrorCode::kNotFound);
  EXPECT_TRUE(sqlite_->ListEvents({}).value().empty());
}

}  // namespace
}  // namespace dispatch::storage
