#include "server/json_convert.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>

namespace dispatch::server {
namespace {

using nlohmann::json;

// JSON has no infinity: unreachable bids' terms are written as null and read back as +inf.
json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
double NumOf(const json& j) {
  return j.is_null() ? std::numeric_limits<double>::infinity() : j.get<double>();
}

json BidJson(const engine::Bid& b) {
  json peaks = json::array();
  for (const auto& [zone, n] : b.peaks) peaks.push_back({zone, n});
  json out = {{"robot", b.robot}, {"reachable", b.reachable}, {"priced", b.priced},
          {"t_d", Num(b.t_d)}, {"t_w", Num(b.t_w)}, {"t_t", Num(b.t_t)},
          {"flow", Num(b.flow)}, {"x", Num(b.x)}, {"bid", Num(b.bid)},
          {"ready_time", Num(b.ready_time)}, {"peaks", peaks}};
  if (b.queue_full) out["queue_full"] = true;  // only when set: older details read the same
  return out;
}

engine::Bid BidOf(const json& j) {
  engine::Bid b;
  b.robot = j.at("robot").get<std::string>();
  b.reachable = j.at("reachable").get<bool>();
  b.priced = j.at("priced").get<bool>();
  b.queue_full = j.value("queue_full", false);
  b.t_d = NumOf(j.at("t_d"));
  b.t_w = NumOf(j.at("t_w"));
  b.t_t = NumOf(j.at("t_t"));
  b.flow = NumOf(j.at("flow"));
  b.x = NumOf(j.at("x"));
  b.bid = NumOf(j.at("bid"));
  b.ready_time = NumOf(j.at("ready_time"));
  for (const auto& p : j.at("peaks")) b.peaks.emplace_back(p.at(0).get<int>(), p.at(1).get<int>());
  return b;
}

json RawAllocation(const AllocationRecord& a) {
  json bids = json::array(), companions = json::array();
  for (const auto& b : a.award.bids) bids.push_back(BidJson(b));
  for (const auto& b : a.award.companion_bids) companions.push_back(BidJson(b));
  return {{"order_id", a.award.order_id}, {"strategy", a.award.strategy},
          {"alpha", a.alpha}, {"beta", a.beta}, {"zeta", a.zeta}, {"time", a.time},
          {"bids", bids}, {"companion_bids", companions}, {"winners", a.award.winners},
          {"reason", a.award.reason}, {"bids_total", a.bids_total},
          {"companion_bids_total", a.companion_bids_total}};
}

}  // namespace

std::string AllocationDetail(const AllocationRecord& allocation) {
  return kAllocationDetailPrefix + RawAllocation(allocation).dump();
}

std::optional<AllocationRecord> ParseAllocationDetail(const std::string& detail) {
  const std::string prefix = kAllocationDetailPrefix;
  if (detail.rfind(prefix, 0) != 0) return std::nullopt;
  try {
    const json j = json::parse(detail.substr(prefix.size()));
    AllocationRecord a;
    a.award.order_id = j.at("order_id").get<std::string>();
    a.award.strategy = j.at("strategy").get<std::string>();
    a.alpha = j.at("alpha").get<double>();
    a.beta = j.at("beta").get<double>();
    a.zeta = j.at("zeta").get<double>();
    a.time = j.at("time").get<double>();
    for (const auto& b : j.at("bids")) a.award.bids.push_back(BidOf(b));
    for (const auto& b : j.at("companion_bids")) a.award.companion_bids.push_back(BidOf(b));
    a.award.winners = j.at("winners").get<std::vector<std::string>>();
    a.award.reason = j.at("reason").get<std::string>();
    // (Explanations stored before the totals kept every bid.)
    a.bids_total = j.value("bids_total", a.award.bids.size());
    a.companion_bids_total = j.value("companion_bids_total", a.award.companion_bids.size());
    return a;
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

}  // namespace dispatch::server
