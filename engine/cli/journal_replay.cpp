#include "engine/cli/journal_replay.h"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <vector>

#include "engine/dispatch/core_replay.h"
#include "engine/dispatch/strategy.h"
#include "engine/io/map_json.h"
#include "engine/routing/route_table.h"
#include "engine/sim/core_stream.h"
#include "storage/journal_json.h"
#include "storage/journal_store.h"

namespace dispatch::engine {
namespace {

constexpr int kPage = 20000;  // entries read at a time

int FailReplay(const std::string& message) {
  std::cerr << "dispatch-sim replay: " << message << "\n";
  return 1;
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ",") + s;
  return out;
}

std::string Time(const std::optional<double>& t, double t0) {
  if (!t) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", *t - t0);
  return buf;
}

// One column of the side-by-side table.
struct Column {
  std::string label, strategy;
  double zeta = 0.0;
  std::size_t robots = 0, completed = 0, orders = 0;
  double makespan = 0.0, per_hour = 0.0, waiting = 0.0;
  std::size_t replans = 0, grants = 0;
};

Column FromSimulation(const std::string& label, const std::string& strategy, double zeta, std::size_t robots,
                      const StreamResult& r) {
  Column c{label, strategy, zeta, robots, r.completed, r.orders.size()};
  c.makespan = r.makespan;
  c.per_hour = r.throughput_per_hour;
  c.waiting = r.total_waiting_time;
  c.replans = r.traffic.replans;
  c.grants = r.traffic.grants;
  return c;
}

void PrintColumns(const std::vector<Column>& cols) {
  auto row = [&](const char* name, auto cell) {
    std::printf("  %-22s", name);
    for (const Column& c : cols) std::printf(" %16s", cell(c).c_str());
    std::printf("\n");
  };
  auto num = [](double v, const char* fmt) {
    char buf[48];
    std::snprintf(buf, sizeof buf, fmt, v);
    return std::string(buf);
  };
  row("", [](const Column& c) { return c.label; });
  row("strategy", [](const Column& c) { return c.strategy; });
  row("zeta", [&](const Column& c) { return num(c.zeta, "%g"); });
  row("robots", [](const Column& c) { return std::to_string(c.robots); });
  row("completed", [](const Column& c) { return std::to_string(c.completed) + "/" + std::to_string(c.orders); });
  row("makespan (s)", [&](const Column& c) { return num(c.makespan, "%.1f"); });
  row("orders/h", [&](const Column& c) { return num(c.per_hour, "%.1f"); });
  row("waiting (robot-s)", [&](const Column& c) { return num(c.waiting, "%.1f"); });
  row("detours", [](const Column& c) { return std::to_string(c.replans); });
  row("intersection grants", [](const Column& c) { return std::to_string(c.grants); });
}

struct Loaded {
  storage::JournalRun run;
  storage::RunSetup setup;
  ReplaySetup replay;
};

Result<Loaded> Load(storage::JournalStore& journal, std::int64_t wanted) {
  auto runs = journal.Runs();
  if (!runs.ok()) return runs.error();
  if (runs->empty()) return NotFound("the database has no recorded runs");
  const storage::JournalRun* run = &runs->back();
  if (wanted != 0) {
    run = nullptr;
    for (const auto& r : *runs) {
      if (r.run == wanted) run = &r;
    }
    if (!run) return NotFound("no run " + std::to_string(wanted) + " (dispatch-sim replay --db FILE --list)");
  }
  auto setup = storage::DecodeRunSetup(run->setup);
  if (!setup.ok()) return setup.error();
  auto map = ParseMapJson(setup->map_json);
  if (!map.ok()) return map.error();
  Loaded out{*run, *setup, {}};
  out.replay.map = std::make_shared<const WarehouseMap>(std::move(map).value());
  RouteTableOptions route_options;
  route_options.speed = setup->allocation.speed;
  route_options.turn_penalty_s = setup->allocation.turn_time;
  route_options.lazy_cache_bytes = setup->route_cache_bytes;
  auto method = ParseRouteTableMethod(setup->route_table);  // the run's table: its ties
  if (!method.ok()) return method.error();
  route_options.method = *method;
  auto routes = MakeRouteTable(out.replay.map, route_options);
  if (!routes.ok()) return routes.error();
  out.replay.routes = std::move(routes).value();
  out.replay.core = setup->core;
  out.replay.strategy = setup->strategy;
  out.replay.allocation = setup->allocation;
  return out;
}

int List(storage::JournalStore& journal) {
  auto runs = journal.Runs();
  if (!runs.ok()) return FailReplay(runs.error().message);
  std::printf("run  entries  bytes     truncated  setup\n");
  for (const auto& r : *runs) {
    auto setup = storage::DecodeRunSetup(r.setup);
    std::printf("%-4lld %-8llu %-9llu %-10s %s\n", static_cast<long long>(r.run),
                static_cast<unsigned long long>(r.entries), static_cast<unsigned long long>(r.bytes),
                r.truncated ? "yes" : "no",
                setup.ok() ? (setup->map_source + ", " + setup->strategy).c_str() : "(unreadable)");
  }
  return 0;
}

}  // namespace

