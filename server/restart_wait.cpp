#include "server/restart_wait.h"

namespace dispatch::server {

std::string RestartWait::List() const {
  std::string out;
  for (const auto& id : awaited_) out += (out.empty() ? "" : ", ") + id;
  return out;
}

}  // namespace dispatch::server
