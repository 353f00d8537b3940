#include "engine/lifelong/lifelong_run.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <limits>
#include <map>
#include <set>

#include "engine/lifelong/lorr_check.h"
#include "engine/lifelong/lorr_output.h"
#include "lorr_files.h"

namespace dispatch::engine {
namespace {

using testing_lorr::LorrExample;
using testing_lorr::WriteProblem;

LorrProblem Load(const std::string& json) {
  auto problem = LoadLorrProblem(json);
  EXPECT_TRUE(problem.ok()) << problem.error().message;
  return std::move(problem).value();
}

LifelongRecord RunFor(const LorrProblem& problem, int steps, const std::string& strategy = "exact") {
  LifelongOptions options;
  options.steps = steps;
  options.strategy = strategy;
  auto record = RunLifelong(problem, options);
  EXPECT_TRUE(record.ok()) << record.error().message;
  return std::move(record).value();
}

LorrCheckReport Check(const LorrProblem& problem, const std::string& output) {
  auto report = CheckLorrOutput(problem, output);
  EXPECT_TRUE(report.ok()) << report.error().message;
  return report.ok() ? report.value() : LorrCheckReport{};
}

// A robot whose task ends in a dead end where an idle robot stands: pushes alone cannot get it
// in (the idle robot can only leave through the first robot's cell); the swap rule backs the
// first robot away and lets the idle one out.
//   row 0: .....
//   row 1: @@.@@      cell 7 is a dead end below cell 2; robot 0 (at cell 0) is nearer the
//                     pickup at cell 1 than robot 1 (at cell 7), so it takes the task "1,7"
TEST(LifelongRunTest, ARobotGetsIntoADeadEndAnotherRobotStandsIn) {
  const LorrProblem problem = Load(WriteProblem("deadend", {".....", "@@.@@"}, {"0", "7"}, {"1,7"}, 2, 0.5));
  const LifelongRecord record = RunFor(problem, 30);
  ASSERT_FALSE(record.events.empty());
  EXPECT_EQ(record.events[0].robot, 0);
  EXPECT_GE(record.tasks_finished, 1);
  EXPECT_EQ(record.planner_errors, 0);
  EXPECT_TRUE(Check(problem, LorrOutputJson(record, problem.grid)).ok());
}

TEST(LifelongRunTest, TasksAreRevealedInFileOrderAndWrapRound) {
  const LorrProblem problem = Load(WriteProblem("wrap", {"......"}, {"0"}, {"1,2", "3,4"}, 1, 2.0));
  const LifelongRecord record = RunFor(problem, 40);
  ASSERT_GE(record.tasks.size(), 4u);
  EXPECT_EQ(record.tasks[0].errands, (std::vector<int>{1, 2}));
  EXPECT_EQ(record.tasks[2].id, 2);
  EXPECT_EQ(record.tasks[2].errands, (std::vector<int>{1, 2}));  // task 2 is the file's task 0
  EXPECT_GE(record.tasks_finished, 3);
  // Two tasks out at once (2.0 x 1 robot): the third is revealed when the first is finished.
  EXPECT_EQ(record.tasks[1].release_step, 0);
  EXPECT_GT(record.tasks[2].release_step, 0);
  EXPECT_TRUE(Check(problem, LorrOutputJson(record, problem.grid)).ok());
}

TEST(LifelongRunTest, ThePublicRandomInstanceRunsLegallyAndTheOutputHasTheCompetitionsKeys) {
  const LorrProblem problem = Load(LorrExample("random.domain/random_32_32_20_100.json"));
  const LifelongRecord record = RunFor(problem, 100);
  EXPECT_EQ(record.planner_errors, 0);
  EXPECT_GT(record.tasks_finished, 20);
  const std::string output = LorrOutputJson(record, problem.grid);
  const auto json = nlohmann::json::parse(output);
  for (const char* key : {"actionModel", "version", "teamSize", "numTaskFinished", "makespan", "numPlannerErrors",
                          "numScheduleErrors", "numEntryTimeouts", "start", "actualPaths", "plannerPaths",
                          "plannerTimes", "errors", "actualSchedule", "plannerSchedule", "scheduleErrors", "events",
                          "tasks"}) {
    EXPECT_TRUE(json.contains(key)) << key;
  }
  EXPECT_EQ(json["actionModel"], "MAPF_T");
  EXPECT_EQ(json["start"][0], nlohmann::json::parse("[11, 8, \"E\"]"));  // cell 360
  EXPECT_EQ(json["actualPaths"][0].get<std::string>().size(), 2u * 100 - 1);
  const LorrCheckReport report = Check(problem, output);
  EXPECT_TRUE(report.ok()) << (report.problems.empty() ? "" : report.problems[0]);
  EXPECT_EQ(report.tasks_finished, record.tasks_finished);
  EXPECT_EQ(report.steps, 100);
}

// Hub labels answer the dense table's costs on a grid (whole cells: exact sums), so the same
// allocations and the same moves follow.
TEST(LifelongRunTest, HubLabelsRunTheDenseTablesRun) {
  const LorrProblem problem = Load(LorrExample("random.domain/random_32_32_20_100.json"));
  LifelongOptions options;
  options.steps = 60;
  const LifelongRecord dense = RunLifelong(problem, options).value();
  options.route_method = RouteTableMethod::kHubLabels;
  const LifelongRecord labels = RunLifelong(problem, options).value();
  EXPECT_EQ(dense.routes, "floyd");
  EXPECT_EQ(labels.routes, "hub_labels");
  EXPECT_GT(labels.tasks_finished, 5);
  EXPECT_EQ(labels.tasks_finished, dense.tasks_finished);
  EXPECT_EQ(labels.actual_actions, dense.actual_actions);
}

// Reassignment (LifelongOptions::reassign): each step the tasks no robot has opened go back to
// the pool. Some tasks change robots, none after it was opened (the checker replays the output
// and refuses an opened task taken away); without the option, or with a pool beyond its
// bound, no task ever changes robots.
TEST(LifelongRunTest, ReassignMovesOnlyTasksNotOpenedYet) {
  const LorrProblem problem = Load(LorrExample("random.domain/random_32_32_20_100.json"));
  LifelongOptions options;
  options.steps = 100;
  auto robots_per_task = [](const LifelongRecord& record) {
    std::map<int, std::set<std::size_t>> robots;
    for (std::size_t r = 0; r < record.actual_schedule.size(); ++r) {
      for (const auto& [step, task] : record.actual_schedule[r]) {
        if (task >= 0) robots[task].insert(r);
      }
    }
    std::size_t moved = 0;
    for (const auto& [task, holders] : robots) moved += holders.size() > 1 ? 1 : 0;
    return moved;
  };
  options.reassign = false;
  const LifelongRecord kept = RunLifelong(problem, options).value();
  EXPECT_EQ(robots_per_task(kept), 0u);
  options.reassign = true;
  options.reassign_max_work = 0.5;  // below any pool's work (1 robot, 1 task: 1)
  EXPECT_TRUE(RunLifelong(problem, options).value().actual_actions == kept.actual_actions);
  options.reassign_max_work = LifelongOptions{}.reassign_max_work;
  const LifelongRecord moved = RunLifelong(problem, options).value();
  EXPECT_GT(robots_per_task(moved), 0u);
  EXPECT_EQ(moved.planner_errors, 0);
  const LorrCheckReport report = Check(problem, LorrOutputJson(moved, problem.grid));
  EXPECT_TRUE(report.ok()) << (report.problems.empty() ? "" : report.problems[0]);
  EXPECT_EQ(report.tasks_finished, moved.tasks_finished);
  EXPECT_GT(moved.tasks_finished, 20);

  // A task taken by another robot while its robot keeps it (no change of its own that step).
  auto good = nlohmann::json::parse(LorrOutputJson(kept, problem.grid));
  const auto [step, task] = kept.actual_schedule[0].front();
  ASSERT_GE(task, 0);
  auto stolen = good;
  stolen["actualSchedule"][1] = std::to_string(step + 1) + ":" + std::to_string(task) + "," +
                                stolen["actualSchedule"][1].get<std::string>();
  const LorrCheckReport refused = Check(problem, stolen.dump());
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.problems[0].find("held by robots 0 and 1"), std::string::npos) << refused.problems[0];
}

// Reassignment spends a credit of work (LifelongOptions::reassign_work_per_step): with none
// it never happens and the run is the run without reassignment; with a credit as large as any
// pool's work it happens in every step; with a small one in some steps only, and the output is
// still valid. Bad values are refused.
TEST(LifelongRunTest, ReassignmentSpendsACreditOfWork) {
  const LorrProblem problem = Load(LorrExample("random.domain/random_32_32_20_100.json"));
  LifelongOptions options;
  options.steps = 100;
  options.reassign = false;
  const LifelongRecord kept = RunLifelong(problem, options).value();
  options.reassign = true;
  options.reassign_work_per_step = 0.0;
  const LifelongRecord none = RunLifelong(problem, options).value();
  EXPECT_EQ(none.reassign_steps, 0);
  EXPECT_TRUE(none.actual_actions == kept.actual_actions);
  options.reassign_work_per_step = options.reassign_max_work;  // 100 robots, 150 tasks: at most 1.5e6
  EXPECT_EQ(RunLifelong(problem, options).value().reassign_steps, 100);
  options.reassign_work_per_step = 1e5;
  const LifelongRecord some = RunLifelong(problem, options).value();
  EXPECT_GT(some.reassign_steps, 0);
  EXPECT_LT(some.reassign_steps, 100);
  const LorrCheckReport report = Check(problem, LorrOutputJson(some, problem.grid));
  EXPECT_TRUE(report.ok()) << (report.problems.empty() ? "" : report.problems[0]);
  EXPECT_EQ(report.tasks_finished, some.tasks_finished);

  for (double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    options.reassign_work_per_step = bad;
    auto refused = RunLifelong(problem, options);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("reassign_work_per_step"), std::string::npos) << refused.error().message;
  }
  options.reassign_work_per_step = 1e7;
  options.reassign_max_work = -1.0;
  EXPECT_FALSE(RunLifelong(problem, options).ok());
}