Status WriteSimulationJournal(const std::string& db, const std::string& map_source, const WarehouseMap& map,
                              const StreamConfig& config, const std::vector<JournalEntry>& journal) {
  auto opened = storage::JournalStore::Open(db);
  if (!opened.ok()) return opened.error();
  storage::RunSetup setup;
  setup.map_json = WriteMapJson(map);
  setup.map_source = map_source;
  setup.strategy = AllocationStrategyName(config.strategy);
  setup.allocation = config.allocation;
  setup.core = CoreOptionsOf(config);
  setup.core.traffic.speed = config.allocation.speed;
  auto encoded = storage::EncodeRunSetup(setup);
  if (!encoded.ok()) return encoded.error();
  auto run = (*opened)->StartRun(0.0, *encoded, 5);
  if (!run.ok()) return run.error();
  constexpr std::size_t kChunk = 10000;
  for (std::size_t i = 0; i < journal.size(); i += kChunk) {
    const std::vector<JournalEntry> chunk(journal.begin() + static_cast<std::ptrdiff_t>(i),
                                          journal.begin() + static_cast<std::ptrdiff_t>(std::min(journal.size(), i + kChunk)));
    if (auto written = (*opened)->Append(*run, chunk); !written.ok()) return written.error();
  }
  return Ok{};
}

