// The competition's output JSON for a lifelong run (issue 19 §2), with the keys and formats the
// LoRR 2024 start kit's simulator writes (v2.1.2), so that its tools (PlanViz) show the run:
//   actionModel "MAPF_T", version "2024 LoRR", teamSize, numTaskFinished, makespan,
//   numPlannerErrors, numScheduleErrors, numEntryTimeouts,
//   start [[row, col, "E"], ...], actualPaths / plannerPaths ["F,R,W,...", ...],
//   plannerTimes [s, ...], errors [[robot, other, step, message], ...],
//   actualSchedule / plannerSchedule ["step:task,step:task", ...] (entries where the task
//   changes, -1 = none), scheduleErrors [], events [[step, robot, task, errands done], ...],
//   tasks [[id, release step, [row, col, row, col, ...]], ...] (the revealed ones).
#pragma once

#include <string>

#include "engine/lifelong/lifelong_run.h"

namespace dispatch::engine {

// The JSON text (indented by 4, as the start kit writes it).
std::string LorrOutputJson(const LifelongRecord& record, const LorrGrid& grid);

}  // namespace dispatch::engine
