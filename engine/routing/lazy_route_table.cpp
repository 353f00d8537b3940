#include "engine/routing/lazy_route_table.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include "engine/routing/dijkstra.h"

namespace dispatch::engine {
namespace {

std::atomic<std::uint64_t> next_table_id{1};

}  // namespace

LazyRouteTable::LazyRouteTable() : id_(next_table_id.fetch_add(1)) {}

Result<std::unique_ptr<LazyRouteTable>> LazyRouteTable::Build(
    std::shared_ptr<const WarehouseMap> map, const RouteTableOptions& options) {
  if (!map) return InvalidArgument("LazyRouteTable: null map");
  auto graph = BuildMapCostGraph(*map, options);
  if (!graph.ok()) return graph.error();
  std::unique_ptr<LazyRouteTable> t(new LazyRouteTable());
  t->map_ = std::move(map);
  t->graph_ = std::move(graph).value();
  t->cache_bytes_ = options.lazy_cache_bytes;
  return t;
}

Result<std::unique_ptr<LazyRouteTable>> LazyRouteTable::BuildWeighted(
    std::shared_ptr<const WarehouseMap> map, const RouteTableOptions& options,
    const std::vector<double>& arc_weight) {
  if (map && arc_weight.size() != map->arcs().size()) {
    return InvalidArgument("LazyRouteTable: " + std::to_string(arc_weight.size()) + " arc weights for " +
                           std::to_string(map->arcs().size()) + " arcs");
  }
  auto t = Build(map, options);
  if (!t.ok()) return t;
  LazyRouteTable& table = **t;
  const MapCostGraph& g = table.graph_;
  std::vector<CostArc> arcs = g.graph.arcs();
  for (std::size_t i = 0; i < arcs.size(); ++i) {
    const ArcId m = g.map_arc[i];
    const double w = arc_weight[static_cast<std::size_t>(m)];
    if (!std::isfinite(w) || w < 1.0) {
      return InvalidArgument("LazyRouteTable: arc " + std::to_string(m) + " has weight " + std::to_string(w) +
                             " (must be finite and >= 1)");
    }
    // The graph arc's cost is the map arc's drive time plus, expanded, a turn penalty: only
    // the drive time is weighted.
    const Arc& arc = table.map_->arc(m);
    const double v = arc.max_speed > 0.0 ? std::min(options.speed, arc.max_speed) : options.speed;
    arcs[i].cost += (w - 1.0) * (arc.length / v);
  }
  auto weighted = CostGraph::Build(g.graph.vertex_count(), std::move(arcs));
  if (!weighted.ok()) return weighted.error();
  table.search_graph_ = std::move(weighted).value();
  table.weighted_ = true;
  return t;
}

// This thread's last lookup (of any table: the key is the table's id, never reused).
struct LazyRouteTable::LastLookup {
  std::uint64_t table = 0;
  PointId to = kNoPoint;
  std::shared_ptr<const Entry> entry;
};

LazyRouteTable::LastLookup& LazyRouteTable::Last() {
  thread_local LastLookup last;
  return last;
}

const LazyRouteTable::Entry* LazyRouteTable::Lookup(PointId to) const {
  LastLookup& last = Last();
  if (last.table == id_ && last.to == to) return last.entry.get();  // no reference count touched
  std::shared_ptr<const Entry> entry = Find(to);
  last.table = id_;
  last.to = to;
  last.entry = std::move(entry);
  return last.entry.get();
}

std::shared_ptr<const LazyRouteTable::Entry> LazyRouteTable::LookupShared(PointId to) const {
  Lookup(to);
  return Last().entry;
}

void LazyRouteTable::Prepare(PointId to) const {
  if (Known(to)) Find(to);
}

std::shared_ptr<const LazyRouteTable::Entry> LazyRouteTable::Find(PointId to) const {
  {
    std::lock_guard lock(mu_);
    if (auto it = index_.find(to); it != index_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second);
      return it->second->second;
    }
    ++searches_;
  }
  const std::vector<VertexId> targets = graph_.TargetVertices(*map_, to);
  ShortestPathTree tree = ReverseDijkstra(weighted_ ? search_graph_ : graph_.graph, targets);
  Entry found{std::move(tree.dist), std::move(tree.via), {}};
  if (weighted_) found.time = UnweightedCosts(found.dist, found.via);
  auto entry = std::make_shared<const Entry>(std::move(found));
  const std::size_t entry_bytes = entry->bytes();

