#include "formats/json_keys.h"

#include <set>
#include <vector>

namespace dispatch::formats {

nlohmann::json ParseNotingDuplicateKey(std::string_view json, std::optional<std::string>* duplicate) {
  duplicate->reset();
  std::vector<std::set<std::string>> open;  // the keys of each object being read, innermost last
  const nlohmann::json::parser_callback_t check = [&](int, nlohmann::json::parse_event_t event,
                                                       nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start) open.emplace_back();
    if (event == Event::object_end && !open.empty()) open.pop_back();
    if (event == Event::key && !open.empty() && !*duplicate && parsed.is_string() &&
        !open.back().insert(parsed.get<std::string>()).second) {
      *duplicate = parsed.get<std::string>();
    }
    return true;  // keep everything: this is the caller's parse
  };
  return nlohmann::json::parse(json.begin(), json.end(), check);
}

}  // namespace dispatch::formats
