#include "engine/allocation/fleet_state.h"

#include <gtest/gtest.h>

#include "allocation_test_util.h"

namespace dispatch::engine {
namespace {

using testing_util::Grid;
using testing_util::MakeFleet;
using testing_util::Pt;
using testing_util::Routes;

// Etas never decrease and every waypoint's arrival is after the previous departure.
void ExpectMonotone(const Plan& plan) {
  for (std::size_t k = 1; k < plan.waypoints.size(); ++k) {
    EXPECT_GE(plan.waypoints[k].eta + 1e-9, plan.waypoints[k - 1].departure()) << k;
    EXPECT_EQ(plan.waypoints[k].seq, static_cast<int>(k));
  }
}

class FleetStateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = Grid(6, 4, 1.0, 3, {{2, 0}, {4, 3}, {5, 0}}, {{0, 3}, {5, 3}});
    routes_ = Routes(map_);
  }
  PlanTask Task(const char* pick, const char* drop, double tw = 2.0) {  // t_w at the drop too
    return PlanTask{{Pt(*map_, pick)}, Pt(*map_, drop), tw, tw};
  }
  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
};

TEST_F(FleetStateTest, CreateRejectsBadRobotsAndConfig) {
  EXPECT_FALSE(FleetState::Create(map_, routes_, {{"", 0, 0.0}}).ok());
  EXPECT_FALSE(FleetState::Create(map_, routes_, {{"A", 0, 0.0}, {"A", 1, 0.0}}).ok());
  Result<FleetState> unknown = FleetState::Create(map_, routes_, {{"A", 999, 0.0}});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("'A'"), std::string::npos);
  AllocationConfig bad;
  bad.sample_step = 0.0;
  Result<FleetState> s = FleetState::Create(map_, routes_, {{"A", 0, 0.0}}, bad);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("sample_step"), std::string::npos);
  EXPECT_FALSE(FleetState::Create(nullptr, routes_, {}).ok());
}

TEST_F(FleetStateTest, APlannedTaskMatchesTheRoutedOneWithoutRouting) {
  // The plan AssignSingle builds, replayed into a fresh fleet whose robot is ready later:
  // the same waypoints shifted in time, the same T_d, T_w and end point.
  FleetState routed = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 1.0}});
  ASSERT_TRUE(routed.AssignSingle(0, "o1", Task("2,0", "0,3")).ok());
  std::vector<Waypoint> segment = routed.plan(0).waypoints;
  FleetState replayed = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 11.0}});
  auto planned = replayed.AssignPlanned(0, "o1", Task("2,0", "0,3"), segment);
  ASSERT_TRUE(planned.ok()) << planned.error().message;
  EXPECT_DOUBLE_EQ(replayed.summary(0).end_time, routed.summary(0).end_time + 10.0);
  EXPECT_DOUBLE_EQ(replayed.summary(0).travel_time, routed.summary(0).travel_time);
  EXPECT_DOUBLE_EQ(replayed.summary(0).work_time, routed.summary(0).work_time);
  EXPECT_EQ(replayed.summary(0).end_point, Pt(*map_, "0,3"));
  ASSERT_EQ(replayed.plan(0).waypoints.size(), segment.size());
  for (std::size_t k = 0; k < segment.size(); ++k) {
    EXPECT_DOUBLE_EQ(replayed.plan(0).waypoints[k].eta, segment[k].eta + 10.0) << k;
    EXPECT_EQ(replayed.plan(0).waypoints[k].point, segment[k].point) << k;
  }
  ExpectMonotone(replayed.plan(0));
  ASSERT_EQ(replayed.queue(0).size(), 1u);
  EXPECT_EQ(replayed.queue(0)[0].order_id, "o1");
  // The next task is routed on from the replayed end, as after AssignSingle.
  ASSERT_TRUE(replayed.AssignSingle(0, "o2", Task("5,0", "5,3", 1.0)).ok());
  ASSERT_TRUE(routed.AssignSingle(0, "o2", Task("5,0", "5,3", 1.0)).ok());
  EXPECT_DOUBLE_EQ(replayed.summary(0).end_time, routed.summary(0).end_time + 10.0);
  // Bad segments are errors.
  EXPECT_FALSE(replayed.AssignPlanned(0, "o3", Task("2,0", "0,3"), {segment.front()}).ok());
  std::vector<Waypoint> backwards = segment;
  backwards[2].eta = backwards[1].eta - 5.0;
  EXPECT_FALSE(replayed.AssignPlanned(0, "o3", Task("2,0", "0,3"), backwards).ok());
  EXPECT_FALSE(replayed.AssignPlanned(9, "o3", Task("2,0", "0,3"), segment).ok());
}