int RunReplay(const ReplayArgs& a) {
  auto opened = storage::JournalStore::Open(a.db, /*read_only=*/true);
  if (!opened.ok()) return FailReplay(opened.error().message);
  storage::JournalStore& journal = **opened;
  if (a.list) return List(journal);
  auto loaded = Load(journal, a.run);
  if (!loaded.ok()) return FailReplay(loaded.error().message);
  auto replay = CoreReplay::Create(loaded->replay);
  if (!replay.ok()) return FailReplay(replay.error().message);
  CoreReplay& core = **replay;

  // The recorded run, entry by entry.
  std::vector<Order> orders;                 // as they entered the core (what-if)
  std::map<std::string, FleetRobot> robots;  // first Hello of each (what-if)
  std::optional<double> t0;                  // the first robot on line
  std::uint64_t expected = 1, matched = 0;
  for (;;) {
    auto page = journal.Read(loaded->run.run, expected - 1, kPage);
    if (!page.ok()) return FailReplay(page.error().message);
    for (const JournalEntry& e : *page) {
      if (e.seq != expected) {
        return FailReplay("the journal of run " + std::to_string(loaded->run.run) + " has a gap: entry " +
                    std::to_string(expected) + " is missing");
      }
      ++expected;
      if (e.input.kind == CoreInput::Kind::kAddOrder && e.input.order) orders.push_back(*e.input.order);
      if (e.input.kind == CoreInput::Kind::kConnect && e.input.robot) {
        robots.emplace(e.input.robot->id, FleetRobot{e.input.robot->id, e.input.robot->current_point, 0.0});
        if (!t0) t0 = e.input.time;
      }
      auto out = core.Feed(e);
      if (!out.ok()) return FailReplay(out.error().message);
      if (*out != e.output) {
        std::printf("replay of run %lld diverged at entry %llu (%s at t=%.3f s%s%s):\n  recorded: %s\n  replayed: %s\n",
                    static_cast<long long>(loaded->run.run), static_cast<unsigned long long>(e.seq),
                    CoreInputKindName(e.input.kind), e.input.time, e.input.robot_id.empty() ? "" : ", robot ",
                    e.input.robot_id.c_str(), e.output.c_str(), out->c_str());
        std::printf("  %llu entries matched before it\n", static_cast<unsigned long long>(matched));
        return 1;
      }
      ++matched;
    }
    if (page->size() < static_cast<std::size_t>(kPage)) break;
  }
  const double start = t0.value_or(0.0);

  // The orders as the run dispatched them.
  std::printf("%-14s %-11s %-9s %-9s %-9s %-9s %s\n", "order", "state", "created", "assigned", "started",
              "finished", "robots");
  Column recorded{"recorded", loaded->setup.strategy, loaded->setup.allocation.zeta, robots.size()};
  double last = 0.0;
  for (const OrderTrace& o : core.orders()) {
    std::printf("%-14s %-11s %-9s %-9s %-9s %-9s %s%s%s\n", o.id.c_str(), OrderStateName(o.state),
                Time(o.created, start).c_str(), Time(o.assigned, start).c_str(), Time(o.started, start).c_str(),
                Time(o.finished, start).c_str(), Join(o.robots).c_str(), o.reason.empty() ? "" : "  ",
                o.reason.c_str());
    ++recorded.orders;
    if (o.state == OrderState::kCompleted) {
      ++recorded.completed;
      last = std::max(last, *o.finished - start);
    }
  }
  recorded.makespan = last;
  recorded.per_hour = last > 0 ? recorded.completed / last * 3600.0 : 0.0;
  recorded.waiting = core.hold_seconds();
  if (const TrafficGate* gate = core.core().gate()) {  // the counters the simulations report
    recorded.replans = gate->stats().replans;
    recorded.grants = gate->stats().grants;
  }
  std::printf("replay of run %lld matched: %llu entries, %zu orders (%zu completed), %zu robots%s\n",
              static_cast<long long>(loaded->run.run), static_cast<unsigned long long>(matched),
              recorded.orders, recorded.completed, robots.size(),
              loaded->run.truncated ? " (recording stopped at its size limit: the run so far)" : "");
  if (!a.what_if) return 0;

  // What if: the recorded orders on the simulator's motion model, with the recorded settings
  // and with the changed ones.
  if (robots.empty()) return FailReplay("--what-if: the run has no robots");
  std::vector<FleetRobot> fleet;
  for (const auto& [id, r] : robots) fleet.push_back(r);
  std::sort(fleet.begin(), fleet.end(), [](const FleetRobot& x, const FleetRobot& y) { return NaturalLess(x.id, y.id); });
  const std::size_t n = a.robots == 0 ? fleet.size() : a.robots;
  if (n > fleet.size()) {
    return FailReplay("--robots " + std::to_string(n) + ": the run had " + std::to_string(fleet.size()) +
                " robots; a what-if can use fewer");
  }
  for (Order& o : orders) {
    o.state = OrderState::kAccepted;
    o.created_time = std::max(0.0, o.created_time - start);
    if (o.release_time) o.release_time = std::max(0.0, *o.release_time - start);
  }
  const std::string strategy = a.strategy.empty() ? loaded->setup.strategy : a.strategy;
  if (auto known = MakeAllocator(strategy); !known.ok()) return FailReplay(known.error().message);
  auto simulate = [&](const std::string& name, double zeta, std::size_t count) -> Result<StreamResult> {
    StreamConfig c;
    c.time_step = a.dt;
    c.max_time = a.max_time;
    c.strategy = ParseAllocationStrategy(name).value_or(AllocationStrategy::kAuction);  // checked above
    c.allocation = loaded->setup.allocation;
    c.allocation.zeta = zeta;
    c.traffic = loaded->setup.core.traffic;
    c.one_formation_per_pick = loaded->setup.core.one_formation_per_pick;
    c.blocked_recovery = loaded->setup.core.blocked_recovery;
    c.check_safety = false;
    return SimulateOnCore(loaded->replay.map, loaded->replay.routes,
                          std::vector<FleetRobot>(fleet.begin(), fleet.begin() + static_cast<std::ptrdiff_t>(count)),
                          orders, c);
  };
  auto same = simulate(loaded->setup.strategy, loaded->setup.allocation.zeta, fleet.size());
  if (!same.ok()) return FailReplay("simulating the recorded settings: " + same.error().message);
  const double zeta = a.zeta.value_or(loaded->setup.allocation.zeta);
  auto changed = simulate(strategy, zeta, n);
  if (!changed.ok()) return FailReplay("simulating the what-if: " + changed.error().message);
  std::printf("\nwhat-if on the simulator's motion model (the recorded orders at their recorded times):\n");
  PrintColumns({recorded, FromSimulation("simulated", loaded->setup.strategy, loaded->setup.allocation.zeta,
                                         fleet.size(), *same),
                FromSimulation("what-if", strategy, zeta, n, *changed)});
  for (const auto* r : {&*same, &*changed}) {
    for (const StreamOrderOutcome& o : r->orders) {
      if (!o.completed) {
        std::printf("  %s: %s failed: %s\n", r == &*same ? "simulated" : "what-if", o.order_id.c_str(),
                    o.failure.c_str());
      }
    }
  }
  return changed->all_completed() ? 0 : 2;
}

}  // namespace dispatch::engine
