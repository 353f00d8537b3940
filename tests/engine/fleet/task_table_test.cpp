#include "engine/fleet/task_table.h"

#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>

#include "engine/map/chu2024_floor.h"

namespace dispatch::engine {
namespace {

std::string ReadShared(const std::string& relative) {
  std::ifstream in(std::string(DISPATCH_SHARED_DIR) + "/" + relative);
  EXPECT_TRUE(in.good()) << relative;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

Eigen::Vector2d Xy(const StopSpec& stop) { return std::get<Eigen::Vector2d>(stop); }

TEST(TaskTableTest, ParsesSeedTable1) {
  const auto orders = ParseTaskTable(ReadShared("scenarios/chu2024-table1.csv"));
  ASSERT_TRUE(orders.ok()) << orders.error().message;
  ASSERT_EQ(orders->size(), 6u);
  const OrderRequest& t3 = (*orders)[2];
  EXPECT_EQ(t3.id, "3");
  EXPECT_TRUE(t3.formation);
  ASSERT_EQ(t3.picks.size(), 3u);
  EXPECT_EQ(Xy(t3.picks[0]), Eigen::Vector2d(4, 5));
  EXPECT_EQ(Xy(t3.picks[1]), Eigen::Vector2d(14, 16.5));
  EXPECT_EQ(Xy(t3.picks[2]), Eigen::Vector2d(30.5, 5));
  EXPECT_EQ(Xy(t3.drop), Eigen::Vector2d(2.25, 6.5));
  EXPECT_FALSE((*orders)[5].formation);
  EXPECT_FALSE(t3.release_time.has_value());
}

// Every task of both seed tables resolves onto the Chu2024 floor, exactly (distance 0).
TEST(TaskTableTest, EverySeedTaskResolvesOnTheChu2024Floor) {
  const auto map = BuildChu2024Floor().value();
  for (const char* file : {"scenarios/chu2024-table1.csv", "scenarios/chu2024-table2.csv"}) {
    const auto orders = ParseTaskTable(ReadShared(file));
    ASSERT_TRUE(orders.ok()) << file << ": " << orders.error().message;
    EXPECT_EQ(orders->size(), std::string(file).find("table1") != std::string::npos ? 6u : 8u);
    for (const OrderRequest& request : *orders) {
      const Result<Order> order = ResolveOrder(map, request);
      ASSERT_TRUE(order.ok()) << file << " task " << request.id << ": " << order.error().message;
      ASSERT_EQ(order->picks.size(), request.picks.size());
      for (std::size_t i = 0; i < request.picks.size(); ++i) {
        EXPECT_EQ(map.point(order->picks[i]).position, Xy(request.picks[i]));
      }
      EXPECT_EQ(map.point(order->drop).position, Xy(request.drop));
    }
  }
}

TEST(TaskTableTest, OptionalReleaseColumnAnyOrderCrlfAndBlankLines) {
  const auto orders = ParseTaskTable(
      "# comment\r\n\r\n  drop , task,picks,formation,release\r\n"
      "6.5 2.75,A,19 17 ; 20.5  10.5,1,12.5\r\n"
      "  # indented comment\n"
      "11.5 2.75,B,10.5 13,0,\n");
  ASSERT_TRUE(orders.ok()) << orders.error().message;
  ASSERT_EQ(orders->size(), 2u);
  EXPECT_EQ((*orders)[0].id, "A");
  EXPECT_TRUE((*orders)[0].formation);
  EXPECT_EQ((*orders)[0].release_time, 12.5);
  EXPECT_EQ(Xy((*orders)[0].picks[1]), Eigen::Vector2d(20.5, 10.5));
  EXPECT_EQ(Xy((*orders)[0].drop), Eigen::Vector2d(6.5, 2.75));
  EXPECT_FALSE((*orders)[1].release_time.has_value());
}

struct Malformed {
  const char* text;
  const char* expected;  // a fragment the message must contain
};

class MalformedTableTest : public ::testing::TestWithParam<Malformed> {};

TEST_P(MalformedTableTest, NamesLineAndColumn) {
  const auto orders = ParseTaskTable(GetParam().text);
  ASSERT_FALSE(orders.ok()) << GetParam().text;
  EXPECT_EQ(orders.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(orders.error().message.find(GetParam().expected), std::string::npos)
      << orders.error().message;
}


INSTANTIATE_TEST_SUITE_P(
    Cases, MalformedTableTest,
    ::testing::Values(
        Malformed{"", "no header"},
        Malformed{"# only comments\n", "no header"},
        Malformed{"task,formation,picks\n", "line 1: header lacks column 'drop'"},
        Malformed{"task,formation,picks,drop,colour\n",
                  "line 1, column 5: unknown column 'colour'"},
        Malformed{"task,task,picks,drop\n",
                  "line 1, column 2: duplicate column 'task'"},
        Malformed{"# c\ntask,formation,picks,drop\n1,0,19 17\n",
                  "line 3: expected 4 fields, got 3"},
        Malformed{"# c\ntask,formation,picks,drop\n1,2,19 17,6.5 2.75\n",
                  "line 3, column 2 (formation): expected 0 or 1, got '2'"},
        Malformed{"# c\ntask,formation,picks,drop\n\n1,0,19 17;20.5,6.5 2.75\n",
                  "line 4, column 3 (picks): pick 2 is not 'x y': '20.5'"},
        Malformed{"# c\ntask,formation,picks,drop\n1,0,,6.5 2.75\n",
                  "line 3, column 3 (picks): no pick points"},
        Malformed{"# c\ntask,formation,picks,drop\n1,0,19 17,6.5 x\n",
                  "line 3, column 4 (drop): expected 'x y', got '6.5 x'"},
        Malformed{"# c\ntask,formation,picks,drop\n1,0,19 17,6.5 2.75 1\n",
                  "line 3, column 4 (drop)"},
        Malformed{"# c\ntask,formation,picks,drop\n,0,19 17,6.5 2.75\n",
                  "line 3, column 1 (task): empty task id"},
        Malformed{"# c\ntask,formation,picks,drop\n1,0,19 17,6.5 2.75\n1,0,19 17,6.5 2.75\n",
                  "line 4, column 1 (task): duplicate task id '1'"},
        Malformed{"task,formation,picks,drop,release\n1,0,19 17,6.5 2.75,-3\n",
                  "line 2, column 5 (release): expected seconds >= 0, got '-3'"}));

}  // namespace
}  // namespace dispatch::engine