// A queue replayed with publish = false is predicted once, at Publish: until then the
// predictor still sees the plan before the calls, afterwards exactly what publishing every
// order would have shown.
TEST_F(FleetStateTest, AQueueReplayedUnpublishedIsPredictedAtPublish) {
  AllocationConfig c;
  c.hold_seconds = 100.0;
  FleetState routed = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 0.0}}, c);
  ASSERT_TRUE(routed.AssignSingle(0, "o1", Task("2,0", "0,3")).ok());
  const std::size_t first_end = routed.plan(0).waypoints.size();
  ASSERT_TRUE(routed.AssignSingle(0, "o2", Task("5,0", "5,3", 1.0)).ok());
  const std::vector<Waypoint>& all = routed.plan(0).waypoints;
  const std::vector<Waypoint> first(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(first_end));
  std::vector<Waypoint> second{all[first_end - 1]};
  second.insert(second.end(), all.begin() + static_cast<std::ptrdiff_t>(first_end), all.end());

  FleetState each = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 0.0}}, c);
  FleetState once = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 0.0}}, c);
  ASSERT_TRUE(each.AssignPlanned(0, "o1", Task("2,0", "0,3"), first).ok());
  ASSERT_TRUE(each.AssignPlanned(0, "o2", Task("5,0", "5,3", 1.0), second).ok());
  ASSERT_TRUE(once.AssignPlanned(0, "o1", Task("2,0", "0,3"), first, false).ok());
  ASSERT_TRUE(once.AssignPlanned(0, "o2", Task("5,0", "5,3", 1.0), second, false).ok());
  const ZoneId start = once.predictor().ZoneAt(map_->point(Pt(*map_, "0,0")).position);
  const ZoneId end = once.predictor().ZoneAt(map_->point(Pt(*map_, "5,3")).position);
  ASSERT_NE(start, end);
  const double late = each.summary(0).end_time + 10.0;
  EXPECT_EQ(once.predictor().CountAt(start, late), 1);  // still the robot idle where it stands
  EXPECT_EQ(once.predictor().CountAt(end, late), 0);
  once.Publish(0);
  EXPECT_EQ(once.summary(0).end_time, each.summary(0).end_time);
  for (double t = 0.0; t <= late; t += 0.25) {
    for (std::size_t z = 0; z < once.predictor().zone_index()->zones().size(); ++z) {
      EXPECT_EQ(once.predictor().CountAt(static_cast<ZoneId>(z), t), each.predictor().CountAt(static_cast<ZoneId>(z), t))
          << "zone " << z << " at " << t;
    }
  }
}

TEST_F(FleetStateTest, SecondTaskStartsWhenTheFirstEnds) {
  FleetState s = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 1.0}});
  EXPECT_EQ(s.summary(0).end_time, 1.0);
  ASSERT_TRUE(s.AssignSingle(0, "o1", Task("2,0", "0,3")).ok());
  // 0,0 -> 2,0 (2 m) work 2 s, -> 0,3 (5 m) work 2 s.
  EXPECT_DOUBLE_EQ(s.summary(0).end_time, 1.0 + 2 + 2 + 5 + 2);
  EXPECT_DOUBLE_EQ(s.summary(0).travel_time, 7.0);
  EXPECT_DOUBLE_EQ(s.summary(0).work_time, 4.0);
  EXPECT_EQ(s.summary(0).end_point, Pt(*map_, "0,3"));
  const double first_end = s.summary(0).end_time;
  ASSERT_TRUE(s.AssignSingle(0, "o2", Task("5,0", "5,3", 1.0)).ok());
  ASSERT_EQ(s.queue(0).size(), 2u);
  EXPECT_DOUBLE_EQ(s.queue(0)[1].start_time, first_end);
  EXPECT_DOUBLE_EQ(s.queue(0)[0].end_time, first_end);
  EXPECT_DOUBLE_EQ(s.summary(0).travel_time, 7.0 + 8.0 + 3.0);
  EXPECT_DOUBLE_EQ(s.summary(0).work_time, 4.0 + 2.0);
  ExpectMonotone(s.plan(0));
  // The plan equals BuildPlan over the whole queue.
  Result<Plan> whole = BuildPlan(*map_, *routes_, Pt(*map_, "0,0"), 1.0, 1.0,
                                 {Task("2,0", "0,3"), Task("5,0", "5,3", 1.0)});
  ASSERT_TRUE(whole.ok());
  ASSERT_EQ(whole->waypoints.size(), s.plan(0).waypoints.size());
  for (std::size_t k = 0; k < whole->waypoints.size(); ++k) {
    EXPECT_EQ(whole->waypoints[k].point, s.plan(0).waypoints[k].point);
    EXPECT_NEAR(whole->waypoints[k].eta, s.plan(0).waypoints[k].eta, 1e-9);
  }
}

