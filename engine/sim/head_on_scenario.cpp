#include "engine/sim/head_on_scenario.h"

#include <memory>
#include <string>
#include <utility>

#include "engine/map/map_builder.h"
#include "engine/routing/route_table.h"
#include "engine/sim/core_stream.h"

namespace dispatch::engine {
namespace {

Result<WarehouseMap> HeadOnFloor() {
  MapBuilder b("wang2019-head-on");
  b.SetFloor({0, -4}, {18, 12});
  b.AddRectZone("z", {0, -4}, {18, 12});
  b.AddPoint("S0", {14, -3}, PointKind::kPick);
  b.AddPoint("S1", {14, 0}, PointKind::kPark);
  b.AddPoint("B", {14, 2}, PointKind::kLane);
  for (int y = 3; y <= 7; ++y) {
    b.AddPoint("c" + std::to_string(y), {14, y}, y == 5 ? PointKind::kPick : PointKind::kLane);
  }
  b.AddPoint("T", {14, 8}, PointKind::kLane);
  b.AddPoint("U", {14, 10}, PointKind::kPick);
  b.AddPoint("P", {14, 11}, PointKind::kPark);
  b.AddPoint("V", {16, 8}, PointKind::kDrop);
  b.AddPoint("X", {16, 2}, PointKind::kDrop);
  b.AddPoint("D1", {7, 2}, PointKind::kLane);
  b.AddPoint("D2", {7, 8}, PointKind::kLane);
  auto lane = [&](const char* f, const char* t, std::optional<double> len = std::nullopt) {
    b.AddPath(f, t, len, 0.0, true);
  };
  lane("S0", "S1");
  lane("S1", "B");
  lane("B", "c3");
  lane("c3", "c4");
  lane("c4", "c5");
  lane("c5", "c6");
  lane("c6", "c7");
  lane("c7", "T");
  lane("T", "U");
  lane("U", "P");
  lane("T", "V");
  lane("B", "X");
  lane("B", "D1");
  lane("D1", "D2");
  lane("D2", "T");
  MapBuildOptions options;
  options.check_service_connectivity = false;
  return b.Build(options);
}

// The two orders of both scenarios: h1 starts at `h1_start`, picks at `h1_pick` for `h1_work`
// seconds and drops at V; h2 waits at its park P, is released at `h2_release`, picks at U
// (1 s) and drops at X. Checks that both complete and that the auction gave each order to the
// robot the scenario means.
struct TwoOrders {
  const char* h1_start;
  const char* h1_pick;
  double h1_work;
  double h2_release;
};

Result<StreamResult> RunTwo(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                            const TwoOrders& two, const StreamConfig& config, const std::string& scenario) {
  const WarehouseMap& m = *map;
  std::vector<FleetRobot> robots{{"h1", *m.FindPoint(two.h1_start), 0.0}, {"h2", *m.FindPoint("P"), 0.0}};
  Order o1;
  o1.id = "O1";
  o1.picks = {*m.FindPoint(two.h1_pick)};
  o1.drop = *m.FindPoint("V");
  o1.work_time = two.h1_work;
  o1.release_time = 0.0;
  Order o2;
  o2.id = "O2";
  o2.picks = {*m.FindPoint("U")};
  o2.drop = *m.FindPoint("X");
  o2.work_time = 1.0;
  o2.release_time = two.h2_release;
  o2.created_time = two.h2_release;
  auto r = SimulateOnCore(map, routes, robots, {o1, o2}, config);
  if (!r.ok()) return r.error();
  if (!r->all_completed()) return InvalidArgument(scenario + ": an order did not complete");
  if (r->orders[0].robot != "h1" || r->orders[1].robot != "h2") {
    return InvalidArgument(scenario + ": O1, O2 went to " + r->orders[0].robot + ", " + r->orders[1].robot);
  }
  return r;
}

double TimeOf(const StreamOrderOutcome& o) { return o.completion_time - o.release_time; }

Result<HeadOnRun> RunHeadOn(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                          double h1_work, HeadOnPolicy policy) {
  StreamConfig config;
  config.traffic.head_on = policy;
  config.traffic.t_w1 = 1000.0;  // the policies alone decide
  config.max_time = 600.0;
  // h1 is nearer c5 than h2 at 0 s; h2 waits at P, next to O2's pick, when O2 is released.
  auto r = RunTwo(std::move(map), std::move(routes), {"S1", "c5", h1_work, 9.0}, config, "head-on scenario");
  if (!r.ok()) return r.error();
  HeadOnRun run;
  run.h1_time = TimeOf(r->orders[0]);
  run.h2_time = TimeOf(r->orders[1]);
  for (const HeadOnRecord& rec : r->traffic.head_on) {
    if (rec.robot != "h2") continue;
    run.replanned = rec.replanned;
    run.wait_estimate = rec.wait_estimate;
    run.replan_extra = rec.replan_extra;
    break;
  }
  return run;
}

Result<CaseOneRun> RunCaseOne(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                              bool head_on_priority) {
  StreamConfig config;
  config.traffic.priority_by_release = true;
  config.traffic.head_on_priority = head_on_priority;
  config.max_time = 600.0;
  auto r = RunTwo(std::move(map), std::move(routes), {"S0", "S0", 1.0, 0.5}, config, "case 1 scenario");
  if (!r.ok()) return r.error();
  CaseOneRun run;
  run.h1_time = TimeOf(r->orders[0]);
  run.h2_time = TimeOf(r->orders[1]);
  run.deadlocks = r->traffic.deadlocks_resolved;
  for (const HeadOnRecord& rec : r->traffic.head_on) {
    run.h1_met_head_on = run.h1_met_head_on || rec.robot == "h1";
    run.h2_met_head_on = run.h2_met_head_on || rec.robot == "h2";
  }
  return run;
}

Result<std::pair<std::shared_ptr<const WarehouseMap>, std::shared_ptr<const RouteTable>>> HeadOnWorld() {
  auto built = HeadOnFloor();
  if (!built.ok()) return built.error();
  auto map = std::make_shared<const WarehouseMap>(std::move(built).value());
  auto table = MakeRouteTable(map, {});
  if (!table.ok()) return table.error();
  return std::pair{map, std::shared_ptr<const RouteTable>(std::move(table).value())};
}

}  // namespace

Result<CaseOneComparison> RunCaseOneComparison() {
  auto world = HeadOnWorld();
  if (!world.ok()) return world.error();
  CaseOneComparison out;
  for (auto [priority, slot] : {std::pair{false, &out.first_come}, std::pair{true, &out.priority}}) {
    auto run = RunCaseOne(world->first, world->second, priority);
    if (!run.ok()) return run.error();
    *slot = *run;
  }
  return out;
}

Result<HeadOnComparison> RunHeadOnComparison(double h1_work) {
  auto world = HeadOnWorld();
  if (!world.ok()) return world.error();
  const auto& [map, routes] = *world;
  HeadOnComparison out;
  out.h1_work = h1_work;
  for (auto [policy, slot] : {std::pair{HeadOnPolicy::kAlwaysWait, &out.wait},
                              std::pair{HeadOnPolicy::kAlwaysReplan, &out.replan},
                              std::pair{HeadOnPolicy::kChooseFaster, &out.chosen}}) {
    auto run = RunHeadOn(map, routes, h1_work, policy);
    if (!run.ok()) return run.error();
    *slot = *run;
  }
  return out;
}

}  // namespace dispatch::engine
