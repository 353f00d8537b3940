// LazyRouteTable: a RouteTable for maps too large for an N x N matrix (SPEC §3.1). The first
// query towards a destination runs one reverse Dijkstra to it over the searched graph (turn
// penalties included: the search starts from the destination point and all its arrival arc
// vertices) and caches, per searched vertex, the double distance to the destination and the
// first arc towards it (12 bytes per vertex). Later queries to that destination are O(1)
// (Path walks the cached arcs). Answers equal FloydRouteTable's up to its float rounding.
//
// The cache is an LRU bounded by options.lazy_cache_bytes (the most recent destination is
// always kept). Thread safety: all const methods may be called concurrently; `mu_` guards the
// LRU list and index. Searches run outside the lock (two threads may search the same
// destination; the first insert wins); entries are immutable shared_ptrs, so a query keeps
// its entry alive even if another thread evicts it. Each thread remembers the last entry it
// looked up (per table), so a run of queries towards one destination (walking a route, a
// bid's robots) takes the lock once.
//
// Weighted (BuildWeighted): the routes minimise the drive time of each map arc times its
// weight (plus the turn penalties, unweighted), and Cost answers the unweighted time of that
// route (what a robot driving it takes): Wang2019's heat-weighted Dijkstra (seed 004 §3.1
// step 5) as a table, for the auction's bids (engine/planning/path_heat.h, HeatRouteTable).
// method() is then "weighted".
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "engine/routing/cost_graph.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

class LazyRouteTable final : public RouteTable {
 public:
  static Result<std::unique_ptr<LazyRouteTable>> Build(std::shared_ptr<const WarehouseMap> map,
                                                       const RouteTableOptions& options);
  // `arc_weight`: one finite weight >= 1 per map arc (kInvalidArgument naming the arc
  // otherwise, or for a vector of another size).
  static Result<std::unique_ptr<LazyRouteTable>> BuildWeighted(std::shared_ptr<const WarehouseMap> map,
                                                               const RouteTableOptions& options,
                                                               const std::vector<double>& arc_weight);

  std::size_t point_count() const override { return graph_.point_count; }
  double Cost(PointId from, PointId to) const override;
  PointId NextHop(PointId from, PointId to) const override;
  Result<Route> Path(PointId from, PointId to) const override;
  void Prepare(PointId to) const override;
  const double* CostsTo(PointId to) const override;
  std::string_view method() const override { return weighted_ ? "weighted" : "lazy"; }
  RouteTableBuildInfo build_info() const override;

  // Cache statistics, for tests and monitoring.
  std::size_t cached_destinations() const;
  std::size_t searches() const;

 private:
  struct Entry {
    std::vector<double> dist;       // per searched vertex: cost to the destination
    std::vector<std::int32_t> via;  // per searched vertex: first graph arc towards it, or -1
    // Weighted tables: per searched vertex, the unweighted cost of its route (dist is the
    // weighted one); empty otherwise.
    std::vector<double> time;
    std::size_t bytes() const {
      return (dist.size() + time.size()) * sizeof(double) + via.size() * sizeof(std::int32_t);
    }
    const std::vector<double>& cost() const { return time.empty() ? dist : time; }
  };
  LazyRouteTable();
  bool Known(PointId p) const { return p >= 0 && static_cast<std::size_t>(p) < graph_.point_count; }
  // Via this thread's last entry: valid until this thread's next Lookup (Cost and NextHop read
  // it at once; a shared_ptr copy per query cost two atomic reference count updates).
  const Entry* Lookup(PointId to) const;
  std::shared_ptr<const Entry> LookupShared(PointId to) const;  // kept alive by the caller
  struct LastLookup;
  static LastLookup& Last();
  std::shared_ptr<const Entry> Find(PointId to) const;    // the cache, or a new search
  std::vector<double> UnweightedCosts(const std::vector<double>& dist, const std::vector<std::int32_t>& via) const;

  std::shared_ptr<const WarehouseMap> map_;
  MapCostGraph graph_;
  // Weighted tables: graph_'s arcs with the weighted costs the searches run on (graph_ keeps
  // the unweighted ones, for Cost and Path).
  bool weighted_ = false;
  CostGraph search_graph_;
  std::size_t cache_bytes_ = 0;
  const std::uint64_t id_;  // unique per table ever built (the per-thread last entry's key)

  mutable std::mutex mu_;
  using Lru = std::list<std::pair<PointId, std::shared_ptr<const Entry>>>;
  mutable Lru lru_;                                            // guarded by mu_; front = newest
  mutable std::unordered_map<PointId, Lru::iterator> index_;   // guarded by mu_
  mutable std::size_t bytes_ = 0;                              // guarded by mu_
  mutable std::size_t searches_ = 0;                           // guarded by mu_
};

}  // namespace dispatch::engine
