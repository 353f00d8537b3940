// Formation orders on the dispatch core (Chu2024 §3.2, issue 4 §3; SimulateOnCore): the seed's
// task tables (members rendezvous at the first pick, then move as one rigid triangle), random
// streams with formations on the Chu2024 floor, and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "engine/cli/scenario.h"
#include "engine/fleet/formation.h"
#include "engine/sim/core_stream.h"
#include "tests/engine/sim/stream_test_support.h"

namespace dispatch::engine::testing {
namespace {

// A team that re-plans on its way (a detour, StepTeamsAfterDeadlocks) turns in place about its
// centre before a segment with a new heading, as its plan does: driven straight from its slot
// for the old heading to its slot for the new one, each member drove a leg of another length
// and the sides ranged over 0.21-0.53 m until the next waypoint (Table 1's T1 at 56.8 s).
TEST(CoreStreamFormationTest, TablesOneAndTwoFormationsGatherAndMoveAsOneRigidAgent) {
  const World w = Chu();
  for (const char* table : {"chu2024-table1.csv", "chu2024-table2.csv"}) {
    SCOPED_TRACE(table);
    auto orders = LoadTaskTableOrders(*w.map, std::string(DISPATCH_SHARED_DIR) + "/scenarios/" + table);
    ASSERT_TRUE(orders.ok()) << orders.error().message;
    auto robots = PlaceRobots(*w.map, 18);
    ASSERT_TRUE(robots.ok());
    StreamConfig c;
    c.check_safety = true;
    c.record_frames = true;
    auto r = SimulateOnCore(w.map, w.routes, *robots, *orders, c);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ExpectSane(w, *orders, *r, c);
    EXPECT_TRUE(r->all_completed());
    ASSERT_TRUE(r->safety.has_value());
    EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
    std::map<std::string, PointId> first_pick;  // by the team's agent
    for (std::size_t i = 0; i < orders->size(); ++i) {
      const Order& o = (*orders)[i];
      const StreamOrderOutcome& out = r->orders[i];
      if (!o.formation) {
        EXPECT_TRUE(out.team.empty()) << o.id;
        continue;
      }
      first_pick["formation " + o.id] = o.picks.front();
      ASSERT_EQ(out.team.size(), 3u) << o.id;
      EXPECT_EQ(out.robot, out.team.front());
      EXPECT_EQ(std::set<std::string>(out.team.begin(), out.team.end()).size(), 3u) << o.id;
    }
    ASSERT_GE(first_pick.size(), 3u);  // Table 1 has 3 formation orders, Table 2 has 4
    // Moved by its team's agent, a member drives to its slot; once all three stand in their
    // slots, one side (0.4 m) from each other, they move as one rigid triangle while the team
    // moves and turns (eq. (9)), until the first leaves after the drop - rigid up to the chords
    // of a turn in place: a robot drives straight from slot to slot, in steps of at most
    // FormationOptions::max_rotation_step (45 degrees), so mid-step the sides are as short as
    // 0.4 cos(22.5 degrees) = 0.370 m. The first time all three stand in their slots, their
    // centre is the first pick point (the rendezvous).
    const double shortest = 0.4 * std::cos(FormationOptions{}.max_rotation_step / 2) - 1e-6;
    std::map<std::string, std::size_t> frames_formed;
    std::set<std::string> formed;  // in their slots now
    for (const SafetyFrame& f : r->frames) {
      std::map<std::string, std::vector<Eigen::Vector2d>> slots;
      for (const RobotSample& s : f.robots) {
        if (s.formation) slots[s.agent].push_back(s.xy);
      }
      for (auto it = formed.begin(); it != formed.end();) {  // one left its slot: the drop is done
        it = slots.count(*it) && slots[*it].size() == 3 ? std::next(it) : formed.erase(it);
      }
      for (const auto& [agent, xy] : slots) {
        ASSERT_TRUE(first_pick.count(agent)) << agent;
        ASSERT_LE(xy.size(), 3u);
        if (xy.size() < 3) continue;
        bool in_slots = true;
        for (std::size_t a = 0; a < xy.size(); ++a) {
          for (std::size_t b = a + 1; b < xy.size(); ++b) in_slots = in_slots && std::abs((xy[a] - xy[b]).norm() - 0.4) < 1e-6;
        }
        if (formed.count(agent)) {
          for (std::size_t a = 0; a < xy.size(); ++a) {
            for (std::size_t b = a + 1; b < xy.size(); ++b) {
              const double side = (xy[a] - xy[b]).norm();
              EXPECT_TRUE(side >= shortest && side <= 0.4 + 1e-6) << agent << " at t=" << f.t << ": side " << side;
            }
          }
        } else if (in_slots && !formed.count(agent)) {
          formed.insert(agent);
          if (frames_formed[agent] == 0) {
            const Eigen::Vector2d centre = (xy[0] + xy[1] + xy[2]) / 3.0;
            EXPECT_LT((centre - w.map->point(first_pick[agent]).position).norm(), 1e-6) << agent;
          }
        }
        if (in_slots) ++frames_formed[agent];
      }
    }
    EXPECT_EQ(frames_formed.size(), first_pick.size());  // every formation formed
    for (const auto& [agent, frames] : frames_formed) {
      std::printf("%s %s: %.1f s in formation\n", table, agent.c_str(), static_cast<double>(frames) * c.time_step);
    }
  }
}

// 200 random orders with 20% formation orders on the Chu2024 floor, 18 robots, seeds 1-3,
// auction and greedy, with the product's formation settings: every run is safe on the robots'
// true positions, every order that fails says it was blocked, a completed formation had three
// robots, and most orders complete.
TEST(CoreStreamFormationTest, RandomStreamsWithFormationsOnChu2024) {
  const World w = Chu();
  std::size_t total = 0, completed = 0, formations = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Stream st = ChuStream(w, 200, seed, 0.2);
    for (AllocationStrategy strategy : {AllocationStrategy::kAuction, AllocationStrategy::kGreedy}) {
      SCOPED_TRACE("seed " + std::to_string(seed) + " " + AllocationStrategyName(strategy));
      StreamConfig c;
      c.strategy = strategy;
      c.max_time = 5000;
      c.check_safety = true;
      c.allocation.formation_max_queue = 1;
      c.one_formation_per_pick = true;
      auto r = SimulateOnCore(w.map, w.routes, st.robots, st.orders, c);
      ASSERT_TRUE(r.ok()) << r.error().message;
      ExpectSane(w, st.orders, *r, c);
      ASSERT_TRUE(r->safety.has_value());
      EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
      for (std::size_t i = 0; i < st.orders.size(); ++i) {
        const StreamOrderOutcome& o = r->orders[i];
        if (!o.completed) {
          EXPECT_NE(o.failure.find("blocked"), std::string::npos) << o.order_id << ": " << o.failure;
        }
        if (!st.orders[i].formation) continue;
        ++formations;
        if (o.completed) {
          EXPECT_EQ(o.team.size(), 3u);
        }
      }
      total += r->orders.size();
      completed += r->completed;
    }
  }
  std::printf("Chu2024 with 20%% formation orders on the core: %zu/%zu orders completed (%zu formation orders)\n",
              completed, total, formations);
  EXPECT_GT(formations, 100u);
  EXPECT_GE(static_cast<double>(completed), 0.9 * static_cast<double>(total));
}

TEST(CoreStreamFormationTest, RunsWithFormationsAreDeterministic) {
  const World w = Chu();
  const Stream st = ChuStream(w, 60, 4, 0.3);
  StreamConfig c;
  c.max_time = 3000;
  c.check_safety = false;
  auto a = SimulateOnCore(w.map, w.routes, st.robots, st.orders, c);
  auto b = SimulateOnCore(w.map, w.routes, st.robots, st.orders, c);
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t i = 0; i < a->orders.size(); ++i) {
    EXPECT_EQ(a->orders[i].team, b->orders[i].team);
    EXPECT_EQ(a->orders[i].completion_time, b->orders[i].completion_time);
  }
  EXPECT_EQ(a->overall_min_distance, b->overall_min_distance);
  EXPECT_EQ(a->traffic.grants, b->traffic.grants);
}

}  // namespace
}  // namespace dispatch::engine::testing
