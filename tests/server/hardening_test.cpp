// Issue 18 §3: faults measured on the running service, each fixed and tested here: a second
// dispatchd on one database, a 3 MB cancel reason, a REST body naming a key twice, a stream
// that never says Hello, /readyz while the database fails writes, /metrics without a role, a
// 1 MB robot id echoed whole.
#include "tests/server/test_support.h"

#include <httplib.h>  // after every header that pulls in Eigen (STYLE.md)

#include <fstream>

#include "engine/common/text.h"
#include "server/auth.h"
#include "storage/fault_injection_store.h"
#include "storage/sqlite_store.h"

namespace dispatch::server::testing {
namespace {

TEST(HardeningTest, ASecondServerOnTheSameDatabaseIsRefusedAndTheLockEndsWithTheFirst) {
  TempDir dir;
  ServerConfig config = TestConfig(dir.File("one.db"));
  auto first = DispatchServer::Start(config);
  ASSERT_TRUE(first.ok()) << first.error().message;
  auto second = DispatchServer::Start(config);
  ASSERT_FALSE(second.ok());
  EXPECT_NE(second.error().message.find("in use by another dispatchd"), std::string::npos) << second.error().message;
  first.value().reset();
  auto again = DispatchServer::Start(config);
  EXPECT_TRUE(again.ok()) << again.error().message;
}

TEST(HardeningTest, ALongCancelReasonIsRefusedAndNotStored) {
  TempDir dir;
  auto server = DispatchServer::Start(TestConfig(dir.File("reason.db")));
  ASSERT_TRUE(server.ok()) << server.error().message;
  auto orders = pb::OrderService::NewStub(ChannelTo(**server));
  grpc::ClientContext submit_ctx;
  pb::SubmitOrderResponse submitted;
  ASSERT_TRUE(orders->SubmitOrder(WithDeadline(submit_ctx), OrderRequest("reason-1", {"K3-2-3N"}, "D-B2"), &submitted)
                  .ok());
  pb::CancelOrderRequest cancel;
  cancel.set_order_id(submitted.order().id());
  cancel.set_reason(std::string(3 << 20, 'r'));
  grpc::ClientContext cancel_ctx;
  pb::Order answer;
  const grpc::Status refused = orders->CancelOrder(WithDeadline(cancel_ctx), cancel, &answer);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(refused.error_message().find("longer than 1024 bytes"), std::string::npos) << refused.error_message();
  grpc::ClientContext get_ctx;
  pb::GetOrderRequest get;
  get.set_order_id(submitted.order().id());
  pb::Order stored;
  ASSERT_TRUE(orders->GetOrder(WithDeadline(get_ctx), get, &stored).ok());
  EXPECT_EQ(stored.state(), pb::ORDER_STATE_ACCEPTED);
  EXPECT_TRUE(stored.reason().empty());
}

TEST(HardeningTest, ARestBodyNamingAKeyTwiceIsRefused) {
  TempDir dir;
  auto server = DispatchServer::Start(TestConfig(dir.File("keys.db")));
  ASSERT_TRUE(server.ok()) << server.error().message;
  httplib::Client client("127.0.0.1", (*server)->ports().http);
  const std::string twice =
      R"({"client_order_id": "dup-keys", "picks": [{"point_name": "K3-2-3N"}], "drop": {"point_name": "D-B2"},
          "drop": {"point_name": "D-B1"}})";
  auto refused = client.Post("/api/v1/orders", twice, "application/json");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 400);
  EXPECT_NE(refused->body.find("the key 'drop' twice"), std::string::npos) << refused->body;
  const std::string once = R"({"client_order_id": "dup-keys", "picks": [{"point_name": "K3-2-3N"}],
                              "drop": {"point_name": "D-B2"}})";
  auto accepted = client.Post("/api/v1/orders", once, "application/json");
  ASSERT_TRUE(accepted);
  EXPECT_EQ(accepted->status, 201) << accepted->body;
}

// A stream that never says Hello is ended after the heartbeat timeout (it held a connection,
// a thread's worth of buffers and a descriptor for ever).
TEST(HardeningTest, AStreamThatNeverSaysHelloIsEnded) {
  TempDir dir;
  ServerConfig config = TestConfig(dir.File("silent.db"));
  config.heartbeat_interval = 0.1;
  config.heartbeat_timeout = 0.5;
  auto server = DispatchServer::Start(config);
  ASSERT_TRUE(server.ok()) << server.error().message;
  auto stub = pb::FleetService::NewStub(ChannelTo(**server));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + kTimeout);
  auto stream = stub->Connect(&ctx);
  pb::ServerMessage m;
  EXPECT_FALSE(stream->Read(&m));  // nothing comes; the server ends the stream
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  EXPECT_NE(status.error_message().find("no Hello"), std::string::npos) << status.error_message();
}

