// Operators' commands on robots through the dispatch core (issue 18 §4,
// engine/dispatch/robot_commands.h, DispatchCore::PlanCommand): each is a Change that changes
// nothing until applied; out of service gives the robot's orders back and keeps it out of every
// round until returned; pause keeps it out of rounds too; only an offline robot is cleared off
// the floor; a robot sent to a station bids again once it is there; the commands replay from
// the core's journal.
#include "engine/dispatch/robot_commands.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dispatch_test_support.h"
#include "engine/dispatch/core_replay.h"
#include "engine/dispatch/dispatch_core.h"
#include "engine/dispatch/journaled_core.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::PointsOfKind;

class RobotCommandsTest : public ::testing::Test {
 protected:
  void Build(bool traffic_control) {
    CoreOptions options;
    options.traffic_control = traffic_control;
    core_ = testing_util::Chu2024Core(options);
    rounds_ = testing_util::AuctionRounds();
  }
  void SetUp() override { Build(true); }

  PointId Park(std::size_t i) const { return PointsOfKind(*Chu2024(), PointKind::kPark).at(i); }

  void ConnectRobot(const std::string& id, PointId at) { testing_util::ConnectAt(*core_, id, at, now_); }

  void AddOrder(const std::string& id) {
    Order o;
    o.id = o.client_id = id;
    o.picks = {PointsOfKind(*Chu2024(), PointKind::kPick).at(3)};
    o.drop = PointsOfKind(*Chu2024(), PointKind::kDrop).at(1);
    o.created_time = now_;
    core_->AddOrder(std::move(o));
  }

  // A round over the accepted orders, applied; false when no robot may bid.
  bool RunRound() { return testing_util::ApplyRound(*core_, *rounds_, now_); }

  Change Command(RobotCommandKind kind, const std::string& robot, PointId to = kNoPoint) {
    Result<Change> c = core_->PlanCommand({kind, robot, "op-1", to}, now_);
    EXPECT_TRUE(c.ok()) << RobotCommandName(kind) << ": " << c.error().message;
    return c.ok() ? *c : Change{};
  }
  ErrorCode Refused(RobotCommandKind kind, const std::string& robot, PointId to = kNoPoint) {
    Result<Change> c = core_->PlanCommand({kind, robot, "op-1", to}, now_);
    EXPECT_FALSE(c.ok()) << RobotCommandName(kind) << " " << robot << " was accepted";
    return c.ok() ? ErrorCode::kInvalidArgument : c.error().code;
  }

  std::optional<OrderState> StateOf(const std::string& id) const {
    const BookOrder* o = core_->order(id);
    return o ? std::optional<OrderState>(o->order->state) : std::nullopt;
  }

  std::unique_ptr<DispatchCore> core_;
  std::unique_ptr<RoundRunner> rounds_;
  double now_ = 0.0;
};

