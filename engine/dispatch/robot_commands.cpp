#include "engine/dispatch/robot_commands.h"

#include "engine/common/text.h"

namespace dispatch::engine {

const char* RobotCommandName(RobotCommandKind kind) {
  switch (kind) {
    case RobotCommandKind::kPause: return "pause";
    case RobotCommandKind::kResume: return "resume";
    case RobotCommandKind::kTakeOutOfService: return "out_of_service";
    case RobotCommandKind::kReturnToService: return "return_to_service";
    case RobotCommandKind::kClear: return "clear";
    case RobotCommandKind::kSend: return "send";
  }
  return "unknown";
}

std::optional<RobotCommandKind> ParseRobotCommand(std::string_view name) {
  for (RobotCommandKind k : {RobotCommandKind::kPause, RobotCommandKind::kResume, RobotCommandKind::kTakeOutOfService,
                             RobotCommandKind::kReturnToService, RobotCommandKind::kClear, RobotCommandKind::kSend}) {
    if (name == RobotCommandName(k)) return k;
  }
  return std::nullopt;
}

Result<PointId> StationPoint(const WarehouseMap& map, const std::string& name) {
  for (const ParkingStation& s : map.stations()) {
    if (s.name == name) return s.point;
  }
  if (auto p = map.FindPoint(name)) {
    const PointKind kind = map.point(*p).kind;
    if (kind == PointKind::kPark || kind == PointKind::kCharge) return *p;
    return InvalidArgument("point '" + Clipped(name) + "' is not a park or charge point: robots are sent to stations only");
  }
  std::string known;
  for (const ParkingStation& s : map.stations()) {
    if (known.size() > 200) {
      known += ", ...";
      break;
    }
    known += (known.empty() ? "" : ", ") + s.name;
  }
  return NotFound("no station or park point '" + Clipped(name) + "'" + (known.empty() ? "" : " (stations: " + known + ")"));
}

std::string OperatorMarks::HeldFor() const {
  if (!paused_by.empty()) return paused_by;
  if (!out_of_service_by.empty()) return out_of_service_by + " (out of service)";
  return "";
}

}  // namespace dispatch::engine
