// DispatchCore's blocked robots (CoreOptions::blocked_recovery): a robot the traffic controller
// blocks is in fault, an obstacle out of every auction, and its orders go back; after
// blocked_recovery seconds it is in service again (0: it stays in fault until its next Hello).
// An order given back CoreOptions::max_give_backs times in a row by the same robot at the same
// point fails at its next loss there.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dispatch_test_support.h"
#include "engine/dispatch/dispatch_core.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::PointsOfKind;

constexpr double kBlockedAfter = 5.0;

class BlockedRecoveryTest : public ::testing::Test {
 protected:
  // R1 at a parking point gets an order whose pick an offline robot stands on: it waits there
  // with no alternative and is blocked after kBlockedAfter.
  void Build(double recovery, int max_give_backs = 3) {
    CoreOptions options;
    options.traffic.blocked_after = kBlockedAfter;
    options.blocked_recovery = recovery;
    options.max_give_backs = max_give_backs;
    core_ = testing_util::Chu2024Core(options);
    rounds_ = testing_util::AuctionRounds();

    const PointId pick = PointsOfKind(*Chu2024(), PointKind::kPick).at(3);
    Robot ghost;
    ghost.id = "G";
    ghost.current_point = pick;
    ghost.pose.position = Chu2024()->point(pick).position;
    core_->RestoreRobot(std::move(ghost), std::nullopt, /*place=*/true);

    Robot r1;
    r1.id = "R1";
    r1.current_point = PointsOfKind(*Chu2024(), PointKind::kPark).at(0);
    r1.pose.position = Chu2024()->point(r1.current_point).position;
    (void)core_->Connect(std::move(r1), now_);

    Order o;
    o.id = o.client_id = "O1";
    o.picks = {pick};
    o.drop = PointsOfKind(*Chu2024(), PointKind::kDrop).at(1);
    core_->AddOrder(std::move(o));
    ASSERT_TRUE(RunRound());
    ASSERT_EQ(core_->order("O1")->robots, std::vector<std::string>{"R1"});
  }

  // One allocation round, every award applied; false when there was nothing to allocate.
  bool RunRound() { return testing_util::ApplyRound(*core_, *rounds_, now_); }

  // R1 drives at once to every waypoint released to it, then reports.
  void Drive() {
    const BookRobot* r = core_->robot("R1");
    (void)core_->Report("R1", r->robot.pose, std::nullopt, RobotState::kIdle, std::nullopt, r->progress.last_reached, now_);
    if (!r->has_assignment) return;
    const std::uint64_t released = core_->ReleasedUpTo("R1");
    for (const Waypoint& w : std::vector<Waypoint>(r->assignment.plan.waypoints)) {
      const auto seq = static_cast<std::uint64_t>(w.seq);
      if (seq <= core_->robot("R1")->progress.last_reached || seq > released) continue;
      const ReportOutcome reached = core_->Reached("R1", seq, Pose{w.xy, 0.0}, now_);
      ASSERT_TRUE(reached.taken) << reached.why;
      if (reached.change) (void)core_->Apply(*reached.change);
    }
  }

  // Steps every 0.5 s until `until` (or the time limit); the owner's part of a block is done
  // as the service does it (PlanLoss, stored and applied).
  void RunUntil(double limit, const std::function<bool(const StepOutcome&)>& until) {
    while (now_ < limit) {
      now_ += 0.5;
      Drive();
      StepOutcome step = core_->Step(now_);
      for (const auto& [id, why] : step.blocked) {
        blocked_at_ = now_;
        last_loss_ = core_->PlanLoss(id, "robot " + id + " blocked: " + why, now_);
        (void)core_->Apply(last_loss_);
      }
      if (until(step)) return;
    }
  }

  std::unique_ptr<DispatchCore> core_;
  std::unique_ptr<RoundRunner> rounds_;
  double now_ = 0.0;
  std::optional<double> blocked_at_;
  Change last_loss_;
};