TEST_F(RobotCommandsTest, OutOfServiceGivesTheOrdersBackAndKeepsTheRobotOutOfRoundsUntilReturned) {
  ConnectRobot("R1", Park(0));
  AddOrder("O1");
  ASSERT_TRUE(RunRound());
  ASSERT_EQ(StateOf("O1"), OrderState::kAssigned);

  const Change out = Command(RobotCommandKind::kTakeOutOfService, "R1");
  ASSERT_EQ(out.orders.size(), 1u);
  EXPECT_EQ(out.orders[0].to, OrderState::kAccepted);
  EXPECT_NE(out.orders[0].detail.find("taken out of service by op-1"), std::string::npos) << out.orders[0].detail;
  EXPECT_EQ(out.marks.at("R1").out_of_service_by, "op-1");
  EXPECT_EQ(StateOf("O1"), OrderState::kAssigned) << "planned only";
  EXPECT_TRUE(core_->robot("R1")->marks.out_of_service_by.empty());

  (void)core_->Apply(out);
  EXPECT_EQ(StateOf("O1"), OrderState::kAccepted);
  EXPECT_EQ(core_->robot("R1")->marks.out_of_service_by, "op-1");
  EXPECT_TRUE(core_->robot("R1")->assignment.order_ids.empty());
  EXPECT_EQ(core_->gate()->RobotState("R1").paused_by, "op-1 (out of service)") << "held where it stands";
  EXPECT_FALSE(RunRound()) << "bid while out of service";
  // Resuming does not put it back in service.
  (void)core_->Apply(Command(RobotCommandKind::kResume, "R1"));
  EXPECT_FALSE(RunRound());

  (void)core_->TakeAllocationDue();
  (void)core_->Apply(Command(RobotCommandKind::kReturnToService, "R1"));
  EXPECT_TRUE(core_->TakeAllocationDue());
  EXPECT_EQ(core_->gate()->RobotState("R1").paused_by, "");
  ASSERT_TRUE(RunRound());
  EXPECT_EQ(StateOf("O1"), OrderState::kAssigned);
  EXPECT_EQ(Refused(RobotCommandKind::kTakeOutOfService, "R9"), ErrorCode::kNotFound);
}

TEST_F(RobotCommandsTest, APausedRobotKeepsItsOrdersButBidsForNoNewOnes) {
  ConnectRobot("R1", Park(0));
  AddOrder("O1");
  ASSERT_TRUE(RunRound());
  const Change paused = Command(RobotCommandKind::kPause, "R1");
  EXPECT_TRUE(paused.orders.empty());
  (void)core_->Apply(paused);
  EXPECT_EQ(core_->robot("R1")->marks.paused_by, "op-1");
  EXPECT_TRUE(core_->gate()->Paused("R1"));
  EXPECT_EQ(StateOf("O1"), OrderState::kAssigned);
  AddOrder("O2");
  EXPECT_FALSE(RunRound()) << "bid while paused";
  (void)core_->Apply(Command(RobotCommandKind::kResume, "R1"));
  EXPECT_FALSE(core_->gate()->Paused("R1"));
  ASSERT_TRUE(RunRound());
  EXPECT_EQ(StateOf("O2"), OrderState::kAssigned);

  Build(false);  // nothing to hold a robot with
  ConnectRobot("R1", Park(0));
  EXPECT_EQ(Refused(RobotCommandKind::kPause, "R1"), ErrorCode::kFailedPrecondition);
}

TEST_F(RobotCommandsTest, OnlyAnOfflineRobotIsClearedOffTheFloorUntilItSaysHelloAgain) {
  ConnectRobot("R1", Park(0));
  AddOrder("O1");
  ASSERT_TRUE(RunRound());
  EXPECT_EQ(Refused(RobotCommandKind::kClear, "R1"), ErrorCode::kFailedPrecondition);
  core_->Disconnect("R1");
  const Change cleared = Command(RobotCommandKind::kClear, "R1");
  ASSERT_EQ(cleared.orders.size(), 1u);
  EXPECT_EQ(cleared.orders[0].to, OrderState::kAccepted);
  EXPECT_TRUE(cleared.marks.at("R1").off_floor);
  (void)core_->Apply(cleared);
  EXPECT_TRUE(core_->robot("R1")->marks.off_floor);
  EXPECT_EQ(StateOf("O1"), OrderState::kAccepted);
  // Another robot may now be sent where R1 stood: it is no obstacle.
  ConnectRobot("R2", Park(1));
  const Change sent = Command(RobotCommandKind::kSend, "R2", Park(0));
  EXPECT_EQ(sent.plans.count("R2"), 1u);
  ConnectRobot("R1", Park(2));
  EXPECT_FALSE(core_->robot("R1")->marks.off_floor) << "a Hello puts it back on the floor";
}

