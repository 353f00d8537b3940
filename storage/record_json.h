// JSON encodings of the stored records' non-queried fields (the "body" columns of the SQLite
// schema) and the canonical content encoding behind OrderContentHash.
//
// Queried fields (ids, states, times) live in their own columns; the rest of a record is one
// JSON text so that adding a field needs no schema migration. Decoders accept exactly what
// the encoders write and report anything else as kIoError "stored ... is corrupt: ...".
// Doubles must be finite (JSON has no inf/NaN): encoders reject others with kInvalidArgument.
// Pure functions; thread-safe.
#pragma once

#include <string>
#include <vector>

#include "storage/store.h"

namespace dispatch::storage {

// kIoError "stored <what> is corrupt: <detail>", the decoders' one error.
Error Corrupt(const char* what, const std::string& detail);

// Order body: picks, drop, work_time, release_time.
Result<std::string> EncodeOrderBody(const engine::Order& order);
// Fills picks, drop, work_time, release_time of `order` from `body`.
Status DecodeOrderBody(const std::string& body, engine::Order& order);

// Robot body: everything of engine::Robot except id and state, and the operator marks in force
// (a "marks" object, absent when there are none).
Result<std::string> EncodeRobotBody(const engine::Robot& robot, const engine::OperatorMarks& marks = {});
Status DecodeRobotBody(const std::string& body, engine::Robot& robot, engine::OperatorMarks* marks = nullptr);

// Operator marks: {"paused_by": ..., "out_of_service_by": ..., "off_floor": true}, each key
// only when set.
std::string EncodeMarks(const engine::OperatorMarks& marks);
Result<engine::OperatorMarks> DecodeMarks(const std::string& text);

// Plan waypoints.
Result<std::string> EncodeWaypoints(const std::vector<engine::Waypoint>& waypoints);
Result<std::vector<engine::Waypoint>> DecodeWaypoints(const std::string& text);

// A JSON array of strings (robot ids, order ids); kInvalidArgument for non-UTF-8 text.
Result<std::string> EncodeStrings(const std::vector<std::string>& strings);
Result<std::vector<std::string>> DecodeStrings(const std::string& text);

}  // namespace dispatch::storage
