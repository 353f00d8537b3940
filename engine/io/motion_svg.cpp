#include "engine/io/motion_svg.h"

#include <cmath>
#include <cstdio>
#include <string_view>

#include "engine/io/xml_text.h"
#include "engine/motion/motion_conflicts.h"

namespace dispatch::engine {
namespace {

std::string Tenths(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

}  // namespace

std::string RenderMotionSvg(const OccupancyGrid& grid, const std::vector<MotionSvgPath>& paths,
                            const MotionSvgOptions& o) {
  const double s = o.pixels_per_metre;
  const double res = grid.resolution();
  const double floor_w = grid.width() * res;
  const double floor_h = grid.height() * res;
  const double legend_h = 18.0 * (static_cast<double>(paths.size()) + (o.title.empty() ? 0.0 : 1.0)) + 8.0;
  const double width = floor_w * s + 2.0 * o.margin_px;
  const double height = floor_h * s + 2.0 * o.margin_px + legend_h;
  auto px = [&](double x) { return o.margin_px + (x - grid.origin().x()) * s; };
  auto py = [&](double y) { return o.margin_px + (floor_h - (y - grid.origin().y())) * s; };

  std::string svg;
  svg += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + Tenths(width) + "\" height=\"" + Tenths(height) +
         "\" viewBox=\"0 0 " + Tenths(width) + " " + Tenths(height) + "\">\n";
  svg += "<rect x=\"0\" y=\"0\" width=\"" + Tenths(width) + "\" height=\"" + Tenths(height) + "\" fill=\"white\"/>\n";
  svg += "<g class=\"grid\">\n";
  for (int iy = 0; iy < grid.height(); ++iy) {
    for (int ix = 0; ix < grid.width();) {
      if (!grid.Occupied(ix, iy)) {
        ++ix;
        continue;
      }
      int end = ix;
      while (end < grid.width() && grid.Occupied(end, iy)) ++end;
      const double x0 = grid.origin().x() + ix * res;
      const double y1 = grid.origin().y() + (iy + 1) * res;
      svg += "<rect class=\"grid-cell\" x=\"" + Tenths(px(x0)) + "\" y=\"" + Tenths(py(y1)) + "\" width=\"" +
             Tenths((end - ix) * res * s) + "\" height=\"" + Tenths(res * s) + "\" fill=\"#444\"/>\n";
      ix = end;
    }
  }
  svg += "</g>\n";
  for (const MotionSvgPath& p : paths) {
    const std::vector<MotionPose>& poses = p.path.poses;
    svg += "<g class=\"motion-path\" data-label=\"" + XmlEscape(p.label) + "\">\n";
    double since = 0.0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (i > 0) {
        since += std::hypot(poses[i].x - poses[i - 1].x, poses[i].y - poses[i - 1].y) +
                 o.spin_radius * std::abs(WrapHeading(poses[i].theta - poses[i - 1].theta)) *
                     (i - 1 < p.path.modes.size() && IsSpin(p.path.modes[i - 1]) ? 1.0 : 0.0);
      }
      if (i != 0 && i + 1 != poses.size() && since < o.footprint_every) continue;
      since = 0.0;
      std::string points;
      for (const auto& [x, y] : FootprintCorners(poses[i], p.footprint, 0.0)) {
        points += Tenths(px(x)) + "," + Tenths(py(y)) + " ";
      }
      points.pop_back();
      svg += "<polygon class=\"footprint\" points=\"" + points + "\" fill=\"" + p.colour +
             "\" fill-opacity=\"0.12\" stroke=\"" + p.colour + "\" stroke-width=\"1\"/>\n";
    }
    if (!poses.empty()) {
      std::string points;
      for (const MotionPose& q : poses) points += Tenths(px(q.x)) + "," + Tenths(py(q.y)) + " ";
      points.pop_back();
      svg += "<polyline class=\"path\" points=\"" + points + "\" fill=\"none\" stroke=\"" + p.colour +
             "\" stroke-width=\"2\"/>\n";
    }
    svg += "</g>\n";
  }
  double ly = floor_h * s + 2.0 * o.margin_px + 12.0;
  svg += "<g class=\"legend\" font-family=\"sans-serif\" font-size=\"13\">\n";
  if (!o.title.empty()) {
    svg += "<text x=\"" + Tenths(o.margin_px) + "\" y=\"" + Tenths(ly) + "\">" + XmlEscape(o.title) + "</text>\n";
    ly += 18.0;
  }
  for (const MotionSvgPath& p : paths) {
    svg += "<rect x=\"" + Tenths(o.margin_px) + "\" y=\"" + Tenths(ly - 10.0) + "\" width=\"20\" height=\"10\" fill=\"" +
           p.colour + "\"/>\n";
    svg += "<text x=\"" + Tenths(o.margin_px + 28.0) + "\" y=\"" + Tenths(ly) + "\">" + XmlEscape(p.label) + "</text>\n";
    ly += 18.0;
  }
  svg += "</g>\n</svg>\n";
  return svg;
}

}  // namespace dispatch::engine
