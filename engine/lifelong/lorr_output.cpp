#include "engine/lifelong/lorr_output.h"

#include <nlohmann/json.hpp>

namespace dispatch::engine {
namespace {

std::string Letters(const std::string& actions) {
  std::string out;
  out.reserve(actions.size() * 2);
  for (char a : actions) {
    if (!out.empty()) out += ',';
    out += a;
  }
  return out;
}

std::string Schedule(const std::vector<std::pair<int, int>>& entries) {
  std::string out;
  for (const auto& [step, task] : entries) {
    if (!out.empty()) out += ',';
    out += std::to_string(step) + ":" + std::to_string(task);
  }
  return out;
}

}  // namespace

std::string LorrOutputJson(const LifelongRecord& record, const LorrGrid& grid) {
  using Json = nlohmann::ordered_json;
  Json out;
  out["actionModel"] = "MAPF_T";
  out["version"] = "2024 LoRR";
  out["teamSize"] = record.team_size;
  out["numTaskFinished"] = record.tasks_finished;
  out["makespan"] = record.makespan;
  out["numPlannerErrors"] = record.planner_errors;
  out["numScheduleErrors"] = record.schedule_errors;
  out["numEntryTimeouts"] = record.entry_timeouts;
  Json start = Json::array();
  for (const GridPose& pose : record.starts) {
    start.push_back(Json::array({pose.cell / grid.width(), pose.cell % grid.width(), DirectionName(pose.direction)}));
  }
  out["start"] = std::move(start);
  Json actual = Json::array();
  for (const std::string& actions : record.actual_actions) actual.push_back(Letters(actions));
  out["actualPaths"] = std::move(actual);
  Json planned = Json::array();
  for (const std::string& actions : record.planner_actions) planned.push_back(Letters(actions));
  out["plannerPaths"] = std::move(planned);
  out["plannerTimes"] = record.planner_seconds;
  Json errors = Json::array();
  for (const LifelongError& e : record.errors) errors.push_back(Json::array({e.robot, e.other, e.step, e.what}));
  out["errors"] = std::move(errors);
  Json actual_schedule = Json::array();
  for (const auto& entries : record.actual_schedule) actual_schedule.push_back(Schedule(entries));
  out["actualSchedule"] = std::move(actual_schedule);
  Json planner_schedule = Json::array();
  for (const auto& entries : record.planner_schedule) planner_schedule.push_back(Schedule(entries));
  out["plannerSchedule"] = std::move(planner_schedule);
  out["scheduleErrors"] = Json::array();
  Json events = Json::array();
  for (const LifelongEvent& e : record.events) events.push_back(Json::array({e.step, e.robot, e.task, e.errands_done}));
  out["events"] = std::move(events);
  Json tasks = Json::array();
  for (const RevealedTask& task : record.tasks) {
    Json cells = Json::array();
    for (int cell : task.errands) {
      cells.push_back(cell / grid.width());
      cells.push_back(cell % grid.width());
    }
    tasks.push_back(Json::array({task.id, task.release_step, std::move(cells)}));
  }
  out["tasks"] = std::move(tasks);
  return out.dump(4);
}

}  // namespace dispatch::engine
