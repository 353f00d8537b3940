// JSON objects that name one key twice: every JSON reader of the product refuses them (issue
// 18 §3: a repeated key was taken silently, the last one winning, so two readers of one
// document could see different values). Used by the REST bodies, the token file, the map
// reader and the order files.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace dispatch::formats {

// The first key an object of `json` repeats; nullopt when none does (or when `json` is not
// JSON: its own reader says why).
std::optional<std::string> FirstDuplicateKey(std::string_view json);

}  // namespace dispatch::formats
