#include "engine/dispatch/allocation_round.h"

#include "engine/dispatch/heat_awards.h"
#include "engine/dispatch/window_awards.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <unordered_map>

namespace dispatch::engine {

bool NaturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const std::string na = a.substr(i, ie - i), nb = b.substr(j, je - j);
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

bool AllocationOrderLess(const Order& a, const Order& b) {
  if (a.priority != b.priority) return a.priority > b.priority;
  if (a.created_time != b.created_time) return a.created_time < b.created_time;
  return NaturalLess(a.id, b.id);
}

RoundRunner::RoundRunner(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                         AllocationConfig config, std::unique_ptr<Allocator> allocator,
                         std::function<double()> stopwatch)
    : map_(std::move(map)),
      routes_(std::move(routes)),
      config_(config),
      allocator_(std::move(allocator)),
      stopwatch_(std::move(stopwatch)) {}

std::shared_ptr<const FreeSpaceMotion> RoundRunner::FreeSpace(std::vector<std::string>& notes) {
  if (free_space_tried_ || map_->free_spaces().empty()) return free_space_;
  free_space_tried_ = true;
  auto motion = FreeSpaceMotion::Create(map_);
  if (!motion.ok()) {
    notes.push_back("allocation: free-space regions not used: " + motion.error().message);
    return nullptr;
  }
  free_space_ = std::make_shared<const FreeSpaceMotion>(std::move(motion).value());
  return free_space_;
}

namespace {

// The kept fleet's prediction origin moves in steps of about this many seconds (a whole number
// of buckets), each step a new fleet: its counts cover no more of the past than that.
constexpr double kOriginStepSeconds = 600.0;

}  // namespace

FleetState* RoundRunner::Prepare(const RoundInput& input, std::vector<std::string>& notes) {
  // The prediction's buckets start at the round's step of the origin, not at time 0: the same
  // bucket times (a whole number of buckets later), without counts for the hours already past.
  TrafficPredictionConfig grid = config_.traffic;
  const double step = std::max(1.0, std::ceil(kOriginStepSeconds / grid.bucket_seconds)) * grid.bucket_seconds;
  if (input.now > grid.origin_time) grid.origin_time += std::floor((input.now - grid.origin_time) / step) * step;
  bool same = kept_.has_value() && kept_origin_ == grid.origin_time && kept_robots_.size() == input.robots.size();
  for (std::size_t i = 0; same && i < input.robots.size(); ++i) {
    same = kept_->robot_id(i) == input.robots[i].id && kept_->robot(i).kind == input.robots[i].kind;
  }
  if (!same) {
    std::vector<FleetRobot> robots;
    for (const RoundRobot& r : input.robots) robots.push_back({r.id, r.start, input.now, r.kind});
    AllocationConfig config = config_;
    config.traffic = grid;
    kept_.reset();
    auto fleet = FleetState::Create(map_, routes_, robots, config, zone_index_, /*publish=*/false);
    if (!fleet.ok()) {
      notes.push_back("allocation: " + fleet.error().message);
      return nullptr;
    }
    kept_.emplace(std::move(fleet).value());
    kept_origin_ = grid.origin_time;
    kept_robots_.assign(input.robots.size(), KeptRobot{});
    zone_index_ = kept_->zone_index();  // one floor, one index: the next fleet skips the grid
    kept_->UseFreeSpace(FreeSpace(notes));  // every planner: the planned ones keep refined segments
  }
  FleetState& fleet = *kept_;
  if (&fleet.routes() != routes_.get()) (void)fleet.UseRoutes(routes_);  // a round's heat routes
  // A queue is replayed from the first bucket start at or after now.
  std::size_t ready_bucket = 0;
  while (grid.origin_time + static_cast<double>(ready_bucket) * grid.bucket_seconds < input.now) ++ready_bucket;
  // The predictor sees each robot once: its replayed queue (not once per order, nor its
  // start first), or its start. An entry the last round left as this one needs stays.
  std::unordered_map<std::string, std::shared_ptr<const Replay>> replays;  // kept for the next round
  for (std::size_t i = 0; i < input.robots.size(); ++i) {
    const RoundRobot& robot = input.robots[i];
    KeptRobot& kept = kept_robots_[i];
    const bool untouched = kept.installed && fleet.revision(i) == kept.revision;
    std::shared_ptr<const Replay> replay;
    std::size_t rounds = 1;  // the rounds `replay` has served this robot, this one included
    if (robot.has_queue()) {
      auto last = replays_.find(robot.id);
      if (last != replays_.end() && last->second->Matches(robot)) replay = last->second;
      if (replay && replay == kept.replay) rounds = kept.rounds + 1;
      if (replay && untouched && replay == kept.replay && kept.bucket == ready_bucket) {
        // As the last round left it.
      } else if (replay && replay->snapshot && fleet.Restore(i, *replay->snapshot, ready_bucket).ok()) {
        // Moved to this round's bucket.
      } else {
        // A queue that lasted a few rounds will likely last a few more: worth a snapshot (its
        // copy), to be moved from bucket to bucket instead of replayed again.
        replay = ReplayAnew(fleet, i, robot, ready_bucket, kept.installed && kept.rounds >= 2);
        rounds = 1;
      }
      if (replay) {
        notes.insert(notes.end(), replay->notes.begin(), replay->notes.end());
        replays.emplace(robot.id, replay);
      }
    }
    if (!replay) {
      if (Status s = fleet.Reset(i, robot.start, input.now); !s.ok()) {
        notes.push_back("allocation: " + s.error().message);
        kept_.reset();
        return nullptr;
      }
      fleet.Publish(i);
    }
    kept = KeptRobot{true, std::move(replay), ready_bucket, fleet.revision(i), rounds};
  }
  replays_ = std::move(replays);
  return &fleet;
}

RoundResult RoundRunner::Run(const RoundInput& input) {
  RoundResult out;
  FleetState* fleet = Prepare(input, out.notes);
  if (fleet == nullptr) return out;
  FleetState& state = *fleet;
  if (config_.routing == RoutingKind::kHeat && config_.planner == PlannerKind::kRules && !input.pending.empty()) {
    if (Status s = UseHeatRoutes(map_, config_, state, input.now); !s.ok()) {
      out.notes.push_back("allocation: heat routes not used for the bids: " + s.error().message);
    }
  }
  RoundSegments segments;  // where each robot's new work begins (the time-window planner)
  segments.first_new.assign(input.robots.size(), RoundSegments::kNothingNew);
  segments.in_formation.assign(input.robots.size(), false);
  std::vector<bool> queued(input.robots.size());  // has orders (before or from this round)
  for (std::size_t i = 0; i < input.robots.size(); ++i) queued[i] = input.robots[i].has_queue();
  // The round's orders as one batch; each award is recorded as the strategy commits it, with
  // the part of each winner's plan it added.
  std::vector<const Order*> batch;
  for (const auto& pending : input.pending) {
    if (static_cast<std::size_t>(pending->team_size()) <= input.robots.size()) batch.push_back(pending.get());
  }
  std::vector<std::size_t> sizes;  // each robot's plan size before the next award
  for (std::size_t i = 0; i < state.robot_count(); ++i) sizes.push_back(state.plan(i).waypoints.size());
  double start = stopwatch_ ? stopwatch_() : 0.0;
  allocator_->AllocateBatch(batch, state, [&](const Order& order, Result<AwardExplanation> award) {
    const double now = stopwatch_ ? stopwatch_() : 0.0;
    const double seconds = now - start;
    start = now;
    if (!award.ok()) {
      out.notes.push_back("order " + order.id + " not allocated (stays accepted): " + award.error().message);
      return;
    }
    RoundAward a;
    a.order_id = order.id;
    a.seconds = seconds;
    for (const auto& w : award->winners) {
      const std::size_t i = *state.FindRobot(w);
      const auto& fp = state.plan(i).waypoints;
      // A robot without a queue gets the whole plan (its start waypoint included).
      const std::size_t from = queued[i] ? sizes[i] : 0;
      queued[i] = true;
      sizes[i] = fp.size();
      segments.first_new[i] = std::min(segments.first_new[i], from);
      if (award->winners.size() > 1) segments.in_formation[i] = true;
      a.segments.emplace_back(fp.begin() + static_cast<std::ptrdiff_t>(std::min(from, fp.size())), fp.end());
      a.after_departure.push_back(from > 0 && from <= fp.size() ? fp[from - 1].departure() : 0.0);
    }
    a.award = std::move(award).value();
    out.awards.push_back(std::move(a));
  });
  if (config_.planner == PlannerKind::kTimeWindows && !out.awards.empty()) {
    PlanAwardsInWindows(map_, *routes_, config_, state, segments, input.now, out.awards, out.notes);
  } else if (config_.planner == PlannerKind::kConflictElimination && !out.awards.empty()) {
    PlanAwardsByConflictElimination(map_, *routes_, config_, state, segments, input.now, out.awards, out.notes);
  } else if (config_.routing == RoutingKind::kHeat && !out.awards.empty()) {
    RouteAwardsByHeat(*map_, config_, state, segments, input.now, out.awards, out.notes);
  }
  return out;
}

bool RoundRunner::Replay::Matches(const RoundRobot& r) const {
  return r.assignment == robot.assignment && r.start == robot.start && r.last_reached == robot.last_reached &&
         r.kind == robot.kind && r.queue == robot.queue;
}

std::shared_ptr<const RoundRunner::Replay> RoundRunner::ReplayAnew(FleetState& fleet, std::size_t index,
                                                                   const RoundRobot& r, std::size_t bucket,
                                                                   bool keep) {
  auto replay = std::make_shared<Replay>();
  replay->robot = r;
  // Replayed from ready time 0, then moved to the round's ready bucket: the same robot and
  // queue give the very same entry whichever round replays it, and a snapshot of it moves to
  // a later bucket exactly as a new replay would (a round's result is a function of its input
  // alone: the journal's replay runs only the rounds it recorded).
  if (!fleet.Reset(index, r.start, 0.0).ok()) return nullptr;  // the caller's Reset says why
  ReplayQueue(fleet, index, r, replay->notes);
  if (keep) replay->snapshot = std::make_shared<const FleetState::RobotSnapshot>(fleet.Snapshot(index));
  (void)fleet.Settle(index, bucket, replay->snapshot ? &replay->snapshot->trace : nullptr);  // a valid index
  return replay;
}

bool RoundRunner::ReplayQueue(FleetState& fleet, std::size_t index, const RoundRobot& r,
                              std::vector<std::string>& notes) const {
  const Assignment& plan = *r.assignment;
  const auto& stored = plan.plan.waypoints;
  const std::vector<std::size_t> starts = SegmentStarts(plan);
  for (std::size_t k = 0; k < plan.order_ids.size(); ++k) {
    if (k >= r.queue.size() || !r.queue[k]) {
      notes.push_back("allocation: queue of " + r.id + " replayed up to " + plan.order_ids[k] +
                      " only: the order is not known");
      return false;
    }
    const Order& order = *r.queue[k];
    std::vector<PointId> ahead;
    if (k == 0) {  // only the picks still ahead of the robot
      for (std::size_t w = 1; w < starts[1] && w < stored.size(); ++w) {
        if (stored[w].action == WaypointAction::kPick && static_cast<std::uint64_t>(stored[w].seq) > r.last_reached) {
          ahead.push_back(stored[w].point);
        }
      }
      if (ahead.empty()) ahead.push_back(order.drop);  // picked: only the drop is left
    }
    const std::vector<PointId>& picks = k == 0 ? ahead : order.picks;
    // The stored waypoints of this order (the first: those not reached yet), re-timed from
    // the queue's end: no routing (on a large floor every random pick is a new destination
    // of the lazy route table, and re-routing every queue each round thrashed its cache).
    const std::size_t begin = starts[k], end = starts[k + 1];
    const std::size_t stop = std::min(end, stored.size());
    std::vector<Waypoint> segment;
    segment.reserve(stop - std::min(begin, stop) + 1);
    const PointId from = fleet.summary(index).end_point;
    Waypoint anchor;  // a move at the queue's end point, at time 0 (seq 0)
    anchor.point = from;
    anchor.xy = map_->point(from).position;
    segment.push_back(anchor);
    for (std::size_t w = begin; w < stop; ++w) {
      Waypoint wp = stored[w];
      if (k == 0 && static_cast<std::uint64_t>(wp.seq) <= r.last_reached) continue;
      if (segment.size() == 1) {
        // Reach the first one from the queue's end at cruise speed, then keep the plan's pace.
        const double lead = (wp.xy - segment.front().xy).norm() / config_.speed;
        segment.front().eta = wp.eta - lead;
      }
      segment.push_back(wp);
    }
    PlanTask task = fleet.TaskOf(picks, order.drop, order.work_time);
    // The stored waypoints keep the poses; the headings matter only to AssignSingle below (a
    // whole order: the first one's stops ahead are no longer the order's stop indices).
    if (k > 0) task.stop_headings = order.stop_headings;
    Status assigned = InvalidArgument("no stored waypoints");
    // Unpublished: the caller gives the predictor the whole replayed queue once.
    if (segment.size() >= 2) assigned = fleet.AssignPlanned(index, order.id, task, std::move(segment), false);
    if (!assigned.ok()) assigned = fleet.AssignSingle(index, order.id, task);
    if (!assigned.ok()) {
      notes.push_back("allocation: queue of " + r.id + " replayed up to " + order.id + " only: " +
                      assigned.error().message);
      return false;
    }
  }
  return true;
}

}  // namespace dispatch::engine
