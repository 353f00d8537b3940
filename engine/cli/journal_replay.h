// dispatch-sim replay (issue 15 §4): a run dispatchd recorded in its database, fed through a
// fresh dispatch core again (engine/dispatch/core_replay.h) and compared call by call; and,
// with what_if, its orders re-run on the simulator's motion model (SimulateOnCore) with the
// recorded settings and with another strategy, zeta or fleet size, side by side.
//
// Reads the database through storage/journal_store.h (read-only); the map and every setting
// come from the run's setup, so nothing but the file is needed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/common/result.h"
#include "engine/dispatch/core_journal.h"
#include "engine/map/warehouse_map.h"
#include "engine/sim/stream_result.h"

namespace dispatch::engine {

struct ReplayArgs {
  std::string db;
  std::int64_t run = 0;  // 0: the newest run
  bool list = false;     // list the runs and exit
  bool what_if = false;
  std::string strategy;        // what-if ("": the recorded one)
  std::optional<double> zeta;  // what-if
  std::size_t robots = 0;      // what-if: the first this many (natural order); 0: all
  double dt = 0.1;             // what-if time step, s
  double max_time = 36000.0;   // what-if: simulated seconds before unfinished orders fail
};

// Writes a SimulateOnCore run's journal (SimulateOnCore's `journal`) as a new run of the SQLite
// file at `db`, with the setup it ran with, so `replay --db` and SQL over core_journal read it
// as they read dispatchd's (`dispatch-sim stream --journal FILE`).
Status WriteSimulationJournal(const std::string& db, const std::string& map_source, const WarehouseMap& map,
                              const StreamConfig& config, const std::vector<JournalEntry>& journal);

// Exit status: 0 matched (and, with what_if, every order completed in the what-if run); 1 an
// error or a divergence (named on stdout); 2 the what-if left orders unfinished.
int RunReplay(const ReplayArgs& args);

}  // namespace dispatch::engine
