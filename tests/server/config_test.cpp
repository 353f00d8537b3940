// dispatchd's command line and config file: defaults, flags, file keys, flags win, errors.
#include <gtest/gtest.h>

#include <fstream>

#include "server/config.h"
#include "tests/server/test_support.h"

namespace dispatch::server::testing {
namespace {

engine::Result<ParsedCommandLine> Parse(std::vector<std::string> args) {
  args.insert(args.begin(), "dispatchd");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return ParseCommandLine(static_cast<int>(argv.size()), argv.data());
}

TEST(ServerConfigTest, FlagsSetTheConfig) {
  auto parsed = Parse({"--grpc-port", "0", "--http-port", "8081", "--db", "x.db", "--map", "chu2024",
                       "--strategy", "exact", "--batch-window", "2.5", "--zeta", "0", "--alpha", "0.3", "--beta", "0.7",
                       "--time-scale", "10", "--bind", "127.0.0.1", "--ports-file", "p.json",
                       "--planner", "time-windows", "--turn-time", "1.5", "--drop-time", "0", "--routing", "heat",
                       "--heat-period", "30", "--priority", "release", "--formation-max-queue", "0",
                       "--one-formation-per-pick", "false", "--head-on-priority", "true", "--head-on-give-way", "true",
                       "--execution", "order", "--route-table", "hub_labels"});
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  const ServerConfig& c = parsed->config;
  EXPECT_TRUE(c.head_on_priority);
  EXPECT_TRUE(c.head_on_give_way);
  EXPECT_EQ(c.execution, "order");
  EXPECT_EQ(c.grpc_port, 0);
  EXPECT_EQ(c.http_port, 8081);
  EXPECT_EQ(c.db, "x.db");
  EXPECT_EQ(c.strategy, "exact");
  EXPECT_DOUBLE_EQ(c.batch_window, 2.5);
  EXPECT_DOUBLE_EQ(c.zeta, 0.0);
  EXPECT_DOUBLE_EQ(c.alpha, 0.3);
  EXPECT_DOUBLE_EQ(c.beta, 0.7);
  EXPECT_DOUBLE_EQ(c.time_scale, 10.0);
  EXPECT_EQ(c.bind, "127.0.0.1");
  EXPECT_EQ(c.ports_file, "p.json");
  EXPECT_EQ(c.planner, "time-windows");
  EXPECT_DOUBLE_EQ(c.turn_time, 1.5);
  EXPECT_EQ(c.drop_time, 0.0);
  EXPECT_EQ(c.routing, "heat");
  EXPECT_EQ(c.route_table, "hub_labels");
  EXPECT_DOUBLE_EQ(c.heat_period, 30.0);
  EXPECT_EQ(c.priority, "release");
  EXPECT_EQ(c.formation_max_queue, 0);
  EXPECT_FALSE(c.one_formation_per_pick);
}

TEST(ServerConfigTest, FileKeysApplyAndFlagsWin) {
  TempDir dir;
  const std::string file = dir.File("dispatchd.json");
  std::ofstream(file) << R"({"grpc_port": 7000, "http_port": 7001, "db": "file.db", "zeta": 50, "drop_time": 2.5,
                              "execution": "claim"})";
  auto parsed = Parse({"--config", file, "--http-port", "9000"});
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  EXPECT_EQ(parsed->config.grpc_port, 7000);
  EXPECT_EQ(parsed->config.http_port, 9000);
  EXPECT_EQ(parsed->config.db, "file.db");
  EXPECT_DOUBLE_EQ(parsed->config.zeta, 50.0);
  EXPECT_EQ(parsed->config.execution, "claim");
  EXPECT_EQ(parsed->config.drop_time, 2.5);
  EXPECT_FALSE(Parse({}).value().config.drop_time.has_value()) << "by default the order's t_w";
  EXPECT_EQ(Parse({"--config", file, "--drop-time", "1"}).value().config.drop_time, 1.0);
  EXPECT_EQ(parsed->config.strategy, "auction");
  EXPECT_DOUBLE_EQ(parsed->config.batch_window, 0.0);
  EXPECT_EQ(parsed->config.planner, "rules");
  // Formations by default: members with nothing queued, one team at a time per first pick.
  EXPECT_EQ(parsed->config.formation_max_queue, 1);
  EXPECT_TRUE(parsed->config.one_formation_per_pick);
}

