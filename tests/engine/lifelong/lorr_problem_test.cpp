#include "engine/lifelong/lorr_problem.h"

#include <gtest/gtest.h>

#include "lorr_files.h"

namespace dispatch::engine {
namespace {

using testing_lorr::LorrExample;
using testing_lorr::WriteProblem;

TEST(LorrProblemTest, LoadsTheMapTheRobotsAndTheTasks) {
  const std::string json = WriteProblem("load", {"....", ".@..", "...."}, {"0", "11", "3"}, {"2,8", "6,0,11"}, 2, 1.5);
  auto problem = LoadLorrProblem(json);
  ASSERT_TRUE(problem.ok()) << problem.error().message;
  EXPECT_EQ(problem->name, "load");
  EXPECT_EQ(problem->grid.height(), 3);
  EXPECT_EQ(problem->grid.width(), 4);
  EXPECT_FALSE(problem->grid.Free(5));
  EXPECT_TRUE(problem->grid.Free(6));
  EXPECT_EQ(problem->starts, (std::vector<int>{0, 11}));  // the first teamSize robots
  ASSERT_EQ(problem->tasks.size(), 2u);
  EXPECT_EQ(problem->tasks[1].id, 1);
  EXPECT_EQ(problem->tasks[1].errands, (std::vector<int>{6, 0, 11}));
  EXPECT_EQ(problem->reveal_count(), 3);
  EXPECT_EQ(problem->grid.CellOf(problem->grid.PointAt(11)), 11);
}

TEST(LorrProblemTest, BadFilesAreRefusedSayingWhere) {
  auto starts_blocked = LoadLorrProblem(WriteProblem("blocked", {"....", ".@.."}, {"5"}, {"0,1"}, 1));
  ASSERT_FALSE(starts_blocked.ok());
  EXPECT_NE(starts_blocked.error().message.find("line 3: cell 5 is blocked"), std::string::npos)
      << starts_blocked.error().message;
  auto off_grid = LoadLorrProblem(WriteProblem("off", {"...."}, {"0"}, {"0,9"}, 1));
  ASSERT_FALSE(off_grid.ok());
  EXPECT_NE(off_grid.error().message.find("cell 9 is outside the 1 x 4 grid"), std::string::npos);
  auto too_few = LoadLorrProblem(WriteProblem("few", {"...."}, {"0"}, {"0,1"}, 2));
  ASSERT_FALSE(too_few.ok());
  EXPECT_NE(too_few.error().message.find("\"teamSize\" is 2"), std::string::npos);
  auto word = LoadLorrProblem(WriteProblem("word", {"...."}, {"0"}, {"0,x"}, 1));
  ASSERT_FALSE(word.ok());
  EXPECT_NE(word.error().message.find("expected a cell id, got 'x'"), std::string::npos);
  auto missing = LoadLorrProblem(::testing::TempDir() + "/none.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kIoError);
}

TEST(LorrProblemTest, LoadsThePublicRandomInstance) {
  auto problem = LoadLorrProblem(LorrExample("random.domain/random_32_32_20_100.json"));
  ASSERT_TRUE(problem.ok()) << problem.error().message;
  EXPECT_EQ(problem->team_size(), 100);
  EXPECT_EQ(problem->tasks.size(), 100000u);
  EXPECT_EQ(problem->reveal_count(), 150);
  EXPECT_EQ(problem->starts[0], 360);
  EXPECT_EQ(problem->tasks[0].errands, (std::vector<int>{627, 871}));
}

}  // namespace
}  // namespace dispatch::engine
