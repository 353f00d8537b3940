// The seed task tables (shared/scenarios/chu2024-table*.csv; Chu2024 Tables 1, 2) as order
// requests: the text format and its errors are formats/task_table_text.h (one parser for the
// engine and the clients); here each row becomes an OrderRequest. Coordinates stay
// coordinates: resolve them with ResolveOrder. work_time keeps its default.
// Errors: kInvalidArgument naming the line number and the column (number and name).
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
