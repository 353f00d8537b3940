#include "engine/lifelong/turn_pibt.h"

#include <algorithm>
#include <array>
#include <numeric>

namespace dispatch::engine {

TurnPibt::TurnPibt(const LorrGrid& grid, std::shared_ptr<const RouteTable> routes, std::uint64_t seed)
    : grid_(grid), routes_(std::move(routes)), random_(seed) {
  occupant_.assign(static_cast<std::size_t>(grid.cell_count()), -1);
  reserved_.assign(static_cast<std::size_t>(grid.cell_count()), -1);
}

double TurnPibt::DeadEndBonus(int cell) const {
  int free = 0;
  for (int d = 0; d < 4; ++d) free += grid_.Free(CellTowards(grid_, cell, d)) ? 1 : 0;
  return free <= 1 ? kDeadEndBonus : 0.0;
}

double TurnPibt::Distance(int cell, int goal) const {
  if (goal < 0) return 0.0;
  return routes_->Cost(grid_.PointAt(cell), grid_.PointAt(goal));
}

bool TurnPibt::Push(int robot, int banned_cell) {
  const auto r = static_cast<std::size_t>(robot);
  const GridPose& pose = (*poses_)[r];
  const int goal = (*goals_)[r];
  struct Candidate {
    int cell;
    double distance;
    int target_first;  // 0 for the cell the robot is turning towards
    int turns;         // 0 for the own cell and the cell ahead
    std::uint64_t tie;
    double score = 0.0;
  };
  std::array<Candidate, 5> candidates{};
  std::size_t count = 0;
  candidates[count++] = {pose.cell, Distance(pose.cell, goal), 1, 0, random_()};
  for (int d = 0; d < 4; ++d) {
    const int cell = CellTowards(grid_, pose.cell, d);
    if (!grid_.Free(cell)) continue;
    candidates[count++] = {cell, Distance(cell, goal), cell == target_[r] ? 0 : 1, TurnsBetween(pose.direction, d),
                           random_()};
  }
  // Steps to the goal through each candidate: a neighbour costs its turns and its distance
  // (one step of the distance is the move itself); staying costs the step it wastes, weighted
  // so that a robot facing away still turns round rather than wait; a neighbour another robot
  // stands in costs the push.
  for (std::size_t k = 0; k < count; ++k) {
    Candidate& c = candidates[k];
    c.score = c.distance + c.turns + (c.cell == pose.cell && goal >= 0 ? kStayCost : 0.0);
    if (c.cell != pose.cell && occupant_[static_cast<std::size_t>(c.cell)] != -1) c.score += kOccupiedCost;
  }
  auto before = [](const Candidate& a, const Candidate& b) {
    if (a.target_first != b.target_first) return a.target_first < b.target_first;
    if (a.score != b.score) return a.score < b.score;
    if (a.distance != b.distance) return a.distance < b.distance;
    if (a.turns != b.turns) return a.turns < b.turns;
    return a.tie < b.tie;
  };
  for (std::size_t k = 1; k < count; ++k) {  // insertion sort of at most 5
    for (std::size_t j = k; j > 0 && before(candidates[j], candidates[j - 1]); --j) {
      std::swap(candidates[j], candidates[j - 1]);
    }
  }
  // A swap the pushes cannot make (Okumura's swap situation, here its dead-end case): the best
  // cell is a dead end whose robot must come out through this robot's cell. This robot backs
  // away instead (its candidates reversed), and that robot follows into the cell it leaves.
  int follower = -1;
  if (count > 1 && candidates[0].cell != pose.cell) {
    const int best = candidates[0].cell;
    const int other = occupant_[static_cast<std::size_t>(best)];
    const int other_goal = other == -1 ? -1 : (*goals_)[static_cast<std::size_t>(other)];
    if (other != -1 && next_[static_cast<std::size_t>(other)] == -1 && DeadEndBonus(best) > 0.0 &&
        other_goal != best) {
      follower = other;
      std::reverse(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(count));
    }
  }
  for (std::size_t k = 0; k < count; ++k) {
    const int cell = candidates[k].cell;
    const auto c = static_cast<std::size_t>(cell);
    if (reserved_[c] != -1 || cell == banned_cell) continue;
    next_[r] = cell;
    reserved_[c] = robot;
    touched_cells_.push_back(cell);
    const int other = occupant_[c];
    if (other != -1 && other != robot && next_[static_cast<std::size_t>(other)] == -1 && !Push(other, pose.cell)) {
      continue;
    }
    if (follower != -1 && cell != pose.cell && next_[static_cast<std::size_t>(follower)] == -1 &&
        reserved_[static_cast<std::size_t>(pose.cell)] == -1) {
      next_[static_cast<std::size_t>(follower)] = pose.cell;
      reserved_[static_cast<std::size_t>(pose.cell)] = follower;
      touched_cells_.push_back(pose.cell);
    }
    return true;
  }
  next_[r] = pose.cell;
  reserved_[static_cast<std::size_t>(pose.cell)] = robot;
  touched_cells_.push_back(pose.cell);
  return false;
}

std::vector<GridAction> TurnPibt::Step(const std::vector<GridPose>& poses, const std::vector<int>& goals) {
  const std::size_t n = poses.size();
  if (priority_.size() != n) {
    priority_.assign(n, 0.0);
    last_goal_.assign(n, -2);
    target_.assign(n, -1);
  }
  poses_ = &poses;
  goals_ = &goals;
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  for (std::size_t r = 0; r < n; ++r) {
    if (goals[r] != last_goal_[r]) {
      last_goal_[r] = goals[r];
      priority_[r] = fraction(random_);
      target_[r] = -1;
    } else if (goals[r] >= 0 && poses[r].cell != goals[r]) {
      priority_[r] += 1.0;
    }
    if (target_[r] == poses[r].cell) target_[r] = -1;
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::vector<double> rank(n);  // the priority the order sorts by, computed once per robot
  for (std::size_t r = 0; r < n; ++r) rank[r] = priority_[r] + DeadEndBonus(poses[r].cell);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const auto x = static_cast<std::size_t>(a);
    const auto y = static_cast<std::size_t>(b);
    if ((goals[x] >= 0) != (goals[y] >= 0)) return goals[x] >= 0;
    return rank[x] > rank[y];
  });
  next_.assign(n, -1);
  for (std::size_t r = 0; r < n; ++r) occupant_[static_cast<std::size_t>(poses[r].cell)] = static_cast<int>(r);
  for (int robot : order) {
    if (next_[static_cast<std::size_t>(robot)] == -1) Push(robot, -1);
  }

