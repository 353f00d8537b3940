// Helpers of the TrafficController tests: text grids (MovingAI cells, 1 m apart, named
// "c<index>" row by row), routes by point name, and one step of an ideal driver.
#pragma once

#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/io/movingai_map.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::engine::testing_traffic {

inline std::shared_ptr<const WarehouseMap> Grid(const std::vector<std::string>& rows) {
  std::string text = "type octile\nheight " + std::to_string(rows.size()) + "\nwidth " +
                     std::to_string(rows[0].size()) + "\nmap\n";
  for (const auto& r : rows) text += r + "\n";
  auto map = ParseMovingAiMap(text, "grid");
  if (!map.ok()) throw std::runtime_error(map.error().message);
  return std::make_shared<const WarehouseMap>(std::move(map).value());
}

inline PointId P(const WarehouseMap& m, const std::string& name) { return *m.FindPoint(name); }

inline std::vector<PointId> Route(const WarehouseMap& m, std::initializer_list<const char*> names) {
  std::vector<PointId> out;
  for (const char* n : names) out.push_back(P(m, n));
  return out;
}

inline TrafficController Make(std::shared_ptr<const WarehouseMap> map, TrafficControllerConfig c = {}) {
  auto ctl = TrafficController::Create(std::move(map), c);
  if (!ctl.ok()) throw std::runtime_error(ctl.error().message);
  return std::move(ctl).value();
}

// One "step" of an ideal driver: arcs take one step; standing robots with a route ask.
inline void Step(TrafficController& ctl, double t) {
  for (std::size_t r = 0; r < ctl.robot_count(); ++r) {
    if (ctl.Next(r) != kNoPoint) {
      ctl.Arrived(r, t);
    } else if (ctl.HasRoute(r)) {
      while (ctl.Request(r, t) == TrafficDecision::kReplanned) {
      }
    }
  }
  ctl.ResolveDeadlocks(t);
}

}  // namespace dispatch::engine::testing_traffic
