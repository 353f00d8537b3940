// Parser of the seed task tables (shared/scenarios/chu2024-table*.csv; Chu2024 Tables 1, 2).
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
// Coordinates stay coordinates: resolve them with ResolveOrder. work_time keeps its default.
// Errors (kInvalidArgument) name the line number and the column (number and name).
//
// Pure parsing of text held by the caller (no file access); thread-safe.
#pragma once

#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/fleet/order.h"

namespace dispatch::engine {

Result<std::vector<OrderRequest>> ParseTaskTable(std::string_view text);

}  // namespace dispatch::engine