  std::vector<GridAction> actions(n, GridAction::kWait);
  for (std::size_t r = 0; r < n; ++r) {
    const GridPose& pose = poses[r];
    if (next_[r] == pose.cell) continue;
    int direction = 0;
    while (CellTowards(grid_, pose.cell, direction) != next_[r]) ++direction;
    if (direction == pose.direction) {
      actions[r] = GridAction::kForward;
    } else {
      actions[r] = TurnTowards(pose.direction, direction);
      target_[r] = next_[r];
    }
  }
  // A forward move stands when the robot ahead (if any) leaves forwards too. 0 unknown,
  // 1 being checked (a cycle back to it is fine), 2 moves, 3 waits.
  std::vector<char> verdict(n, 0);
  auto moves = [&](auto&& self, std::size_t r) -> bool {
    if (verdict[r] == 1 || verdict[r] == 2) return true;
    if (verdict[r] == 3) return false;
    verdict[r] = 1;
    const int ahead = occupant_[static_cast<std::size_t>(next_[r])];
    const bool ok = ahead == -1 || (actions[static_cast<std::size_t>(ahead)] == GridAction::kForward &&
                                    self(self, static_cast<std::size_t>(ahead)));
    verdict[r] = ok ? 2 : 3;
    if (!ok) actions[r] = GridAction::kWait;
    return ok;
  };
  for (std::size_t r = 0; r < n; ++r) {
    if (actions[r] == GridAction::kForward) moves(moves, r);
  }
  for (std::size_t r = 0; r < n; ++r) occupant_[static_cast<std::size_t>(poses[r].cell)] = -1;
  for (int cell : touched_cells_) reserved_[static_cast<std::size_t>(cell)] = -1;
  touched_cells_.clear();
  return actions;
}

}  // namespace dispatch::engine
