#include "engine/routing/hub_labels.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <queue>
#include <utility>

#include "engine/common/numbers.h"

namespace dispatch::engine {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The minimum of da[i] + db[j] over the hubs both sorted lists hold; +inf when none.
double MergeMin(const std::int32_t* ha, const double* da, std::size_t na, const std::int32_t* hb,
                const double* db, std::size_t nb) {
  double best = kInf;
  std::size_t i = 0, j = 0;
  while (i < na && j < nb) {
    if (ha[i] < hb[j]) {
      ++i;
    } else if (hb[j] < ha[i]) {
      ++j;
    } else {
      best = std::min(best, da[i] + db[j]);
      ++i;
      ++j;
    }
  }
  return best;
}

// Pruning keeps an entry unless another hub is shorter by more than this: two routes of
// equal cost summed in another order must not prune each other (hub_labels.h).
double Tolerance(double d) { return 1e-9 * std::max(1.0, d); }

}  // namespace

// Builds the hierarchy, then the labels (hub_labels.h).
class HubLabelBuilder {
 public:
  // An arc of the hierarchy (the graph's, or a shortcut): towards `to` in out_, from `to` in
  // in_, costing w; `first` is the graph arc its route starts with (from its tail).
  struct Edge {
    VertexId to = kNoVertex;
    double w = 0.0;
    std::int32_t first = -1;
  };
  struct Shortcut {
    VertexId from = kNoVertex, to = kNoVertex;
    double w = 0.0;
    std::int32_t first = -1;
  };

  HubLabelBuilder(const CostGraph& graph, const HubLabelOptions& options, const CancelCheck& cancelled)
      : n_(graph.vertex_count()), options_(options), cancelled_(cancelled), out_(n_), in_(n_),
        up_out_(n_), up_in_(n_), rank_(n_, -1), deleted_(n_, 0), level_(n_, 0), priority_(n_, 0),
        dist_(n_, kInf) {
    for (std::size_t id = 0; id < graph.arc_count(); ++id) {
      const CostArc& a = graph.arcs()[id];
      if (a.from != a.to) AddOrImprove(a.from, a.to, a.cost, static_cast<std::int32_t>(id));
    }
  }

  Result<HubLabels> Run() {
    const Clock::time_point start = Clock::now();
    if (!Contract()) return Cancelled();
    out_.clear();
    in_.clear();
    labels_.stats_.contract_seconds = SecondsSince(start);
    const Clock::time_point labelled = Clock::now();
    if (!Label()) return Cancelled();
    labels_.stats_.label_seconds = SecondsSince(labelled);
    labels_.stats_.shortcuts = shortcuts_;
    labels_.stats_.label_entries = labels_.fwd_hub_.size() + labels_.bwd_hub_.size();
    labels_.stats_.bytes = labels_.stats_.label_entries * (2 * sizeof(std::int32_t) + sizeof(double)) +
                           4 * n_ * sizeof(std::uint64_t);
    return std::move(labels_);
  }

 private:
  static Error Cancelled() { return {ErrorCode::kFailedPrecondition, "hub label build cancelled"}; }
  bool Stop(std::size_t done) const { return done % 256 == 0 && cancelled_ && cancelled_(); }

  // u -> x costs at most w, starting with graph arc `first`: a new arc, or a cheaper one in
  // place of the old.
  void AddOrImprove(VertexId u, VertexId x, double w, std::int32_t first) {
    auto& out = out_[static_cast<std::size_t>(u)];
    auto it = std::find_if(out.begin(), out.end(), [x](const Edge& e) { return e.to == x; });
    if (it != out.end()) {
      if (w >= it->w) return;
      *it = {x, w, first};
      auto& in = in_[static_cast<std::size_t>(x)];
      *std::find_if(in.begin(), in.end(), [u](const Edge& e) { return e.to == u; }) = {u, w, first};
      return;
    }
    out.push_back({x, w, first});
    in_[static_cast<std::size_t>(x)].push_back({u, w, first});
  }

