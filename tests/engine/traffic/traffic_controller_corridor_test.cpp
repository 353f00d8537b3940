// TrafficController: who keeps a robot out of a single-lane corridor held by others - one
// robot at a time where a service point is inside, but not a robot already inside that drives
// away from one standing behind it, and never a teammate.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/io/movingai_map.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::engine {
namespace {

std::shared_ptr<const WarehouseMap> Row(const std::string& cells) {
  auto map = ParseMovingAiMap("type octile\nheight 1\nwidth " + std::to_string(cells.size()) + "\nmap\n" + cells + "\n", "row");
  if (!map.ok()) throw std::runtime_error(map.error().message);
  return std::make_shared<const WarehouseMap>(std::move(map).value());
}

PointId P(const WarehouseMap& m, const std::string& name) { return *m.FindPoint(name); }

TrafficController Make(std::shared_ptr<const WarehouseMap> map) {
  auto ctl = TrafficController::Create(std::move(map), {});
  if (!ctl.ok()) throw std::runtime_error(ctl.error().message);
  return std::move(ctl).value();
}

// A drives into the corridor (a pick point inside: one robot at a time) and stops at c1, still
// holding it. B, placed further in at c3, may drive on away from A (to c5), not towards it.
// Found on a dense grid: an idle robot inside such a corridor could not step aside for a
// formation waiting behind it, the corridor held by a robot standing behind it.
TEST(TrafficControllerCorridorTest, InsideAOneRobotCorridorARobotDrivesOnAwayFromOneBehindIt) {
  auto map = Row("..S...");
  ASSERT_TRUE(IsServicePoint(map->point(P(*map, "c2")).kind));
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c0"));
  ASSERT_TRUE(ctl.SetRoute(a, {P(*map, "c0"), P(*map, "c1")}).ok());
  ASSERT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);
  ctl.Arrived(a, 1.0);  // standing at c1, inside the corridor it holds
  ASSERT_TRUE(ctl.InExclusiveCorridor(P(*map, "c1")));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c3"));
  ASSERT_TRUE(ctl.SetRoute(b, {P(*map, "c3"), P(*map, "c2")}).ok());
  EXPECT_EQ(ctl.Request(b, 1.0), TrafficDecision::kWait) << "towards A";
  ASSERT_TRUE(ctl.SetRoute(b, {P(*map, "c3"), P(*map, "c4"), P(*map, "c5")}).ok());
  EXPECT_EQ(ctl.Request(b, 2.0), TrafficDecision::kGo) << ctl.why(b);
}

// A member leaving its team's agent drives through a corridor the agent holds: teammates never
// keep each other out of a corridor (as they do not off points). Found on a dense grid: a team
// at a corner drop waited for ever for its first member to drive on from the point beside it.
TEST(TrafficControllerCorridorTest, TeammatesDoNotKeepEachOtherOutOfACorridor) {
  auto map = Row("......");
  for (int group : {0, 9}) {
    SCOPED_TRACE(group);
    TrafficController fresh = Make(map);
    const std::size_t a = *fresh.AddRobot("A", P(*map, "c1"), 9);
    ASSERT_TRUE(fresh.SetRoute(a, {P(*map, "c1"), P(*map, "c2"), P(*map, "c3")}).ok());
    ASSERT_EQ(fresh.Request(a, 0.0), TrafficDecision::kGo);  // A holds the lane eastwards
    const std::size_t b = *fresh.AddRobot("B", P(*map, "c5"), group);
    ASSERT_TRUE(fresh.SetRoute(b, {P(*map, "c5"), P(*map, "c4")}).ok());
    EXPECT_EQ(fresh.Request(b, 0.0), group == 9 ? TrafficDecision::kGo : TrafficDecision::kWait) << fresh.why(b);
  }
}

}  // namespace
}  // namespace dispatch::engine
