// dispatch-map: look at a warehouse map from the command line.
//   dispatch-map summary --map chu2024
//   dispatch-map routes  --map chu2024 [--from P1 --to D-T3] [--method floyd|dijkstra|auto|lazy|hub_labels]
//   dispatch-map svg     --map chu2024 --out chu2024.svg
//   dispatch-map export  --map chu2024 --out chu2024.json
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "engine/io/map_source.h"
#include "engine/io/map_json.h"
#include "engine/io/map_svg.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {
namespace {

int Fail(const std::string& message) {
  std::cerr << "dispatch-map: " << message << "\n";
  return 1;
}

void PrintSummary(const WarehouseMap& map) {
  const Eigen::Vector2d size = map.floor_max() - map.floor_min();
  std::printf("Map '%s': floor (%.2f, %.2f) .. (%.2f, %.2f) m, %.2f x %.2f m\n",
              map.name().c_str(), map.floor_min().x(), map.floor_min().y(), map.floor_max().x(),
              map.floor_max().y(), size.x(), size.y());
  std::map<std::string, int> kinds;
  for (const Point& p : map.points()) ++kinds[PointKindName(p.kind)];
  std::printf("Points: %zu (", map.point_count());
  const char* sep = "";
  for (const char* k : {"lane", "intersection", "pick", "drop", "park", "charge"}) {
    std::printf("%s%s %d", sep, k, kinds[k]);
    sep = ", ";
  }
  int bidirectional = 0;
  double lane_length = 0;
  for (const Path& p : map.paths()) {
    bidirectional += p.bidirectional;
    lane_length += p.length;
  }
  std::printf(")\nPaths: %zu (one-way %zu, bidirectional single lanes %d) -> %zu arcs, %.1f m of lanes\n",
              map.paths().size(), map.paths().size() - static_cast<std::size_t>(bidirectional),
              bidirectional, map.arcs().size(), lane_length);
  std::printf("Intersections: %zu, shelves: %zu, parking stations: %zu", map.intersections().size(),
              map.shelves().size(), map.stations().size());
  int capacity = 0;
  for (const auto& s : map.stations()) capacity += s.capacity;
  std::printf(" (%d slots)\nZones: %zu\n", capacity, map.zones().size());
  if (map.zones().size() <= 24) {
    std::map<ZoneId, int> per_zone;
    for (const Point& p : map.points()) ++per_zone[p.zone];
    for (std::size_t z = 0; z < map.zones().size(); ++z) {
      std::printf("  %-6s area %8.2f m^2, %4d points\n", map.zones()[z].name.c_str(),
                  map.zones()[z].area, per_zone[static_cast<ZoneId>(z)]);
    }
  }
  if (!map.free_spaces().empty()) {
    std::printf("Free spaces (four-wheel steer): %zu\n", map.free_spaces().size());
    for (const FreeSpace& f : map.free_spaces()) {
      std::printf("  %-6s area %8.2f m^2, %4zu points\n", f.name.c_str(), f.area, f.points.size());
    }
  }
}

std::string Via(const WarehouseMap& map, const Route& r, std::size_t limit) {
  std::string out;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    if (r.points.size() > limit && i == limit / 2) {
      out += " ... ";
      i = r.points.size() - limit / 2;
    }
    if (!out.empty() && out.back() != ' ') out += " > ";
    out += map.point(r.points[i]).name;
  }
  return out;
}

// A spread-out, deterministic sample: station -> pick, pick -> drop.
std::vector<std::pair<PointId, PointId>> SampleRoutes(const WarehouseMap& map, int samples) {
  std::vector<PointId> parks, picks, drops;
  for (std::size_t i = 0; i < map.point_count(); ++i) {
    const auto id = static_cast<PointId>(i);
    switch (map.point(id).kind) {
      case PointKind::kPark: parks.push_back(id); break;
      case PointKind::kPick: picks.push_back(id); break;
      case PointKind::kDrop: drops.push_back(id); break;
      default: break;
    }
  }
  if (parks.empty()) parks = picks;
  std::vector<std::pair<PointId, PointId>> pairs;
  if (picks.empty() || drops.empty() || parks.empty()) return pairs;
  for (int i = 0; i < samples; ++i) {
    const PointId park = parks[(i * parks.size()) / samples];
    const PointId pick = picks[((2 * i + 1) * picks.size()) / (2 * samples)];
    const PointId drop = drops[((i * 7 + 3) * drops.size() / 11) % drops.size()];
    pairs.push_back({park, pick});
    pairs.push_back({pick, drop});
  }
  return pairs;
}

std::optional<PointId> FindPointOrStation(const WarehouseMap& map, const std::string& name) {
  if (auto p = map.FindPoint(name)) return p;
  for (const auto& s : map.stations()) {
    if (s.name == name) return s.point;
  }
  return std::nullopt;
}