TEST_F(BlockedRecoveryTest, ABlockedRobotIsBackInServiceAfterTheRecoveryTime) {
  Build(10.0);
  std::optional<double> recovered_at;
  RunUntil(200.0, [&](const StepOutcome& step) {
    for (const std::string& id : step.recovered) {
      if (id == "R1") recovered_at = now_;
    }
    if (blocked_at_ && !recovered_at) {  // in fault meanwhile: an obstacle out of the auction
      EXPECT_EQ(core_->robot("R1")->robot.state, RobotState::kFault);
      RoundCommit commit;
      EXPECT_FALSE(core_->MakeRound(now_, commit).has_value()) << "a faulted robot must not bid";
    }
    return recovered_at.has_value();
  });
  ASSERT_TRUE(blocked_at_.has_value()) << core_->gate()->Describe("R1");
  ASSERT_TRUE(recovered_at.has_value());
  EXPECT_GE(*blocked_at_, kBlockedAfter);
  EXPECT_GE(*recovered_at - *blocked_at_, 10.0);
  EXPECT_LE(*recovered_at - *blocked_at_, 10.5);
  EXPECT_EQ(core_->robot("R1")->robot.state, RobotState::kIdle);
  // Its order went back when it was blocked; now R1 bids for it again.
  EXPECT_EQ(core_->order("O1")->order->state, OrderState::kAccepted);
  EXPECT_TRUE(core_->TakeAllocationDue());
  ASSERT_TRUE(RunRound());
  EXPECT_EQ(core_->order("O1")->robots, std::vector<std::string>{"R1"});
  // The pick is still taken: R1 waits again, timed from its recovery, and is reported blocked
  // again after blocked_after (not at once, nor never: its order must not stay with it).
  const double reassigned = now_;
  blocked_at_.reset();
  RunUntil(reassigned + 100.0, [&](const StepOutcome&) { return blocked_at_.has_value(); });
  ASSERT_TRUE(blocked_at_.has_value()) << core_->gate()->Describe("R1");
  EXPECT_GE(*blocked_at_ - *recovered_at, kBlockedAfter);
  EXPECT_EQ(core_->order("O1")->order->state, OrderState::kAccepted);
  EXPECT_EQ(core_->robot("R1")->robot.state, RobotState::kFault);
}

TEST_F(BlockedRecoveryTest, WithoutRecoveryABlockedRobotStaysInFaultUntilItsNextHello) {
  Build(0.0);
  RunUntil(300.0, [&](const StepOutcome& step) {
    EXPECT_TRUE(step.recovered.empty());
    return false;
  });
  ASSERT_TRUE(blocked_at_.has_value());
  EXPECT_EQ(core_->robot("R1")->robot.state, RobotState::kFault);
  // A report does not end the fault; a Hello does.
  const BookRobot* r = core_->robot("R1");
  (void)core_->Report("R1", r->robot.pose, std::nullopt, RobotState::kIdle, std::nullopt, r->progress.last_reached, now_);
  EXPECT_EQ(core_->robot("R1")->robot.state, RobotState::kFault);
  Robot hello = core_->robot("R1")->robot;
  hello.state = RobotState::kIdle;
  (void)core_->Connect(std::move(hello), now_);
  EXPECT_EQ(core_->robot("R1")->robot.state, RobotState::kIdle);
  // In service again: it gets the order back and, the pick still taken, waits again, timed
  // from the Hello, and is reported blocked again after blocked_after (its order goes back).
  const double hello_at = now_;
  ASSERT_TRUE(RunRound());
  EXPECT_EQ(core_->order("O1")->robots, std::vector<std::string>{"R1"});
  const double reassigned = now_;
  blocked_at_.reset();
  RunUntil(reassigned + 100.0, [&](const StepOutcome&) { return blocked_at_.has_value(); });
  ASSERT_TRUE(blocked_at_.has_value()) << core_->gate()->Describe("R1");
  EXPECT_GE(*blocked_at_ - hello_at, kBlockedAfter);
  EXPECT_EQ(core_->order("O1")->order->state, OrderState::kAccepted);
}

TEST_F(BlockedRecoveryTest, AnOrderLostMaxTimesInARowAtOnePointFailsAtItsNextLossThere) {
  // The pick stays taken for ever: without the limit R1 would get O1 back, block, and so on.
  Build(10.0, /*max_give_backs=*/2);
  for (int loss = 1; loss <= 3; ++loss) {
    SCOPED_TRACE("loss " + std::to_string(loss));
    blocked_at_.reset();
    RunUntil(now_ + 100.0, [&](const StepOutcome&) { return blocked_at_.has_value(); });
    ASSERT_TRUE(blocked_at_.has_value()) << core_->gate()->Describe("R1");
    ASSERT_EQ(last_loss_.orders.size(), 1u);
    const OrderChange& line = last_loss_.orders.front();
    EXPECT_EQ(line.order_id, "O1");
    if (loss == 3) {
      EXPECT_EQ(line.to, OrderState::kFailed);
      EXPECT_NE(line.detail.find("robot R1 blocked: "), std::string::npos) << line.detail;
      EXPECT_NE(line.detail.find("(given back 2 times in a row by R1 there)"), std::string::npos) << line.detail;
      EXPECT_EQ(core_->order("O1"), nullptr) << "a failed order leaves the book";
      break;
    }
    EXPECT_EQ(line.to, OrderState::kAccepted);
    EXPECT_EQ(core_->order("O1")->lost_there, loss);
    // Back in service, R1 gets it again.
    bool recovered = false;
    RunUntil(now_ + 100.0, [&](const StepOutcome& step) {
      for (const std::string& id : step.recovered) recovered = recovered || id == "R1";
      return recovered;
    });
    ASSERT_TRUE(recovered);
    ASSERT_TRUE(RunRound());
    EXPECT_EQ(core_->order("O1")->robots, std::vector<std::string>{"R1"});
  }
  EXPECT_EQ(core_->robot("R1")->robot.state, RobotState::kFault);
}

}  // namespace
}  // namespace dispatch::engine
