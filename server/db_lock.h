// One dispatchd per database (issue 18 §3: a second one on the same file would interleave its
// writes with the first's): an exclusive flock(2) on "<db>.lock", held for the server's life
// and released by the kernel when the process ends, however it ends. The lock file says
// which process holds it. (Not the database file itself: SQLite's own POSIX locks on it are
// dropped when any descriptor of that file in the process is closed.)
#pragma once

#include <string>

#include "engine/common/result.h"

namespace dispatch::server {

class DatabaseLock {
 public:
  // kFailedPrecondition naming the holder's pid when another process (or another server in
  // this one) holds it; kIoError when the lock file cannot be created.
  static engine::Result<DatabaseLock> Acquire(const std::string& db_path);
  DatabaseLock(DatabaseLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  DatabaseLock& operator=(DatabaseLock&& other) noexcept;
  DatabaseLock(const DatabaseLock&) = delete;
  DatabaseLock& operator=(const DatabaseLock&) = delete;
  ~DatabaseLock();

 private:
  explicit DatabaseLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace dispatch::server
