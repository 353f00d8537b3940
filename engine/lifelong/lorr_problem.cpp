#include "engine/lifelong/lorr_problem.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/io/movingai_map.h"

namespace dispatch::engine {
namespace {

Result<std::string> ReadText(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError(path + ": cannot open " + what);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return IoError(path + ": read error");
  return buffer.str();
}

// The lines of a LoRR agents/tasks file after its optional "#" line: the count, then the
// entries. Line numbers are 1-based in the file.
struct Lines {
  std::vector<std::pair<int, std::string_view>> entries;  // (line number, text)
};

Result<Lines> CountedLines(std::string_view text, const std::string& what) {
  std::vector<std::pair<int, std::string_view>> lines;
  int number = 0;
  for (std::size_t at = 0; at < text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number;
    if (!(lines.empty() && !line.empty() && line.front() == '#') && !line.empty()) lines.emplace_back(number, line);
    at = end + 1;
  }
  if (lines.empty()) return InvalidArgument(what + ": empty file, expected a count");
  long count = 0;
  auto [ptr, ec] = std::from_chars(lines[0].second.data(), lines[0].second.data() + lines[0].second.size(), count);
  if (ec != std::errc{} || ptr != lines[0].second.data() + lines[0].second.size() || count < 0) {
    return InvalidArgument(what + ": line " + std::to_string(lines[0].first) + ": expected a count, got '" +
                           std::string(lines[0].second) + "'");
  }
  if (static_cast<std::size_t>(count) != lines.size() - 1) {
    return InvalidArgument(what + ": the count says " + std::to_string(count) + " entries, the file has " +
                           std::to_string(lines.size() - 1));
  }
  Lines out;
  out.entries.assign(lines.begin() + 1, lines.end());
  return out;
}

Result<int> FreeCell(std::string_view field, int line, const LorrGrid& grid, const std::string& what) {
  long cell = 0;
  auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), cell);
  const std::string where = what + ": line " + std::to_string(line) + ": ";
  if (ec != std::errc{} || ptr != field.data() + field.size()) {
    return InvalidArgument(where + "expected a cell id, got '" + std::string(field) + "'");
  }
  if (cell < 0 || cell >= grid.cell_count()) {
    return InvalidArgument(where + "cell " + std::to_string(cell) + " is outside the " + std::to_string(grid.height()) +
                           " x " + std::to_string(grid.width()) + " grid");
  }
  if (!grid.Free(static_cast<int>(cell))) {
    return InvalidArgument(where + "cell " + std::to_string(cell) +
                           " is blocked or outside the floor's largest connected part");
  }
  return static_cast<int>(cell);
}

std::string Resolve(const std::string& base_dir, const std::string& path) {
  if (path.empty() || path.front() == '/' || base_dir.empty()) return path;
  return base_dir + "/" + path;
}

}  // namespace

Result<LorrGrid> LorrGrid::FromMap(std::shared_ptr<const WarehouseMap> map, int height, int width) {
  if (map == nullptr || height <= 0 || width <= 0) return InvalidArgument("a LoRR grid needs a map and a size");
  LorrGrid grid;
  grid.height_ = height;
  grid.width_ = width;
  grid.point_of_cell_.assign(static_cast<std::size_t>(height) * static_cast<std::size_t>(width), kNoPoint);
  grid.cell_of_point_.assign(map->point_count(), -1);
  for (std::size_t p = 0; p < map->point_count(); ++p) {
    const std::string& name = map->point(static_cast<PointId>(p)).name;
    long cell = -1;
    if (name.size() < 2 || name[0] != 'c' ||
        std::from_chars(name.data() + 1, name.data() + name.size(), cell).ptr != name.data() + name.size() ||
        cell < 0 || cell >= grid.cell_count()) {
      return InvalidArgument("map point '" + name + "' is not a grid cell c<id> of a " + std::to_string(height) +
                             " x " + std::to_string(width) + " grid");
    }
    grid.point_of_cell_[static_cast<std::size_t>(cell)] = static_cast<PointId>(p);
    grid.cell_of_point_[p] = static_cast<int>(cell);
  }
  grid.map_ = std::move(map);
  return grid;
}

int LorrProblem::reveal_count() const {
  const double reveal = std::floor(num_tasks_reveal * static_cast<double>(team_size()));
  return reveal < 1.0 ? 1 : static_cast<int>(reveal);
}

