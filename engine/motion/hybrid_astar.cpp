#include "engine/motion/hybrid_astar.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <optional>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "engine/motion/reeds_shepp.h"

namespace dispatch::engine {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

struct Move {
  MotionMode mode = MotionMode::kForward;
  double amount = 0.0;  // metres, or radians for spins
};

struct PoseNode {
  MotionPose pose;
  double g = 0.0;
  int parent = -1;
  Move move;  // how the parent reached this node (unused for the start)
  bool closed = false;
};

class PoseSearch {
 public:
  PoseSearch(const FootprintChecker& checker, const MotionPose& start, const MotionPose& goal,
         const HybridAStarOptions& options)
      : checker_(checker), start_(start), goal_(goal), o_(options),
        bin_width_(kTwoPi / options.heading_bins),
        spin_spacing_(options.sample_spacing / std::max(checker.circumradius(), 1e-3)) {
    moves_ = {{MotionMode::kForward, o_.step},         {MotionMode::kReverse, o_.step},
              {MotionMode::kArcForwardLeft, o_.step},  {MotionMode::kArcForwardRight, o_.step},
              {MotionMode::kArcReverseLeft, o_.step},  {MotionMode::kArcReverseRight, o_.step}};
    if (o_.allow_crab) {
      moves_.push_back({MotionMode::kCrabLeft, o_.step});
      moves_.push_back({MotionMode::kCrabRight, o_.step});
    }
    if (o_.allow_spin) {
      moves_.push_back({MotionMode::kSpinLeft, o_.spin_bins * bin_width_});
      moves_.push_back({MotionMode::kSpinRight, o_.spin_bins * bin_width_});
    }
  }

  Result<MotionPath> Run();

 private:
  double Dist(const Move& m) const { return IsSpin(m.mode) ? m.amount * o_.spin_radius : m.amount; }

  // Eq. (4): the cost of `m` after a move in `previous` (nullopt at the start). A search move
  // is one step, so its switch penalty is lambda_switch * dist; a longer analytic segment
  // pays it on its first step's worth only (as if driven in steps), not on its whole length.
  double StepCost(const Move& m, std::optional<MotionMode> previous) const {
    const double dist = Dist(m);
    double cost = dist * (1.0 + (IsArc(m.mode) ? o_.lambda_turn : 0.0));
    if (previous && DriveClassOf(*previous) != DriveClassOf(m.mode)) {
      cost += o_.lambda_switch * std::min(dist, IsSpin(m.mode) ? Dist({m.mode, o_.spin_bins * bin_width_}) : o_.step);
    }
    return cost;
  }

  // Eq. (5) h and eq. (6) f.
  double F(const MotionPose& p, double g) const {
    const double dx = goal_.x - p.x;
    const double dy = goal_.y - p.y;
    double h_o = std::abs(dx) + std::abs(dy);
    if (!steps_to_goal_.empty()) {
      const OccupancyGrid& grid = checker_.grid();
      const int ix = grid.CellX(p.x);
      const int iy = grid.CellY(p.y);
      if (grid.InBounds(ix, iy)) {
        const int steps = steps_to_goal_[static_cast<std::size_t>(iy) * grid.width() + ix];
        if (steps >= 0) h_o = steps * grid.resolution();
      }
    }
    const double h = h_o + o_.heading_weight * std::abs(WrapHeading(goal_.theta - p.theta));
    return g + HeuristicWeight(o_, std::hypot(dx, dy)) * h;
  }