TEST_F(RobotCommandsTest, ARobotSentToAStationBidsAgainOnceItIsThere) {
  Build(false);  // every waypoint released: the test drives them
  ConnectRobot("R1", Park(0));
  ConnectRobot("R2", Park(1));
  const Change sent = Command(RobotCommandKind::kSend, "R1", Park(2));
  ASSERT_EQ(sent.plans.count("R1"), 1u);
  const Assignment& plan = sent.plans.at("R1");
  EXPECT_TRUE(plan.order_ids.empty());
  ASSERT_GE(plan.plan.waypoints.size(), 2u);
  EXPECT_EQ(plan.plan.waypoints.front().point, Park(0));
  EXPECT_EQ(plan.plan.waypoints.back().point, Park(2));
  EXPECT_EQ(plan.plan.waypoints.back().action, WaypointAction::kPark);
  ASSERT_EQ(sent.sends.size(), 1u);
  EXPECT_EQ(sent.sends[0].kind, PlanSend::Kind::kFull);
  EXPECT_EQ(core_->TripTo("R1"), kNoPoint) << "planned only";
  const std::vector<RobotCommand> messages = core_->Apply(sent);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0].message.kind, RobotMessage::Kind::kAssignment);
  EXPECT_EQ(core_->TripTo("R1"), Park(2));

  // Refused: a robot on its way, a robot serving orders, a station another robot is sent to,
  // a point that is not on the map, an unknown robot.
  EXPECT_EQ(Refused(RobotCommandKind::kSend, "R2", Park(2)), ErrorCode::kFailedPrecondition);
  EXPECT_EQ(Refused(RobotCommandKind::kSend, "R2", Park(0) + 100000), ErrorCode::kNotFound);
  EXPECT_EQ(Refused(RobotCommandKind::kSend, "R9", Park(3)), ErrorCode::kNotFound);
  AddOrder("O1");
  ASSERT_TRUE(RunRound());
  EXPECT_EQ(core_->order("O1")->robots, std::vector<std::string>{"R2"}) << "R1 bid on its way";
  EXPECT_EQ(Refused(RobotCommandKind::kSend, "R2", Park(3)), ErrorCode::kFailedPrecondition);

  for (const Waypoint& w : core_->robot("R1")->assignment.plan.waypoints) {
    now_ += 1.0;
    const ReportOutcome reached = core_->Reached("R1", static_cast<std::uint64_t>(w.seq), Pose{w.xy, 0.0}, now_);
    ASSERT_TRUE(reached.taken) << reached.why;
  }
  EXPECT_EQ(core_->TripTo("R1"), kNoPoint);
  EXPECT_EQ(core_->robot("R1")->robot.current_point, Park(2));
  AddOrder("O2");
  ASSERT_TRUE(RunRound());
  EXPECT_EQ(core_->order("O2")->robots, std::vector<std::string>{"R1"});
}

TEST_F(RobotCommandsTest, MarksRestoredWithARobotKeepItOutOfRounds) {
  Robot r;
  r.id = "R1";
  r.current_point = Park(0);
  r.pose.position = Chu2024()->point(Park(0)).position;
  core_->RestoreRobot(r, std::nullopt, /*place=*/true, OperatorMarks{"", "op-2", false});
  EXPECT_EQ(core_->gate()->RobotState("R1").paused_by, "op-2 (out of service)");
  ConnectRobot("R1", Park(0));
  AddOrder("O1");
  EXPECT_FALSE(RunRound()) << "bid while out of service after a restart";
  EXPECT_EQ(core_->robot("R1")->marks.out_of_service_by, "op-2");
}

