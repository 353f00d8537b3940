#include "server/explanation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace dispatch::server {
namespace {

void KeepBest(std::vector<engine::Bid>& bids, const std::vector<std::string>& winners, std::size_t keep) {
  if (bids.size() <= keep) return;
  auto value = [](const engine::Bid& b) {
    return b.reachable && std::isfinite(b.bid) ? b.bid : std::numeric_limits<double>::infinity();
  };
  std::vector<std::size_t> order(bids.size());
  std::iota(order.begin(), order.end(), 0);
  // Winners first, then by value; ties by robot order (stable).
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const bool wa = std::find(winners.begin(), winners.end(), bids[a].robot) != winners.end();
    const bool wb = std::find(winners.begin(), winners.end(), bids[b].robot) != winners.end();
    if (wa != wb) return wa;
    return value(bids[a]) < value(bids[b]);
  });
  std::vector<bool> kept(bids.size(), false);
  for (std::size_t i = 0; i < keep; ++i) kept[order[i]] = true;
  std::vector<engine::Bid> out;
  out.reserve(keep);
  for (std::size_t i = 0; i < bids.size(); ++i) {
    if (kept[i]) out.push_back(std::move(bids[i]));
  }
  bids = std::move(out);
}

}  // namespace

void KeepBestBids(AllocationRecord& record, std::size_t keep) {
  engine::AwardExplanation& a = record.award;
  record.bids_total = a.bids.size();
  record.companion_bids_total = a.companion_bids.size();
  KeepBest(a.bids, a.winners, keep);
  KeepBest(a.companion_bids, a.winners, keep);
}

}  // namespace dispatch::server
