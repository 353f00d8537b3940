// The operator surface over HTTP against an in-process dispatchd (issue 6 §1-2): the map,
// live zone densities, intersection grant holders, Prometheus metrics, an order's remaining
// routes, and the web map's files (built in, or from --web-root).
// httplib.h comes after every header that pulls in Eigen (see STYLE.md on `_res`).
#include "tests/server/test_support.h"

#include "engine/io/map_json.h"
#include "server/dispatcher.h"
#include "server/web_assets.h"

#include <fstream>
#include <regex>

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace dispatch::server::testing {
namespace {

using nlohmann::json;

constexpr double kParkX = 3.875, kParkY = -1.25;  // park-P1 on the Chu2024 floor

class OperatorEndpointsTest : public ::testing::Test {
 protected:
  void Start(ServerConfig config) {
    auto started = DispatchServer::Start(config);
    ASSERT_TRUE(started.ok()) << started.error().message;
    server_ = std::move(started).value();
    client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->ports().http);
    client_->set_read_timeout(10, 0);
  }
  void SetUp() override {
    ServerConfig config = TestConfig(dir_.File("ops.db"));
    config.time_scale = 50;  // plans' times run fast, so a robot following one is not held long
    Start(config);
  }

  json GetJson(const std::string& path) {
    auto r = client_->Get(path);
    EXPECT_TRUE(r) << "no HTTP response to " << path;
    if (!r) return json();
    EXPECT_EQ(r->status, 200) << path << ": " << r->body;
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/json") << path;
    return json::parse(r->body);
  }

  // Submits K3-2-3N -> D-B2 and returns its id and the robot's Assignment.
  std::pair<std::string, pb::Assignment> SubmitAndAssign(FakeRobot& robot, const std::string& client_id) {
    pb::OrderService::Stub stub(ChannelTo(*server_));
    grpc::ClientContext ctx;
    pb::SubmitOrderResponse submitted;
    const grpc::Status s = stub.SubmitOrder(WithDeadline(ctx), OrderRequest(client_id, {"K3-2-3N"}, "D-B2"), &submitted);
    EXPECT_TRUE(s.ok()) << s.error_message();
    auto assignment = robot.WaitFor(pb::ServerMessage::kAssignment);
    EXPECT_TRUE(assignment) << "no assignment";
    return {submitted.order().id(), assignment ? assignment->assignment() : pb::Assignment()};
  }

  TempDir dir_;
  std::unique_ptr<DispatchServer> server_;
  std::unique_ptr<httplib::Client> client_;
};

// Reports the plan's waypoints as they are released until a Grant enters an intersection;
// returns that Grant (nullopt if none came).
std::optional<pb::Grant> DriveToFirstIntersection(FakeRobot& robot, const pb::Assignment& plan) {
  std::uint64_t released = plan.released_up_to_sequence();
  for (const auto& w : plan.waypoints()) {
    while (w.sequence() > released) {
      auto m = robot.WaitFor(pb::ServerMessage::kGrant);
      if (!m) return std::nullopt;
      released = std::max<std::uint64_t>(released, m->grant().release_up_to_sequence());
      if (m->grant().intersection_id() >= 0) return m->grant();
    }
    pb::RobotMessage reached;
    reached.mutable_waypoint_reached()->set_sequence(w.sequence());
    reached.mutable_waypoint_reached()->mutable_pose()->set_x(w.x());
    reached.mutable_waypoint_reached()->mutable_pose()->set_y(w.y());
    pb::RobotMessage report;  // the traffic layer follows robots by their state reports
    report.mutable_state_report()->mutable_pose()->set_x(w.x());
    report.mutable_state_report()->mutable_pose()->set_y(w.y());
    report.mutable_state_report()->set_state(pb::ROBOT_STATE_MOVING);
    report.mutable_state_report()->set_last_waypoint_sequence(w.sequence());
    if (!robot.Write(reached) || !robot.Write(report)) return std::nullopt;
  }
  return std::nullopt;
}

TEST_F(OperatorEndpointsTest, MapIsTheServedFloorInTheMapFormat) {
  auto r = client_->Get("/api/v1/map");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/json");
  auto parsed = engine::ParseMapJson(r->body);
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  EXPECT_EQ(parsed->name(), "chu2024");
  EXPECT_EQ(parsed->point_count(), server_->dispatcher().map().point_count());
  EXPECT_EQ(r->body, engine::WriteMapJson(server_->dispatcher().map()));
}

TEST_F(OperatorEndpointsTest, ZonesCountTheConnectedRobotsInThem) {
  const json before = GetJson("/api/v1/zones");
  ASSERT_EQ(before["zones"].size(), server_->dispatcher().map().zones().size());
  for (const auto& z : before["zones"]) {
    EXPECT_TRUE(z["robot_ids"].empty());
    EXPECT_GT(z["area"].get<double>(), 0);
    EXPECT_GE(z["polygon"].size(), 3u);
  }
  FakeRobot robot(ChannelTo(*server_), "R7");
  robot.Connect(kParkX, kParkY);
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kWelcome));
  const json after = GetJson("/api/v1/zones");
  int total = 0;
  for (const auto& z : after["zones"]) {
    total += static_cast<int>(z["robot_ids"].size());
    if (z["robot_ids"].size() == 1) {
      EXPECT_EQ(z["robot_ids"], json::array({"R7"}));
      EXPECT_DOUBLE_EQ(z["density"].get<double>(), 1.0 / z["area"].get<double>());
      // park-P1's zone: the polygon holds the robot's position.
      const auto& p = z["polygon"];
      double lo_x = 1e9, hi_x = -1e9, lo_y = 1e9, hi_y = -1e9;
      for (const auto& v : p) {
        lo_x = std::min(lo_x, v["x"].get<double>()), hi_x = std::max(hi_x, v["x"].get<double>());
        lo_y = std::min(lo_y, v["y"].get<double>()), hi_y = std::max(hi_y, v["y"].get<double>());
      }
      EXPECT_TRUE(kParkX >= lo_x && kParkX <= hi_x && kParkY >= lo_y && kParkY <= hi_y) << z.dump();
    }
  }
  EXPECT_EQ(total, 1);
}

