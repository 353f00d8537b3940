// An independent replay of a LoRR output JSON (issue 19 §2: "a project test replays every
// output with the project's own checker"). It reads only the output and the problem, never the
// run that wrote it, and recomputes what the output claims:
//  - the starts are the problem's start cells, facing east;
//  - every step of actualPaths is a legal MAPF_T joint step (CheckJointStep: no blocked cell,
//    no vertex conflict, no swap); 'T' (a timeout step) is a wait;
//  - every revealed task's errands are the task file's entry for its id (wrapping round);
//  - actualSchedule never gives a task to two robots at once, nor takes an opened task away;
//  - the events are exactly the errands the replay sees done: a robot standing, after step s,
//    on the next errand of the task it holds then ([s, robot, task, errands done so far]);
//  - numTaskFinished is the number of tasks whose every errand was done.
// Thread-safe (pure).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "engine/lifelong/lorr_problem.h"

namespace dispatch::engine {

struct LorrCheckReport {
  int steps = 0;
  int tasks_finished = 0;          // recomputed
  std::vector<std::string> problems;  // empty: the output is valid (at most 20 kept, then a count)
  bool ok() const { return problems.empty(); }
};

// kInvalidArgument when the text is not an output JSON at all (not JSON, missing keys, wrong
// types); rule violations are LorrCheckReport::problems.
Result<LorrCheckReport> CheckLorrOutput(const LorrProblem& problem, std::string_view output_json);

}  // namespace dispatch::engine
