#include "engine/routing/floyd.h"

#include <algorithm>
#include <atomic>
#include <barrier>
#include <limits>
#include <thread>

#include "engine/routing/dijkstra.h"

namespace dispatch::engine {
namespace {

constexpr float kNoPath = std::numeric_limits<float>::infinity();
constexpr std::size_t kTile = 64;

Error Cancelled() { return {ErrorCode::kFailedPrecondition, "all-pairs build cancelled"}; }

// Seed steps 1-2 over a `stride` x `stride` matrix (stride >= n; extra vertices isolated):
// D from the cheapest parallel arc, D(i, i) = 0; P (when asked for) -1, i on the diagonal and
// the head of each arc.
void InitMatrices(const CostGraph& graph, std::size_t stride, std::vector<float>& dist,
                  std::vector<VertexId>* next) {
  dist.assign(stride * stride, kNoPath);
  if (next) next->assign(stride * stride, kNoVertex);
  for (std::size_t i = 0; i < stride; ++i) {
    dist[i * stride + i] = 0.0f;
    if (next) (*next)[i * stride + i] = static_cast<VertexId>(i);
  }
  for (const CostArc& a : graph.arcs()) {
    const std::size_t ij = static_cast<std::size_t>(a.from) * stride + static_cast<std::size_t>(a.to);
    const auto c = static_cast<float>(a.cost);
    if (c < dist[ij]) {
      dist[ij] = c;
      if (next) (*next)[ij] = a.to;
    }
  }
}

// Relaxes tile C through the kTile intermediates of its k-block (Chu2024 §3.1 step 3 on D):
// C(i, j) = min(C(i, j), A(i, k) + B(k, j)). k is the outer loop, so A or B may be C itself
// (phases 1 and 2). `skip_diag` skips i == k, whose row cannot improve (D(k, k) = 0) and would
// alias the B row. Rows with A(i, k) = inf are skipped. The j loop is a plain min over
// contiguous floats, which GCC vectorises (SSE2: addps + minps on 4 floats).
void RelaxTile(float* c, const float* a, const float* b, std::size_t stride, bool skip_diag) {
  for (std::size_t k = 0; k < kTile; ++k) {
    const float* bk = b + k * stride;
    for (std::size_t i = 0; i < kTile; ++i) {
      if (skip_diag && i == k) continue;
      const float aik = a[i * stride + k];
      if (aik == kNoPath) continue;
      float* ci = c + i * stride;
#pragma GCC ivdep
      for (std::size_t j = 0; j < kTile; ++j) ci[j] = std::min(ci[j], aik + bk[j]);
    }
  }
}

// Successor row i from final distances: next(i, j) = the head w of the out-arc (i, w) that
// minimises cost + D(w, j) (Bellman's equation), i for j == i, kNoVertex when unreachable.
// O(out-degree * n) per row; the compare/select loop vectorises like RelaxTile.
void DeriveSuccessorRow(const CostGraph& graph, const float* dist, std::size_t stride,
                        std::size_t n, std::size_t i, float* best, VertexId* next) {
  std::fill_n(best, n, kNoPath);
  std::fill_n(next, n, kNoVertex);
  for (std::int32_t id : graph.out_arcs(static_cast<VertexId>(i))) {
    const CostArc& arc = graph.arc(id);
    if (static_cast<std::size_t>(arc.to) == i) continue;  // a self-loop never helps
    const auto cost = static_cast<float>(arc.cost);
    const VertexId w = arc.to;
    const float* dw = dist + static_cast<std::size_t>(w) * stride;
#pragma GCC ivdep
    for (std::size_t j = 0; j < n; ++j) {
      const float bj = best[j];
      const VertexId nj = next[j];
      const float via = std::min(bj, cost + dw[j]);
      // All-ones when w is strictly better; a mask select is what GCC vectorises.
      const VertexId better = -static_cast<VertexId>(via != bj);
      best[j] = via;
      next[j] = (w & better) | (nj & ~better);
    }
  }
  next[i] = static_cast<VertexId>(i);
}

// Successors chosen by Bellman's equation can form a cycle among vertices joined by zero-cost
// arcs (equal distances: each may pick the other), or, in principle, around arcs cheaper than
// float rounding. Checks that the
// successor pointers of every column j form an in-tree rooted at j, O(n^2) in all, and
// recomputes a column that does not by one exact reverse Dijkstra to j.
void RepairSuccessorCycles(const CostGraph& graph, AllPairsTable& t) {
  const std::size_t n = t.n;
  std::vector<std::uint8_t> state(n);  // 0 unseen, 1 on the current walk, 2 reaches j
  std::vector<VertexId> walk;
  for (std::size_t j = 0; j < n; ++j) {
    std::fill(state.begin(), state.end(), 0);
    state[j] = 2;
    bool broken = false;
    for (std::size_t i = 0; i < n && !broken; ++i) {
      walk.clear();
      VertexId v = static_cast<VertexId>(i);
      while (v != kNoVertex && state[static_cast<std::size_t>(v)] == 0) {
        state[static_cast<std::size_t>(v)] = 1;
        walk.push_back(v);
        v = t.next[static_cast<std::size_t>(v) * n + j];
      }
      if (v != kNoVertex && state[static_cast<std::size_t>(v)] == 1) {
        broken = true;
      }
      for (VertexId w : walk) state[static_cast<std::size_t>(w)] = 2;
    }
    if (!broken) continue;
    const VertexId root[] = {static_cast<VertexId>(j)};
    const ShortestPathTree tree = ReverseDijkstra(graph, root);
    for (std::size_t i = 0; i < n; ++i) {
      t.dist[i * n + j] = static_cast<float>(tree.dist[i]);
      t.next[i * n + j] = i == j ? static_cast<VertexId>(j)
                          : tree.via[i] < 0 ? kNoVertex
                                            : graph.arc(tree.via[i]).to;
    }
  }
}

}  // namespace

AllPairsTable InitAllPairsTable(const CostGraph& graph) {
  AllPairsTable t;
  t.n = graph.vertex_count();
  InitMatrices(graph, t.n, t.dist, &t.next);
  return t;
}

Result<AllPairsTable> FloydTextbook(const CostGraph& graph, const CancelCheck& cancelled) {
  AllPairsTable t = InitAllPairsTable(graph);
  const std::size_t n = t.n;
  float* d = t.dist.data();
  VertexId* p = t.next.data();
  for (std::size_t k = 0; k < n; ++k) {
    if (cancelled && cancelled()) return Cancelled();
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        if (d[i * n + k] + d[k * n + j] < d[i * n + j]) {
          d[i * n + j] = d[i * n + k] + d[k * n + j];
          p[i * n + j] = p[i * n + k];
        }
      }
    }
  }
  return t;
}

