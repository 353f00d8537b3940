// JSON encodings of the dispatch core's journal (issue 15 §4, engine/dispatch/core_journal.h):
// one entry's input (the `input` column; kind and time have their own columns) and a run's
// setup (what the core and the allocation were built with, the map included, so a replay needs
// nothing but the database).
//
// Inputs use short keys (a report is about 120 bytes); doubles print in their shortest
// round-trip form, so a replay reads back exactly the values the core was given. Decoders
// accept what the encoders write and report anything else as kIoError "stored ... is corrupt".
// Pure functions; thread-safe.
#pragma once

#include <cstddef>
#include <string>

#include "engine/allocation/allocation_config.h"
#include "engine/common/result.h"
#include "engine/dispatch/core_journal.h"
#include "engine/dispatch/dispatch_core.h"

namespace dispatch::storage {

using engine::Result;

// What a run was started with.
struct RunSetup {
  std::string version = "1";  // of this encoding
  std::string map_json;       // engine::WriteMapJson of the floor
  std::string map_source;     // where it came from ("builtin:chu2024", a path)
  std::string strategy = "auction";
  engine::AllocationConfig allocation;
  engine::CoreOptions core;
  std::size_t route_cache_bytes = 0;  // the lazy route table's bound (results do not depend on it)
  // The route table's method (RouteTableMethodNames): tables may break ties between routes of
  // equal cost differently, so a replay builds the same one. Journals before it: "floyd".
  std::string route_table = "floyd";
  double time_scale = 1.0;            // dispatcher seconds per wall second
};

Result<std::string> EncodeRunSetup(const RunSetup& setup);
Result<RunSetup> DecodeRunSetup(const std::string& text);

// The input without its kind and time (those are columns).
Result<std::string> EncodeCoreInput(const engine::CoreInput& input);
Result<engine::CoreInput> DecodeCoreInput(engine::CoreInput::Kind kind, double time, const std::string& text);

}  // namespace dispatch::storage