  std::lock_guard lock(mu_);
  if (auto it = index_.find(to); it != index_.end()) return it->second->second;  // raced
  lru_.emplace_front(to, entry);
  index_[to] = lru_.begin();
  bytes_ += entry_bytes;
  while (bytes_ > cache_bytes_ && lru_.size() > 1) {
    const auto& victim = lru_.back();
    bytes_ -= victim.second->bytes();
    index_.erase(victim.first);
    lru_.pop_back();
  }
  return entry;
}

double LazyRouteTable::Cost(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) return std::numeric_limits<double>::infinity();
  if (from == to) return 0.0;
  return Lookup(to)->cost()[static_cast<std::size_t>(from)];
}

// Along a reverse tree (`dist`, `via`: each vertex's first arc towards the destination), each
// vertex's unweighted cost to the destination: the sum of graph_'s costs of its tree arcs.
std::vector<double> LazyRouteTable::UnweightedCosts(const std::vector<double>& dist,
                                                    const std::vector<std::int32_t>& via) const {
  const double unknown = -1.0;
  std::vector<double> time(via.size(), unknown);
  std::vector<VertexId> chain;
  for (std::size_t s = 0; s < via.size(); ++s) {
    auto v = static_cast<VertexId>(s);
    while (time[static_cast<std::size_t>(v)] == unknown && via[static_cast<std::size_t>(v)] >= 0) {
      chain.push_back(v);
      v = graph_.graph.arc(via[static_cast<std::size_t>(v)]).to;
    }
    const auto root = static_cast<std::size_t>(v);
    if (time[root] == unknown) {  // a destination vertex (0) or unreachable (+infinity)
      time[root] = std::isfinite(dist[root]) ? 0.0 : std::numeric_limits<double>::infinity();
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const CostArc& a = graph_.graph.arc(via[static_cast<std::size_t>(*it)]);
      time[static_cast<std::size_t>(*it)] = a.cost + time[static_cast<std::size_t>(a.to)];
    }
    chain.clear();
  }
  return time;
}

const double* LazyRouteTable::CostsTo(PointId to) const {
  // Without turn penalties the searched vertices are the points (dist[p] = Cost(p, to)).
  if (graph_.expanded || !Known(to)) return nullptr;
  return Lookup(to)->cost().data();
}

PointId LazyRouteTable::NextHop(PointId from, PointId to) const {
  if (!Known(from) || !Known(to) || from == to) return kNoPoint;
  const std::int32_t via = Lookup(to)->via[static_cast<std::size_t>(from)];
  if (via < 0) return kNoPoint;
  return map_->arc(graph_.map_arc[static_cast<std::size_t>(via)]).to;
}

Result<Route> LazyRouteTable::Path(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) {
    return NoRouteError(*map_, from, to);
  }
  if (from == to) return Route{{from}, {}, 0.0, 0.0};
  const std::shared_ptr<const Entry> entry = LookupShared(to);
  if (entry->via[static_cast<std::size_t>(from)] < 0) {
    return NoRouteError(*map_, from, to);
  }
  if (weighted_) {  // the tree's own arcs (a parallel arc cheaper unweighted may be hotter)
    Route route{{from}, {}, 0.0, 0.0};
    for (VertexId v = from; entry->via[static_cast<std::size_t>(v)] >= 0;) {
      const std::int32_t id = entry->via[static_cast<std::size_t>(v)];
      const ArcId a = graph_.map_arc[static_cast<std::size_t>(id)];
      route.arcs.push_back(a);
      route.points.push_back(map_->arc(a).to);
      route.cost += graph_.graph.arc(id).cost;
      route.length += map_->arc(a).length;
      v = graph_.graph.arc(id).to;
    }
    return route;
  }
  // Follow the first-arc pointers; they form a tree rooted at the destination's vertices.
  std::vector<VertexId> path{from};
  VertexId v = from;
  while (entry->via[static_cast<std::size_t>(v)] >= 0) {
    v = graph_.graph.arc(entry->via[static_cast<std::size_t>(v)]).to;
    path.push_back(v);
  }
  return RouteFromVertexPath(*map_, graph_, path);
}

RouteTableBuildInfo LazyRouteTable::build_info() const {
  return {std::string(method()), graph_.point_count, graph_.graph.vertex_count(), graph_.graph.arc_count(),
          graph_.expanded, cache_bytes_, graph_.speed};
}

std::size_t LazyRouteTable::cached_destinations() const {
  std::lock_guard lock(mu_);
  return lru_.size();
}

std::size_t LazyRouteTable::searches() const {
  std::lock_guard lock(mu_);
  return searches_;
}

}  // namespace dispatch::engine
