#include "engine/io/map_svg.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string_view>
#include <vector>

#include "engine/io/xml_text.h"

namespace dispatch::engine {
namespace {

constexpr std::size_t kMaxZoneLabels = 200;
constexpr double kAutoSidePx = 1200.0;

// Shortest fixed-point text with at most 2 decimals ("12", "3.5", "-0.25").
std::string Coordinate(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

struct KindStyle {
  const char* css;    // class name
  const char* fill;   // colour
  const char* label;  // legend text
};

KindStyle StyleOf(PointKind kind) {
  switch (kind) {
    case PointKind::kLane: return {"lane", "#9e9e9e", "lane point"};
    case PointKind::kIntersection: return {"intersection", "#6a1b9a", "intersection point"};
    case PointKind::kPick: return {"pick", "#2e7d32", "pick"};
    case PointKind::kDrop: return {"drop", "#c62828", "drop"};
    case PointKind::kPark: return {"park", "#1565c0", "park / station"};
    case PointKind::kCharge: return {"charge", "#ef6c00", "charge"};
  }
  return {"lane", "#9e9e9e", "lane point"};
}

constexpr std::array<PointKind, 6> kKinds = {PointKind::kLane, PointKind::kIntersection,
                                             PointKind::kPick, PointKind::kDrop,
                                             PointKind::kPark, PointKind::kCharge};

// Floor (x, y) -> SVG pixels, y flipped.
struct Frame {
  Eigen::Vector2d min, max;
  double scale = 1.0;
  double margin = 20.0;
  double X(double x) const { return margin + (x - min.x()) * scale; }
  double Y(double y) const { return margin + (max.y() - y) * scale; }
  double map_width() const { return 2 * margin + (max.x() - min.x()) * scale; }
  double map_height() const { return 2 * margin + (max.y() - min.y()) * scale; }
};

std::string ZoneFill(std::size_t i) {
  return "hsl(" + std::to_string((i * 67) % 360) + ",70%,60%)";
}

void RenderZones(std::ostringstream& out, const WarehouseMap& map, const Frame& f) {
  out << "<g class=\"zones\">\n";
  for (std::size_t i = 0; i < map.zones().size(); ++i) {
    const Zone& z = map.zones()[i];
    out << "<polygon class=\"zone\" fill=\"" << ZoneFill(i) << "\" points=\"";
    for (std::size_t k = 0; k < z.polygon.size(); ++k) {
      out << (k ? " " : "") << Coordinate(f.X(z.polygon[k].x())) << ',' << Coordinate(f.Y(z.polygon[k].y()));
    }
    out << "\"><title>" << XmlEscape(z.name) << "</title></polygon>\n";
  }
  out << "</g>\n";
}

// Free-space regions (narrow areas for four-wheel-steer robots), over the zones.
void RenderFreeSpaces(std::ostringstream& out, const WarehouseMap& map, const Frame& f) {
  if (map.free_spaces().empty()) return;
  out << "<g class=\"free-spaces\">\n";
  for (const FreeSpace& s : map.free_spaces()) {
    out << "<polygon class=\"free-space\" points=\"";
    for (std::size_t k = 0; k < s.polygon.size(); ++k) {
      out << (k ? " " : "") << Coordinate(f.X(s.polygon[k].x())) << ',' << Coordinate(f.Y(s.polygon[k].y()));
    }
    out << "\"><title>free space " << XmlEscape(s.name) << "</title></polygon>\n";
  }
  out << "</g>\n";
}

// Zone names and areas, drawn last so lanes and points do not hide them.
void RenderZoneLabels(std::ostringstream& out, const WarehouseMap& map, const Frame& f,
                      const SvgOptions& options) {
  if (!options.show_zone_labels || map.zones().size() > kMaxZoneLabels) return;
  out << "<g class=\"zone-labels\">\n";
  for (const Zone& z : map.zones()) {
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const auto& v : z.polygon) c += v;
    c /= static_cast<double>(z.polygon.size());
    out << "<text class=\"zone-label\" x=\"" << Coordinate(f.X(c.x())) << "\" y=\"" << Coordinate(f.Y(c.y()))
        << "\">" << XmlEscape(z.name) << "<tspan x=\"" << Coordinate(f.X(c.x())) << "\" dy=\"1.1em\">S="
        << Coordinate(z.area) << " m\u00b2</tspan></text>\n";
  }
  out << "</g>\n";
}

void RenderDetailed(std::ostringstream& out, const WarehouseMap& map, const Frame& f,
                    const SvgOptions& options) {
  const double r = std::clamp(0.15 * f.scale, 2.0, 6.0);  // point radius, px
  out << "<g class=\"shelves\">\n";
  for (const Shelf& s : map.shelves()) {
    out << "<rect class=\"shelf\" x=\"" << Coordinate(f.X(s.min.x())) << "\" y=\"" << Coordinate(f.Y(s.max.y()))
        << "\" width=\"" << Coordinate((s.max.x() - s.min.x()) * f.scale) << "\" height=\""
        << Coordinate((s.max.y() - s.min.y()) * f.scale) << "\"><title>" << XmlEscape(s.name)
        << "</title></rect>\n";
  }
  out << "</g>\n<g class=\"intersections\">\n";
  for (const Intersection& x : map.intersections()) {
    for (PointId id : x.inner) {
      const Point& p = map.point(id);
      out << "<circle class=\"inter-inner\" cx=\"" << Coordinate(f.X(p.position.x())) << "\" cy=\""
          << Coordinate(f.Y(p.position.y())) << "\" r=\"" << Coordinate(3 * r) << "\"><title>"
          << XmlEscape(x.name) << " inner</title></circle>\n";
    }
    for (PointId id : x.approach) {
      const Point& p = map.point(id);
      out << "<rect class=\"approach\" x=\"" << Coordinate(f.X(p.position.x()) - 2 * r) << "\" y=\""
          << Coordinate(f.Y(p.position.y()) - 2 * r) << "\" width=\"" << Coordinate(4 * r) << "\" height=\""
          << Coordinate(4 * r) << "\"><title>" << XmlEscape(x.name) << " approach</title></rect>\n";
    }
  }
  out << "</g>\n<g class=\"paths\">\n";
  for (const Path& path : map.paths()) {
    Eigen::Vector2d a(f.X(map.point(path.from).position.x()),
                      f.Y(map.point(path.from).position.y()));
    Eigen::Vector2d b(f.X(map.point(path.to).position.x()), f.Y(map.point(path.to).position.y()));
    const Eigen::Vector2d d = b - a;
    const double len = d.norm();
    if (len > 2.5 * r) {  // stop at the point circles so arrowheads stay visible
      a += d / len * r;
      b -= d / len * r;
    }
    out << "<line class=\"" << (path.bidirectional ? "lane2" : "oneway") << "\" x1=\"" << Coordinate(a.x())
        << "\" y1=\"" << Coordinate(a.y()) << "\" x2=\"" << Coordinate(b.x()) << "\" y2=\"" << Coordinate(b.y())
        << '"' << (path.bidirectional ? "" : " marker-end=\"url(#arrow)\"") << "/>\n";
  }
  out << "</g>\n<g class=\"points\">\n";
  for (const Point& p : map.points()) {
    out << "<circle class=\"pt " << StyleOf(p.kind).css << "\" cx=\"" << Coordinate(f.X(p.position.x()))
        << "\" cy=\"" << Coordinate(f.Y(p.position.y())) << "\" r=\""
        << Coordinate(IsServicePoint(p.kind) ? r : 0.6 * r) << "\"><title>" << XmlEscape(p.name)
        << "</title></circle>\n";
  }
  for (const ParkingStation& s : map.stations()) {
    const Point& p = map.point(s.point);
    out << "<text class=\"station-label\" x=\"" << Coordinate(f.X(p.position.x()) + 1.5 * r) << "\" y=\""
        << Coordinate(f.Y(p.position.y()) + 3 * r) << "\">" << XmlEscape(s.name) << " \u00d7" << s.capacity
        << "</text>\n";
  }
  if (options.show_point_labels) {
    for (const Point& p : map.points()) {
      out << "<text class=\"pt-label\" x=\"" << Coordinate(f.X(p.position.x()) + 1.5 * r) << "\" y=\""
          << Coordinate(f.Y(p.position.y()) - 1.5 * r) << "\">" << XmlEscape(p.name) << "</text>\n";
    }
  }
  out << "</g>\n";
}

// Compact style: one <path> per class, world coordinates in a flipped group.
void RenderCompact(std::ostringstream& out, const WarehouseMap& map, const Frame& f) {
  out << "<g class=\"world\" transform=\"matrix(" << Coordinate(f.scale) << " 0 0 " << Coordinate(-f.scale)
      << ' ' << Coordinate(f.X(0.0)) << ' ' << Coordinate(f.Y(0.0)) << ")\">\n";
  if (!map.shelves().empty()) {
    out << "<path class=\"shelf\" d=\"";
    for (const Shelf& s : map.shelves()) {
      out << 'M' << Coordinate(s.min.x()) << ' ' << Coordinate(s.min.y()) << 'h' << Coordinate(s.max.x() - s.min.x())
          << 'v' << Coordinate(s.max.y() - s.min.y()) << 'h' << Coordinate(s.min.x() - s.max.x()) << 'z';
    }
    out << "\"/>\n";
  }
  for (int bidirectional = 1; bidirectional >= 0; --bidirectional) {
    std::string d;
    for (const Path& path : map.paths()) {
      if (path.bidirectional != (bidirectional == 1)) continue;
      const Eigen::Vector2d& a = map.point(path.from).position;
      const Eigen::Vector2d& b = map.point(path.to).position;
      d += 'M' + Coordinate(a.x()) + ' ' + Coordinate(a.y());
      if (a.y() == b.y()) {
        d += 'H' + Coordinate(b.x());
      } else if (a.x() == b.x()) {
        d += 'V' + Coordinate(b.y());
      } else {
        d += 'L' + Coordinate(b.x()) + ' ' + Coordinate(b.y());
      }
    }
    if (!d.empty()) {
      out << "<path class=\"" << (bidirectional ? "lane2" : "oneway") << " compact\" d=\"" << d
          << "\"/>\n";
    }
  }
  constexpr double kCell = 0.6;  // metres
  for (PointKind kind : kKinds) {
    std::string d;
    for (const Point& p : map.points()) {
      if (p.kind != kind) continue;
      d += 'M' + Coordinate(p.position.x() - kCell / 2) + ' ' + Coordinate(p.position.y() - kCell / 2) + "h" +
           Coordinate(kCell) + "v" + Coordinate(kCell) + "h-" + Coordinate(kCell) + 'z';
    }
    if (!d.empty()) out << "<path class=\"pt " << StyleOf(kind).css << "\" d=\"" << d << "\"/>\n";
  }
  for (const Intersection& x : map.intersections()) {
    for (PointId id : x.inner) {
      const Point& p = map.point(id);
      out << "<circle class=\"inter-inner\" cx=\"" << Coordinate(p.position.x()) << "\" cy=\""
          << Coordinate(p.position.y()) << "\" r=\"0.6\"/>\n";
    }
  }
  out << "</g>\n";
}

// The legend's entries: the fixed ones, the point kinds, and free space on maps that have it.
std::size_t LegendEntries(const WarehouseMap& map) { return 12 + (map.free_spaces().empty() ? 0 : 1); }

void RenderLegend(std::ostringstream& out, const WarehouseMap& map, double top, double width) {
  struct Entry {
    std::string swatch;
    std::string text;
  };
  std::vector<Entry> entries = {
      {"<rect class=\"zone\" fill=\"hsl(0,70%,60%)\" x=\"0\" y=\"-6\" width=\"16\" height=\"12\"/>",
       "zone (S = area)"},
      {"<rect class=\"shelf\" x=\"0\" y=\"-6\" width=\"16\" height=\"12\"/>", "shelf"},
      {"<line class=\"oneway\" x1=\"0\" y1=\"0\" x2=\"16\" y2=\"0\" marker-end=\"url(#arrow)\"/>",
       "one-way lane"},
      {"<line class=\"lane2\" x1=\"0\" y1=\"0\" x2=\"16\" y2=\"0\"/>", "single lane (both ways)"},
      {"<circle class=\"inter-inner\" cx=\"8\" cy=\"0\" r=\"6\"/>", "intersection inner"},
      {"<rect class=\"approach\" x=\"3\" y=\"-5\" width=\"10\" height=\"10\"/>", "approach point"},
  };
  for (PointKind kind : kKinds) {
    entries.push_back({std::string("<circle class=\"pt ") + StyleOf(kind).css +
                           "\" cx=\"8\" cy=\"0\" r=\"4\"/>",
                       StyleOf(kind).label});
  }
  if (!map.free_spaces().empty()) {
    entries.push_back({"<rect class=\"free-space\" x=\"0\" y=\"-6\" width=\"16\" height=\"12\"/>",
                       "free space (four-wheel steer)"});
  }
  constexpr double kEntryWidth = 170.0;
  constexpr double kRowHeight = 20.0;
  const int per_row = std::max(1, static_cast<int>((width - 20.0) / kEntryWidth));
  out << "<g class=\"legend\">\n";
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double x = 20.0 + static_cast<double>(static_cast<int>(i) % per_row) * kEntryWidth;
    const double y = top + 14.0 + static_cast<double>(static_cast<int>(i) / per_row) * kRowHeight;
    out << "<g transform=\"translate(" << Coordinate(x) << ' ' << Coordinate(y) << ")\">" << entries[i].swatch
        << "<text x=\"22\" y=\"4\">" << XmlEscape(entries[i].text) << "</text></g>\n";
  }
  out << "</g>\n";
}

double LegendHeight(std::size_t entries, double width) {
  const int per_row = std::max(1, static_cast<int>((width - 20.0) / 170.0));
  const int rows = (static_cast<int>(entries) + per_row - 1) / per_row;
  return 14.0 + rows * 20.0;
}

}  // namespace