  // The Manhattan distance through the grid's free cells (h_o, see the header): breadth-first
  // from the goal's cell, 4-connected.
  void SweepFromGoal() {
    const OccupancyGrid& grid = checker_.grid();
    const int w = grid.width();
    const double min_clearance = checker_.footprint().width / 2.0 - grid.resolution() / 2.0;
    auto passable = [&](int ix, int iy) {
      return !grid.Occupied(ix, iy) && (!grid.has_clearance() || grid.Clearance(ix, iy) >= min_clearance);
    };
    steps_to_goal_.assign(static_cast<std::size_t>(w) * grid.height(), -1);
    const int gx = grid.CellX(goal_.x);
    const int gy = grid.CellY(goal_.y);
    if (!grid.InBounds(gx, gy)) return;
    std::vector<int> queue{gy * w + gx};
    steps_to_goal_[queue[0]] = 0;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const int cell = queue[head];
      const int cx = cell % w;
      const int cy = cell / w;
      const int next_steps = steps_to_goal_[cell] + 1;
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const int nx = cx + dx;
        const int ny = cy + dy;
        if (!passable(nx, ny) || steps_to_goal_[ny * w + nx] >= 0) continue;
        steps_to_goal_[ny * w + nx] = next_steps;
        queue.push_back(ny * w + nx);
      }
    }
  }

  std::int64_t Key(const MotionPose& p) const {
    const OccupancyGrid& grid = checker_.grid();
    const std::int64_t ix = grid.CellX(p.x);
    const std::int64_t iy = grid.CellY(p.y);
    std::int64_t ib = static_cast<std::int64_t>(std::lround(p.theta / bin_width_)) % o_.heading_bins;
    if (ib < 0) ib += o_.heading_bins;
    return (iy * grid.width() + ix) * o_.heading_bins + ib;
  }

  double Spacing(MotionMode mode) const { return IsSpin(mode) ? spin_spacing_ : o_.sample_spacing; }

  // Samples `m` from `from` into `out` (poses after `from`); false when a sample collides.
  bool Sweep(const MotionPose from, const Move& m, MotionPath* out, MotionPose& end) const {
    // `from` by value: callers pass their `end` as the start of the next move.
    const int steps = std::max(1, static_cast<int>(std::ceil(m.amount / Spacing(m.mode) - 1e-9)));
    for (int k = 1; k <= steps; ++k) {
      end = Advance(from, m.mode, m.amount * k / steps, o_.min_turn_radius);
      if (checker_.Collides(end)) return false;
      if (out) {
        out->poses.push_back(end);
        out->modes.push_back(m.mode);
      }
    }
    return true;
  }

  // A tail of moves from `from`: sampled into `out` and priced by eq. (4) after `previous`;
  // nullopt when it collides.
  std::optional<double> Tail(const MotionPose& from, const std::vector<Move>& moves,
                             std::optional<MotionMode> previous, MotionPath& out) const {
    out.poses.assign(1, from);
    out.modes.clear();
    double cost = 0.0;
    MotionPose at = from;
    for (const Move& m : moves) {
      if (m.amount < 1e-9) continue;
      if (!Sweep(at, m, &out, at)) return std::nullopt;
      cost += StepCost(m, previous);
      previous = m.mode;
    }
    return cost;
  }

  // BIT2024 step 6: the straight (Reeds-Shepp) and crab analytic expansions from node `i`.
  bool Analytic(int i, MotionPath& tail, std::string& kind) const;

  MotionPath Reconstruct(int last) const;

  const FootprintChecker& checker_;
  MotionPose start_;
  MotionPose goal_;
  const HybridAStarOptions& o_;
  double bin_width_;
  double spin_spacing_;
  std::vector<Move> moves_;
  std::vector<PoseNode> nodes_;
  std::vector<int> steps_to_goal_;  // per cell, -1: not reached (empty: plain Manhattan)
};

bool PoseSearch::Analytic(int i, MotionPath& tail, std::string& kind) const {
  const PoseNode& n = nodes_[i];
  const std::optional<MotionMode> previous = i == 0 ? std::nullopt : std::optional(n.move.mode);
  std::optional<double> best;
  MotionPath candidate;
  // Straight variant: the shortest collision-free of the shortest Reeds-Shepp paths.
  const std::vector<RsPath> rs = ReedsSheppPaths(n.pose, goal_, o_.min_turn_radius);
  for (int k = 0; k < std::min<int>(o_.rs_candidates, static_cast<int>(rs.size())); ++k) {
    std::vector<Move> moves;
    for (const RsSegment& seg : rs[k].segments) moves.push_back({RsSegmentMode(seg), std::abs(seg.length)});
    if (const std::optional<double> cost = Tail(n.pose, moves, previous, candidate)) {
      best = cost;
      tail = candidate;
      kind = "reeds_shepp";
      break;
    }
  }
  // Crab variant: spin to the goal heading, then straight and crab legs in either order.
  const double turn = WrapHeading(goal_.theta - n.pose.theta);
  if (o_.allow_crab && (o_.allow_spin || std::abs(turn) < 1e-9)) {
    const Move spin{turn >= 0.0 ? MotionMode::kSpinLeft : MotionMode::kSpinRight, std::abs(turn)};
    const double dx = goal_.x - n.pose.x;
    const double dy = goal_.y - n.pose.y;
    const double along = std::cos(goal_.theta) * dx + std::sin(goal_.theta) * dy;
    const double across = -std::sin(goal_.theta) * dx + std::cos(goal_.theta) * dy;
    const Move straight{along >= 0.0 ? MotionMode::kForward : MotionMode::kReverse, std::abs(along)};
    const Move crab{across >= 0.0 ? MotionMode::kCrabLeft : MotionMode::kCrabRight, std::abs(across)};
    for (const std::vector<Move>& moves : {std::vector<Move>{spin, straight, crab}, std::vector<Move>{spin, crab, straight}}) {
      const std::optional<double> cost = Tail(n.pose, moves, previous, candidate);
      if (cost && (!best || *cost < *best)) {
        best = cost;
        tail = candidate;
        kind = "crab";
      }
    }
  }
  return best.has_value();
}

MotionPath PoseSearch::Reconstruct(int last) const {
  std::vector<int> chain;
  for (int i = last; i >= 0; i = nodes_[i].parent) chain.push_back(i);
  std::reverse(chain.begin(), chain.end());
  MotionPath path;
  path.poses.push_back(nodes_[chain.front()].pose);
  for (std::size_t k = 1; k < chain.size(); ++k) {
    MotionPose end;
    Sweep(nodes_[chain[k - 1]].pose, nodes_[chain[k]].move, &path, end);
    path.poses.back() = nodes_[chain[k]].pose;  // the very pose the search stored
  }
  return path;
}

