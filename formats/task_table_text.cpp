#include "formats/task_table_text.h"

#include <charconv>
#include <cmath>
#include <optional>
#include <set>
#include <string>

namespace dispatch::formats {
namespace {

std::string_view Trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::vector<std::string_view> Split(std::string_view s, char sep) {
  std::vector<std::string_view> parts;
  std::size_t begin = 0;
  while (true) {
    const auto end = s.find(sep, begin);
    parts.push_back(s.substr(begin, end == std::string_view::npos ? end : end - begin));
    if (end == std::string_view::npos) break;
    begin = end + 1;
  }
  return parts;
}

std::optional<double> ParseNumber(std::string_view s) {
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

// "x y" with any blanks between and around.
std::optional<Xy> ParseXy(std::string_view s) {
  s = Trim(s);
  const auto gap = s.find_first_of(" \t");
  if (gap == std::string_view::npos) return std::nullopt;
  const auto x = ParseNumber(s.substr(0, gap));
  const auto y = ParseNumber(Trim(s.substr(gap)));
  if (!x || !y) return std::nullopt;
  return Xy{*x, *y};
}

enum class Column { kTask, kFormation, kPicks, kDrop, kRelease };

std::optional<Column> ParseColumn(std::string_view name) {
  if (name == "task") return Column::kTask;
  if (name == "formation") return Column::kFormation;
  if (name == "picks") return Column::kPicks;
  if (name == "drop") return Column::kDrop;
  if (name == "release") return Column::kRelease;
  return std::nullopt;
}

}  // namespace

TaskTableText ParseTaskTableText(std::string_view text) {
  TaskTableText out;
  auto fail = [&out](std::string why) {
    out.rows.clear();
    out.error = std::move(why);
    return out;
  };
  std::vector<Column> columns;
  std::vector<std::string> names;
  std::set<std::string, std::less<>> ids;
  const std::vector<std::string_view> lines = Split(text, '\n');
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const std::string line_no = "line " + std::to_string(n + 1);
    const std::string_view line = Trim(lines[n]);
    if (line.empty() || line.front() == '#') continue;
    const std::vector<std::string_view> fields = Split(line, ',');
    if (columns.empty()) {  // the header
      std::set<Column> seen;
      for (std::size_t c = 0; c < fields.size(); ++c) {
        const std::string name(Trim(fields[c]));
        const auto column = ParseColumn(name);
        const std::string where = line_no + ", column " + std::to_string(c + 1);
        if (!column) return fail(where + ": unknown column '" + name + "'");
        if (!seen.insert(*column).second) {
          return fail(where + ": duplicate column '" + name + "'");
        }
        columns.push_back(*column);
        names.push_back(name);
      }
      for (const char* required : {"task", "formation", "picks", "drop"}) {
        if (!seen.count(*ParseColumn(required))) {
          return fail(line_no + ": header lacks column '" + required + "'");
        }
      }
      continue;
    }
    if (fields.size() != columns.size()) {
      return fail(line_no + ": expected " + std::to_string(columns.size()) +
                             " fields, got " + std::to_string(fields.size()));
    }
    TaskRow order;
    for (std::size_t c = 0; c < fields.size(); ++c) {
      const std::string_view field = Trim(fields[c]);
      const std::string where =
          line_no + ", column " + std::to_string(c + 1) + " (" + names[c] + ")";
      const std::string got = "'" + std::string(field) + "'";
      switch (columns[c]) {
        case Column::kTask:
          if (field.empty()) return fail(where + ": empty task id");
          if (!ids.insert(std::string(field)).second) {
            return fail(where + ": duplicate task id " + got);
          }
          order.task = std::string(field);
          break;
        case Column::kFormation:
          if (field != "0" && field != "1") {
            return fail(where + ": expected 0 or 1, got " + got);
          }
          order.formation = field == "1";
          break;
        case Column::kPicks: {
          if (field.empty()) return fail(where + ": no pick points");
          const auto picks = Split(field, ';');
          for (std::size_t p = 0; p < picks.size(); ++p) {
            const auto xy = ParseXy(picks[p]);
            if (!xy) {
              return fail(where + ": pick " + std::to_string(p + 1) +
                                     " is not 'x y': '" + std::string(Trim(picks[p])) + "'");
            }
            order.picks.emplace_back(*xy);
          }
          break;
        }
        case Column::kDrop: {
          const auto xy = ParseXy(field);
          if (!xy) return fail(where + ": expected 'x y', got " + got);
          order.drop = *xy;
          break;
        }
        case Column::kRelease: {
          if (field.empty()) break;
          const auto t = ParseNumber(field);
          if (!t || *t < 0.0) {
            return fail(where + ": expected seconds >= 0, got " + got);
          }
          order.release = *t;
          break;
        }
      }
    }
    out.rows.push_back(std::move(order));
  }
  if (columns.empty()) return fail("task table has no header line");
  return out;
}

}  // namespace dispatch::formats
