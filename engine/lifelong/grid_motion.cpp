#include "engine/lifelong/grid_motion.h"

#include <unordered_map>

namespace dispatch::engine {

const char* DirectionName(int direction) {
  static const char* const kNames[] = {"E", "S", "W", "N"};
  return kNames[((direction % 4) + 4) % 4];
}

int CellTowards(const LorrGrid& grid, int cell, int direction) {
  const int row = cell / grid.width();
  const int col = cell % grid.width();
  static const int kRow[] = {0, 1, 0, -1};
  static const int kCol[] = {1, 0, -1, 0};
  const int r = row + kRow[direction & 3];
  const int c = col + kCol[direction & 3];
  if (r < 0 || r >= grid.height() || c < 0 || c >= grid.width()) return -1;
  return r * grid.width() + c;
}

GridPose Apply(const LorrGrid& grid, const GridPose& pose, GridAction action) {
  GridPose next = pose;
  switch (action) {
    case GridAction::kForward: {
      const int cell = CellTowards(grid, pose.cell, pose.direction);
      if (grid.Free(cell)) next.cell = cell;
      break;
    }
    case GridAction::kClockwise: next.direction = (pose.direction + 1) & 3; break;
    case GridAction::kCounterClockwise: next.direction = (pose.direction + 3) & 3; break;
    case GridAction::kWait: break;
  }
  return next;
}

int TurnsBetween(int from, int direction) {
  const int d = ((direction - from) % 4 + 4) % 4;
  return d == 3 ? 1 : d;
}

GridAction TurnTowards(int from, int direction) {
  const int d = ((direction - from) % 4 + 4) % 4;
  if (d == 0) return GridAction::kWait;
  return d == 3 ? GridAction::kCounterClockwise : GridAction::kClockwise;
}

std::vector<StepViolation> CheckJointStep(const LorrGrid& grid, const std::vector<GridPose>& poses,
                                          const std::vector<GridAction>& actions) {
  std::vector<StepViolation> found;
  const int n = static_cast<int>(poses.size());
  if (actions.size() != poses.size()) {
    found.push_back({0, -1, std::to_string(actions.size()) + " actions for " + std::to_string(n) + " robots"});
    return found;
  }
  std::vector<int> next(poses.size());
  for (int i = 0; i < n; ++i) {
    const auto a = static_cast<std::size_t>(i);
    next[a] = poses[a].cell;
    if (actions[a] != GridAction::kForward) continue;
    const int cell = CellTowards(grid, poses[a].cell, poses[a].direction);
    if (!grid.Free(cell)) {
      found.push_back({i, -1, "robot " + std::to_string(i) + " drives " + (cell < 0 ? "off the grid" : "into blocked cell " + std::to_string(cell)) +
                                  " from cell " + std::to_string(poses[a].cell)});
    } else {
      next[a] = cell;
    }
  }
  std::unordered_map<int, int> at_start;
  std::unordered_map<int, int> at_end;
  at_start.reserve(poses.size());
  at_end.reserve(poses.size());
  for (int i = 0; i < n; ++i) at_start.emplace(poses[static_cast<std::size_t>(i)].cell, i);
  for (int i = 0; i < n; ++i) {
    const auto a = static_cast<std::size_t>(i);
    auto [it, fresh] = at_end.emplace(next[a], i);
    if (!fresh) {
      found.push_back({i, it->second, "robots " + std::to_string(it->second) + " and " + std::to_string(i) +
                                          " both end in cell " + std::to_string(next[a])});
    }
    if (next[a] == poses[a].cell) continue;
    auto there = at_start.find(next[a]);
    if (there != at_start.end() && there->second < i && next[static_cast<std::size_t>(there->second)] == poses[a].cell) {
      found.push_back({i, there->second, "robots " + std::to_string(there->second) + " and " + std::to_string(i) +
                                             " swap cells " + std::to_string(poses[a].cell) + " and " +
                                             std::to_string(next[a])});
    }
  }
  return found;
}

}  // namespace dispatch::engine
