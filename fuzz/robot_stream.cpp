// A robot stream's messages through the dispatch core (issue 18 §5), as the dispatcher feeds
// them (server/dispatcher_robots.cpp): a fresh core on the Chu2024 floor with robots R1 and R2
// connected and one order awarded, then the input as robot messages, each a 2-byte length
// (little-endian) and a RobotMessage: parsed (RobotInboundFromProto), then a Hello through the
// robot checks and Connect, a state report through Report, an arrival through Reached, a
// pick/drop through PlanTask, every change applied, the traffic gate stepped after each. Half
// a dispatcher second passes per message. What is checked: nothing crashes, and no sanitizer
// (ASan, UBSan) reports, whatever the sequence; the book's consistency is not checked here.
#include "engine/allocation/allocation_config.h"
#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/dispatch_core.h"
#include "engine/dispatch/order_intake.h"
#include "engine/dispatch/robot_intake.h"
#include "engine/dispatch/strategy.h"
#include "fuzz/chu2024_floor.h"
#include "server/proto_convert.h"
#include "warehouse/dispatch/v1/fleet.pb.h"

namespace {

namespace engine = dispatch::engine;
using dispatch::server::RobotInbound;

void ApplyAll(engine::DispatchCore& core, const engine::Change& change) { (void)core.Apply(change); }

void Connect(engine::DispatchCore& core, const dispatch::fuzz::Floor& f, const std::string& id, const std::string& at, double now) {
  engine::Robot r;
  r.id = id;
  r.current_point = *f.map->FindPoint(at);
  r.pose.position = f.map->point(r.current_point).position;
  (void)core.Connect(r, now);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const dispatch::fuzz::Floor& f = dispatch::fuzz::TheFloor();
  auto created = engine::DispatchCore::Create(f.map, f.routes, engine::CoreOptions{});
  if (!created.ok()) __builtin_trap();
  engine::DispatchCore& core = **created;
  double now = 0.0;
  Connect(core, f, "R1", "park-P1", now);
  Connect(core, f, "R2", "park-P2", now);
  engine::OrderRequest request;
  request.client_id = "fuzz-1";
  request.picks.push_back(std::string("K3-2-3N"));
  request.drop = std::string("D-B2");
  core.AddOrder(engine::AdmitOrder(*f.map, *f.routes, request, {}, "ord-1").value());
  engine::RoundRunner rounds(f.map, f.routes, {}, engine::MakeAllocator("auction").value());
  engine::RoundCommit commit;
  if (auto input = core.MakeRound(now, commit)) {
    commit.awards = rounds.Run(*input).awards;
    ApplyAll(core, core.PlanAwards(commit, commit.awards.size(), now));
  }
  std::string who;  // the stream's robot: R1's unless a Hello names another
  std::size_t at = 0;
  while (at + 2 <= size) {
    const std::size_t n = data[at] | (static_cast<std::size_t>(data[at + 1]) << 8);
    at += 2;
    if (at + n > size) break;
    ::warehouse::dispatch::v1::RobotMessage message;
    const bool parsed = message.ParseFromArray(data + at, static_cast<int>(n));
    at += n;
    now += 0.5;
    if (!parsed) continue;
    auto in = dispatch::server::RobotInboundFromProto(message);
    if (!in.ok()) continue;
    const RobotInbound& m = *in;
    if (m.kind == RobotInbound::Kind::kHello) {
      auto point = engine::LocateRobot(*f.map, m.robot_id, m.pose, 1.0);
      if (!point.ok()) continue;
      engine::Robot r;
      r.id = m.robot_id;
      r.pose = m.pose;
      r.current_point = *point;
      if (m.diameter > 0) r.diameter = m.diameter;
      if (m.max_speed > 0) r.max_speed = m.max_speed;
      if (!engine::ValidateRobot(r).ok()) continue;
      (void)core.Connect(r, now);
      who = m.robot_id;
    } else {
      const std::string id = who.empty() ? "R1" : who;
      switch (m.kind) {
        case RobotInbound::Kind::kState: {
          auto out = core.Report(id, m.pose, m.arc_id, m.state, m.battery, m.sequence, now);
          if (out.change) ApplyAll(core, *out.change);
          break;
        }
        case RobotInbound::Kind::kWaypointReached: {
          auto out = core.Reached(id, m.sequence, m.has_pose ? std::optional<engine::Pose>(m.pose) : std::nullopt, now);
          if (out.change) ApplyAll(core, *out.change);
          break;
        }
        case RobotInbound::Kind::kTaskEvent: {
          auto out = core.PlanTask(id, {m.order_id, m.dropped}, now);
          if (out.kind == engine::TaskOutcome::Kind::kChange) ApplyAll(core, out.change);
          break;
        }
        default: break;
      }
    }
    const engine::StepOutcome step = core.Step(now);
    for (const auto& [robot, why] : step.blocked) ApplyAll(core, core.PlanLoss(robot, why, now));
  }
  return 0;
}