Result<AllPairsTable> FloydBlocked(const CostGraph& graph, int threads,
                                   const CancelCheck& cancelled) {
  const std::size_t n = graph.vertex_count();
  if (n == 0) return AllPairsTable{};
  const std::size_t tiles = (n + kTile - 1) / kTile;
  const std::size_t s = tiles * kTile;  // padded stride; padding vertices stay isolated
  std::vector<float> dist;
  InitMatrices(graph, s, dist, nullptr);
  float* d = dist.data();
  auto at = [s](std::size_t ti, std::size_t tj) { return ti * kTile * s + tj * kTile; };

  AllPairsTable t;
  t.n = n;
  t.dist.resize(n * n);
  t.next.resize(n * n);
  const auto workers = static_cast<std::size_t>(std::clamp(threads, 1, 64));
  std::atomic<bool> stop{false};
  std::barrier sync(static_cast<std::ptrdiff_t>(workers));
  auto work = [&](std::size_t w) {
    for (std::size_t kb = 0; kb < tiles; ++kb) {
      // Phase 1: the diagonal tile, by worker 0 (which also polls the cancel check).
      if (w == 0) {
        if (cancelled && cancelled()) {
          stop = true;
        } else {
          const std::size_t kk = at(kb, kb);
          RelaxTile(d + kk, d + kk, d + kk, s, true);
        }
      }
      sync.arrive_and_wait();
      if (stop) return;
      // Phase 2: the tiles of row kb and column kb, dealt round-robin.
      for (std::size_t tile = w; tile < tiles; tile += workers) {
        if (tile == kb) continue;
        const std::size_t kk = at(kb, kb), row = at(kb, tile), col = at(tile, kb);
        RelaxTile(d + row, d + kk, d + row, s, true);
        RelaxTile(d + col, d + col, d + kk, s, false);
      }
      sync.arrive_and_wait();
      // Phase 3: every other tile, by tile rows dealt round-robin.
      for (std::size_t ti = w; ti < tiles; ti += workers) {
        if (ti == kb) continue;
        const std::size_t col = at(ti, kb);
        for (std::size_t tj = 0; tj < tiles; ++tj) {
          if (tj == kb) continue;
          const std::size_t c = at(ti, tj), row = at(kb, tj);
          RelaxTile(d + c, d + col, d + row, s, false);
        }
      }
      sync.arrive_and_wait();
    }
    // D is final: copy it out and derive the successor rows, rows dealt round-robin.
    std::vector<float> best(n);
    for (std::size_t i = w; i < n; i += workers) {
      std::copy_n(d + i * s, n, t.dist.data() + i * n);
      DeriveSuccessorRow(graph, d, s, n, i, best.data(), t.next.data() + i * n);
    }
  };
  {
    std::vector<std::jthread> pool;
    for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(work, w);
    work(0);
  }
  if (stop) return Cancelled();
  RepairSuccessorCycles(graph, t);
  return t;
}

std::vector<VertexId> WalkNext(const AllPairsTable& table, VertexId from, VertexId to) {
  std::vector<VertexId> path{from};
  VertexId v = from;
  while (v != to) {
    v = table.Next(v, to);
    if (v == kNoVertex || path.size() > table.n) return {};
    path.push_back(v);
  }
  return path;
}

}  // namespace dispatch::engine
