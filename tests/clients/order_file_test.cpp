#include "clients/order_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "clients/order_text.h"

namespace dispatch::clients {
namespace {

const std::string kShared = DISPATCH_SHARED_DIR;

TEST(OrderFileTest, SeedTable1AsItIs) {
  auto orders = LoadOrderFile(kShared + "/scenarios/chu2024-table1.csv");
  ASSERT_TRUE(orders.ok()) << orders.error;
  ASSERT_EQ(orders.orders.size(), 6u);
  const v1::SubmitOrderRequest& t1 = orders.orders[0];
  EXPECT_EQ(t1.client_order_id(), "chu2024-table1-1");
  EXPECT_TRUE(t1.formation());
  ASSERT_EQ(t1.picks_size(), 2);
  EXPECT_EQ(t1.picks(0).position().x(), 19.0);
  EXPECT_EQ(t1.picks(0).position().y(), 17.0);
  EXPECT_EQ(t1.picks(1).position().x(), 20.5);
  EXPECT_EQ(t1.drop().position().x(), 6.5);
  EXPECT_EQ(t1.drop().position().y(), 2.75);
  EXPECT_FALSE(t1.has_work_time());  // the server's default
  EXPECT_FALSE(orders.orders[3].formation());
  EXPECT_EQ(orders.orders[3].picks_size(), 3);
}

TEST(OrderFileTest, SameFileGivesTheSameClientIds) {
  auto a = LoadOrderFile(kShared + "/scenarios/chu2024-table2.csv");
  auto b = LoadOrderFile(kShared + "/scenarios/chu2024-table2.csv", "x-");
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a.orders.size(), b.orders.size());
  EXPECT_EQ(a.orders[7].client_order_id(), "chu2024-table2-8");
  EXPECT_EQ(b.orders[7].client_order_id(), "x-8");
}

TEST(OrderFileTest, JsonOrdersWithNamesAndCoordinates) {
  auto orders = ParseOrderText(R"([
      {"client_order_id": "A-1", "priority": 2, "picks": [{"x": 19, "y": 17}, "K2-4-3S"],
       "drop": {"point": "D-T3", "heading": -1.5}, "formation": true, "work_time": 3, "release_time": 30},
      {"picks": ["P1"], "drop": {"x": 6.5, "y": 2.75}}])",
                               true, "file-");
  ASSERT_TRUE(orders.ok()) << orders.error;
  ASSERT_EQ(orders.orders.size(), 2u);
  const auto& a = orders.orders[0];
  EXPECT_EQ(a.client_order_id(), "A-1");
  EXPECT_EQ(a.priority(), 2);
  EXPECT_TRUE(a.formation());
  EXPECT_EQ(a.work_time(), 3.0);
  EXPECT_EQ(a.release_time(), 30.0);
  EXPECT_EQ(a.picks(1).point_name(), "K2-4-3S");
  EXPECT_EQ(a.drop().point_name(), "D-T3");
  EXPECT_EQ(a.drop().heading(), -1.5);
  EXPECT_FALSE(a.picks(0).has_heading());
  EXPECT_EQ(orders.orders[1].client_order_id(), "file-2");
  auto single = ParseOrderText(R"({"picks": ["P1"], "drop": "D1"})", true, "s-");
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single.orders.size(), 1u);
}

TEST(OrderFileTest, BadFilesNameTheProblem) {
  struct Case {
    std::string text;
    bool json;
    std::string expect;
  };
  const Case cases[] = {
      {"[{\"picks\": [], \"drop\": \"D1\"}]", true, "order 1.picks"},
      {"[{\"picks\": [\"P1\"]}]", true, "order 1.drop: missing"},
      {"[{\"picks\": [{\"x\": 1}], \"drop\": \"D1\"}]", true, "order 1.picks[0].y"},
      {"[{\"picks\": [{\"x\": 1, \"y\": 2, \"heading\": \"north\"}], \"drop\": \"D1\"}]", true,
       "order 1.picks[0].heading: must be a finite number"},
      {"[{\"picks\": [\"P1\"], \"drop\": \"D1\", \"colour\": 3}]", true, "unknown field 'colour'"},
      {"[{\"picks\": [\"P1\"], \"drop\": \"D1\", \"priority\": \"high\"}]", true, "priority"},
      {"[{\"picks\": [\"P1\"], \"drop\": \"D1\", \"work_time\": -1}]", true, "work_time"},
      {"{not json", true, "bad JSON"},
      {"[{\"picks\": [\"P1\"], \"drop\": \"D1\", \"drop\": \"D2\"}]", true, "the key 'drop' appears twice"},
      {"[]", true, "no orders"},
      {"task,formation,picks,drop\n1,2,1 1,2 2\n", false, "line 2"},
      {"task,formation,picks\n", false, "drop"},
  };
  for (const Case& c : cases) {
    auto r = ParseOrderText(c.text, c.json, "p-");
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_NE(r.error.find(c.expect), std::string::npos)
        << c.text << " -> " << r.error;
  }
  auto missing = LoadOrderFile("/nonexistent/orders.csv");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error.find("/nonexistent/orders.csv"), std::string::npos);
}

TEST(OrderFileTest, StopArguments) {
  EXPECT_EQ(ParseStopArgument("19 17").position().x(), 19.0);
  EXPECT_EQ(ParseStopArgument("6.5,2.75").position().y(), 2.75);
  EXPECT_EQ(ParseStopArgument("K2-4-3S").point_name(), "K2-4-3S");
  EXPECT_EQ(ParseStopArgument("19 17 3").point_name(), "19 17 3");
}

TEST(OrderTextTest, StatesRoundTripAndTables) {
  for (const char* name : {"accepted", "assigned", "in_progress", "completed", "cancelled", "failed"}) {
    auto s = ParseStateName(name);
    ASSERT_TRUE(s.has_value()) << name;
    EXPECT_STREQ(StateName(*s), name);
  }
  EXPECT_FALSE(ParseStateName("done").has_value());
  v1::Order o;
  o.set_id("o7");
  o.set_client_order_id("c7");
  o.set_state(v1::ORDER_STATE_COMPLETED);
  o.add_robot_ids("R5");
  o.add_robot_ids("R6");
  o.set_created_time(1.0);
  o.set_finished_time(59.5);
  o.set_distance(42.25);
  const std::string row = OrderTableRow(o);
  EXPECT_NE(row.find("42.2"), std::string::npos) << row;  // the distance column
  EXPECT_NE(row.find("completed"), std::string::npos);
  EXPECT_NE(row.find("R5 R6"), std::string::npos);
  EXPECT_NE(row.find("58.50"), std::string::npos);
  v1::OrderEvent e;
  e.set_event_id(3);
  e.set_order_id("o7");
  e.set_type(v1::ORDER_EVENT_TYPE_STATE_CHANGED);
  e.set_previous_state(v1::ORDER_STATE_ASSIGNED);
  e.set_state(v1::ORDER_STATE_IN_PROGRESS);
  EXPECT_NE(DescribeEvent(e).find("assigned -> in_progress"), std::string::npos);
  EXPECT_NE(NewClientId(), NewClientId());
}

}  // namespace
}  // namespace dispatch::clients
