#include "engine/allocation/bid.h"

#include <cstdio>

namespace dispatch::engine {

std::string DescribeBid(const Bid& bid) {
  if (bid.queue_full) return bid.robot + " has a full queue";
  if (!bid.reachable) return bid.robot + " cannot reach the order";
  char buf[200];
  if (!bid.priced) {
    std::snprintf(buf, sizeof(buf),
                  " B>=%.2f (T_t=%.2f, T_d=%.2f, T_w=%.2f, F>=%.4f from part of the route: "
                  "could not win)",
                  bid.bid, bid.t_t, bid.t_d, bid.t_w, bid.flow);
    return bid.robot + buf;
  }
  std::snprintf(buf, sizeof(buf), " B=%.2f (T_t=%.2f, T_d=%.2f, T_w=%.2f, F=%.4f, x=%.2f)",
                bid.bid, bid.t_t, bid.t_d, bid.t_w, bid.flow, bid.x);
  return bid.robot + buf;
}

}  // namespace dispatch::engine