TEST_F(FleetStateTest, PredictionFollowsEveryAward) {
  AllocationConfig c;
  c.hold_seconds = 100.0;
  FleetState s = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 0.0}, {"B", Pt(*map_, "5,3"), 0.0}}, c);
  const TrafficPredictor& p = s.predictor();
  const ZoneId z00 = p.ZoneAt(map_->point(Pt(*map_, "0,0")).position);
  const ZoneId z11 = p.ZoneAt(map_->point(Pt(*map_, "5,3")).position);
  ASSERT_NE(z00, z11);
  // Idle robots are seen where they stand (hold_seconds).
  EXPECT_EQ(p.CountAt(z00, 50.0), 1);
  EXPECT_EQ(p.CountAt(z11, 50.0), 1);
  ASSERT_TRUE(s.AssignSingle(0, "o1", Task("4,3", "5,3", 1.0)).ok());
  // A drives to the far zone and stays there.
  EXPECT_EQ(p.CountAt(z00, 50.0), 0);
  EXPECT_EQ(p.CountAt(z11, 50.0), 2);
  EXPECT_EQ(p.CountAt(z11, 50.0, "A"), 1);
  EXPECT_EQ(p.CountAt(z00, 0.0), 1);
}

// A state built on a previous state's zone index shares it and predicts the same counts;
// an index of another map or cell size is refused.
TEST_F(FleetStateTest, SharedZoneIndexGivesTheSamePrediction) {
  const std::vector<FleetRobot> robots = {{"A", Pt(*map_, "0,0"), 0.0}, {"B", Pt(*map_, "5,3"), 0.0}};
  FleetState first = MakeFleet(map_, routes_, robots);
  Result<FleetState> created =
      FleetState::Create(map_, routes_, robots, AllocationConfig{}, first.zone_index());
  ASSERT_TRUE(created.ok()) << created.error().message;
  FleetState again = std::move(created).value();
  EXPECT_EQ(again.zone_index(), first.zone_index());
  ASSERT_TRUE(first.AssignSingle(0, "o1", Task("4,3", "5,3", 1.0)).ok());
  ASSERT_TRUE(again.AssignSingle(0, "o1", Task("4,3", "5,3", 1.0)).ok());
  for (ZoneId z = 0; z < static_cast<ZoneId>(map_->zones().size()); ++z) {
    for (double t = 0.0; t < 30.0; t += 0.5) {
      EXPECT_EQ(again.predictor().CountAt(z, t), first.predictor().CountAt(z, t)) << z << " " << t;
    }
  }
  AllocationConfig coarse;
  coarse.traffic.zone_cell_size = 1.0;
  Result<FleetState> other_cell =
      FleetState::Create(map_, routes_, robots, coarse, first.zone_index());
  ASSERT_FALSE(other_cell.ok());
  EXPECT_NE(other_cell.error().message.find("zone index"), std::string::npos);
  auto other_map = Grid(3, 3, 1.0, 1, {{1, 1}}, {{0, 2}});
  auto other_routes = Routes(other_map);
  EXPECT_FALSE(FleetState::Create(other_map, other_routes, {{"A", 0, 0.0}}, AllocationConfig{},
                                  first.zone_index())
                   .ok());
}

