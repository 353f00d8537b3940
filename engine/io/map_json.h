// The versioned JSON map format (SPEC §2 map source 1; documented in engine/io/map_format.md,
// schema in engine/io/map.schema.json).
//
// ParseMapJson checks the file's shape (format tag, version, required fields, field types,
// point kinds) and then hands the parts to MapBuilder, so every MapBuilder::Build rule holds
// for a returned map. Every error message names the offending field with a JSON path such as
// "points[3].x: expected a number, got string"; builder messages are passed through.
// WriteMapJson emits a canonical text (fixed key order, one element per line, elements in the
// map's order), so Write(Parse(Write(m))) == Write(m).
//
// Thread safety: free functions without shared state; safe to call concurrently.
#pragma once

#include <string>
#include <string_view>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

inline constexpr std::string_view kMapJsonFormat = "warehouse-map";
inline constexpr int kMapJsonVersion = 1;

// Parses a map from JSON text. Errors: kInvalidArgument with a message naming the problem.
Result<WarehouseMap> ParseMapJson(std::string_view text);

// Reads and parses a file. Errors: kIoError when the file cannot be read; parse errors are
// prefixed with the path ("maps/a.json: points[3].x: ...").
Result<WarehouseMap> LoadMapJsonFile(const std::string& path);

// Canonical, pretty JSON text of a map (version kMapJsonVersion), ending with a newline.
std::string WriteMapJson(const WarehouseMap& map);

}  // namespace dispatch::engine
