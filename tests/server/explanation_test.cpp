// KeepBestBids: an award's explanation keeps the winners' bids and the lowest others, in robot
// order, and counts them all.
#include "server/explanation.h"

#include "server/json_convert.h"
#include "engine/map/chu2024_floor.h"
#include "server/proto_convert.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

namespace dispatch::server {
namespace {

std::vector<engine::Bid> Bids(int n) {
  std::vector<engine::Bid> out;
  for (int i = 1; i <= n; ++i) {
    engine::Bid b;
    b.robot = "R" + std::to_string(i);
    b.bid = 1000.0 - i;  // the later robots bid lower
    out.push_back(b);
  }
  return out;
}

std::vector<std::string> Robots(const std::vector<engine::Bid>& bids) {
  std::vector<std::string> out;
  for (const auto& b : bids) out.push_back(b.robot);
  return out;
}

TEST(KeepBestBidsTest, KeepsEveryBidUpToTheLimit) {
  AllocationRecord r;
  r.award.bids = Bids(5);
  r.award.winners = {"R5"};
  KeepBestBids(r, 5);
  EXPECT_EQ(Robots(r.award.bids), (std::vector<std::string>{"R1", "R2", "R3", "R4", "R5"}));
  EXPECT_EQ(r.bids_total, 5u);
  EXPECT_EQ(r.companion_bids_total, 0u);
}

TEST(KeepBestBidsTest, KeepsTheWinnersAndTheLowestOthersInRobotOrder) {
  AllocationRecord r;
  r.award.bids = Bids(10);
  r.award.bids[9].reachable = false;  // R10 cannot reach the order: never among the lowest
  r.award.bids[9].bid = std::numeric_limits<double>::infinity();
  r.award.winners = {"R2"};  // a winner with a high bid (e.g. the leader of a formation)
  r.award.companion_bids = Bids(10);
  KeepBestBids(r, 4);
  EXPECT_EQ(Robots(r.award.bids), (std::vector<std::string>{"R2", "R7", "R8", "R9"}));
  EXPECT_EQ(Robots(r.award.companion_bids), (std::vector<std::string>{"R2", "R8", "R9", "R10"}));
  EXPECT_EQ(r.bids_total, 10u);
  EXPECT_EQ(r.companion_bids_total, 10u);
}

// A robot that did not bid because its queue was full (AllocationConfig::max_queue) says so in
// the stored explanation, after a restart (the journal's detail read back) and over the API.
TEST(ExplanationTest, AFullQueueIsStoredAndShown) {
  AllocationRecord r;
  r.award.order_id = "ord-1";
  r.award.bids = Bids(2);
  r.award.bids[0].reachable = false;
  r.award.bids[0].queue_full = true;
  r.award.bids[0].bid = r.award.bids[0].t_d = r.award.bids[0].t_w = r.award.bids[0].t_t =
      std::numeric_limits<double>::infinity();
  r.award.winners = {"R2"};
  auto back = ParseAllocationDetail(AllocationDetail(r));
  ASSERT_TRUE(back.has_value());
  ASSERT_EQ(back->award.bids.size(), 2u);
  EXPECT_TRUE(back->award.bids[0].queue_full);
  EXPECT_FALSE(back->award.bids[1].queue_full);
  auto map = engine::BuildChu2024Floor();
  ASSERT_TRUE(map.ok());
  warehouse::dispatch::v1::AllocationExplanation proto;
  AllocationToProto(*back, *map, &proto);
  ASSERT_EQ(proto.bids_size(), 2);
  EXPECT_TRUE(proto.bids(0).queue_full());
  EXPECT_FALSE(proto.bids(0).reachable());
  EXPECT_FALSE(proto.bids(1).queue_full());
}

}  // namespace
}  // namespace dispatch::server
