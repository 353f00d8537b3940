// DispatchCore (engine/dispatch/dispatch_core.h): decisions are values (Change) that change the
// book only once applied; a round's award that no longer holds is not committed; a lost robot's
// orders go back (assigned) or fail (started).
#include "engine/dispatch/dispatch_core.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dispatch_test_support.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::PointsOfKind;

class DispatchCoreTest : public ::testing::Test {
 protected:
  void SetUp() override { Build(CoreOptions{}); }

  void Build(CoreOptions options) {
    options.traffic_control = false;  // every waypoint released at once: the test drives them
    core_ = testing_util::Chu2024Core(options);
    rounds_ = testing_util::AuctionRounds();
  }

  void ConnectRobot(const std::string& id, PointId at) { testing_util::ConnectAt(*core_, id, at, now_); }

  Order MakeOrder(const std::string& id) const {
    const auto picks = PointsOfKind(*Chu2024(), PointKind::kPick);
    const auto drops = PointsOfKind(*Chu2024(), PointKind::kDrop);
    Order o;
    o.id = o.client_id = id;
    o.picks = {picks.at(3)};
    o.drop = drops.at(1);
    o.created_time = now_;
    return o;
  }

  // One round, every award planned; the change is returned unapplied.
  Change PlanRound(RoundCommit& commit) {
    std::optional<RoundInput> input = core_->MakeRound(now_, commit);
    EXPECT_TRUE(input.has_value());
    if (!input) return {};
    commit.awards = rounds_->Run(*input).awards;
    return core_->PlanAwards(commit, commit.awards.size(), now_);
  }

  // The order's state in the book; nullopt once it has left it (terminal orders are the
  // owner's to keep).
  std::optional<OrderState> StateOf(const std::string& id) const {
    const BookOrder* o = core_->order(id);
    return o ? std::optional<OrderState>(o->order->state) : std::nullopt;
  }
  // The state the change moves the order to.
  static std::optional<OrderState> To(const Change& c, const std::string& id) {
    for (const OrderChange& line : c.orders) {
      if (line.order_id == id && line.to) return line.to;
    }
    return std::nullopt;
  }

  // Drives robot `id` through its released waypoints up to and including its first pick.
  void DriveToPick(const std::string& id, const std::string& order) {
    const BookRobot* r = core_->robot(id);
    ASSERT_TRUE(r && r->has_assignment);
    for (const Waypoint& w : r->assignment.plan.waypoints) {
      if (w.seq <= 0) continue;
      now_ += 1.0;
      const ReportOutcome reached = core_->Reached(id, static_cast<std::uint64_t>(w.seq), Pose{w.xy, 0.0}, now_);
      ASSERT_TRUE(reached.taken) << reached.why;
      if (reached.change) (void)core_->Apply(*reached.change);
      if (w.action == WaypointAction::kPick) break;
    }
    TaskOutcome picked = core_->PlanTask(id, {order, false}, now_);
    ASSERT_EQ(picked.kind, TaskOutcome::Kind::kChange) << picked.why;
    (void)core_->Apply(picked.change);
  }

  std::unique_ptr<DispatchCore> core_;
  std::unique_ptr<RoundRunner> rounds_;
  double now_ = 0.0;
};

TEST_F(DispatchCoreTest, AnAwardChangesTheBookOnlyOnceApplied) {
  const auto parks = PointsOfKind(*Chu2024(), PointKind::kPark);
  ConnectRobot("R1", parks.at(0));
  core_->AddOrder(MakeOrder("O1"));
  ASSERT_TRUE(core_->TakeAllocationDue());
  RoundCommit commit;
  const Change change = PlanRound(commit);
  ASSERT_EQ(change.orders.size(), 1u);
  EXPECT_EQ(change.orders[0].to, OrderState::kAssigned);
  EXPECT_EQ(change.orders[0].robots, std::vector<std::string>{"R1"});
  ASSERT_EQ(change.plans.count("R1"), 1u);
  // Planned, not applied: the book is as it was (the owner stores the change first).
  EXPECT_EQ(StateOf("O1"), OrderState::kAccepted);
  EXPECT_FALSE(core_->robot("R1")->has_assignment);
  const std::vector<RobotCommand> sent = core_->Apply(change);
  EXPECT_EQ(StateOf("O1"), OrderState::kAssigned);
  EXPECT_TRUE(core_->robot("R1")->has_assignment);
  ASSERT_FALSE(sent.empty());
  EXPECT_EQ(sent[0].robot, "R1");
  EXPECT_EQ(sent[0].message.kind, RobotMessage::Kind::kAssignment);
  EXPECT_EQ(sent[0].message.order_ids, std::vector<std::string>{"O1"});
}

TEST_F(DispatchCoreTest, ACancelIsPlannedThenAppliedAndAnUnknownOrderIsNotFound) {
  const auto parks = PointsOfKind(*Chu2024(), PointKind::kPark);
  ConnectRobot("R1", parks.at(0));
  core_->AddOrder(MakeOrder("O1"));
  RoundCommit commit;
  (void)core_->Apply(PlanRound(commit));
  auto unknown = core_->PlanCancel("nope", "operator", now_);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
  auto cancel = core_->PlanCancel("O1", "operator", now_);
  ASSERT_TRUE(cancel.ok()) << cancel.error().message;
  EXPECT_EQ(To(*cancel, "O1"), OrderState::kCancelled);
  EXPECT_EQ(StateOf("O1"), OrderState::kAssigned);  // not yet
  const std::vector<RobotCommand> sent = core_->Apply(*cancel);
  EXPECT_EQ(StateOf("O1"), std::nullopt);  // terminal: out of the book
  ASSERT_FALSE(sent.empty());
  EXPECT_EQ(sent.back().message.kind, RobotMessage::Kind::kCancel);
}