// /readyz said ready while the database could not take writes: now 503 with why, from a write
// that failed for I/O until a write succeeds again (the disk back).
TEST(HardeningTest, NotReadyWhileTheDatabaseFailsWritesAndReadyWhenItRecovers) {
  TempDir dir;
  ServerConfig config = TestConfig(dir.File("ready.db"));
  auto sqlite = storage::SqliteStore::Open(config.db);
  ASSERT_TRUE(sqlite.ok()) << sqlite.error().message;
  storage::FaultInjectionStore faulty(**sqlite);
  auto server = DispatchServer::Start(config, &faulty);
  ASSERT_TRUE(server.ok()) << server.error().message;
  httplib::Client client("127.0.0.1", (*server)->ports().http);
  auto orders = pb::OrderService::NewStub(ChannelTo(**server));
  auto submit = [&](const std::string& id) {
    grpc::ClientContext ctx;
    pb::SubmitOrderResponse response;
    return orders->SubmitOrder(WithDeadline(ctx), OrderRequest(id, {"K3-2-3N"}, "D-B2"), &response);
  };
  auto ready = client.Get("/readyz");
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->status, 200) << ready->body;
  faulty.FailWritesFrom(faulty.writes() + 1);  // the disk turns read-only, or fills up
  EXPECT_EQ(submit("ready-1").error_code(), grpc::StatusCode::UNAVAILABLE);
  auto failing = client.Get("/readyz");
  ASSERT_TRUE(failing);
  EXPECT_EQ(failing->status, 503) << failing->body;
  EXPECT_NE(failing->body.find("last write failed"), std::string::npos) << failing->body;
  faulty.FailWritesFrom(0);
  EXPECT_TRUE(submit("ready-1").ok());
  auto recovered = client.Get("/readyz");
  ASSERT_TRUE(recovered);
  EXPECT_EQ(recovered->status, 200) << recovered->body;
  (*server)->Shutdown();
}

// Issue 18 §2: /metrics needs a role that reads them (operator, admin) unless metrics_open;
// /healthz and /readyz stay open; /api/v1/session tells any valid token who it is (the web
// map offers robot commands from it), and everyone is admin without tokens.
TEST(HardeningTest, MetricsNeedARoleUnlessOpen) {
  TempDir dir;
  const std::string tokens = dir.File("tokens.json");
  std::ofstream(tokens) << R"({"tokens": [{"name": "w", "role": "wms", "sha256": ")" << Sha256Hex("wms-secret")
                        << R"("}, {"name": "o", "role": "operator", "sha256": ")" << Sha256Hex("op-secret") << R"("}]})";
  for (const bool open : {false, true}) {
    ServerConfig config = TestConfig(dir.File(open ? "open.db" : "closed.db"));
    config.auth_tokens = tokens;
    config.metrics_open = open;
    auto server = DispatchServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.error().message;
    httplib::Client client("127.0.0.1", (*server)->ports().http);
    auto status_with = [&](const std::string& path, const std::string& secret) {
      httplib::Headers headers;
      if (!secret.empty()) headers.emplace("Authorization", "Bearer " + secret);
      auto r = client.Get(path, headers);
      return r ? r->status : -1;
    };
    EXPECT_EQ(status_with("/metrics", ""), open ? 200 : 401) << open;
    EXPECT_EQ(status_with("/metrics", "wms-secret"), open ? 200 : 403) << open;
    EXPECT_EQ(status_with("/metrics", "op-secret"), 200) << open;
    EXPECT_EQ(status_with("/healthz", ""), 200);
    EXPECT_EQ(status_with("/readyz", ""), 200);
    EXPECT_EQ(status_with("/api/v1/robots", ""), 401);
    EXPECT_EQ(status_with("/api/v1/session", ""), 401);
    EXPECT_EQ(status_with("/api/v1/session", "not-a-token"), 401);
    for (const auto& [secret, body] :
         {std::pair{"wms-secret", R"({"name":"w","role":"wms","robot_commands":false,"tokens_required":true})"},
          std::pair{"op-secret", R"({"name":"o","role":"operator","robot_commands":true,"tokens_required":true})"}}) {
      auto r = client.Get("/api/v1/session", {{"Authorization", std::string("Bearer ") + secret}});
      ASSERT_TRUE(r);
      EXPECT_EQ(r->status, 200);
      EXPECT_EQ(r->body, body);
    }
  }
  auto server = DispatchServer::Start(TestConfig(dir.File("no-tokens.db")));
  ASSERT_TRUE(server.ok()) << server.error().message;
  httplib::Client client("127.0.0.1", (*server)->ports().http);
  auto r = client.Get("/api/v1/session");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->body, R"({"name":"","role":"admin","robot_commands":true,"tokens_required":false})");
}

TEST(HardeningTest, AHugeRobotIdIsQuotedClipped) {
  EXPECT_EQ(engine::Clipped("R1"), "R1");
  const std::string huge(1 << 20, 'x');
  const std::string clipped = engine::Clipped(huge);
  EXPECT_EQ(clipped, std::string(64, 'x') + "... (1048576 bytes)");
  EXPECT_EQ(engine::Clipped("\xc3\xa9\xc3\xa9", 3), "\xc3\xa9... (4 bytes)");  // whole characters
  TempDir dir;
  auto server = DispatchServer::Start(TestConfig(dir.File("id.db")));
  ASSERT_TRUE(server.ok()) << server.error().message;
  FakeRobot robot(ChannelTo(**server), huge);
  robot.Connect(30.625, 24.75);
  const grpc::Status ended = robot.AwaitEnd();
  EXPECT_EQ(ended.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_LT(ended.error_message().size(), 300u) << ended.error_message().substr(0, 300);
  EXPECT_NE(ended.error_message().find("(1048576 bytes)"), std::string::npos);
}

}  // namespace
}  // namespace dispatch::server::testing
