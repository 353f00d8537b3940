#include "engine/allocation/allocation_config.h"

#include <cmath>
#include <string>

namespace dispatch::engine {

Status ValidateAllocationConfig(const AllocationConfig& config) {
  auto non_negative = [](const char* name, double v) -> Status {
    if (!std::isfinite(v) || v < 0.0) {
      return InvalidArgument(std::string("allocation config: ") + name +
                             " must be finite and >= 0, got " + std::to_string(v));
    }
    return Ok{};
  };
  auto positive = [](const char* name, double v) -> Status {
    if (!std::isfinite(v) || v <= 0.0) {
      return InvalidArgument(std::string("allocation config: ") + name +
                             " must be finite and > 0, got " + std::to_string(v));
    }
    return Ok{};
  };
  for (Status s : {non_negative("alpha", config.alpha), non_negative("beta", config.beta),
                   non_negative("zeta", config.zeta), positive("sample_step h", config.sample_step),
                   positive("speed v", config.speed), non_negative("hold_seconds", config.hold_seconds),
                   positive("traffic bucket_seconds", config.traffic.bucket_seconds),
                   positive("traffic zone_cell_size", config.traffic.zone_cell_size),
                   positive("heat_period", config.heat_period)}) {
    if (!s.ok()) return s;
  }
  for (Status s : {positive("windows body_length", config.windows.body_length),
                   non_negative("windows headway_s", config.windows.headway_s),
                   non_negative("turn_time", config.turn_time)}) {
    if (!s.ok()) return s;
  }
  if (config.work_time_override) {
    if (Status s = non_negative("work_time_override", *config.work_time_override); !s.ok()) {
      return s;
    }
  }
  if (config.drop_time) {
    if (Status s = non_negative("drop_time", *config.drop_time); !s.ok()) return s;
  }
  return Ok{};
}

const char* PlannerName(PlannerKind planner) {
  switch (planner) {
    case PlannerKind::kRules: return "rules";
    case PlannerKind::kTimeWindows: return "time-windows";
    case PlannerKind::kConflictElimination: return "conflict-elimination";
  }
  return "?";
}

std::optional<PlannerKind> ParsePlanner(std::string_view name) {
  for (PlannerKind p : {PlannerKind::kRules, PlannerKind::kTimeWindows, PlannerKind::kConflictElimination}) {
    if (name == PlannerName(p)) return p;
  }
  return std::nullopt;
}

const char* RoutingName(RoutingKind routing) {
  switch (routing) {
    case RoutingKind::kFloyd: return "floyd";
    case RoutingKind::kHeat: return "heat";
  }
  return "?";
}

std::optional<RoutingKind> ParseRouting(std::string_view name) {
  for (RoutingKind r : {RoutingKind::kFloyd, RoutingKind::kHeat}) {
    if (name == RoutingName(r)) return r;
  }
  return std::nullopt;
}

std::vector<std::string> RoutingNames() { return {RoutingName(RoutingKind::kFloyd), RoutingName(RoutingKind::kHeat)}; }

std::vector<std::string> PlannerNames() {
  return {PlannerName(PlannerKind::kRules), PlannerName(PlannerKind::kTimeWindows),
          PlannerName(PlannerKind::kConflictElimination)};
}

}  // namespace dispatch::engine
