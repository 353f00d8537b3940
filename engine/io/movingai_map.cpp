#include "engine/io/movingai_map.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdint>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

constexpr long kMaxCells = 50'000'000;  // guards the int cell ids

enum class Cell : std::uint8_t { kBlocked, kLane, kPick, kDrop };

std::optional<Cell> ClassifyCell(char c) {
  switch (c) {
    case '.':
    case 'G':
      return Cell::kLane;
    case 'S':
      return Cell::kPick;
    case 'E':
      return Cell::kDrop;
    case '@':
    case 'T':
    case 'O':
    case 'W':
      return Cell::kBlocked;
    default:
      return std::nullopt;
  }
}

// Lines of the text, without '\n' or a trailing '\r'.
std::vector<std::string_view> SplitLines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string LinePrefix(std::size_t index) { return "line " + std::to_string(index + 1) + ": "; }

std::string Printable(char c) {
  if (c >= 0x20 && c < 0x7f) return std::string("'") + c + "'";
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02x", static_cast<unsigned char>(c));
  return buf;
}

struct Grid {
  int height = 0;
  int width = 0;
  std::vector<Cell> cells;  // row-major, row 0 = first text row
};

Result<Grid> ParseGrid(std::string_view text) {
  std::vector<std::string_view> lines = SplitLines(text);
  Grid grid;
  bool have_type = false;
  std::size_t i = 0;
  for (;; ++i) {
    if (i >= lines.size()) {
      return InvalidArgument(LinePrefix(i) + "bad header: missing the 'map' line (expected " +
                             "'type octile', 'height H', 'width W', 'map')");
    }
    std::string_view line = Trim(lines[i]);
    if (line.empty()) continue;
    if (line == "map") break;
    std::size_t space = line.find_first_of(" \t");
    std::string_view key = line.substr(0, space);
    std::string_view value =
        space == std::string_view::npos ? std::string_view() : Trim(line.substr(space));
    if (key == "type") {
      if (value != "octile") {
        return InvalidArgument(LinePrefix(i) + "bad header: unsupported map type '" +
                               std::string(value) + "' (expected 'octile')");
      }
      have_type = true;
    } else if (key == "height" || key == "width") {
      long n = 0;
      auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
      if (ec != std::errc() || ptr != value.data() + value.size() || n <= 0 || n > kMaxCells) {
        return InvalidArgument(LinePrefix(i) + "bad header: " + std::string(key) +
                               " must be a positive integer, got '" + std::string(value) + "'");
      }
      (key == "height" ? grid.height : grid.width) = static_cast<int>(n);
    } else {
      return InvalidArgument(LinePrefix(i) +
                             "bad header: expected 'type', 'height', 'width' or 'map', got '" +
                             std::string(line) + "'");
    }
  }
  if (!have_type || grid.height == 0 || grid.width == 0) {
    std::string missing = !have_type ? "type" : grid.height == 0 ? "height" : "width";
    return InvalidArgument(LinePrefix(i) + "bad header: 'map' before the '" + missing +
                           "' line");
  }
  if (static_cast<long>(grid.height) * grid.width > kMaxCells) {
    return InvalidArgument(LinePrefix(i) + "bad header: " + std::to_string(grid.height) + " x " +
                           std::to_string(grid.width) + " cells is too large");
  }
  const std::size_t first_row = i + 1;
  const auto width = static_cast<std::size_t>(grid.width);
  grid.cells.resize(static_cast<std::size_t>(grid.height) * width);
  for (int r = 0; r < grid.height; ++r) {
    const std::size_t li = first_row + static_cast<std::size_t>(r);
    if (li >= lines.size()) {
      return InvalidArgument(LinePrefix(li) + "missing rows: the header declares height " +
                             std::to_string(grid.height) + ", the file has " + std::to_string(r) +
                             " rows");
    }
    std::string_view row = lines[li];
    if (row.size() != width) {
      return InvalidArgument(LinePrefix(li) + "expected " + std::to_string(width) +
                             " characters, got " + std::to_string(row.size()));
    }
    Cell* out = grid.cells.data() + static_cast<std::size_t>(r) * width;
    for (std::size_t c = 0; c < width; ++c) {
      std::optional<Cell> cell = ClassifyCell(row[c]);
      if (!cell) {
        return InvalidArgument("line " + std::to_string(li + 1) + ", column " +
                               std::to_string(c + 1) + ": unknown character " + Printable(row[c]) +
                               " (free: . G S E; blocked: @ T O W)");
      }
      out[c] = *cell;
    }
  }
  for (std::size_t li = first_row + static_cast<std::size_t>(grid.height); li < lines.size();
       ++li) {
    if (!Trim(lines[li]).empty()) {
      return InvalidArgument(LinePrefix(li) + "extra row: the header declares height " +
                             std::to_string(grid.height));
    }
  }
  return grid;
}

