#include "formats/json_keys.h"

#include <nlohmann/json.hpp>

#include <set>
#include <vector>

namespace dispatch::formats {

std::optional<std::string> FirstDuplicateKey(std::string_view json) {
  std::vector<std::set<std::string>> open;  // the keys of each object being read, innermost last
  std::optional<std::string> duplicate;
  const nlohmann::json::parser_callback_t check = [&](int, nlohmann::json::parse_event_t event,
                                                       nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start) open.emplace_back();
    if (event == Event::object_end && !open.empty()) open.pop_back();
    if (event == Event::key && !open.empty() && !duplicate && parsed.is_string() &&
        !open.back().insert(parsed.get<std::string>()).second) {
      duplicate = parsed.get<std::string>();
    }
    return true;  // (a value a callback discards still has its insides reported: not relied on)
  };
  try {
    const nlohmann::json parsed = nlohmann::json::parse(json.begin(), json.end(), check);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
  return duplicate;
}

}  // namespace dispatch::formats
