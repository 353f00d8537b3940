// Operator commands on robots (issue 18 §4) and the marks they leave on a robot, kept across
// restarts: pause and resume (held at its next point, plan and orders kept), out of service
// and back (its orders given back as for a lost robot, held where it stands, out of every
// auction), clear (an offline robot taken off the floor: no obstacle until it says Hello
// again) and send (an idle robot driven to a station).
//
// Values only.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

enum class RobotCommandKind { kPause, kResume, kTakeOutOfService, kReturnToService, kClear, kSend };

// "pause", "resume", "out_of_service", "return_to_service", "clear", "send".
const char* RobotCommandName(RobotCommandKind kind);
std::optional<RobotCommandKind> ParseRobotCommand(std::string_view name);

struct OperatorCommand {
  RobotCommandKind kind = RobotCommandKind::kPause;
  std::string robot;
  std::string by;         // who (a token's name; "": an operator)
  PointId to = kNoPoint;  // kSend: the station's point
};

struct OperatorMarks {
  std::string paused_by;          // "": not paused
  std::string out_of_service_by;  // "": in service
  bool off_floor = false;         // cleared off the floor while offline, until it says Hello
  bool operator==(const OperatorMarks&) const = default;
  // Whom the traffic gate holds it for ("": nobody): who paused it, else who took it out of
  // service.
  std::string HeldFor() const;
};

// The point a robot is sent to: the parking or charging station named `name`, or the park or
// charge point of that name. Errors: kNotFound (none such; names the stations), kInvalidArgument
// (a point of another kind: robots are not parked in aisles).
Result<PointId> StationPoint(const WarehouseMap& map, const std::string& name);

}  // namespace dispatch::engine
