// Bids and award explanations (SPEC §3.2: "why this robot?"). A Bid holds every term of
// Chu2024 eqs. (1)-(8) for one robot and one order; an AwardExplanation holds all bids of one
// auction round and the reason the winners won.
//
// Invariant of a reachable Bid from an allocator: bid == BidValue(alpha, beta, t_t, t_d, x),
// t_t == t_d + t_w, x == zeta * flow. An unreachable robot (no route to the order) has
// reachable = false and every time term +infinity. A bid that was not priced (priced = false:
// large fleets, see AllocationConfig::price_every_bid_up_to) has its time terms, flow = a
// lower bound of F_i from part of its route's samples, x and bid to match (so bid is a lower
// bound of its full bid, and it already exceeds the bids that decided the award), and no
// peaks. Plain values; thread-safe to share.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct Bid {
  std::string robot;
  bool reachable = true;
  bool queue_full = false;  // not bidding: its queue is full (AllocationConfig::max_queue); reachable = false
  bool priced = true;  // F_i evaluated; false: flow, x and bid are lower bounds
  double t_d = 0.0;   // T_d,i: travel time of the whole queue + this order, s (eq. (3))
  double t_w = 0.0;   // T_w,i: work time n_c * t_w + drop times of the whole queue + this order, s (eq. (3))
  double t_t = 0.0;   // T_t,i = T_d,i + T_w,i (eq. (2))
  double flow = 0.0;  // F_i (eq. (8))
  double x = 0.0;     // x_i = zeta * F_i (eq. (5))
  double bid = 0.0;   // B_i (eq. (4)); the value the strategy ranks by
  double ready_time = 0.0;  // when the robot finishes its queue before this order, s
  std::vector<std::pair<ZoneId, int>> peaks;  // N_p,max(i) per zone visited (eq. (6))
};

// Chu2024 eq. (4): B = alpha * T_t + beta * T_d + x (eq. (1) when x = 0).
inline double BidValue(double alpha, double beta, double t_t, double t_d, double x) {
  return alpha * t_t + beta * t_d + x;
}

struct AwardExplanation {
  std::string order_id;
  std::string strategy;     // Allocator::name()
  std::vector<Bid> bids;    // every robot's bid for the order, in robot order
  // Formations: every robot except the leader, its cost to reach the first pick point
  // (terms as in Bid, over its queue plus the leg to the first pick), in robot order.
  std::vector<Bid> companion_bids;
  std::vector<std::string> winners;  // leader first
  std::string reason;                // e.g. "R5: lowest bid 69.50 (next R3 71.20)"
};

// "R5 B=69.50 (T_t=..., T_d=..., T_w=..., F=..., x=...)" for logs and operator answers.
std::string DescribeBid(const Bid& bid);

}  // namespace dispatch::engine