// Marks the cells of the largest 4-connected free component (ties: lowest first cell id).
std::vector<bool> LargestComponent(const Grid& grid) {
  const int n = grid.height * grid.width;
  std::vector<int> component(static_cast<std::size_t>(n), -1);
  std::vector<int> stack;
  int best = -1;
  int best_size = 0;
  int count = 0;
  for (int start = 0; start < n; ++start) {
    if (grid.cells[static_cast<std::size_t>(start)] == Cell::kBlocked ||
        component[static_cast<std::size_t>(start)] >= 0) {
      continue;
    }
    const int label = count++;
    int size = 0;
    component[static_cast<std::size_t>(start)] = label;
    stack.push_back(start);
    while (!stack.empty()) {
      const int cell = stack.back();
      stack.pop_back();
      ++size;
      const int r = cell / grid.width;
      const int c = cell % grid.width;
      const int neighbours[4][2] = {{r - 1, c}, {r + 1, c}, {r, c - 1}, {r, c + 1}};
      for (const auto& nb : neighbours) {
        if (nb[0] < 0 || nb[0] >= grid.height || nb[1] < 0 || nb[1] >= grid.width) continue;
        const auto next = static_cast<std::size_t>(nb[0] * grid.width + nb[1]);
        if (grid.cells[next] == Cell::kBlocked || component[next] >= 0) continue;
        component[next] = label;
        stack.push_back(static_cast<int>(next));
      }
    }
    if (size > best_size) {
      best_size = size;
      best = label;
    }
  }
  std::vector<bool> keep(static_cast<std::size_t>(n), false);
  for (std::size_t k = 0; k < keep.size(); ++k) keep[k] = component[k] == best && best >= 0;
  return keep;
}

std::string CellName(int id) { return "c" + std::to_string(id); }

}  // namespace

