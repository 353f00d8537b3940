// FNV-1a 64 (Fowler-Noll-Vo): the one content hash of the project - order contents for
// idempotent resubmission (storage), the map version tag (dispatchd). Not cryptographic: it
// tells equal content from different content, nothing more. Pure; thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace dispatch::engine {

inline constexpr std::uint64_t kFnv1a64OffsetBasis = 14695981039346656037ull;
inline constexpr std::uint64_t kFnv1a64Prime = 1099511628211ull;

// `basis` other than the standard one only to read hashes made with another (see the map
// version tag in server/server.h).
std::uint64_t Fnv1a64(std::string_view text, std::uint64_t basis = kFnv1a64OffsetBasis);
// 16 lower-case hex digits.
std::string Hex64(std::uint64_t value);

}  // namespace dispatch::engine