Result<std::vector<int>> ParseLorrAgents(std::string_view text, const LorrGrid& grid, const std::string& what) {
  Result<Lines> lines = CountedLines(text, what);
  if (!lines) return lines.error();
  std::vector<int> starts;
  for (const auto& [number, line] : lines->entries) {
    Result<int> cell = FreeCell(line, number, grid, what);
    if (!cell) return cell.error();
    starts.push_back(*cell);
  }
  return starts;
}

Result<std::vector<LorrTask>> ParseLorrTasks(std::string_view text, const LorrGrid& grid, const std::string& what) {
  Result<Lines> lines = CountedLines(text, what);
  if (!lines) return lines.error();
  std::vector<LorrTask> tasks;
  tasks.reserve(lines->entries.size());
  for (const auto& [number, line] : lines->entries) {
    LorrTask task;
    task.id = static_cast<int>(tasks.size());
    for (std::size_t at = 0; at <= line.size();) {
      std::size_t comma = line.find(',', at);
      if (comma == std::string_view::npos) comma = line.size();
      Result<int> cell = FreeCell(line.substr(at, comma - at), number, grid, what);
      if (!cell) return cell.error();
      task.errands.push_back(*cell);
      at = comma + 1;
    }
    tasks.push_back(std::move(task));
  }
  return tasks;
}

Result<LorrProblem> LoadLorrProblem(const std::string& json_path) {
  Result<std::string> text = ReadText(json_path, "LoRR problem file");
  if (!text) return text.error();
  nlohmann::json json = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_object()) return InvalidArgument(json_path + ": not a JSON object");
  for (const char* key : {"mapFile", "agentFile", "taskFile"}) {
    if (!json.contains(key) || !json[key].is_string()) {
      return InvalidArgument(json_path + ": \"" + key + "\" must be a file name");
    }
  }
  if (!json.contains("teamSize") || !json["teamSize"].is_number_integer() || json["teamSize"].get<long>() < 1) {
    return InvalidArgument(json_path + ": \"teamSize\" must be an integer >= 1");
  }
  LorrProblem problem;
  if (json.contains("numTasksReveal")) {
    if (!json["numTasksReveal"].is_number() || !(json["numTasksReveal"].get<double>() > 0.0)) {
      return InvalidArgument(json_path + ": \"numTasksReveal\" must be a number > 0");
    }
    problem.num_tasks_reveal = json["numTasksReveal"].get<double>();
  }
  const std::size_t slash = json_path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? std::string() : json_path.substr(0, slash);
  problem.name = json_path.substr(slash == std::string::npos ? 0 : slash + 1);
  if (auto dot = problem.name.rfind('.'); dot != std::string::npos && dot > 0) problem.name.erase(dot);
  problem.map_file = Resolve(dir, json["mapFile"].get<std::string>());

  MovingAiImportReport report;
  Result<WarehouseMap> map = LoadMovingAiMapFile(problem.map_file, {}, &report);
  if (!map) return map.error();
  Result<LorrGrid> grid =
      LorrGrid::FromMap(std::make_shared<const WarehouseMap>(std::move(map).value()), report.height, report.width);
  if (!grid) return Error{grid.error().code, problem.map_file + ": " + grid.error().message};
  problem.grid = std::move(grid).value();

  const std::string agents_file = Resolve(dir, json["agentFile"].get<std::string>());
  Result<std::string> agents_text = ReadText(agents_file, "LoRR agents file");
  if (!agents_text) return agents_text.error();
  Result<std::vector<int>> starts = ParseLorrAgents(*agents_text, problem.grid, agents_file);
  if (!starts) return starts.error();
  const long team = json["teamSize"].get<long>();
  if (static_cast<long>(starts->size()) < team) {
    return InvalidArgument(json_path + ": \"teamSize\" is " + std::to_string(team) + ", " + agents_file + " has " +
                           std::to_string(starts->size()) + " robots");
  }
  problem.starts.assign(starts->begin(), starts->begin() + team);

  const std::string tasks_file = Resolve(dir, json["taskFile"].get<std::string>());
  Result<std::string> tasks_text = ReadText(tasks_file, "LoRR tasks file");
  if (!tasks_text) return tasks_text.error();
  Result<std::vector<LorrTask>> tasks = ParseLorrTasks(*tasks_text, problem.grid, tasks_file);
  if (!tasks) return tasks.error();
  problem.tasks = std::move(tasks).value();
  return problem;
}

}  // namespace dispatch::engine