Result<WarehouseMap> ParseMovingAiMap(std::string_view text, std::string name,
                                      const MovingAiImportOptions& options,
                                      MovingAiImportReport* report) {
  if (options.tile_cells < 1) {
    return InvalidArgument("MovingAI import: tile_cells must be >= 1, got " +
                           std::to_string(options.tile_cells));
  }
  Result<Grid> parsed = ParseGrid(text);
  if (!parsed) return parsed.error();
  const Grid& grid = *parsed;
  const int h = grid.height;
  const int w = grid.width;
  const int n = h * w;

  MovingAiImportReport counts;
  counts.height = h;
  counts.width = w;
  for (Cell c : grid.cells) counts.free_cells += c != Cell::kBlocked ? 1 : 0;
  if (counts.free_cells == 0) return InvalidArgument("MovingAI map '" + name + "' has no free cells");
  const std::vector<bool> keep = LargestComponent(grid);
  auto kept = [&](int r, int c) { return keep[static_cast<std::size_t>(r * w + c)]; };

  MapBuilder builder(name);
  builder.SetFloor({-0.5, -0.5}, {w - 0.5, h - 0.5});

  // Zones: tiles of tile_cells x tile_cells cells that hold a kept point.
  const int t = options.tile_cells;
  const int tile_rows = (h + t - 1) / t;
  const int tile_cols = (w + t - 1) / t;
  std::vector<bool> tile_used(static_cast<std::size_t>(tile_rows) * tile_cols, false);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      if (kept(r, c)) tile_used[static_cast<std::size_t>((r / t) * tile_cols + c / t)] = true;
    }
  }
  std::vector<std::string> tile_names(tile_used.size());
  for (int tr = 0; tr < tile_rows; ++tr) {
    for (int tc = 0; tc < tile_cols; ++tc) {
      const auto k = static_cast<std::size_t>(tr * tile_cols + tc);
      if (!tile_used[k]) continue;
      tile_names[k] = "t" + std::to_string(tr) + "_" + std::to_string(tc);
      const int r0 = tr * t;
      const int r1 = std::min(h, r0 + t);  // exclusive
      const int c0 = tc * t;
      const int c1 = std::min(w, c0 + t);
      // Rows r0..r1-1 span y = h-1-row, i.e. [h-r1, h-1-r0], plus half a cell on each side.
      builder.AddRectZone(tile_names[k], {c0 - 0.5, h - r1 - 0.5}, {c1 - 0.5, h - r0 - 0.5});
      ++counts.zones;
    }
  }

  for (int id = 0; id < n; ++id) {
    if (!keep[static_cast<std::size_t>(id)]) {
      counts.dropped_cells += grid.cells[static_cast<std::size_t>(id)] != Cell::kBlocked ? 1 : 0;
      continue;
    }
    const int r = id / w;
    const int c = id % w;
    PointKind kind = PointKind::kLane;
    switch (grid.cells[static_cast<std::size_t>(id)]) {
      case Cell::kPick: kind = PointKind::kPick; break;
      case Cell::kDrop: kind = PointKind::kDrop; break;
      default: break;
    }
    builder.AddPoint(CellName(id), Eigen::Vector2d(c, h - 1 - r), kind,
                     tile_names[static_cast<std::size_t>((r / t) * tile_cols + c / t)]);
    ++counts.points;
  }
  for (int id = 0; id < n; ++id) {
    if (!keep[static_cast<std::size_t>(id)]) continue;
    const int r = id / w;
    const int c = id % w;
    // Right and lower neighbours; both have higher ids. Kept cells are one component, so an
    // adjacent free cell of a kept cell is kept too.
    if (c + 1 < w && kept(r, c + 1)) {
      builder.AddPath(CellName(id), CellName(id + 1), 1.0, options.max_speed, true);
      ++counts.lanes;
    }
    if (r + 1 < h && kept(r + 1, c)) {
      builder.AddPath(CellName(id), CellName(id + w), 1.0, options.max_speed, true);
      ++counts.lanes;
    }
  }
  // The kept cells form one component of bidirectional lanes, so every service point reaches
  // every other one: skip the builder's (costly) all-service-points check.
  Result<WarehouseMap> map = builder.Build(MapBuildOptions{.check_service_connectivity = false});
  if (map && report != nullptr) *report = counts;
  return map;
}

Result<WarehouseMap> LoadMovingAiMapFile(const std::string& path,
                                         const MovingAiImportOptions& options,
                                         MovingAiImportReport* report) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError(path + ": cannot open MovingAI map file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return IoError(path + ": read error");
  std::string name = path;
  if (auto slash = name.find_last_of('/'); slash != std::string::npos) name.erase(0, slash + 1);
  if (auto dot = name.rfind('.'); dot != std::string::npos && dot > 0) name.erase(dot);
  Result<WarehouseMap> map = ParseMovingAiMap(buffer.str(), name, options, report);
  if (!map) return Error{map.error().code, path + ": " + map.error().message};
  return map;
}

}  // namespace dispatch::engine