TEST_F(FleetStateTest, FormationMembersStartAfterTheirOwnQueues) {
  FleetState s = MakeFleet(map_, routes_,
                           {{"A", Pt(*map_, "0,0"), 0.0}, {"B", Pt(*map_, "5,3"), 0.0},
                            {"C", Pt(*map_, "0,3"), 0.0}});
  ASSERT_TRUE(s.AssignSingle(1, "o1", Task("4,3", "0,3", 1.0)).ok());
  const double b_free = s.summary(1).end_time;  // 1 + 1 + 4 + 1 = 7
  EXPECT_DOUBLE_EQ(b_free, 7.0);
  ASSERT_TRUE(s.AssignFormation({0, 1, 2}, "f1", Task("2,0", "5,3", 1.0)).ok());
  for (std::size_t r = 0; r < 3; ++r) {
    ExpectMonotone(s.plan(r));
    ASSERT_FALSE(s.queue(r).empty());
    const QueuedTask& q = s.queue(r).back();
    EXPECT_EQ(q.order_id, "f1");
    EXPECT_EQ(q.team, (std::vector<std::string>{"A", "B", "C"}));
    EXPECT_EQ(s.summary(r).end_point, Pt(*map_, "5,3"));
  }
  // B's leg starts at 7 from 0,3: 5 m to 2,0 plus the slot distance D_f; A and C wait for it.
  const double d_f = FormationRadius();
  const double rendezvous = 7.0 + 5.0 + d_f;
  EXPECT_DOUBLE_EQ(s.queue(1).back().start_time, 7.0);
  // All members share the formation's end.
  EXPECT_NEAR(s.summary(0).end_time, s.summary(1).end_time, 1e-9);
  EXPECT_NEAR(s.summary(2).end_time, s.summary(1).end_time, 1e-9);
  EXPECT_GT(s.summary(0).end_time, rendezvous);
  // A's slot wait ends at the rendezvous.
  bool found = false;
  for (const Waypoint& w : s.plan(0).waypoints) {
    if (w.action == WaypointAction::kWait) {
      EXPECT_NEAR(w.departure(), rendezvous, 1e-9);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  // T_d of a member: its leg to the first pick + the centre's route pick -> drop (6 m).
  EXPECT_DOUBLE_EQ(s.summary(0).travel_time, 2.0 + 6.0);
  EXPECT_DOUBLE_EQ(s.summary(2).travel_time, 5.0 + 6.0);
}

// Chu2024 eq. (3)'s n_c counts the picks only; the drop's work is drop_time: by default the
// order's t_w (or the override), as at a pick; 0 is the seed's model.
TEST_F(FleetStateTest, TaskOfWorksAtTheDropAsConfigured) {
  AllocationConfig c;
  const auto task_of = [&](const AllocationConfig& config) {
    return MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 0.0}}, config)
        .TaskOf({Pt(*map_, "2,0"), Pt(*map_, "4,0")}, Pt(*map_, "0,3"), 4.0);
  };
  PlanTask t = task_of(c);
  EXPECT_EQ(t.work_time, 4.0);
  EXPECT_EQ(t.drop_time, 4.0);
  EXPECT_EQ(TaskPointCount(t), 2);
  EXPECT_DOUBLE_EQ(TaskWorkTime(t), 12.0);
  c.work_time_override = 3.0;
  EXPECT_DOUBLE_EQ(TaskWorkTime(task_of(c)), 9.0);
  c.drop_time = 0.0;
  EXPECT_DOUBLE_EQ(TaskWorkTime(task_of(c)), 6.0);
  c.drop_time = 1.5;
  EXPECT_DOUBLE_EQ(TaskWorkTime(task_of(c)), 7.5);
}

TEST_F(FleetStateTest, FailedAssignChangesNothing) {
  FleetState s = MakeFleet(map_, routes_, {{"A", 0, 0.0}, {"B", 1, 0.0}, {"C", 2, 0.0}});
  EXPECT_FALSE(s.AssignFormation({0, 0, 1}, "f", Task("2,0", "5,3")).ok());
  EXPECT_FALSE(s.AssignSingle(7, "o", Task("2,0", "5,3")).ok());
  PlanTask bad{{}, Pt(*map_, "5,3"), 1.0};
  EXPECT_FALSE(s.AssignSingle(0, "o", bad).ok());
  for (std::size_t r = 0; r < 3; ++r) {
    EXPECT_TRUE(s.queue(r).empty());
    EXPECT_EQ(s.plan(r).waypoints.size(), 1u);
  }
}

