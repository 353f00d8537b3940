// Storage test helpers: fast store options, and a per-test temporary directory under the
// system temp dir that is removed with everything in it when the object goes out of scope.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include "storage/sqlite_store.h"

namespace dispatch::storage::testing {

// Options for tests that write many records: synchronous = NORMAL (durable against a
// process crash, which is all these tests exercise; the kill -9 test uses the defaults).
inline SqliteOptions FastOptions() {
  SqliteOptions options;
  options.full_sync = false;
  return options;
}

class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "dispatch-storage-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace dispatch::storage::testing