int RunRoutes(const WarehouseMap& loaded, const RouteTableOptions& options, const std::string& from,
              const std::string& to, int samples) {
  auto map = std::make_shared<const WarehouseMap>(loaded);
  const auto start = std::chrono::steady_clock::now();
  auto table = MakeRouteTable(map, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!table.ok()) return Fail(table.error().message);
  const RouteTableBuildInfo info = (*table)->build_info();
  std::printf("Route table: %s over %zu vertices / %zu arcs%s, built in %.3f s, %.1f MiB%s\n",
              info.method.c_str(), info.vertex_count, info.arc_count,
              info.turn_expanded ? " (turn-expanded)" : "", seconds,
              static_cast<double>(info.table_bytes) / (1 << 20), info.method == "lazy" ? " (cache bound)" : "");
  std::vector<std::pair<PointId, PointId>> pairs;
  if (!from.empty() || !to.empty()) {
    auto f = FindPointOrStation(*map, from);
    auto t = FindPointOrStation(*map, to);
    if (!f) return Fail("unknown point or station '" + from + "'");
    if (!t) return Fail("unknown point or station '" + to + "'");
    pairs.push_back({*f, *t});
  } else {
    pairs = SampleRoutes(*map, samples);
  }
  std::printf("%-18s %-18s %9s %9s %5s  %s\n", "from", "to", "length_m", "time_s", "hops", "via");
  for (const auto& [f, t] : pairs) {
    auto route = (*table)->Path(f, t);
    if (!route.ok()) {
      std::printf("%-18s %-18s %s\n", map->point(f).name.c_str(), map->point(t).name.c_str(),
                  route.error().message.c_str());
      continue;
    }
    std::printf("%-18s %-18s %9.2f %9.2f %5zu  %s\n", map->point(f).name.c_str(),
                map->point(t).name.c_str(), route->length, route->cost, route->arcs.size(),
                Via(*map, *route, pairs.size() == 1 ? 1000 : 6).c_str());
  }
  return 0;
}

int WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) return Fail("cannot write '" + path + "'");
  std::printf("wrote %s (%zu bytes)\n", path.c_str(), text.size());
  return 0;
}

int Main(int argc, char** argv) {
  CLI::App app{"Inspect warehouse maps: summary, routes, SVG rendering, JSON export"};
  app.require_subcommand(1);
  std::string source = "chu2024";
  std::string out, from, to, method = "floyd";
  RouteTableOptions options;
  int samples = 6;
  bool no_labels = false;

  auto add_map = [&](CLI::App* cmd) {
    cmd->add_option("--map", source, "chu2024, a .json map file or a MovingAI .map file")
        ->capture_default_str();
  };
  auto* summary = app.add_subcommand("summary", "Print what the map holds");
  add_map(summary);
  auto* routes = app.add_subcommand("routes", "Print shortest routes with lengths and times");
  add_map(routes);
  routes->add_option("--from", from, "Start point id (default: a sample of routes)");
  routes->add_option("--to", to, "End point id");
  routes->add_option("--speed", options.speed, "Robot speed, m/s")->capture_default_str()
      ->check(CLI::PositiveNumber);
  routes->add_option("--turn-penalty", options.turn_penalty_s, "Seconds per 90 degree turn")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  routes->add_option("--method", method, "floyd, dijkstra, auto, lazy or hub_labels")->capture_default_str()
      ->check(CLI::IsMember(RouteTableMethodNames()));
  routes->add_option("--samples", samples, "Sample size (station->pick->drop)")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  auto* svg = app.add_subcommand("svg", "Render the map to an SVG file");
  add_map(svg);
  svg->add_option("--out", out, "Output .svg file")->required();
  svg->add_flag("--no-labels", no_labels, "Leave point labels out");
  auto* exp = app.add_subcommand("export", "Write the map in the JSON map format");
  add_map(exp);
  exp->add_option("--out", out, "Output .json file")->required();
  CLI11_PARSE(app, argc, argv);

  auto map = LoadMapSource(source);
  if (!map.ok()) return Fail(map.error().message);
  if (summary->parsed()) {
    PrintSummary(*map);
    return 0;
  }
  if (routes->parsed()) {
    options.method = ParseRouteTableMethod(method).value();
    return RunRoutes(*map, options, from, to, samples);
  }
  if (svg->parsed()) {
    SvgOptions svg_options;
    svg_options.show_point_labels = !no_labels;
    return WriteFile(out, RenderMapSvg(*map, svg_options));
  }
  return WriteFile(out, WriteMapJson(*map));
}

}  // namespace
}  // namespace dispatch::engine

int main(int argc, char** argv) { return dispatch::engine::Main(argc, argv); }