TEST_F(OperatorEndpointsTest, IntersectionsShowWhoHoldsTheGrant) {
  const json idle = GetJson("/api/v1/intersections");
  EXPECT_TRUE(idle["control"].get<bool>());
  ASSERT_EQ(idle["intersections"].size(), server_->dispatcher().map().intersections().size());
  for (const auto& x : idle["intersections"]) {
    EXPECT_FALSE(x["inner"].empty());
    EXPECT_FALSE(x["approach"].empty());
    EXPECT_TRUE(x["holder_ids"].empty());
    EXPECT_TRUE(x["waiting_ids"].empty());
  }
  FakeRobot robot(ChannelTo(*server_), "R7");
  robot.Connect(kParkX, kParkY);
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kWelcome));
  auto [id, plan] = SubmitAndAssign(robot, "ops-x");
  auto grant = DriveToFirstIntersection(robot, plan);
  ASSERT_TRUE(grant) << "the route to K3-2-3N crosses no intersection";
  // Snapshots of robot traffic are published within 20 ms: poll until R7 shows as holder.
  json held;
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  for (bool seen = false; !seen && std::chrono::steady_clock::now() < deadline;) {
    held = GetJson("/api/v1/intersections");
    for (const auto& x : held["intersections"]) seen = seen || (x["id"] == grant->intersection_name() && !x["holder_ids"].empty());
  }
  int holders = 0;
  for (const auto& x : held["intersections"]) {
    if (x["id"] == grant->intersection_name()) {
      EXPECT_EQ(x["holder_ids"], json::array({"R7"})) << x.dump();
    }
    holders += static_cast<int>(x["holder_ids"].size());
  }
  EXPECT_EQ(holders, 1);
  // ?active=1: only the intersection R7 holds (the others are idle), the same entry.
  const json active = GetJson("/api/v1/intersections?active=1");
  ASSERT_EQ(active["intersections"].size(), 1u) << active.dump();
  EXPECT_EQ(active["intersections"][0]["id"], grant->intersection_name());
  EXPECT_EQ(active["intersections"][0]["holder_ids"], json::array({"R7"}));
  EXPECT_EQ(GetJson("/api/v1/intersections?active=0")["intersections"].size(),
            server_->dispatcher().map().intersections().size());
  auto bad = client_->Get("/api/v1/intersections?active=maybe");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("active must be"), std::string::npos) << bad->body;
}