  // Dijkstra from `u` over the remaining graph without `skip`, up to cost `limit` or the
  // settle limit; dist_ holds the results for the touched vertices.
  void Witness(VertexId u, VertexId skip, double limit) {
    for (VertexId t : touched_) dist_[static_cast<std::size_t>(t)] = kInf;
    touched_.clear();
    using Item = std::pair<double, VertexId>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
    dist_[static_cast<std::size_t>(u)] = 0.0;
    touched_.push_back(u);
    heap.emplace(0.0, u);
    int settled = 0;
    while (!heap.empty()) {
      const auto [d, v] = heap.top();
      heap.pop();
      if (d > dist_[static_cast<std::size_t>(v)]) continue;
      if (d > limit || ++settled > options_.witness_settle_limit) break;
      for (const Edge& e : out_[static_cast<std::size_t>(v)]) {
        if (e.to == skip) continue;
        const double nd = d + e.w;
        double& old = dist_[static_cast<std::size_t>(e.to)];
        if (nd < old) {
          if (old == kInf) touched_.push_back(e.to);
          old = nd;
          heap.emplace(nd, e.to);
        }
      }
    }
  }

  // The shortcuts contracting v needs now (each starts as its arc into v).
  void Shortcuts(VertexId v, std::vector<Shortcut>& found) {
    found.clear();
    const auto& out = out_[static_cast<std::size_t>(v)];
    for (const Edge& in : in_[static_cast<std::size_t>(v)]) {
      double limit = -1.0;  // stays negative when v leads nowhere but back to in.to
      for (const Edge& o : out) {
        if (o.to != in.to) limit = std::max(limit, in.w + o.w);
      }
      if (limit < 0.0) continue;
      Witness(in.to, v, limit);
      for (const Edge& o : out) {
        if (o.to == in.to) continue;
        if (dist_[static_cast<std::size_t>(o.to)] > in.w + o.w) found.push_back({in.to, o.to, in.w + o.w, in.first});
      }
    }
  }

  int Priority(VertexId v) {
    Shortcuts(v, scratch_);
    const auto i = static_cast<std::size_t>(v);
    const int removed = static_cast<int>(in_[i].size() + out_[i].size());
    return 2 * (static_cast<int>(scratch_.size()) - removed) + deleted_[i] + level_[i];
  }

  bool Contract() {
    using Item = std::pair<int, VertexId>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    for (std::size_t v = 0; v < n_; ++v) {
      if (Stop(v)) return false;
      priority_[v] = Priority(static_cast<VertexId>(v));
      queue.emplace(priority_[v], static_cast<VertexId>(v));
    }
    std::int32_t next_rank = 0;
    while (!queue.empty()) {
      const auto [p, v] = queue.top();
      queue.pop();
      const auto i = static_cast<std::size_t>(v);
      if (rank_[i] >= 0 || p != priority_[i]) continue;  // contracted, or a stale entry
      // Lazy update: contract v only if its current priority is still the lowest.
      const int now = Priority(v);
      if (!queue.empty() && now > queue.top().first) {
        priority_[i] = now;
        queue.emplace(now, v);
        continue;
      }
      if (Stop(static_cast<std::size_t>(next_rank) + 1)) return false;
      rank_[i] = next_rank++;
      order_.push_back(v);
      Shortcuts(v, added_);
      shortcuts_ += added_.size();
      up_out_[i] = out_[i];
      up_in_[i] = in_[i];
      for (const Edge& e : out_[i]) Detach(in_[static_cast<std::size_t>(e.to)], v);
      for (const Edge& e : in_[i]) Detach(out_[static_cast<std::size_t>(e.to)], v);
      for (const Shortcut& c : added_) AddOrImprove(c.from, c.to, c.w, c.first);
      std::vector<VertexId>& neighbours = neighbours_;
      neighbours.clear();
      for (const Edge& e : out_[i]) neighbours.push_back(e.to);
      for (const Edge& e : in_[i]) neighbours.push_back(e.to);
      out_[i].clear();
      in_[i].clear();
      std::sort(neighbours.begin(), neighbours.end());
      neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
      for (VertexId x : neighbours) {
        const auto k = static_cast<std::size_t>(x);
        ++deleted_[k];
        level_[k] = std::max(level_[k], level_[i] + 1);
        priority_[k] = Priority(x);
        queue.emplace(priority_[k], x);
      }
    }
    return true;
  }

  static void Detach(std::vector<Edge>& edges, VertexId v) {
    edges.erase(std::remove_if(edges.begin(), edges.end(), [v](const Edge& e) { return e.to == v; }),
                edges.end());
  }

