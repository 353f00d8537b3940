// A League of Robot Runners 2024 problem (issue 19 §2; ../shared/benchmarks/README.md): the
// floor as a grid of cells, the robots' start cells and the task list, loaded from the
// competition's problem JSON and the files it names.
//
// Cells are the competition's ids, row * width + column. The grid comes from the product's
// MovingAI importer (movingai_map.h), so the floor has one reading: a free cell is one of the
// imported map's points (named "c<cell>"); blocked cells and free cells outside the floor's
// largest connected part are not. A task's errands are cells visited in order (2024: pickup,
// delivery); its id is its index in the task file.
//
// Errors name the file and line or field: a missing key, a team size that does not match the
// agents file, a start or errand on a blocked cell, a count that does not match the lines.
// Plain values: safe to share once loaded.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct LorrTask {
  int id = 0;
  std::vector<int> errands;  // cells, visited in order (>= 1)
};

// The floor's cells and the imported map they stand for.
class LorrGrid {
 public:
  // Wraps a map imported from a `.map` of height x width cells (points named "c<cell>").
  static Result<LorrGrid> FromMap(std::shared_ptr<const WarehouseMap> map, int height, int width);

  int height() const { return height_; }
  int width() const { return width_; }
  int cell_count() const { return height_ * width_; }
  bool Free(int cell) const {
    return cell >= 0 && cell < cell_count() && point_of_cell_[static_cast<std::size_t>(cell)] != kNoPoint;
  }
  // The map point at a free cell (kNoPoint elsewhere), and back.
  PointId PointAt(int cell) const { return Free(cell) ? point_of_cell_[static_cast<std::size_t>(cell)] : kNoPoint; }
  int CellOf(PointId point) const { return cell_of_point_.at(static_cast<std::size_t>(point)); }
  const std::shared_ptr<const WarehouseMap>& map() const { return map_; }

 private:
  int height_ = 0;
  int width_ = 0;
  std::vector<PointId> point_of_cell_;
  std::vector<int> cell_of_point_;
  std::shared_ptr<const WarehouseMap> map_;
};

struct LorrProblem {
  std::string name;        // the problem file's stem
  std::string map_file;    // as resolved from the problem file
  LorrGrid grid;
  std::vector<int> starts;  // one cell per robot (teamSize of them)
  std::vector<LorrTask> tasks;
  double num_tasks_reveal = 1.5;  // tasks revealed at once per robot

  int team_size() const { return static_cast<int>(starts.size()); }
  // How many tasks are revealed at once: numTasksReveal x teamSize, rounded down, >= 1.
  int reveal_count() const;
};

// Reads FILE.json (mapFile, agentFile, taskFile relative to it, teamSize, numTasksReveal).
Result<LorrProblem> LoadLorrProblem(const std::string& json_path);

// The agents and tasks file texts (an optional "# ..." first line, the count, then the lines);
// `what` prefixes errors. Cells are checked against `grid`.
Result<std::vector<int>> ParseLorrAgents(std::string_view text, const LorrGrid& grid, const std::string& what);
Result<std::vector<LorrTask>> ParseLorrTasks(std::string_view text, const LorrGrid& grid, const std::string& what);

}  // namespace dispatch::engine