TEST_F(OperatorEndpointsTest, OrderDetailHasEachRobotsRemainingRoute) {
  FakeRobot robot(ChannelTo(*server_), "R7");
  robot.Connect(kParkX, kParkY);
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kWelcome));
  auto [id, plan] = SubmitAndAssign(robot, "ops-route");
  ASSERT_GT(plan.waypoints_size(), 2);
  const json order = GetJson("/api/v1/orders/" + id);
  ASSERT_TRUE(order["routes"].contains("R7")) << order.dump();
  const json& route = order["routes"]["R7"]["waypoints"];
  ASSERT_FALSE(route.empty());
  EXPECT_EQ(route.back()["action"], "WAYPOINT_ACTION_DROP");
  EXPECT_EQ(order["order"]["id"], id);
  EXPECT_TRUE(order["allocation"].is_object());
  std::size_t released = 0;
  for (const auto& w : route) released += w["released"].get<bool>() ? 1 : 0;
  EXPECT_LT(released, route.size()) << "traffic control releases the route point by point";
  // Each waypoint matches the robot's plan.
  for (const auto& w : route) {
    bool found = false;
    for (const auto& p : plan.waypoints()) {
      if (std::to_string(p.sequence()) == w["sequence"].get<std::string>()) {  // uint64: a string
        found = true;
        EXPECT_DOUBLE_EQ(p.x(), w["position"]["x"].get<double>());
        EXPECT_DOUBLE_EQ(p.y(), w["position"]["y"].get<double>());
      }
    }
    EXPECT_TRUE(found) << w.dump();
  }
}

// One sample line of the text format: name{labels} value.
double MetricValue(const std::string& text, const std::string& series) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(series + " ", 0) == 0) return std::stod(line.substr(series.size() + 1));
  }
  ADD_FAILURE() << "no series " << series << " in\n" << text;
  return -1;
}

TEST_F(OperatorEndpointsTest, MetricsInPrometheusTextFormat) {
  FakeRobot robot(ChannelTo(*server_), "R7");
  robot.Connect(kParkX, kParkY);
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kWelcome));
  SubmitAndAssign(robot, "ops-metrics");
  auto r = client_->Get("/metrics");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type").rfind("text/plain; version=0.0.4", 0), 0u);
  const std::string& text = r->body;
  EXPECT_EQ(MetricValue(text, R"(dispatch_orders{state="assigned"})"), 1);
  EXPECT_EQ(MetricValue(text, R"(dispatch_orders{state="completed"})"), 0);
  EXPECT_EQ(MetricValue(text, "dispatch_robot_streams"), 1);
  EXPECT_EQ(MetricValue(text, "dispatch_allocation_seconds_count"), 1);
  EXPECT_GT(MetricValue(text, "dispatch_allocation_seconds_sum"), 0);
  EXPECT_EQ(MetricValue(text, R"(dispatch_db_write_seconds_count{op="insert_order"})"), 1);
  EXPECT_GE(MetricValue(text, R"(dispatch_db_write_seconds_count{op="transaction"})"), 1);
  // Every histogram has its +Inf bucket equal to its count.
  EXPECT_EQ(MetricValue(text, R"(dispatch_allocation_seconds_bucket{le="+Inf"})"), 1);
  for (const char* family : {"dispatch_grant_wait_seconds", "dispatch_holds_total", "dispatch_replans_total",
                             "dispatch_deadlocks_resolved_total", "dispatch_robots"}) {
    EXPECT_NE(text.find(std::string("# TYPE ") + family), std::string::npos) << family;
  }
}

