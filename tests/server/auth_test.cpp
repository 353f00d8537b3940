// Tokens and roles (server/auth.h, issue 18 §2): the token file's checks, the role table and
// what Authorize answers.
#include "server/auth.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/server/test_support.h"

namespace dispatch::server {
namespace {

std::string Entry(const std::string& name, const std::string& role, const std::string& secret,
                  const std::string& robot = "") {
  std::string e = R"({"name": ")" + name + R"(", "role": ")" + role + R"(", "sha256": ")" + Sha256Hex(secret) + "\"";
  if (!robot.empty()) e += R"(, "robot_id": ")" + robot + "\"";
  return e + "}";
}

std::string File(const std::vector<std::string>& entries) {
  std::string s = R"({"tokens": [)";
  for (std::size_t i = 0; i < entries.size(); ++i) s += (i ? ", " : "") + entries[i];
  return s + "]}";
}

TEST(AuthTest, Sha256IsTheStandardDigest) {
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(AuthTest, TokenFileErrorsNameTheTokenAndField) {
  struct Case {
    std::string text, words;
  };
  const std::vector<Case> cases = {
      {"not json", "not JSON"},
      {R"({"tokens": {}})", "\"tokens\" array"},
      {R"({"tokens": [], "extra": 1})", "unknown key 'extra'"},
      {R"({"tokens": [], "tokens": []})", "repeats the key 'tokens'"},
      {File({R"({"name": "a", "role": "wms", "sha256": "00"})"}), "64 hex digits"},
      {File({R"({"name": "a", "role": "king", "sha256": ")" + Sha256Hex("x") + "\"}"}), "'role'"},
      {File({R"({"role": "wms", "sha256": ")" + Sha256Hex("x") + "\"}"}), "'name' is required"},
      {File({Entry("r", "robot", "x")}), "needs 'robot_id'"},
      {File({Entry("w", "wms", "x", "R1")}), "only a robot token"},
      {File({Entry("a", "wms", "x"), Entry("a", "admin", "y")}), "'a': the name is used twice"},
      {File({Entry("a", "wms", "x"), Entry("b", "admin", "x")}), "same secret"},
      {File({R"({"name": "a", "role": "wms", "secret": "x"})"}), "unknown key 'secret'"},
      {File({R"({"name": "a", "role": "wms", "sha256": 5})"}), "must be a string"},
  };
  for (const Case& c : cases) {
    auto parsed = TokenSet::Parse(c.text);
    ASSERT_FALSE(parsed.ok()) << c.text;
    EXPECT_NE(parsed.error().message.find(c.words), std::string::npos) << parsed.error().message;
  }
}

TEST(AuthTest, RolesPermitWhatTheIssueLists) {
  for (Access a : {Access::kSubmitOrder, Access::kReadOrders, Access::kCancelOrder, Access::kReadFleet,
                   Access::kReadMap, Access::kMetrics, Access::kRobotCommand, Access::kRobotStream}) {
    EXPECT_TRUE(Permits(Role::kAdmin, a)) << AccessName(a);
  }
  EXPECT_TRUE(Permits(Role::kWms, Access::kSubmitOrder));
  EXPECT_TRUE(Permits(Role::kWms, Access::kCancelOrder));
  EXPECT_FALSE(Permits(Role::kWms, Access::kReadFleet));
  EXPECT_FALSE(Permits(Role::kWms, Access::kRobotCommand));
  EXPECT_FALSE(Permits(Role::kWms, Access::kRobotStream));
  EXPECT_TRUE(Permits(Role::kOperator, Access::kReadFleet));
  EXPECT_TRUE(Permits(Role::kOperator, Access::kRobotCommand));
  EXPECT_TRUE(Permits(Role::kOperator, Access::kCancelOrder));
  EXPECT_FALSE(Permits(Role::kOperator, Access::kSubmitOrder));
  EXPECT_FALSE(Permits(Role::kOperator, Access::kRobotStream));
  EXPECT_TRUE(Permits(Role::kRobot, Access::kRobotStream));
  EXPECT_FALSE(Permits(Role::kRobot, Access::kReadOrders));
  EXPECT_FALSE(Permits(Role::kRobot, Access::kRobotCommand));
}

TEST(AuthTest, AuthorizeAnswersWhoAndWhyNot) {
  testing::TempDir dir;
  const std::string path = dir.File("tokens.json");
  {
    std::ofstream(path) << File({Entry("wms-1", "wms", "s3cret"), Entry("r1", "robot", "robo", "R1")});
  }
  auto auth = Authenticator::FromFile(path);
  ASSERT_TRUE(auth.ok()) << auth.error().message;
  const Authenticator& a = **auth;
  EXPECT_EQ(a.Authorize(std::nullopt, Access::kReadOrders).status.code, StatusCode::kUnauthenticated);
  EXPECT_EQ(a.Authorize("Basic czNjcmV0", Access::kReadOrders).status.code, StatusCode::kUnauthenticated);
  EXPECT_EQ(a.Authorize("Bearer nope", Access::kReadOrders).status.code, StatusCode::kUnauthenticated);
  const auto ok = a.Authorize("bearer  s3cret ", Access::kSubmitOrder);
  EXPECT_TRUE(ok.status.ok()) << ok.status.message;
  EXPECT_EQ(ok.principal.name, "wms-1");
  const auto denied = a.Authorize("Bearer s3cret", Access::kRobotCommand);
  EXPECT_EQ(denied.status.code, StatusCode::kPermissionDenied);
  EXPECT_NE(denied.status.message.find("wms-1"), std::string::npos);
  const auto robot = a.Authorize("Bearer robo", Access::kRobotStream);
  EXPECT_TRUE(robot.status.ok());
  EXPECT_EQ(robot.principal.robot_id, "R1");
  // Without a token file everything is allowed, as the anonymous admin.
  EXPECT_TRUE(Authenticator().Authorize(std::nullopt, Access::kRobotCommand).status.ok());
}

TEST(AuthTest, ReloadTakesNewTokensAndKeepsTheOldOnesOnABadFile) {
  testing::TempDir dir;
  const std::string path = dir.File("tokens.json");
  { std::ofstream(path) << File({Entry("old", "wms", "one")}); }
  auto auth = Authenticator::FromFile(path);
  ASSERT_TRUE(auth.ok());
  { std::ofstream(path) << File({Entry("new", "operator", "two")}); }
  ASSERT_TRUE((*auth)->Reload().ok());
  EXPECT_EQ((*auth)->Authorize("Bearer one", Access::kReadOrders).status.code, StatusCode::kUnauthenticated);
  EXPECT_TRUE((*auth)->Authorize("Bearer two", Access::kReadOrders).status.ok());
  { std::ofstream(path) << "{broken"; }
  EXPECT_FALSE((*auth)->Reload().ok());
  EXPECT_TRUE((*auth)->Authorize("Bearer two", Access::kReadOrders).status.ok());
}

}  // namespace
}  // namespace dispatch::server
