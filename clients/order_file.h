// Order files for wmsctl (SPEC §5): what a WMS operator hands to `wmsctl submit`.
//
//  - CSV: the seed task tables as they are (engine/fleet/task_table.h: comment lines, the
//    header task,formation,picks,drop[,release], coordinates "x y;x y"). Row `task` becomes
//    client order id `<prefix><task>`, so submitting the same file twice is idempotent.
//  - JSON: one order object or an array of them (or {"orders": [...]}):
//      {"client_order_id": "A-17", "priority": 2, "formation": false, "work_time": 5,
//       "release_time": 30, "picks": [{"x": 19, "y": 17}, "K2-4-3S"], "drop": {"x": 6.5, "y": 2.75}}
//    A stop is a point name (string) or {"x": .., "y": ..} (or {"point": "name"}); an object
//    may add "heading": radians, the heading the robot must have there (a point inside a
//    free-space region of the map; the server says so otherwise);
//    client_order_id defaults to `<prefix><index>` (1-based).
// Errors name the file and the line (CSV) or the order index and field (JSON). The CSV
// parser is formats/task_table_text.h, the one the engine reads task tables with; the
// clients do not link the engine (STYLE.md). Pure parsing of text held by the caller plus one
// file read; thread-safe.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "warehouse/dispatch/v1/orders.pb.h"

namespace dispatch::clients {

namespace v1 = ::warehouse::dispatch::v1;

// The orders of a file, or why there are none.
struct OrderFile {
  std::vector<v1::SubmitOrderRequest> orders;
  std::string error;  // empty when the file parsed
  bool ok() const { return error.empty(); }
};

// Parses `text` as CSV or JSON (`json` chooses); `prefix` prefixes generated client ids.
OrderFile ParseOrderText(std::string_view text, bool json, const std::string& prefix);
// Reads `path`: JSON when it ends in .json, else CSV. Default prefix: the file's stem + "-".
OrderFile LoadOrderFile(const std::string& path, const std::string& prefix = "");

// Parses "x y" / "x,y" into a coordinate stop, or takes the text as a point name.
v1::StopSpec ParseStopArgument(const std::string& text);

}  // namespace dispatch::clients
