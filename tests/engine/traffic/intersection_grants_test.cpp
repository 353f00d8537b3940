// Intersection grants (Chu2024 §3.3 crossing rule): FIFO, exclusivity, sharing, release.
#include "engine/traffic/intersection_grants.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "engine/map/chu2024_floor.h"

namespace dispatch::engine {
namespace {

const Movement kEast{1, 2};
const Movement kNorth{3, 4};
const Movement kWest{5, 6};

GrantRequest Req(std::string agent, Movement m, double t, int priority = 0) {
  return {std::move(agent), m, t, priority};
}

TEST(IntersectionGrantsTest, FirstRequestIsGrantedImmediately) {
  IntersectionGrants g(2);
  ASSERT_TRUE(g.Request(1, Req("R1", kEast, 0.0)).ok());
  EXPECT_TRUE(g.Granted(1, "R1"));
  EXPECT_FALSE(g.Granted(0, "R1"));
  EXPECT_EQ(g.grants_issued(), 1u);
}

TEST(IntersectionGrantsTest, CrossingMovementsAreExclusiveAndServedFifo) {
  IntersectionGrants g(1);
  ASSERT_TRUE(g.Request(0, Req("R1", kEast, 1.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R3", kWest, 3.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kNorth, 2.0)).ok());
  EXPECT_TRUE(g.Granted(0, "R1"));
  EXPECT_FALSE(g.Granted(0, "R2"));
  EXPECT_TRUE(g.Waiting(0, "R2"));
  EXPECT_EQ(g.Queue(0), (std::vector<std::string>{"R2", "R3"}));
  ASSERT_TRUE(g.Release(0, "R1").ok());
  EXPECT_TRUE(g.Granted(0, "R2"));  // earlier request first, not R3
  EXPECT_FALSE(g.Granted(0, "R3"));
  ASSERT_TRUE(g.Release(0, "R2").ok());
  EXPECT_TRUE(g.Granted(0, "R3"));
  EXPECT_EQ(g.grants_issued(), 3u);
}

TEST(IntersectionGrantsTest, SameDirectionShares) {
  IntersectionGrants g(1);
  ASSERT_TRUE(g.Request(0, Req("R1", kEast, 1.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kEast, 2.0)).ok());
  EXPECT_TRUE(g.Granted(0, "R1"));
  EXPECT_TRUE(g.Granted(0, "R2"));
  EXPECT_EQ(g.Holders(0).size(), 2u);
  // A crossing request waits until both have left.
  ASSERT_TRUE(g.Request(0, Req("R3", kNorth, 3.0)).ok());
  ASSERT_TRUE(g.Release(0, "R1").ok());
  EXPECT_FALSE(g.Granted(0, "R3"));
  ASSERT_TRUE(g.Release(0, "R2").ok());
  EXPECT_TRUE(g.Granted(0, "R3"));
}

TEST(IntersectionGrantsTest, SameDirectionBehindAWaitingCrosserWaits) {
  // Strict FIFO: no overtaking of a waiting crossing request (no starvation).
  IntersectionGrants g(1);
  ASSERT_TRUE(g.Request(0, Req("R1", kEast, 1.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kNorth, 2.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R3", kEast, 3.0)).ok());
  EXPECT_FALSE(g.Granted(0, "R3"));
  ASSERT_TRUE(g.Release(0, "R1").ok());
  EXPECT_TRUE(g.Granted(0, "R2"));
  EXPECT_FALSE(g.Granted(0, "R3"));
}

TEST(IntersectionGrantsTest, TiesBreakByPriorityThenAgentId) {
  IntersectionGrants g(1);
  ASSERT_TRUE(g.Request(0, Req("R9", kWest, 0.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kEast, 5.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R1", kNorth, 5.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("F:T1", kEast, 5.0, 1)).ok());
  EXPECT_EQ(g.Queue(0), (std::vector<std::string>{"F:T1", "R1", "R2"}));
}

TEST(IntersectionGrantsTest, RepeatedRequestKeepsItsPlace) {
  IntersectionGrants g(1);
  ASSERT_TRUE(g.Request(0, Req("R1", kEast, 0.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kNorth, 1.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R3", kNorth, 2.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kNorth, 9.0)).ok());  // same movement: idempotent
  EXPECT_EQ(g.Queue(0), (std::vector<std::string>{"R2", "R3"}));
  EXPECT_FALSE(g.Request(0, Req("R2", kWest, 9.0)).ok());  // another movement: error
  EXPECT_EQ(g.grants_issued(), 1u);
}

TEST(IntersectionGrantsTest, FormationHoldsOneGrantAsOneAgent) {
  IntersectionGrants g(1);
  ASSERT_TRUE(g.Request(0, Req("F:T1", kEast, 0.0, 1)).ok());
  ASSERT_TRUE(g.Request(0, Req("R4", kNorth, 0.5)).ok());
  EXPECT_EQ(g.Holders(0), std::vector<std::string>{"F:T1"});
  EXPECT_FALSE(g.Granted(0, "R4"));
  ASSERT_TRUE(g.Release(0, "F:T1").ok());
  EXPECT_TRUE(g.Granted(0, "R4"));
}

// An agent found inside (placed there) holds a grant at once, even beside a holder of another
// movement, withdraws its own queued request, and keeps crossing movements out until it
// releases.
TEST(IntersectionGrantsTest, AnAgentFoundInsideHoldsAGrantAtOnce) {
  IntersectionGrants g(1);
  ASSERT_TRUE(g.Request(0, Req("R1", kEast, 1.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kNorth, 2.0)).ok());
  ASSERT_TRUE(g.Occupy(0, "R2").ok());
  EXPECT_TRUE(g.Granted(0, "R1"));
  EXPECT_TRUE(g.Granted(0, "R2"));
  EXPECT_TRUE(g.Queue(0).empty());
  ASSERT_TRUE(g.Occupy(0, "R2").ok());  // idempotent
  EXPECT_EQ(g.Holders(0), (std::vector<std::string>{"R1", "R2"}));
  ASSERT_TRUE(g.Release(0, "R1").ok());
  ASSERT_TRUE(g.Request(0, Req("R3", kWest, 3.0)).ok());
  EXPECT_FALSE(g.Granted(0, "R3"));  // R2 is still inside
  ASSERT_TRUE(g.Release(0, "R2").ok());
  EXPECT_TRUE(g.Granted(0, "R3"));
  EXPECT_FALSE(g.Occupy(1, "R4").ok());
  EXPECT_FALSE(g.Occupy(0, "").ok());
}

TEST(IntersectionGrantsTest, ErrorsAreValues) {
  IntersectionGrants g(1);
  EXPECT_EQ(g.Request(1, Req("R1", kEast, 0.0)).error().code, ErrorCode::kNotFound);
  EXPECT_EQ(g.Request(0, Req("", kEast, 0.0)).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(g.Release(0, "R1").error().code, ErrorCode::kNotFound);
  // Withdrawing a waiting request is allowed.
  ASSERT_TRUE(g.Request(0, Req("R1", kEast, 0.0)).ok());
  ASSERT_TRUE(g.Request(0, Req("R2", kNorth, 1.0)).ok());
  ASSERT_TRUE(g.Release(0, "R2").ok());
  EXPECT_TRUE(g.Queue(0).empty());
}

TEST(TrafficGuardsTest, Chu2024FloorGuardsIntersectionsAndMerges) {
  auto map = BuildChu2024Floor();
  ASSERT_TRUE(map.ok()) << map.error().message;
  const TrafficGuards only = BuildTrafficGuards(*map, false);
  EXPECT_EQ(only.guards.size(), 42u);
  const TrafficGuards all = BuildTrafficGuards(*map, true);
  EXPECT_GT(all.guards.size(), 42u);
  for (std::size_t g = 0; g < all.guards.size(); ++g) {
    for (PointId p : all.guards[g].inner) {
      EXPECT_EQ(all.guard_of_point[static_cast<std::size_t>(p)], static_cast<int>(g));
    }
    if (g >= 42) {
      EXPECT_EQ(all.guards[g].intersection, -1);
      EXPECT_GE(map->in_arcs(all.guards[g].inner.front()).size(), 2u);
    }
  }
}

}  // namespace
}  // namespace dispatch::engine
