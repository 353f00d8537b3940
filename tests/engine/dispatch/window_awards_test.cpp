// The time-window planner in an allocation round (window_awards.h): the same awards as the
// rules, each single-robot segment re-planned with its stops kept.
#include "engine/dispatch/window_awards.h"

#include <gtest/gtest.h>

#include "engine/dispatch/strategy.h"
#include "engine/planning/time_windows.h"
#include "tests/engine/dispatch/dispatch_test_support.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::Chu2024Routes;
using testing_util::PointsOfKind;

std::shared_ptr<const Order> MakeOrder(const std::string& id, PointId pick, PointId drop, double created) {
  auto o = std::make_shared<Order>();
  o->id = id;
  o->client_id = id;
  o->picks = {pick};
  o->drop = drop;
  o->created_time = created;
  return o;
}

RoundResult RunRound(PlannerKind planner, const RoundInput& input) {
  AllocationConfig config;
  config.planner = planner;
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

TEST(WindowAwards, SegmentsKeepTheirAwardsAndStopsAndFollowTheMapsArcs) {
  const auto& map = *Chu2024();
  const auto parks = PointsOfKind(map, PointKind::kPark);
  const auto picks = PointsOfKind(map, PointKind::kPick);
  const auto drops = PointsOfKind(map, PointKind::kDrop);
  RoundInput input;
  input.now = 50.0;
  for (int i = 0; i < 8; ++i) {
    input.robots.push_back({"R" + std::to_string(i + 1), parks.at(static_cast<std::size_t>(i) * 2), {}, 0, {}});
  }
  for (int k = 0; k < 10; ++k) {  // more orders than robots: some robots get a queue (distinct drops:
    // a robot stays at its last drop, so a second order there would keep the rules' route)
    input.pending.push_back(MakeOrder("o" + std::to_string(k), picks.at(static_cast<std::size_t>(k * 7 % 96)),
                                      drops.at(static_cast<std::size_t>(k % 10)), 1.0 + k));
  }
  const RoundResult rules = RunRound(PlannerKind::kRules, input);
  const RoundResult windows = RunRound(PlannerKind::kTimeWindows, input);
  EXPECT_TRUE(windows.notes.empty()) << windows.notes.front();
  ASSERT_EQ(rules.awards.size(), windows.awards.size());
  int changed = 0;
  for (std::size_t k = 0; k < rules.awards.size(); ++k) {
    const RoundAward& a = rules.awards[k];
    const RoundAward& b = windows.awards[k];
    SCOPED_TRACE(b.order_id);
    EXPECT_EQ(a.order_id, b.order_id);
    EXPECT_EQ(a.award.winners, b.award.winners);
    ASSERT_EQ(b.segments.size(), 1u);
    EXPECT_EQ(StopsOf(a.segments[0]), StopsOf(b.segments[0]));
    const auto& seg = b.segments[0];
    for (std::size_t i = 1; i < seg.size(); ++i) {
      EXPECT_LE(seg[i - 1].departure(), seg[i].eta + 1e-9);
      if (seg[i].point != seg[i - 1].point) {
        EXPECT_TRUE(map.FindArc(seg[i - 1].point, seg[i].point));
      }
    }
    if (a.segments[0].size() != seg.size() || a.segments[0].back().eta != seg.back().eta) ++changed;
  }
  EXPECT_GT(changed, 0);  // some robot waits or goes round another
}

TEST(WindowAwards, PlannerNamesRoundTrip) {
  for (const std::string& name : PlannerNames()) EXPECT_EQ(PlannerName(*ParsePlanner(name)), name);
  EXPECT_FALSE(ParsePlanner("cbs"));
  AllocationConfig bad;
  bad.windows.body_length = 0.0;
  EXPECT_FALSE(ValidateAllocationConfig(bad).ok());
}

}  // namespace
}  // namespace dispatch::engine