// A robot's entry as a value (Snapshot) moved to a later bucket in another state (Restore) is
// the entry moved in place (Settle): the same start, plan, summary, queue times and
// prediction. Reset makes the robot stand again; every change moves the revision.
TEST_F(FleetStateTest, SnapshotsMoveByWholeBucketsAsTheEntryDoes) {
  AllocationConfig c;
  c.hold_seconds = 30.0;
  c.traffic.bucket_seconds = 0.5;
  FleetState made = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 0.0}}, c);
  ASSERT_TRUE(made.AssignSingle(0, "o1", Task("2,0", "0,3")).ok());
  ASSERT_TRUE(made.AssignSingle(0, "o2", Task("5,0", "5,3", 1.0)).ok());
  const FleetState::RobotSnapshot snap = made.Snapshot(0);
  FleetState moved = MakeFleet(map_, routes_, {{"A", Pt(*map_, "5,3"), 9.0}}, c);  // elsewhere, later
  const std::uint64_t before = made.revision(0), moved_before = moved.revision(0);
  ASSERT_TRUE(moved.Restore(0, snap, 7).ok());
  ASSERT_TRUE(made.Settle(0, 7).ok());
  EXPECT_GT(made.revision(0), before);
  EXPECT_GT(moved.revision(0), moved_before);
  EXPECT_EQ(made.robot(0).ready_time, 3.5);
  EXPECT_EQ(moved.robot(0).ready_time, 3.5);
  EXPECT_EQ(moved.robot(0).start, Pt(*map_, "0,0"));
  EXPECT_EQ(made.summary(0).end_time, snap.summary.end_time + 3.5);
  EXPECT_EQ(moved.summary(0).end_time, made.summary(0).end_time);
  EXPECT_EQ(moved.summary(0).travel_time, made.summary(0).travel_time);
  ASSERT_EQ(moved.plan(0).waypoints.size(), made.plan(0).waypoints.size());
  for (std::size_t k = 0; k < made.plan(0).waypoints.size(); ++k) {
    EXPECT_EQ(moved.plan(0).waypoints[k].point, made.plan(0).waypoints[k].point);
    EXPECT_EQ(moved.plan(0).waypoints[k].eta, made.plan(0).waypoints[k].eta);
  }
  ASSERT_EQ(moved.queue(0).size(), 2u);
  EXPECT_EQ(moved.queue(0)[1].start_time, made.queue(0)[1].start_time);
  EXPECT_EQ(moved.queue(0)[1].start_time, snap.queue[1].start_time + 3.5);
  // Predicted as the moved plan would be by Publish.
  FleetState published = MakeFleet(map_, routes_, {{"A", Pt(*map_, "0,0"), 3.5}}, c);
  ASSERT_TRUE(published.AssignSingle(0, "o1", Task("2,0", "0,3")).ok());
  ASSERT_TRUE(published.AssignSingle(0, "o2", Task("5,0", "5,3", 1.0)).ok());
  const std::size_t zones = made.predictor().zone_index()->zones().size();
  for (double t = 0.0; t <= made.summary(0).end_time + 40.0; t += 0.25) {
    for (std::size_t z = 0; z < zones; ++z) {
      const ZoneId zone = static_cast<ZoneId>(z);
      EXPECT_EQ(moved.predictor().CountAt(zone, t), made.predictor().CountAt(zone, t)) << z << " at " << t;
      EXPECT_EQ(published.predictor().CountAt(zone, t), made.predictor().CountAt(zone, t)) << z << " at " << t;
    }
  }
  FleetState other = MakeFleet(map_, routes_, {{"B", Pt(*map_, "0,0"), 3.5}}, c);
  EXPECT_FALSE(other.Restore(0, snap, 7).ok());  // a snapshot of A
  EXPECT_TRUE(other.queue(0).empty());

  const std::uint64_t settled = made.revision(0);
  ASSERT_TRUE(made.Reset(0, Pt(*map_, "5,3"), 2.0).ok());
  EXPECT_GT(made.revision(0), settled);
  EXPECT_TRUE(made.queue(0).empty());
  ASSERT_EQ(made.plan(0).waypoints.size(), 1u);
  EXPECT_EQ(made.plan(0).waypoints[0].point, Pt(*map_, "5,3"));
  EXPECT_EQ(made.summary(0).end_time, 2.0);
  EXPECT_EQ(made.summary(0).travel_time, 0.0);
  EXPECT_FALSE(made.Reset(0, 999, 2.0).ok());
  EXPECT_FALSE(made.Reset(3, Pt(*map_, "5,3"), 2.0).ok());
}

}  // namespace
}  // namespace dispatch::engine