// The checker finds what a run that broke the rules would write.
TEST(LifelongRunTest, TheCheckerFindsBrokenOutputs) {
  const LorrProblem problem = Load(WriteProblem("tamper", {".....", "@@.@@"}, {"0", "4"}, {"2,7", "1,3"}, 2, 1.0));
  const LifelongRecord record = RunFor(problem, 30);
  ASSERT_GE(record.tasks_finished, 1);
  const auto good = nlohmann::json::parse(LorrOutputJson(record, problem.grid));
  ASSERT_TRUE(Check(problem, good.dump()).ok());

  auto claims_more = good;
  claims_more["numTaskFinished"] = record.tasks_finished + 1;
  EXPECT_FALSE(Check(problem, claims_more.dump()).ok());

  auto lost_event = good;
  lost_event["events"].erase(lost_event["events"].begin());
  EXPECT_FALSE(Check(problem, lost_event.dump()).ok());

  auto into_wall = good;  // robot 0 starts facing east at cell 0: turn south and drive into '@'
  std::string path = into_wall["actualPaths"][0];
  path[0] = 'R';
  path[2] = 'F';
  into_wall["actualPaths"][0] = path;
  EXPECT_FALSE(Check(problem, into_wall.dump()).ok());

  auto other_errands = good;
  other_errands["tasks"][0][2] = nlohmann::json::parse("[0, 2, 0, 3]");
  EXPECT_FALSE(Check(problem, other_errands.dump()).ok());

  auto moved_start = good;
  moved_start["start"][0] = nlohmann::json::parse("[0, 1, \"E\"]");
  EXPECT_FALSE(Check(problem, moved_start.dump()).ok());

  EXPECT_FALSE(CheckLorrOutput(problem, "[1, 2]").ok());
  auto wrong_type = good;  // a word where a row belongs: refused, not thrown
  wrong_type["tasks"][0][2][0] = "row";
  auto refused = CheckLorrOutput(problem, wrong_type.dump());
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("wrong type"), std::string::npos) << refused.error().message;
}

TEST(LifelongRunTest, BadOptionsAreRefused) {
  const LorrProblem problem = Load(WriteProblem("options", {"...."}, {"0"}, {"1,2"}, 1));
  LifelongOptions options;
  options.strategy = "nearest";
  auto unknown = RunLifelong(problem, options);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("unknown strategy 'nearest'"), std::string::npos);
  options = {};
  options.steps = -1;
  EXPECT_FALSE(RunLifelong(problem, options).ok());
}

}  // namespace
}  // namespace dispatch::engine