  // One label of vertex v (rank r): its upward neighbours' labels plus the arc to each,
  // merged, then pruned against the opposite labels of its hubs (hub_labels.h). Each entry's
  // first arc: forward, the first arc of v's upward arc it came by; backward, the hub's first
  // arc towards the neighbour it came from (then on along the arc to v), or that arc's first
  // when the hub is the neighbour itself.
  void BuildLabel(VertexId v, const std::vector<Edge>& up, bool forward) {
    HubLabels& l = labels_;
    const auto& hub = forward ? l.fwd_hub_ : l.bwd_hub_;
    const auto& dist = forward ? l.fwd_dist_ : l.bwd_dist_;
    const auto& arc = forward ? l.fwd_arc_ : l.bwd_arc_;
    const auto& begin = forward ? l.fwd_begin_ : l.bwd_begin_;
    const auto& end = forward ? l.fwd_end_ : l.bwd_end_;
    const std::int32_t r = rank_[static_cast<std::size_t>(v)];
    cand_hub_.clear();
    best_[static_cast<std::size_t>(r)] = 0.0;
    best_arc_[static_cast<std::size_t>(r)] = -1;
    cand_hub_.push_back(r);
    for (const Edge& e : up) {
      const auto x = static_cast<std::size_t>(e.to);
      for (std::uint64_t k = begin[x]; k < end[x]; ++k) {
        const auto h = static_cast<std::size_t>(hub[k]);
        const double d = e.w + dist[k];
        if (best_[h] == kInf) cand_hub_.push_back(hub[k]);
        if (d < best_[h]) {
          best_[h] = d;
          best_arc_[h] = forward || arc[k] < 0 ? e.first : arc[k];
        }
      }
    }
    std::sort(cand_hub_.begin(), cand_hub_.end());
    cand_dist_.clear();
    cand_arc_.clear();
    for (std::int32_t h : cand_hub_) {
      cand_dist_.push_back(best_[static_cast<std::size_t>(h)]);
      cand_arc_.push_back(best_arc_[static_cast<std::size_t>(h)]);
    }
    for (std::int32_t h : cand_hub_) best_[static_cast<std::size_t>(h)] = kInf;
    // Prune: the true distance between v and hub h is the best route over the candidate's
    // hubs and h's final opposite label (h ranks higher, so its labels are built).
    const auto& ohub = forward ? l.bwd_hub_ : l.fwd_hub_;
    const auto& odist = forward ? l.bwd_dist_ : l.fwd_dist_;
    const auto& obegin = forward ? l.bwd_begin_ : l.fwd_begin_;
    const auto& oend = forward ? l.bwd_end_ : l.fwd_end_;
    auto& out_hub = forward ? l.fwd_hub_ : l.bwd_hub_;
    auto& out_dist = forward ? l.fwd_dist_ : l.bwd_dist_;
    auto& out_arc = forward ? l.fwd_arc_ : l.bwd_arc_;
    const std::uint64_t first = out_hub.size();
    for (std::size_t k = 0; k < cand_hub_.size(); ++k) {
      const std::int32_t h = cand_hub_[k];
      if (h != r) {
        const auto hv = static_cast<std::size_t>(order_[static_cast<std::size_t>(h)]);
        const double best = MergeMin(cand_hub_.data(), cand_dist_.data(), cand_hub_.size(),
                                     ohub.data() + obegin[hv], odist.data() + obegin[hv], oend[hv] - obegin[hv]);
        if (best < cand_dist_[k] - Tolerance(cand_dist_[k])) continue;
      }
      out_hub.push_back(h);
      out_dist.push_back(cand_dist_[k]);
      out_arc.push_back(cand_arc_[k]);
    }
    const auto i = static_cast<std::size_t>(v);
    (forward ? l.fwd_begin_ : l.bwd_begin_)[i] = first;
    (forward ? l.fwd_end_ : l.bwd_end_)[i] = out_hub.size();
    labels_.stats_.max_label = std::max<std::size_t>(labels_.stats_.max_label, out_hub.size() - first);
  }

  bool Label() {
    HubLabels& l = labels_;
    l.fwd_begin_.assign(n_, 0);
    l.fwd_end_.assign(n_, 0);
    l.bwd_begin_.assign(n_, 0);
    l.bwd_end_.assign(n_, 0);
    best_.assign(n_, kInf);
    best_arc_.assign(n_, -1);
    for (std::size_t k = n_; k-- > 0;) {
      if (Stop(n_ - k)) return false;
      const VertexId v = order_[k];
      const auto i = static_cast<std::size_t>(v);
      BuildLabel(v, up_out_[i], true);
      BuildLabel(v, up_in_[i], false);
      std::vector<Edge>().swap(up_out_[i]);
      std::vector<Edge>().swap(up_in_[i]);
    }
    return true;
  }

