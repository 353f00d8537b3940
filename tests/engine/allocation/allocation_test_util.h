// Shared fixtures of the allocation tests: small hand-made floors, grids and fleets.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/allocation/fleet_state.h"
#include "engine/fleet/order.h"
#include "engine/map/map_builder.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine::testing_util {

inline std::shared_ptr<const WarehouseMap> Share(Result<WarehouseMap> map) {
  if (!map.ok()) throw std::runtime_error(map.error().message);
  return std::make_shared<const WarehouseMap>(std::move(map).value());
}

inline std::shared_ptr<const RouteTable> Routes(std::shared_ptr<const WarehouseMap> map,
                                                double speed = 1.0) {
  RouteTableOptions options;
  options.speed = speed;
  options.method = RouteTableMethod::kAuto;
  Result<std::unique_ptr<RouteTable>> t = MakeRouteTable(std::move(map), options);
  if (!t.ok()) throw std::runtime_error(t.error().message);
  return std::shared_ptr<const RouteTable>(std::move(t).value());
}

// A w x h grid of points "x,y" spaced `spacing` metres, joined by bidirectional single lanes,
// with zones of zone_cells x zone_cells points. Kinds: listed picks/drops, the rest lanes.
inline std::shared_ptr<const WarehouseMap> Grid(int w, int h, double spacing, int zone_cells,
                                                const std::vector<std::pair<int, int>>& picks,
                                                const std::vector<std::pair<int, int>>& drops) {
  MapBuilder b("grid");
  const double half = spacing / 2;
  b.SetFloor({-half, -half}, {(w - 1) * spacing + half, (h - 1) * spacing + half});
  for (int zx = 0; zx * zone_cells < w; ++zx) {
    for (int zy = 0; zy * zone_cells < h; ++zy) {
      const double x0 = zx * zone_cells * spacing - half;
      const double y0 = zy * zone_cells * spacing - half;
      const double x1 = std::min(w, (zx + 1) * zone_cells) * spacing - half;
      const double y1 = std::min(h, (zy + 1) * zone_cells) * spacing - half;
      b.AddRectZone("z" + std::to_string(zx) + "_" + std::to_string(zy), {x0, y0}, {x1, y1});
    }
  }
  auto name = [](int x, int y) { return std::to_string(x) + "," + std::to_string(y); };
  auto kind = [&](int x, int y) {
    for (auto p : picks) if (p == std::make_pair(x, y)) return PointKind::kPick;
    for (auto p : drops) if (p == std::make_pair(x, y)) return PointKind::kDrop;
    return PointKind::kLane;
  };
  for (int x = 0; x < w; ++x) {
    for (int y = 0; y < h; ++y) b.AddPoint(name(x, y), {x * spacing, y * spacing}, kind(x, y));
  }
  for (int x = 0; x < w; ++x) {
    for (int y = 0; y < h; ++y) {
      if (x + 1 < w) b.AddPath(name(x, y), name(x + 1, y), std::nullopt, 0.0, true);
      if (y + 1 < h) b.AddPath(name(x, y), name(x, y + 1), std::nullopt, 0.0, true);
    }
  }
  MapBuildOptions options;
  options.check_service_connectivity = false;  // a connected grid
  return Share(b.Build(options));
}

inline PointId Pt(const WarehouseMap& map, const std::string& name) {
  auto p = map.FindPoint(name);
  if (!p) throw std::runtime_error("no point " + name);
  return *p;
}

inline Order MakeOrder(std::string id, std::vector<PointId> picks, PointId drop,
                       bool formation = false, double created = 0.0) {
  Order o;
  o.id = std::move(id);
  o.picks = std::move(picks);
  o.drop = drop;
  o.formation = formation;
  o.created_time = created;
  return o;
}

inline FleetState MakeFleet(std::shared_ptr<const WarehouseMap> map,
                            std::shared_ptr<const RouteTable> routes,
                            const std::vector<FleetRobot>& robots,
                            const AllocationConfig& config = {}) {
  Result<FleetState> s = FleetState::Create(std::move(map), std::move(routes), robots, config);
  if (!s.ok()) throw std::runtime_error(s.error().message);
  return std::move(s).value();
}

}  // namespace dispatch::engine::testing_util
