// The seed task tables' text format (shared/scenarios/chu2024-table*.csv; Chu2024 Tables 1,
// 2), parsed once for both sides of the wire: the engine resolves the rows into orders
// (engine/fleet/task_table.h), wmsctl turns them into SubmitOrder requests
// (clients/order_file.h). A file format, not a domain model: the standard library only, so
// clients need not link the engine (STYLE.md: clients talk to the server through proto/REST).
//
// Format: UTF-8 text, one record per line (LF or CRLF). Blank lines and lines whose first
// non-blank character is '#' are ignored. The first other line is the header; it must name
// the columns task, formation, picks and drop (any order) and may add `release` (seconds);
// any other column is an error. Fields:
//   task       order id (non-empty, unique in the table)
//   formation  0 or 1 (1: a 3-robot formation carries the item)
//   picks      pick coordinates in visiting order, "x y;x y;..." (>= 1)
//   drop       drop coordinate "x y"
//   release    optional: earliest start time in seconds (>= 0); an empty field = none
// Errors name the line number and the column (number and name).
//
// Pure parsing of text held by the caller (no file access); thread-safe.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dispatch::formats {

using Xy = std::array<double, 2>;  // metres

struct TaskRow {
  std::string task;
  bool formation = false;
  std::vector<Xy> picks;  // in visiting order, at least one
  Xy drop{};
  std::optional<double> release;  // seconds
};

struct TaskTableText {
  std::vector<TaskRow> rows;  // in file order
  std::string error;          // empty when the text parsed
  bool ok() const { return error.empty(); }
};

TaskTableText ParseTaskTableText(std::string_view text);

}  // namespace dispatch::formats
