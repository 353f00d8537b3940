#include "engine/routing/route_table.h"

#include <cmath>

#include "engine/routing/cost_graph.h"
#include "engine/routing/floyd_route_table.h"
#include "engine/routing/hub_label_route_table.h"
#include "engine/routing/lazy_route_table.h"

namespace dispatch::engine {
namespace {

// Per-thread costs measured by routing_bench (Release, SSE2, 2-core Xeon at 2 GHz): blocked
// Floyd ~0.15 ns per relaxation (1.18 s for 2048^3 on one thread), all-pairs Dijkstra ~2-4 ns
// per n * (n + m) * log2(n) unit on sparse road-like graphs. Crossover for m ~ 3n: n ~ 700.
constexpr double kFloydNsPerRelax = 0.15;
constexpr double kDijkstraNsPerOp = 3.0;

std::string Describe(const WarehouseMap& map, PointId p) {
  if (p < 0 || static_cast<std::size_t>(p) >= map.point_count()) {
    return "unknown point " + std::to_string(p);
  }
  return "point '" + map.point(p).name + "' (" + std::to_string(p) + ")";
}

bool Known(const WarehouseMap& map, PointId p) {
  return p >= 0 && static_cast<std::size_t>(p) < map.point_count();
}

}  // namespace

Error NoRouteError(const WarehouseMap& map, PointId from, PointId to) {
  const std::string what = "no route from " + Describe(map, from) + " to " + Describe(map, to);
  if (!Known(map, from) || !Known(map, to)) return NotFound(what + ": unknown point");
  return Unreachable(what);
}

const std::vector<std::string>& RouteTableMethodNames() {
  static const std::vector<std::string> names = {"floyd", "dijkstra", "auto", "lazy", "hub_labels"};
  return names;
}

Result<RouteTableMethod> ParseRouteTableMethod(std::string_view name) {
  static constexpr RouteTableMethod kMethods[] = {RouteTableMethod::kFloyd, RouteTableMethod::kDijkstra,
                                                  RouteTableMethod::kAuto, RouteTableMethod::kLazy,
                                                  RouteTableMethod::kHubLabels};
  const auto& names = RouteTableMethodNames();
  std::string known;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return kMethods[i];
    known += (i ? ", " : "") + names[i];
  }
  return InvalidArgument("unknown route table method '" + std::string(name) + "' (known: " + known + ")");
}

RouteTableMethod ChooseDenseMethod(std::size_t vertices, std::size_t arcs) {
  const double n = static_cast<double>(vertices);
  const double m = static_cast<double>(arcs);
  const double floyd = n * n * n * kFloydNsPerRelax;
  const double dijkstra = n * (n + m) * std::log2(n + 2.0) * kDijkstraNsPerOp;
  return dijkstra < floyd ? RouteTableMethod::kDijkstra : RouteTableMethod::kFloyd;
}

Result<std::unique_ptr<RouteTable>> MakeRouteTable(std::shared_ptr<const WarehouseMap> map,
                                                   const RouteTableOptions& options,
                                                   const CancelCheck& cancelled) {
  if (!map) return InvalidArgument("MakeRouteTable: null map");
  if (options.threads < 1) {
    return InvalidArgument("route table threads must be >= 1, got " +
                           std::to_string(options.threads));
  }
  // Searched vertex count: points, plus one per arc with the turn-expanded graph.
  const std::size_t vertices =
      map->point_count() + (options.turn_penalty_s > 0.0 ? map->arcs().size() : 0);
  const std::size_t arcs = options.turn_penalty_s > 0.0 ? 3 * map->arcs().size()
                                                        : map->arcs().size();
  RouteTableOptions resolved = options;
  if (options.method == RouteTableMethod::kHubLabels) {
    auto labels = HubLabelRouteTable::Build(std::move(map), options, cancelled);
    if (!labels.ok()) return labels.error();
    return std::unique_ptr<RouteTable>(std::move(labels).value());
  }
  if (options.method == RouteTableMethod::kLazy || vertices > options.lazy_threshold_points) {
    auto lazy = LazyRouteTable::Build(std::move(map), resolved);
    if (!lazy.ok()) return lazy.error();
    return std::unique_ptr<RouteTable>(std::move(lazy).value());
  }
  if (options.method == RouteTableMethod::kAuto) {
    resolved.method = ChooseDenseMethod(vertices, arcs);
  }
  auto dense = FloydRouteTable::Build(std::move(map), resolved, cancelled);
  if (!dense.ok()) return dense.error();
  return std::unique_ptr<RouteTable>(std::move(dense).value());
}

}  // namespace dispatch::engine
