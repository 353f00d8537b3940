// kill -9 durability: a child process writes orders and acknowledges each one over a pipe
// only after the store returned OK; the parent SIGKILLs it mid-stream, reopens the database
// and finds every acknowledged order with its journal, and nothing half-written.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>

#include "storage/sqlite_store.h"
#include "tests/storage/temp_dir.h"

namespace dispatch::storage {
namespace {

using engine::OrderState;

engine::Order NumberedOrder(std::int32_t i) {
  engine::Order o;
  o.id = "o" + std::to_string(i);
  o.client_id = "client-" + std::to_string(i);
  o.picks = {i % 7, (i + 1) % 7};
  o.drop = 100 + i;
  o.created_time = i;
  return o;
}

// Child body: never returns. Writes order i and moves it to assigned in one transaction,
// then acknowledges i on `ack_fd`. Stops only when killed (or on an error: acks -1).
[[noreturn]] void WriteUntilKilled(const std::string& path, int ack_fd) {
  auto store = SqliteStore::Open(path);  // default options: WAL, synchronous = FULL
  std::int32_t i = 0;
  auto ack = [&](std::int32_t value) {
    if (write(ack_fd, &value, sizeof value) != static_cast<ssize_t>(sizeof value)) _exit(3);
  };
  if (!store.ok()) {
    ack(-1);
    _exit(1);
  }
  for (;; ++i) {
    Status s = store.value()->RunInTransaction([&](Store& tx) -> Status {
      auto inserted = tx.InsertOrder(NumberedOrder(i), "");
      if (!inserted.ok()) return inserted.error();
      auto assigned = tx.TransitionOrder({"o" + std::to_string(i), OrderState::kAssigned,
                                          i + 0.5, std::vector<std::string>{"R1"}, "won", {}, ""});
      if (!assigned.ok()) return assigned.error();
      return engine::Ok{};
    });
    if (!s.ok()) {
      ack(-1);
      _exit(2);
    }
    ack(i);
  }
}

TEST(StorageCrashTest, EveryAcknowledgedOrderSurvivesSigkill) {
  constexpr std::int32_t kAcked = 40;
  testing::TempDir dir;
  const std::string path = dir.File("dispatch.db");
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(fds[0]);
    WriteUntilKilled(path, fds[1]);
  }
  close(fds[1]);
  // Read exactly kAcked acknowledgements (the child keeps writing meanwhile), then kill it
  // while it is most likely inside its next transaction.
  for (std::int32_t expected = 0; expected < kAcked; ++expected) {
    std::int32_t got = -2;
    ssize_t n;
    do {
      n = read(fds[0], &got, sizeof got);
    } while (n < 0 && errno == EINTR);
    if (n != static_cast<ssize_t>(sizeof got) || got != expected) {
      kill(child, SIGKILL);
      waitpid(child, nullptr, 0);
      close(fds[0]);
      FAIL() << "child acknowledged " << got << " (read " << n << " bytes), expected "
             << expected;
    }
  }
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int wstatus = 0;
  ASSERT_EQ(waitpid(child, &wstatus, 0), child);
  close(fds[0]);
  ASSERT_TRUE(WIFSIGNALED(wstatus));
  EXPECT_EQ(WTERMSIG(wstatus), SIGKILL);

  auto reopened = SqliteStore::Open(path);
  ASSERT_TRUE(reopened.ok()) << reopened.error().message;
  SqliteStore& store = *reopened.value();
  for (std::int32_t i = 0; i < kAcked; ++i) {
    auto r = store.GetOrder("o" + std::to_string(i));
    ASSERT_TRUE(r.ok()) << "acknowledged order " << i << " lost: " << r.error().message;
    EXPECT_EQ(r->order.state, OrderState::kAssigned);
    EXPECT_EQ(r->order.picks, NumberedOrder(i).picks);
    EXPECT_EQ(r->order.drop, 100 + i);
    EXPECT_EQ(r->robots, std::vector<std::string>{"R1"});
  }
  // Whatever the child wrote after its last ack is either wholly there or wholly absent:
  // every stored order is assigned with exactly its two journal entries.
  OrderQuery all;
  all.page_size = kMaxPageSize;
  auto page = store.ListOrders(all);
  ASSERT_TRUE(page.ok());
  EXPECT_GE(page->orders.size(), static_cast<size_t>(kAcked));
  EventQuery events;
  events.limit = 100000;
  EXPECT_EQ(store.ListEvents(events).value().size(), 2 * page->orders.size());
  for (const OrderRecord& r : page->orders) {
    EXPECT_EQ(r.order.state, OrderState::kAssigned) << r.order.id;
    EXPECT_EQ(store.ListEvents({r.order.id, 0, 10}).value().size(), 2u) << r.order.id;
  }
}

}  // namespace
}  // namespace dispatch::storage