TEST_F(OperatorEndpointsTest, WebMapFilesAreBuiltIn) {
  ASSERT_FALSE(BuiltInWebAssets().empty());
  auto index = client_->Get("/");
  ASSERT_TRUE(index);
  ASSERT_EQ(index->status, 200);
  EXPECT_EQ(index->get_header_value("Content-Type"), "text/html; charset=utf-8");
  EXPECT_NE(index->body.find("<html"), std::string::npos);
  for (const WebAsset& asset : BuiltInWebAssets()) {
    auto r = client_->Get(std::string(asset.path));
    ASSERT_TRUE(r) << asset.path;
    EXPECT_EQ(r->status, 200) << asset.path;
    EXPECT_EQ(r->get_header_value("Content-Type"), asset.content_type) << asset.path;
    EXPECT_EQ(r->body, asset.body) << asset.path;
    // Every file the page refers to is served.
    std::regex ref(R"((?:src|href)=["']([^"':]+)["'])");
    for (std::sregex_iterator m(r->body.begin(), r->body.end(), ref), end; m != end; ++m) {
      std::string path = (*m)[1].str();
      if (path.empty() || path[0] == '#') continue;
      if (path[0] != '/') path = "/" + path;
      auto referred = client_->Get(path);
      ASSERT_TRUE(referred) << path;
      EXPECT_EQ(referred->status, 200) << asset.path << " refers to " << path;
    }
  }
}

TEST_F(OperatorEndpointsTest, WebRootServesThePageFromAFolder) {
  server_.reset();
  const std::string root = dir_.File("web");
  std::filesystem::create_directories(root);
  std::ofstream(root + "/index.html") << "<html>from the folder</html>";
  ServerConfig config = TestConfig(dir_.File("ops2.db"));
  config.web_root = root;
  Start(config);
  auto index = client_->Get("/");
  ASSERT_TRUE(index);
  EXPECT_EQ(index->status, 200);
  EXPECT_EQ(index->body, "<html>from the folder</html>");
  auto missing = client_->Get("/app-that-is-not-there.js");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  EXPECT_EQ(GetJson("/api/v1/status")["map_name"], "chu2024");  // the API is still there
  // Issue 18 §3: nothing outside the folder, also not through a link inside it or "..".
  std::ofstream(dir_.File("secret.txt")) << "outside";
  std::filesystem::create_symlink(dir_.File("secret.txt"), root + "/leak.txt");
  std::filesystem::create_directories(root + "/js");
  std::ofstream(root + "/js/app.js") << "inside";
  for (const char* path : {"/leak.txt", "/../secret.txt", "/js/../../secret.txt", "/%2e%2e/secret.txt"}) {
    auto outside = client_->Get(path);
    ASSERT_TRUE(outside) << path;
    EXPECT_EQ(outside->status, 404) << path;
    EXPECT_EQ(outside->body.find("outside"), std::string::npos) << path;
  }
  auto inside = client_->Get("/js/app.js");
  ASSERT_TRUE(inside);
  EXPECT_EQ(inside->body, "inside");
  EXPECT_EQ(inside->get_header_value("Content-Type"), "text/javascript");

  ServerConfig bad = TestConfig(dir_.File("ops3.db"));
  bad.web_root = dir_.File("no-such-folder");
  auto refused = DispatchServer::Start(bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("web_root"), std::string::npos) << refused.error().message;
}

}  // namespace
}  // namespace dispatch::server::testing