Result<MotionPath> PoseSearch::Run() {
  if (o_.manhattan_through_free_cells) SweepFromGoal();
  using Entry = std::tuple<double, int>;  // f, node index (creation order breaks ties)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  std::unordered_map<std::int64_t, int> best;  // state key -> node with the least g
  nodes_.push_back({start_, 0.0, -1, {}, false});
  best.emplace(Key(start_), 0);
  open.emplace(F(start_, 0.0), 0);
  std::size_t expanded = 0;
  while (!open.empty()) {
    if (o_.limits.Exhausted(expanded)) {
      return Error{ErrorCode::kFailedPrecondition,
                   "hybrid A*: stopped after " + std::to_string(expanded) + " expansions"};
    }
    const int i = std::get<1>(open.top());
    open.pop();
    const std::int64_t key = Key(nodes_[i].pose);
    if (nodes_[i].closed || best.at(key) != i) continue;
    nodes_[i].closed = true;
    ++expanded;
    const MotionPose pose = nodes_[i].pose;
    const double distance = std::hypot(goal_.x - pose.x, goal_.y - pose.y);
    if (distance <= o_.goal_xy_tolerance &&
        std::abs(WrapHeading(goal_.theta - pose.theta)) <= o_.goal_theta_tolerance) {
      MotionPath path = Reconstruct(i);
      path.finish = "search";
      Summarize(path);
      path.nodes_expanded = expanded;
      return path;
    }
    if (distance < o_.analytic_range) {
      MotionPath tail;
      std::string kind;
      if (Analytic(i, tail, kind)) {
        MotionPath path = Reconstruct(i);
        path.poses.insert(path.poses.end(), tail.poses.begin() + 1, tail.poses.end());
        path.modes.insert(path.modes.end(), tail.modes.begin(), tail.modes.end());
        path.finish = kind;
        Summarize(path);
        path.nodes_expanded = expanded;
        return path;
      }
    }
    for (const Move& m : moves_) {
      MotionPose end;
      if (!Sweep(pose, m, nullptr, end)) continue;
      const std::int64_t next_key = Key(end);
      const double g = nodes_[i].g + StepCost(m, i == 0 ? std::nullopt : std::optional(nodes_[i].move.mode));
      const auto found = best.find(next_key);
      if (found != best.end() && (nodes_[found->second].closed || nodes_[found->second].g <= g)) continue;
      const int j = static_cast<int>(nodes_.size());
      nodes_.push_back({end, g, i, m, false});
      best[next_key] = j;
      open.emplace(F(end, g), j);
    }
  }
  return Unreachable("hybrid A*: no path from (" + std::to_string(start_.x) + ", " + std::to_string(start_.y) +
                     ") to (" + std::to_string(goal_.x) + ", " + std::to_string(goal_.y) + ") after " +
                     std::to_string(expanded) + " expansions (every reachable state)");
}

}  // namespace

double HeuristicWeight(const HybridAStarOptions& options, double distance) {
  if (!options.adaptive_xi || options.xi_bands.empty()) return options.fixed_xi;
  for (const XiBand& band : options.xi_bands) {
    if (distance >= band.from) return band.xi;
  }
  return options.xi_bands.back().xi;
}

Result<MotionPath> PlanHybridAStar(const FootprintChecker& checker, const MotionPose& start,
                                   const MotionPose& goal, const HybridAStarOptions& options) {
  if (options.heading_bins < 4 || !(options.step > 0.0) || !(options.min_turn_radius > 0.0) ||
      options.spin_bins < 1 || !(options.spin_radius > 0.0) || !(options.sample_spacing > 0.0) ||
      options.rs_candidates < 0 || options.lambda_turn < 0.0 || options.lambda_switch < 0.0) {
    return InvalidArgument("hybrid A*: options out of range");
  }
  for (std::size_t k = 1; k < options.xi_bands.size(); ++k) {
    if (options.xi_bands[k].from >= options.xi_bands[k - 1].from) {
      return InvalidArgument("hybrid A*: xi bands must be sorted by distance, descending");
    }
  }
  auto describe = [](const MotionPose& p) {
    return "(" + std::to_string(p.x) + ", " + std::to_string(p.y) + ", " + std::to_string(p.theta) + ")";
  };
  if (checker.Collides(start)) return InvalidArgument("hybrid A*: start pose " + describe(start) + " collides");
  if (checker.Collides(goal)) return InvalidArgument("hybrid A*: goal pose " + describe(goal) + " collides");
  MotionPose s = start;
  MotionPose g = goal;
  s.theta = WrapHeading(s.theta);
  g.theta = WrapHeading(g.theta);
  return PoseSearch(checker, s, g, options).Run();
}

}  // namespace dispatch::engine