TEST_F(DispatchCoreTest, AnAwardWhoseOrderWasCancelledMeanwhileIsNotCommitted) {
  const auto parks = PointsOfKind(*Chu2024(), PointKind::kPark);
  ConnectRobot("R1", parks.at(0));
  core_->AddOrder(MakeOrder("O1"));
  RoundCommit commit;
  std::optional<RoundInput> input = core_->MakeRound(now_, commit);
  ASSERT_TRUE(input.has_value());
  commit.awards = rounds_->Run(*input).awards;  // the round ran on its worker meanwhile...
  ASSERT_EQ(commit.awards.size(), 1u);
  auto cancel = core_->PlanCancel("O1", "client", now_);  // ...and the client cancelled
  ASSERT_TRUE(cancel.ok());
  (void)core_->Apply(*cancel);
  const Change change = core_->PlanAwards(commit, commit.awards.size(), now_);
  EXPECT_TRUE(change.orders.empty());
  EXPECT_TRUE(change.plans.empty());
  EXPECT_EQ(StateOf("O1"), std::nullopt);
}

TEST_F(DispatchCoreTest, ALostRobotsAssignedOrderGoesBackAndItsStartedOneFails) {
  const auto parks = PointsOfKind(*Chu2024(), PointKind::kPark);
  ConnectRobot("R1", parks.at(0));
  ConnectRobot("R2", parks.at(1));
  core_->AddOrder(MakeOrder("O1"));
  core_->AddOrder(MakeOrder("O2"));
  RoundCommit commit;
  (void)core_->Apply(PlanRound(commit));
  ASSERT_EQ(StateOf("O1"), OrderState::kAssigned);
  ASSERT_EQ(StateOf("O2"), OrderState::kAssigned);
  const std::string r1 = core_->order("O1")->robots.at(0);
  const std::string r2 = core_->order("O2")->robots.at(0);
  ASSERT_NE(r1, r2) << "one order each";
  DriveToPick(r1, "O1");
  ASSERT_EQ(StateOf("O1"), OrderState::kInProgress);

  const Change started = core_->PlanLoss(r1, "robot " + r1 + " blocked", now_);
  const Change waiting = core_->PlanLoss(r2, "robot " + r2 + " lost", now_);
  EXPECT_EQ(To(started, "O1"), OrderState::kFailed);  // the load is on the robot
  EXPECT_EQ(To(waiting, "O2"), OrderState::kAccepted);
  EXPECT_EQ(StateOf("O1"), OrderState::kInProgress);  // planned only
  EXPECT_EQ(StateOf("O2"), OrderState::kAssigned);
  (void)core_->Apply(started);
  (void)core_->Apply(waiting);
  EXPECT_EQ(StateOf("O1"), std::nullopt);
  EXPECT_EQ(StateOf("O2"), OrderState::kAccepted);  // re-allocated
  EXPECT_TRUE(core_->order("O2")->robots.empty());
  EXPECT_TRUE(core_->TakeAllocationDue());
  EXPECT_TRUE(core_->PlanLoss("R9", "unknown", now_).empty());
}

TEST_F(DispatchCoreTest, OneFormationAtATimeHeadsForAFirstPick) {
  CoreOptions options;
  options.one_formation_per_pick = true;
  Build(options);
  const auto parks = PointsOfKind(*Chu2024(), PointKind::kPark);
  for (int i = 0; i < 6; ++i) ConnectRobot("R" + std::to_string(i + 1), parks.at(static_cast<std::size_t>(i)));
  Order f1 = MakeOrder("F1"), f2 = MakeOrder("F2"), single = MakeOrder("S1");
  f1.formation = f2.formation = true;
  Order other = MakeOrder("F3");  // another first pick
  other.formation = true;
  other.picks = {PointsOfKind(*Chu2024(), PointKind::kPick).at(7)};
  for (const Order& o : {f1, f2, single, other}) core_->AddOrder(o);
  RoundCommit commit;
  std::optional<RoundInput> input = core_->MakeRound(now_, commit);
  ASSERT_TRUE(input.has_value());
  std::vector<std::string> pending;
  for (const auto& o : input->pending) pending.push_back(o->id);
  // F2 shares F1's first pick: it waits; a single order and another pick's formation do not.
  EXPECT_EQ(pending, (std::vector<std::string>{"F1", "F3", "S1"}));
  commit.awards = rounds_->Run(*input).awards;
  (void)core_->Apply(core_->PlanAwards(commit, commit.awards.size(), now_));
  ASSERT_EQ(StateOf("F1"), OrderState::kAssigned);
  // While F1 is heading for its pick, F2 is not in any round.
  RoundCommit again;
  std::optional<RoundInput> next = core_->MakeRound(now_, again);
  EXPECT_FALSE(next.has_value()) << "F2 only is pending, and it waits";
  // F1's leader reaches the pick: F1 has started, F2 may be allocated.
  DriveToPick(core_->order("F1")->robots.front(), "F1");
  ASSERT_EQ(StateOf("F1"), OrderState::kInProgress);
  EXPECT_TRUE(core_->TakeAllocationDue());
  RoundCommit third;
  next = core_->MakeRound(now_, third);
  ASSERT_TRUE(next.has_value());
  ASSERT_EQ(next->pending.size(), 1u);
  EXPECT_EQ(next->pending[0]->id, "F2");
}

}  // namespace
}  // namespace dispatch::engine
