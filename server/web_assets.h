// The web map's files (server/web/), built into dispatchd by cmake/embed_files.cmake so the
// page needs no build step and no files beside the binary. Thread-safe (immutable).
#pragma once

#include <string_view>
#include <vector>

namespace dispatch::server {

struct WebAsset {
  std::string_view path;          // "/index.html", "/app.js", ...
  std::string_view content_type;  // from the extension
  std::string_view body;
};

const std::vector<WebAsset>& BuiltInWebAssets();

}  // namespace dispatch::server
