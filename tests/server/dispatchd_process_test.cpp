// The dispatchd binary as a process: it writes its ports file once listening, answers on
// both ports, exits 0 on SIGTERM, and after SIGTERM or kill -9 a restart on the same
// database has every acknowledged order. Waits by reading the child's log pipe (blocking
// reads) and on waitpid, never by sleeping.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/server/test_support.h"

namespace dispatch::server::testing {
namespace {

class Dispatchd {
 public:
  // Starts dispatchd on 127.0.0.1 with ephemeral ports and waits until it has written its
  // ports file (it logs "listening" just before).
  Dispatchd(const std::string& db, const std::string& ports_file) {
    // Everything the child needs is built before fork (only exec-safe calls after it).
    const std::string bin = std::string(DISPATCH_BINARY_DIR) + "/server/dispatchd";
    int fds[2];
    EXPECT_EQ(pipe(fds), 0);
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      dup2(fds[1], STDERR_FILENO);
      close(fds[0]);
      execl(bin.c_str(), bin.c_str(), "--bind", "127.0.0.1", "--grpc-port", "0", "--http-port", "0",
            "--db", db.c_str(), "--ports-file", ports_file.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    log_ = fdopen(fds[0], "r");
    // dispatchd logs "ports written to FILE" once the file (tmp + rename) is complete.
    char line[1024];
    std::string all;
    bool written = false;
    while (!written && std::fgets(line, sizeof line, log_)) {
      all += line;
      written = std::string(line).find("ports written") != std::string::npos;
    }
    if (!written) {
      ADD_FAILURE() << "dispatchd ended before writing its ports file; log:\n" << all;
      return;
    }
    std::ifstream in(ports_file);
    const auto j = nlohmann::json::parse(in);
    grpc_port = j["grpc_port"];
    http_port = j["http_port"];
  }
  ~Dispatchd() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (log_) std::fclose(log_);
  }
  int Signal(int sig) {
    kill(pid_, sig);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }
  int grpc_port = 0;
  int http_port = 0;

 private:
  pid_t pid_ = -1;
  FILE* log_ = nullptr;
};

std::shared_ptr<grpc::Channel> Channel(int port) {
  return grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials());
}

std::vector<std::string> SubmitSome(int port, const std::string& prefix, int n) {
  auto stub = pb::OrderService::NewStub(Channel(port));
  std::vector<std::string> ids;
  for (int i = 0; i < n; ++i) {
    grpc::ClientContext ctx;
    pb::SubmitOrderResponse response;
    const grpc::Status s = stub->SubmitOrder(WithDeadline(ctx),
                                             OrderRequest(prefix + std::to_string(i), {"K3-2-3N"}, "D-B2"),
                                             &response);
    EXPECT_TRUE(s.ok()) << s.error_message();
    ids.push_back(response.order().id());
  }
  return ids;
}

std::vector<std::string> ListIds(int port) {
  auto stub = pb::OrderService::NewStub(Channel(port));
  grpc::ClientContext ctx;
  pb::ListOrdersResponse response;
  EXPECT_TRUE(stub->ListOrders(WithDeadline(ctx), pb::ListOrdersRequest(), &response).ok());
  std::vector<std::string> ids;
  for (const auto& o : response.orders()) ids.push_back(o.id());
  return ids;
}

TEST(DispatchdProcessTest, SigtermExitsCleanlyAndRestartKeepsOrders) {
  TempDir dir;
  std::vector<std::string> ids;
  {
    Dispatchd d(dir.File("d.db"), dir.File("ports.json"));
    ASSERT_GT(d.grpc_port, 0);
    ASSERT_GT(d.http_port, 0);
    ids = SubmitSome(d.grpc_port, "term-", 3);
    const int status = d.Signal(SIGTERM);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0);
  }
  std::remove(dir.File("ports.json").c_str());
  Dispatchd again(dir.File("d.db"), dir.File("ports.json"));
  EXPECT_EQ(ListIds(again.grpc_port), ids);
}

TEST(DispatchdProcessTest, KillNineLosesNoAcknowledgedOrder) {
  TempDir dir;
  std::vector<std::string> ids;
  {
    Dispatchd d(dir.File("k.db"), dir.File("ports.json"));
    ids = SubmitSome(d.grpc_port, "kill-", 5);
    const int status = d.Signal(SIGKILL);
    ASSERT_TRUE(WIFSIGNALED(status));
  }
  std::remove(dir.File("ports.json").c_str());
  Dispatchd again(dir.File("k.db"), dir.File("ports.json"));
  EXPECT_EQ(ListIds(again.grpc_port), ids);
  // Resubmitting after the crash is recognised, not duplicated.
  auto stub = pb::OrderService::NewStub(Channel(again.grpc_port));
  grpc::ClientContext ctx;
  pb::SubmitOrderResponse response;
  ASSERT_TRUE(stub->SubmitOrder(WithDeadline(ctx), OrderRequest("kill-4", {"K3-2-3N"}, "D-B2"), &response).ok());
  EXPECT_FALSE(response.created());
  EXPECT_EQ(response.order().id(), ids[4]);
  EXPECT_EQ(ListIds(again.grpc_port).size(), ids.size());
}

}  // namespace
}  // namespace dispatch::server::testing
