// A round's routes other than the route table's (issue 16 §3): the time-window planner
// (window_awards.h) and Wang2019's path heat (heat_awards.h). Either gives the strategy's
// awards with their stops, only routed or timed again.
#include <gtest/gtest.h>

#include "engine/dispatch/heat_awards.h"
#include "engine/dispatch/strategy.h"
#include "engine/dispatch/window_awards.h"
#include "tests/engine/dispatch/dispatch_test_support.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::Chu2024Routes;
using testing_util::MakeOrder;
using testing_util::PointsOfKind;

RoundResult RunRound(const AllocationConfig& config, const RoundInput& input) {
  RoundRunner runner(Chu2024(), Chu2024Routes(), config, std::move(MakeAllocator("auction")).value());
  return runner.Run(input);
}

struct Stop {
  PointId point;
  WaypointAction action;
  double dwell;
  bool operator==(const Stop& o) const { return point == o.point && action == o.action && dwell == o.dwell; }
};

std::vector<Stop> StopsOf(const std::vector<Waypoint>& segment) {
  std::vector<Stop> out;
  for (const Waypoint& w : segment) {
    if (w.action == WaypointAction::kPick || w.action == WaypointAction::kDrop) out.push_back({w.point, w.action, w.dwell});
  }
  return out;
}

// 8 robots at parking stations, 10 orders with distinct drops (a robot stays at its last
// drop: a second order there would keep the table's route under the time windows).
RoundInput BusyRound() {
  const auto& map = *Chu2024();
  const auto parks = PointsOfKind(map, PointKind::kPark);
  const auto picks = PointsOfKind(map, PointKind::kPick);
  const auto drops = PointsOfKind(map, PointKind::kDrop);
  RoundInput input;
  input.now = 50.0;
  for (int i = 0; i < 8; ++i) {
    input.robots.push_back({"R" + std::to_string(i + 1), parks.at(static_cast<std::size_t>(i) * 2), {}, 0, {}});
  }
  for (int k = 0; k < 10; ++k) {  // more orders than robots: some robots get a queue
    input.pending.push_back(MakeOrder("o" + std::to_string(k), picks.at(static_cast<std::size_t>(k * 7 % 96)),
                                      drops.at(static_cast<std::size_t>(k)), 1.0 + k));
  }
  return input;
}

class RoundRoutesTest : public ::testing::TestWithParam<bool> {  // true: time windows, false: heat
 protected:
  AllocationConfig Config() const {
    AllocationConfig c;
    if (GetParam()) {
      c.planner = PlannerKind::kTimeWindows;
    } else {
      c.routing = RoutingKind::kHeat;
    }
    return c;
  }
};

TEST_P(RoundRoutesTest, SegmentsKeepTheirAwardsAndStopsAndFollowTheMapsArcs) {
  const auto& map = *Chu2024();
  const RoundInput input = BusyRound();
  const RoundResult table = RunRound(AllocationConfig{}, input);
  const RoundResult other = RunRound(Config(), input);
  EXPECT_TRUE(other.notes.empty()) << other.notes.front();
  ASSERT_EQ(table.awards.size(), other.awards.size());
  int changed = 0;
  for (std::size_t k = 0; k < table.awards.size(); ++k) {
    const RoundAward& a = table.awards[k];
    const RoundAward& b = other.awards[k];
    SCOPED_TRACE(b.order_id);
    EXPECT_EQ(a.order_id, b.order_id);
    EXPECT_EQ(a.award.winners, b.award.winners);
    ASSERT_EQ(b.segments.size(), 1u);
    EXPECT_EQ(StopsOf(a.segments[0]), StopsOf(b.segments[0]));
    const auto& seg = b.segments[0];
    for (std::size_t i = 1; i < seg.size(); ++i) {
      EXPECT_LE(seg[i - 1].departure(), seg[i].eta + 1e-9);
      if (seg[i].point == seg[i - 1].point) continue;
      const auto arc = map.FindArc(seg[i - 1].point, seg[i].point);
      ASSERT_TRUE(arc);
      if (!GetParam()) {  // heat: timed at 1 m/s along its route
        EXPECT_NEAR(seg[i].eta - seg[i - 1].departure(), map.arc(*arc).length, 1e-9);
      }
    }
    if (a.segments[0].size() != seg.size() || a.segments[0].back().eta != seg.back().eta) ++changed;
  }
  EXPECT_GT(changed, 0);  // some robot waits for, or goes round, the others
}

INSTANTIATE_TEST_SUITE_P(TimeWindowsAndHeat, RoundRoutesTest, ::testing::Bool(),
                         [](const auto& info) { return std::string(info.param ? "TimeWindows" : "Heat"); });

TEST(RoundRoutes, NamesRoundTripAndBadSettingsAreRefused) {
  for (const std::string& name : PlannerNames()) EXPECT_EQ(PlannerName(*ParsePlanner(name)), name);
  for (const std::string& name : RoutingNames()) EXPECT_EQ(RoutingName(*ParseRouting(name)), name);
  EXPECT_FALSE(ParsePlanner("cbs"));
  EXPECT_FALSE(ParseRouting("astar"));
  AllocationConfig bad;
  bad.windows.body_length = 0.0;
  EXPECT_FALSE(ValidateAllocationConfig(bad).ok());
  bad = {};
  bad.heat_period = 0.0;
  EXPECT_FALSE(ValidateAllocationConfig(bad).ok());
}

}  // namespace
}  // namespace dispatch::engine
