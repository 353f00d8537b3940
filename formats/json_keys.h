// JSON objects that name one key twice: every JSON reader of the product refuses them (issue
// 18 §3: a repeated key was taken silently, the last one winning, so two readers of one
// document could see different values). Used by the REST bodies, the token file, the map
// reader and the order files, in the one parse each does.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <string_view>

namespace dispatch::formats {

// nlohmann::json::parse(json) (it throws as that does), also setting *duplicate to the first
// key an object of `json` repeats (nullopt: none).
nlohmann::json ParseNotingDuplicateKey(std::string_view json, std::optional<std::string>* duplicate);

}  // namespace dispatch::formats