TEST(ServerConfigTest, BadValuesAreNamed) {
  TempDir dir;
  const std::string file = dir.File("bad.json");
  std::ofstream(file) << R"({"grpc_prot": 1})";
  auto unknown_key = Parse({"--config", file});
  ASSERT_FALSE(unknown_key.ok());
  EXPECT_NE(unknown_key.error().message.find("grpc_prot"), std::string::npos);
  auto strategy = Parse({"--strategy", "random"});
  ASSERT_FALSE(strategy.ok());
  EXPECT_NE(strategy.error().message.find("random"), std::string::npos);
  auto drop = Parse({"--drop-time", "-1"});
  ASSERT_FALSE(drop.ok());
  EXPECT_NE(drop.error().message.find("drop_time must be finite and >= 0"), std::string::npos) << drop.error().message;
  auto planner = Parse({"--planner", "cbs"});
  ASSERT_FALSE(planner.ok());
  EXPECT_NE(planner.error().message.find("planner must be one of rules, time-windows, conflict-elimination, got 'cbs'"), std::string::npos);
  EXPECT_FALSE(Parse({"--turn-time", "-1"}).ok());
  auto window = Parse({"--batch-window", "-1"});
  ASSERT_FALSE(window.ok());
  EXPECT_EQ(window.error().message, "batch_window must be >= 0 seconds");
  auto routing = Parse({"--routing", "astar"});
  ASSERT_FALSE(routing.ok());
  EXPECT_NE(routing.error().message.find("routing must be floyd or heat, got 'astar'"), std::string::npos);
  auto table = Parse({"--route-table", "ch"});
  ASSERT_FALSE(table.ok());
  EXPECT_NE(table.error().message.find("route_table: unknown route table method 'ch' (known: floyd, dijkstra, auto, lazy, hub_labels)"),
            std::string::npos) << table.error().message;
  EXPECT_FALSE(Parse({"--heat-period", "0"}).ok());
  EXPECT_FALSE(Parse({"--priority", "fifo"}).ok());
  auto execution = Parse({"--execution", "eager"});
  ASSERT_FALSE(execution.ok());
  EXPECT_EQ(execution.error().message, "execution must be times, claim or order, got 'eager'");
  auto queue = Parse({"--formation-max-queue", "-1"});
  ASSERT_FALSE(queue.ok());
  EXPECT_NE(queue.error().message.find("formation_max_queue must be >= 0"), std::string::npos);
  auto port = Parse({"--grpc-port", "70000"});
  ASSERT_FALSE(port.ok());
  EXPECT_NE(port.error().message.find("grpc_port"), std::string::npos);
  auto scale = Parse({"--time-scale", "0"});
  ASSERT_FALSE(scale.ok());
  EXPECT_NE(scale.error().message.find("time_scale"), std::string::npos);
  auto half_tls = Parse({"--tls-cert", file});
  ASSERT_FALSE(half_tls.ok());
  EXPECT_NE(half_tls.error().message.find("tls_cert and tls_key go together"), std::string::npos);
  auto missing = Parse({"--auth-tokens", dir.File("none.json")});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("auth_tokens"), std::string::npos);
  auto client_ca = Parse({"--tls-client-ca", file});
  ASSERT_FALSE(client_ca.ok());
  EXPECT_NE(client_ca.error().message.find("tls_client_ca needs tls_cert"), std::string::npos);
}

// Issue 18 §1: with no TLS and no --bind, dispatchd listens on loopback only.
TEST(ServerConfigTest, SecureByDefaultBindsLoopbackWithoutTls) {
  ServerConfig c;
  EXPECT_EQ(EffectiveBind(c), "127.0.0.1");
  c.tls_cert = "server.crt";
  c.tls_key = "server.key";
  EXPECT_EQ(EffectiveBind(c), "0.0.0.0");
  c.bind = "10.0.0.5";
  EXPECT_EQ(EffectiveBind(c), "10.0.0.5");
}

}  // namespace
}  // namespace dispatch::server::testing
