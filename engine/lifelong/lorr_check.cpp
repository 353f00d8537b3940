#include "engine/lifelong/lorr_check.h"

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <tuple>

#include "engine/lifelong/grid_motion.h"

namespace dispatch::engine {
namespace {

using Json = nlohmann::json;
constexpr std::size_t kMaxProblems = 20;

// CheckLorrOutput's work; nlohmann's type errors (a string where a cell belongs) escape it.
Result<LorrCheckReport> Replay(const LorrProblem& problem, std::string_view output_json);

class Findings {
 public:
  explicit Findings(LorrCheckReport& report) : report_(report) {}
  void Add(std::string what) {
    if (report_.problems.size() < kMaxProblems) report_.problems.push_back(std::move(what));
    ++count_;
  }
  void Close() {
    if (count_ > kMaxProblems) report_.problems.push_back("... and " + std::to_string(count_ - kMaxProblems) + " more");
  }

 private:
  LorrCheckReport& report_;
  std::size_t count_ = 0;
};

Result<std::vector<std::string>> StringList(const Json& json, const char* key) {
  if (!json.contains(key) || !json[key].is_array()) return InvalidArgument(std::string("\"") + key + "\" must be an array");
  std::vector<std::string> out;
  for (const Json& item : json[key]) {
    if (!item.is_string()) return InvalidArgument(std::string("\"") + key + "\" must hold strings");
    out.push_back(item.get<std::string>());
  }
  return out;
}

// "1:5,40:-1" -> {(1, 5), (40, -1)}.
Result<std::vector<std::pair<int, int>>> ParseSchedule(const std::string& text, std::size_t robot) {
  std::vector<std::pair<int, int>> out;
  for (std::size_t at = 0; at < text.size();) {
    std::size_t comma = text.find(',', at);
    if (comma == std::string::npos) comma = text.size();
    const std::string entry = text.substr(at, comma - at);
    const std::size_t colon = entry.find(':');
    try {
      if (colon == std::string::npos) throw std::invalid_argument("no colon");
      out.emplace_back(std::stoi(entry.substr(0, colon)), std::stoi(entry.substr(colon + 1)));
    } catch (const std::exception&) {
      return InvalidArgument("actualSchedule of robot " + std::to_string(robot) + ": bad entry '" + entry + "'");
    }
    at = comma + 1;
  }
  return out;
}

}  // namespace

Result<LorrCheckReport> CheckLorrOutput(const LorrProblem& problem, std::string_view output_json) {
  try {
    return Replay(problem, output_json);
  } catch (const Json::exception& e) {  // a value of the wrong type where a number belongs
    return InvalidArgument(std::string("the output has a value of the wrong type: ") + e.what());
  }
}

namespace {

Result<LorrCheckReport> Replay(const LorrProblem& problem, std::string_view output_json) {
  const Json out = Json::parse(output_json, nullptr, /*allow_exceptions=*/false);
  if (out.is_discarded() || !out.is_object()) return InvalidArgument("the output is not a JSON object");
  for (const char* key : {"teamSize", "numTaskFinished"}) {
    if (!out.contains(key) || !out[key].is_number_integer()) return InvalidArgument(std::string("\"") + key + "\" must be an integer");
  }
  for (const char* key : {"start", "events", "tasks"}) {
    if (!out.contains(key) || !out[key].is_array()) return InvalidArgument(std::string("\"") + key + "\" must be an array");
  }
  Result<std::vector<std::string>> paths = StringList(out, "actualPaths");
  if (!paths) return paths.error();
  Result<std::vector<std::string>> schedules = StringList(out, "actualSchedule");
  if (!schedules) return schedules.error();

  LorrCheckReport report;
  Findings findings(report);
  const LorrGrid& grid = problem.grid;
  const std::size_t n = problem.starts.size();
  if (out["teamSize"].get<long>() != static_cast<long>(n) || out["start"].size() != n || paths->size() != n ||
      schedules->size() != n) {
    return InvalidArgument("the output is for " + std::to_string(out["teamSize"].get<long>()) + " robots (" +
                           std::to_string(out["start"].size()) + " starts, " + std::to_string(paths->size()) +
                           " paths, " + std::to_string(schedules->size()) + " schedules), the problem has " +
                           std::to_string(n));
  }
  std::vector<GridPose> poses(n);
  for (std::size_t r = 0; r < n; ++r) {
    const Json& s = out["start"][r];
    const int cell = problem.starts[r];
    if (!s.is_array() || s.size() != 3 || s[0] != cell / grid.width() || s[1] != cell % grid.width() || s[2] != "E") {
      findings.Add("robot " + std::to_string(r) + " starts at " + s.dump() + ", the problem says [" +
                   std::to_string(cell / grid.width()) + "," + std::to_string(cell % grid.width()) + ",\"E\"]");
    }
    poses[r] = {cell, 0};
  }
  // Actions per robot per step.
  std::vector<std::vector<GridAction>> actions(n);
  for (std::size_t r = 0; r < n; ++r) {
    const std::string& text = (*paths)[r];
    for (std::size_t i = 0; i < text.size(); i += 2) {
      const char a = text[i];
      if ((a != 'F' && a != 'R' && a != 'C' && a != 'W' && a != 'T') || (i + 1 < text.size() && text[i + 1] != ',')) {
        return InvalidArgument("actualPaths of robot " + std::to_string(r) + ": bad action at character " + std::to_string(i));
      }
      actions[r].push_back(a == 'T' ? GridAction::kWait : static_cast<GridAction>(a));
    }
    if (actions[r].size() != actions[0].size()) {
      return InvalidArgument("actualPaths of robot " + std::to_string(r) + " has " + std::to_string(actions[r].size()) +
                             " steps, robot 0's has " + std::to_string(actions[0].size()));
    }
  }
  report.steps = static_cast<int>(actions[0].size());

  // Revealed tasks.
  std::map<int, std::vector<int>> errands_of;
  for (const Json& t : out["tasks"]) {
    if (!t.is_array() || t.size() != 3 || !t[0].is_number_integer() || !t[2].is_array() || t[2].size() % 2 != 0) {
      return InvalidArgument("bad task entry " + t.dump());
    }
    const int id = t[0].get<int>();
    std::vector<int> cells;
    for (std::size_t k = 0; k + 1 < t[2].size(); k += 2) cells.push_back(t[2][k].get<int>() * grid.width() + t[2][k + 1].get<int>());
    if (id < 0 || problem.tasks.empty() ||
        problem.tasks[static_cast<std::size_t>(id) % problem.tasks.size()].errands != cells) {
      findings.Add("task " + std::to_string(id) + " has errands " + t[2].dump() + ", not the task file's");
    }
    errands_of[id] = std::move(cells);
  }
  // Schedule changes by step: (step, robot, task).
  std::vector<std::tuple<int, int, int>> changes;
  for (std::size_t r = 0; r < n; ++r) {
    Result<std::vector<std::pair<int, int>>> entries = ParseSchedule((*schedules)[r], r);
    if (!entries) return entries.error();
    for (const auto& [step, task] : *entries) changes.emplace_back(step, static_cast<int>(r), task);
  }
  std::stable_sort(changes.begin(), changes.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  // The robots whose schedule changes at a step: one schedule may move a task no robot has
  // opened from one of them to another (the competition lets a scheduler do so).
  std::set<std::pair<int, int>> changing;  // (step, robot)
  for (const auto& [step, robot, task] : changes) changing.emplace(step, robot);
  std::set<std::tuple<int, int, int, int>> claimed;
  for (const Json& e : out["events"]) {
    if (!e.is_array() || e.size() != 4) return InvalidArgument("bad event entry " + e.dump());
    claimed.emplace(e[0].get<int>(), e[1].get<int>(), e[2].get<int>(), e[3].get<int>());
  }

  // The replay.
  std::vector<int> held(n, -1);
  std::map<int, int> holder;  // task -> robot
  std::map<int, int> done;    // task -> errands done
  std::set<std::tuple<int, int, int, int>> seen;
  std::size_t next_change = 0;
  auto apply_changes = [&](int step, bool releases) {
    for (std::size_t k = next_change; k < changes.size() && std::get<0>(changes[k]) <= step; ++k) {
      const auto [s, robot, task] = changes[k];
      const auto r = static_cast<std::size_t>(robot);
      if ((task == -1) != releases) continue;
      if (held[r] == task) continue;
      if (held[r] != -1 && done[held[r]] > 0 && done[held[r]] < static_cast<int>(errands_of[held[r]].size())) {
        findings.Add("step " + std::to_string(s) + ": robot " + std::to_string(robot) + " drops opened task " +
                     std::to_string(held[r]));
      }
      if (held[r] != -1) holder.erase(held[r]);
      if (task != -1) {
        if (!errands_of.count(task)) findings.Add("step " + std::to_string(s) + ": robot " + std::to_string(robot) + " takes unrevealed task " + std::to_string(task));
        if (auto h = holder.find(task); h != holder.end()) {
          const int other = h->second;
          if (done[task] == 0 && changing.count({s, other})) {
            held[static_cast<std::size_t>(other)] = -1;  // moved in the same schedule
          } else {
            findings.Add("step " + std::to_string(s) + ": task " + std::to_string(task) + " held by robots " +
                         std::to_string(other) + " and " + std::to_string(robot));
          }
        }
        holder[task] = robot;
      }
      held[r] = task;
    }
    if (releases) {
      while (next_change < changes.size() && std::get<0>(changes[next_change]) <= step) ++next_change;
    }
  };
  apply_changes(0, false);
  apply_changes(0, true);
  for (int s = 0; s < report.steps; ++s) {
    std::vector<GridAction> step(n);
    for (std::size_t r = 0; r < n; ++r) step[r] = actions[r][static_cast<std::size_t>(s)];
    for (const StepViolation& v : CheckJointStep(grid, poses, step)) findings.Add("step " + std::to_string(s + 1) + ": " + v.what);
    for (std::size_t r = 0; r < n; ++r) poses[r] = Apply(grid, poses[r], step[r]);
    const int t = s + 1;
    apply_changes(t, false);
    for (std::size_t r = 0; r < n; ++r) {
      const int task = held[r];
      if (task == -1 || !errands_of.count(task)) continue;
      const std::vector<int>& errands = errands_of[task];
      int& progress = done[task];
      if (progress < static_cast<int>(errands.size()) && poses[r].cell == errands[static_cast<std::size_t>(progress)]) {
        ++progress;
        seen.emplace(t, static_cast<int>(r), task, progress);
        if (progress == static_cast<int>(errands.size())) ++report.tasks_finished;
      }
    }
    apply_changes(t, true);
  }
  for (const auto& e : claimed) {
    if (!seen.count(e)) {
      findings.Add("event [" + std::to_string(std::get<0>(e)) + "," + std::to_string(std::get<1>(e)) + "," +
                   std::to_string(std::get<2>(e)) + "," + std::to_string(std::get<3>(e)) + "] did not happen in the replay");
    }
  }
  for (const auto& e : seen) {
    if (!claimed.count(e)) {
      findings.Add("the replay sees robot " + std::to_string(std::get<1>(e)) + " do errand " + std::to_string(std::get<3>(e)) +
                   " of task " + std::to_string(std::get<2>(e)) + " at step " + std::to_string(std::get<0>(e)) +
                   ", the events do not say so");
    }
  }
  if (out["numTaskFinished"].get<int>() != report.tasks_finished) {
    findings.Add("numTaskFinished is " + std::to_string(out["numTaskFinished"].get<int>()) + ", the replay finishes " +
                 std::to_string(report.tasks_finished));
  }
  findings.Close();
  return report;
}

}  // namespace

}  // namespace dispatch::engine