  const std::size_t n_;
  const HubLabelOptions options_;
  const CancelCheck& cancelled_;
  std::vector<std::vector<Edge>> out_, in_;        // the remaining graph
  std::vector<std::vector<Edge>> up_out_, up_in_;  // per vertex: its arcs when contracted
  std::vector<std::int32_t> rank_;
  std::vector<VertexId> order_;                    // by rank
  std::vector<int> deleted_, level_, priority_;
  std::vector<double> dist_;                       // witness searches
  std::vector<VertexId> touched_;
  std::vector<Shortcut> scratch_, added_;           // Priority's, Contract's
  std::vector<VertexId> neighbours_;               // Contract's
  std::size_t shortcuts_ = 0;
  std::vector<double> best_;                       // labelling, by hub rank
  std::vector<std::int32_t> best_arc_;             // labelling, by hub rank: best_'s first arc
  std::vector<std::int32_t> cand_hub_, cand_arc_;
  std::vector<double> cand_dist_;
  HubLabels labels_;
};

Result<HubLabels> HubLabels::Build(const CostGraph& graph, const HubLabelOptions& options,
                                   const CancelCheck& cancelled) {
  if (options.witness_settle_limit < 1) {
    return InvalidArgument("hub labels: witness_settle_limit must be >= 1, got " +
                           std::to_string(options.witness_settle_limit));
  }
  return HubLabelBuilder(graph, options, cancelled).Run();
}

double HubLabels::Distance(VertexId from, VertexId to) const {
  const std::size_t n = vertex_count();
  if (from < 0 || to < 0 || static_cast<std::size_t>(from) >= n || static_cast<std::size_t>(to) >= n) {
    return kInf;
  }
  if (from == to) return 0.0;
  const auto s = static_cast<std::size_t>(from);
  const auto t = static_cast<std::size_t>(to);
  return MergeMin(fwd_hub_.data() + fwd_begin_[s], fwd_dist_.data() + fwd_begin_[s], fwd_end_[s] - fwd_begin_[s],
                  bwd_hub_.data() + bwd_begin_[t], bwd_dist_.data() + bwd_begin_[t], bwd_end_[t] - bwd_begin_[t]);
}

void HubLabels::Spread(VertexId to, HubSpread& by_hub) const {
  const auto t = static_cast<std::size_t>(to);
  for (std::uint64_t k = bwd_begin_[t]; k < bwd_end_[t]; ++k) {
    const auto h = static_cast<std::size_t>(bwd_hub_[k]);
    by_hub.dist[h] = bwd_dist_[k];
    by_hub.arc[h] = bwd_arc_[k];
  }
}

void HubLabels::Unspread(VertexId to, HubSpread& by_hub) const {
  const auto t = static_cast<std::size_t>(to);
  for (std::uint64_t k = bwd_begin_[t]; k < bwd_end_[t]; ++k) by_hub.dist[static_cast<std::size_t>(bwd_hub_[k])] = kInf;
}

double HubLabels::DistanceVia(VertexId from, const HubSpread& by_hub) const {
  if (from < 0 || static_cast<std::size_t>(from) >= vertex_count()) return kInf;
  const auto s = static_cast<std::size_t>(from);
  const double* to_go = by_hub.dist.data();
  double best = kInf;
  for (std::uint64_t k = fwd_begin_[s]; k < fwd_end_[s]; ++k) {
    best = std::min(best, fwd_dist_[k] + to_go[static_cast<std::size_t>(fwd_hub_[k])]);
  }
  return best;
}

HubLabels::FirstHop HubLabels::FirstVia(VertexId from, const HubSpread& by_hub) const {
  if (from < 0 || static_cast<std::size_t>(from) >= vertex_count()) return {};
  const auto s = static_cast<std::size_t>(from);
  const double* to_go = by_hub.dist.data();
  FirstHop best;
  for (std::uint64_t k = fwd_begin_[s]; k < fwd_end_[s]; ++k) {
    const auto h = static_cast<std::size_t>(fwd_hub_[k]);
    const double c = fwd_dist_[k] + to_go[h];
    if (c < best.cost) best = {c, fwd_arc_[k] >= 0 ? fwd_arc_[k] : by_hub.arc[h]};
  }
  return best;
}

}  // namespace dispatch::engine