std::string RenderMapSvg(const WarehouseMap& map, const SvgOptions& options) {
  Frame f;
  f.min = map.floor_min();
  f.max = map.floor_max();
  f.margin = options.margin_px;
  const Eigen::Vector2d extent = (f.max - f.min).cwiseMax(1e-9);
  f.scale = options.pixels_per_metre > 0 ? options.pixels_per_metre
                                         : std::clamp(kAutoSidePx / extent.maxCoeff(), 1.0, 80.0);
  const bool compact = map.point_count() > options.detail_limit;
  const double width = std::max(f.map_width(), options.show_legend ? 540.0 : 0.0);
  const double legend_top = f.map_height();
  const double height = legend_top + (options.show_legend ? LegendHeight(LegendEntries(map), width) : 0.0);

  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << Coordinate(width) << "\" height=\""
      << Coordinate(height) << "\" viewBox=\"0 0 " << Coordinate(width) << ' ' << Coordinate(height) << "\">\n";
  out << "<title>" << XmlEscape(map.name()) << "</title>\n";
  out << "<defs>\n<marker id=\"arrow\" viewBox=\"0 0 10 10\" refX=\"10\" refY=\"5\" "
         "markerWidth=\"5\" markerHeight=\"5\" orient=\"auto\"><path d=\"M0 0L10 5L0 10z\" "
         "fill=\"#37474f\"/></marker>\n</defs>\n";
  out << "<style>\n"
         ".floor{fill:#fafafa;stroke:#424242;stroke-width:1}\n"
         ".zone{fill-opacity:0.15;stroke:#757575;stroke-width:0.5}\n"
         ".zone-label{font:bold 11px sans-serif;fill:#424242;fill-opacity:0.8;text-anchor:middle}\n"
         ".shelf{fill:#8d6e63;stroke:#4e342e;stroke-width:0.5}\n"
         ".free-space{fill:#a5d6a7;fill-opacity:0.45;stroke:#2e7d32;stroke-width:1;stroke-dasharray:3 2}\n"
         ".oneway{stroke:#37474f;stroke-width:1.2;fill:none}\n"
         ".lane2{stroke:#0277bd;stroke-width:1.2;stroke-dasharray:4 2;fill:none}\n"
         ".compact{stroke-width:0.12;stroke-dasharray:none}\n"
         ".inter-inner{fill:#ce93d8;fill-opacity:0.45;stroke:#6a1b9a;stroke-width:0.8}\n"
         ".approach{fill:none;stroke:#6a1b9a;stroke-width:1.2}\n"
         ".pt-label,.station-label{font:9px sans-serif;fill:#212121}\n"
         ".station-label{font-weight:bold;fill:#1565c0}\n"
         ".legend text{font:11px sans-serif;fill:#212121}\n";
  for (PointKind kind : kKinds) {
    out << ".pt." << StyleOf(kind).css << "{fill:" << StyleOf(kind).fill << "}\n";
  }
  out << "</style>\n";
  out << "<rect class=\"floor\" x=\"" << Coordinate(f.X(f.min.x())) << "\" y=\"" << Coordinate(f.Y(f.max.y()))
      << "\" width=\"" << Coordinate(extent.x() * f.scale) << "\" height=\""
      << Coordinate(extent.y() * f.scale) << "\"/>\n";
  RenderZones(out, map, f);
  RenderFreeSpaces(out, map, f);
  if (compact) {
    RenderCompact(out, map, f);
  } else {
    RenderDetailed(out, map, f, options);
  }
  RenderZoneLabels(out, map, f, options);
  if (options.show_legend) RenderLegend(out, map, legend_top, width);
  out << "</svg>\n";
  return out.str();
}

}  // namespace dispatch::engine
