#include "engine/routing/lazy_route_table.h"

#include <atomic>
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
  ShortestPathTree tree = ReverseDijkstra(graph_.graph, targets);
  auto entry = std::make_shared<const Entry>(Entry{std::move(tree.dist), std::move(tree.via)});
  const std::size_t entry_bytes =
      entry->dist.size() * sizeof(double) + entry->via.size() * sizeof(std::int32_t);

  std::lock_guard lock(mu_);
  if (auto it = index_.find(to); it != index_.end()) return it->second->second;  // raced
  lru_.emplace_front(to, entry);
  index_[to] = lru_.begin();
  bytes_ += entry_bytes;
  while (bytes_ > cache_bytes_ && lru_.size() > 1) {
    const auto& victim = lru_.back();
    bytes_ -= victim.second->dist.size() * sizeof(double) +
              victim.second->via.size() * sizeof(std::int32_t);
    index_.erase(victim.first);
    lru_.pop_back();
  }
  return entry;
}

double LazyRouteTable::Cost(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) return std::numeric_limits<double>::infinity();
  if (from == to) return 0.0;
  return Lookup(to)->dist[static_cast<std::size_t>(from)];
}

const double* LazyRouteTable::CostsTo(PointId to) const {
  // Without turn penalties the searched vertices are the points (dist[p] = Cost(p, to)).
  if (graph_.expanded || !Known(to)) return nullptr;
  return Lookup(to)->dist.data();
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
  return {"lazy", graph_.point_count, graph_.graph.vertex_count(), graph_.graph.arc_count(),
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
