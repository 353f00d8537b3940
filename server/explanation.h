// What an award's explanation keeps of its bids. Every robot bids for every order (Chu2024
// eq. (4)); with a thousand robots the explanation stored with each award (and its JSON) would
// cost more than the auction itself, so it keeps the winners' bids and the lowest others, and
// says how many there were.
#pragma once

#include <cstddef>

#include "server/snapshot.h"

namespace dispatch::server {

// Bids an explanation keeps per list (leader bids, companion bids).
inline constexpr std::size_t kExplainedBids = 32;

// Keeps, in each of record.award's bid lists, the winners' bids and the lowest others (by
// bid value; unreachable ones last) up to `keep` in all, in their original (robot) order;
// sets record.bids_total / companion_bids_total to the lists' sizes before.
void KeepBestBids(AllocationRecord& record, std::size_t keep = kExplainedBids);

}  // namespace dispatch::server
