// The allocation explanation as the journal stores it: a progress event whose detail is
// "allocation: " + JSON, so it survives restarts. (REST bodies are proto JSON:
// server/rest_views.h.) Pure functions; thread-safe.
#pragma once

#include <optional>
#include <string>

#include "server/snapshot.h"

namespace dispatch::server {

inline constexpr const char* kAllocationDetailPrefix = "allocation: ";

std::string AllocationDetail(const AllocationRecord& allocation);
// nullopt when `detail` is not an allocation detail (or is corrupt).
std::optional<AllocationRecord> ParseAllocationDetail(const std::string& detail);

}  // namespace dispatch::server