// Every command is a journal entry; a fresh core fed the journal (CoreReplay, as dispatch-sim
// replay does) gives the same output for each, refusals included, and ends with the same marks.
TEST(RobotCommandsJournalTest, CommandsReplayEntryByEntry) {
  CoreOptions options;
  JournaledCore core(testing_util::Chu2024Core(options), /*recording=*/true);
  const auto parks = PointsOfKind(*Chu2024(), PointKind::kPark);
  for (const auto& [id, at] : {std::pair{"R1", parks.at(0)}, std::pair{"R2", parks.at(1)}}) {
    Robot r;
    r.id = id;
    r.current_point = at;
    r.pose.position = Chu2024()->point(at).position;
    (void)core.Connect(r, 0.0);
  }
  double now = 1.0;
  auto command = [&](RobotCommandKind kind, const std::string& robot, PointId to = kNoPoint) {
    Result<Change> c = core.PlanCommand({kind, robot, "op-1", to}, now += 1.0);
    if (c.ok()) (void)core.Apply(*c);
    return c.ok();
  };
  EXPECT_TRUE(command(RobotCommandKind::kPause, "R1"));
  EXPECT_TRUE(command(RobotCommandKind::kSend, "R2", parks.at(3)));
  EXPECT_TRUE(command(RobotCommandKind::kTakeOutOfService, "R1"));
  EXPECT_FALSE(command(RobotCommandKind::kClear, "R2"));  // connected: refused, journaled too
  core.Disconnect("R1");
  EXPECT_TRUE(command(RobotCommandKind::kClear, "R1"));
  EXPECT_TRUE(command(RobotCommandKind::kResume, "R1"));
  const std::vector<JournalEntry> journal = core.TakeEntries();

  ReplaySetup setup;
  setup.map = Chu2024();
  setup.routes = testing_util::Chu2024Routes();
  setup.core = options;
  auto replay = CoreReplay::Create(setup);
  ASSERT_TRUE(replay.ok()) << replay.error().message;
  std::size_t commands = 0;
  for (const JournalEntry& e : journal) {
    auto out = (*replay)->Feed(e);
    ASSERT_TRUE(out.ok()) << out.error().message;
    EXPECT_EQ(*out, e.output) << "entry " << e.seq << " (" << CoreInputKindName(e.input.kind) << ")";
    if (e.input.kind == CoreInput::Kind::kPlanCommand) ++commands;
  }
  EXPECT_EQ(commands, 6u);
  for (const char* id : {"R1", "R2"}) {
    EXPECT_EQ((*replay)->core().robot(id)->marks, core.robot(id)->marks) << id;
    EXPECT_EQ((*replay)->core().TripTo(id), core.core().TripTo(id)) << id;
  }
  EXPECT_EQ(core.robot("R1")->marks, (OperatorMarks{"", "op-1", true}));
  EXPECT_EQ(core.core().TripTo("R2"), parks.at(3));
}

TEST(StationPointTest, AStationOrAParkOrChargePointByName) {
  const WarehouseMap& map = *Chu2024();
  ASSERT_FALSE(map.stations().empty());
  const ParkingStation& station = map.stations().front();
  auto by_station = StationPoint(map, station.name);
  ASSERT_TRUE(by_station.ok()) << by_station.error().message;
  EXPECT_EQ(*by_station, station.point);
  auto by_point = StationPoint(map, map.point(station.point).name);
  ASSERT_TRUE(by_point.ok()) << by_point.error().message;
  EXPECT_EQ(*by_point, station.point);
  const PointId pick = PointsOfKind(map, PointKind::kPick).at(0);
  EXPECT_EQ(StationPoint(map, map.point(pick).name).error().code, ErrorCode::kInvalidArgument);
  auto unknown = StationPoint(map, "nowhere");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
  EXPECT_NE(unknown.error().message.find(station.name), std::string::npos) << "names the stations";
}

TEST(RobotCommandNameTest, EveryCommandParsesBackFromItsName) {
  for (RobotCommandKind k : {RobotCommandKind::kPause, RobotCommandKind::kResume, RobotCommandKind::kTakeOutOfService,
                             RobotCommandKind::kReturnToService, RobotCommandKind::kClear, RobotCommandKind::kSend}) {
    EXPECT_EQ(ParseRobotCommand(RobotCommandName(k)), k);
  }
  EXPECT_EQ(ParseRobotCommand("explode"), std::nullopt);
}

}  // namespace
}  // namespace dispatch::engine
