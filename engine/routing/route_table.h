// RouteTable: shortest travel-time routes between map points (SPEC §3.1, Chu2024 §3.1).
//
// Costs are travel times in seconds: arc length / min(robot speed, arc max_speed), plus an
// optional turn penalty per heading change (Wang2019 eq. (3), turning time t_c). Lengths in
// metres come from Path().
//
// Implementations: FloydRouteTable (dense N x N tables, O(1) Cost/NextHop; built by blocked
// Floyd or all-pairs Dijkstra), LazyRouteTable (per-destination reverse Dijkstra, cached,
// memory-bounded) and HubLabelRouteTable (hub labels: any pair without a search, memory
// bounded by the labels). All give the same costs (dense costs are float-precision: relative
// difference <= ~1e-5). Every RouteTable is safe for concurrent const calls.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

// Returns true when a long computation should stop; it then returns an Error.
using CancelCheck = std::function<bool()>;

struct Route {
  std::vector<PointId> points;  // from ... to; {from} when from == to
  std::vector<ArcId> arcs;      // arcs[i] joins points[i] -> points[i + 1]
  double cost = 0;              // seconds, summed arc costs (+ turn penalties)
  double length = 0;            // metres
};

struct RouteTableBuildInfo {
  std::string method;              // "floyd", "dijkstra" or "lazy": what actually ran
  std::size_t point_count = 0;     // map points
  std::size_t vertex_count = 0;    // searched graph vertices (points + arcs with turn penalty)
  std::size_t arc_count = 0;       // searched graph arcs
  bool turn_expanded = false;      // the arc-expanded graph is used (turn_penalty_s > 0)
  std::size_t table_bytes = 0;     // dense tables; for lazy: the cache bound
  double speed = 0.0;              // the cruise speed of its costs (0: not known)
};

class RouteTable {
 public:
  virtual ~RouteTable() = default;
  virtual std::size_t point_count() const = 0;
  // Seconds; +infinity if unreachable or an id is unknown; 0 for from == to.
  virtual double Cost(PointId from, PointId to) const = 0;
  // The point after `from` on a cheapest route; kNoPoint if unreachable, unknown or from == to.
  virtual PointId NextHop(PointId from, PointId to) const = 0;
  // kNotFound / kUnreachable errors name both points.
  virtual Result<Route> Path(PointId from, PointId to) const = 0;
  virtual std::string_view method() const = 0;
  virtual RouteTableBuildInfo build_info() const { return {std::string(method()), point_count()}; }
  // Does now what later queries towards `to` need (a lazy table's reverse search), so that a
  // caller can pay it on another thread than the one that queries. Dense tables: nothing.
  virtual void Prepare(PointId /*to*/) const {}
  // Cost(p, to) for every point p, by point id, when the table holds them side by side (a lazy
  // table without turn penalties); nullptr otherwise (ask Cost). Valid until this thread's next
  // query of the table towards another destination.
  virtual const double* CostsTo(PointId /*to*/) const { return nullptr; }
};

enum class RouteTableMethod {
  kFloyd,     // dense, blocked multi-threaded Floyd-Warshall (Chu2024 §3.1)
  kDijkstra,  // dense, one Dijkstra per source (same tables as kFloyd)
  kAuto,      // the dense method expected faster for this graph (see ChooseDenseMethod)
  kLazy,      // per-destination reverse Dijkstra, cached (LazyRouteTable)
  kHubLabels, // hub labels over a contraction hierarchy: any pair, bounded memory (HubLabelRouteTable)
};

struct RouteTableOptions {
  double speed = 1.0;           // robot cruise speed, m/s (> 0)
  double turn_penalty_s = 0.0;  // seconds per 90 degrees of heading change (U-turn = 2x); >= 0
  RouteTableMethod method = RouteTableMethod::kFloyd;
  // Above this many searched vertices MakeRouteTable uses the lazy table whatever `method`
  // says. A dense table keeps a float distance and an int32 successor per vertex pair:
  // 8 N^2 bytes, i.e. 128 MiB at N = 4096 (~12 N^2 = 192 MiB peak while Floyd builds), and
  // Floyd needs N^3 ~ 6.9e10 relaxations there (~10 s on one core of the 2-core build
  // machine, see routing_bench). Beyond that memory and build time grow too fast for a
  // service that rebuilds its table when the map changes.
  std::size_t lazy_threshold_points = 4096;
  // Bound of the lazy table's per-destination cache: 12 bytes per searched vertex per
  // destination, so 256 MiB keeps ~22k destinations of a 1000-vertex graph, or ~220 of a
  // 100k-vertex grid. At least one destination is always kept.
  std::size_t lazy_cache_bytes = std::size_t{256} << 20;
  int threads = 2;  // worker threads for dense builds (>= 1)
};

// The methods by name, as the command lines and configuration take them: "floyd", "dijkstra",
// "auto", "lazy", "hub_labels". kInvalidArgument listing them for another name.
const std::vector<std::string>& RouteTableMethodNames();
Result<RouteTableMethod> ParseRouteTableMethod(std::string_view name);

// kAuto's rule, a cost model calibrated with routing_bench (Release, 2 cores): blocked Floyd
// costs ~n^3 * kFloydNsPerRelax, all-pairs Dijkstra ~n * (n + m) * log2(n) * kDijkstraNsPerOp
// (both divided by the thread count); the cheaper one wins. Returns kFloyd or kDijkstra.
// On sparse maps (m ~ 3n) Dijkstra wins above roughly 700 vertices; Floyd wins on small or
// dense graphs.
RouteTableMethod ChooseDenseMethod(std::size_t vertices, std::size_t arcs);

// The error Path() returns when there is no route: kNotFound naming the unknown point(s), or
// kUnreachable naming both points ("no route from point 'a' (3) to point 'b' (7)").
Error NoRouteError(const WarehouseMap& map, PointId from, PointId to);

// Builds the table chosen by `options` (see lazy_threshold_points; kHubLabels is built
// whatever the size). `cancelled` is polled on the calling thread during dense and hub label
// builds; a cancelled build returns kFailedPrecondition.
// Errors: kInvalidArgument for a null map or bad options.
Result<std::unique_ptr<RouteTable>> MakeRouteTable(std::shared_ptr<const WarehouseMap> map,
                                                   const RouteTableOptions& options,
                                                   const CancelCheck& cancelled = {});

}  // namespace dispatch::engine
