// dispatchd: the warehouse dispatch service. See server/config.h for the flags and
// server/server.h for what runs. SIGTERM / SIGINT shut it down gracefully.
#include <spdlog/spdlog.h>

#include <sys/resource.h>

#include <csignal>
#include <cstdio>

#include "server/config.h"
#include "server/server.h"

namespace {

// Every connection and stream costs a descriptor; with a low soft limit (256 under some
// launchers) idle connections locked gRPC out for good (issue 18 §3). The soft limit is raised
// to the hard one.
void RaiseDescriptorLimit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur >= limit.rlim_max) return;
  const rlim_t before = limit.rlim_cur;
  limit.rlim_cur = limit.rlim_max;
  if (setrlimit(RLIMIT_NOFILE, &limit) == 0) {
    spdlog::info("open files: soft limit raised from {} to {}", before, limit.rlim_cur);
  } else {
    spdlog::warn("open files: the soft limit of {} could not be raised", before);
  }
}

}  // namespace

int main(int argc, char** argv) {
  auto parsed = dispatch::server::ParseCommandLine(argc, argv);
  if (!parsed.ok()) {
    std::fprintf(stderr, "dispatchd: %s\n", parsed.error().message.c_str());
    return 2;
  }
  if (parsed->exit_code >= 0) return parsed->exit_code;
  const auto& config = parsed->config;
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  RaiseDescriptorLimit();
  // A file grown to the file-size limit (RLIMIT_FSIZE, a quota) fails the write with EFBIG
  // like a full disk instead of killing the process: the store reports it, SubmitOrder answers
  // UNAVAILABLE, and the service goes on once there is room (issue 18 §5).
  std::signal(SIGXFSZ, SIG_IGN);

  // Block the shutdown signals in every thread (threads inherit the mask) and wait for them
  // here, so no handler runs inside gRPC or SQLite code.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);  // re-read the token file
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  auto server = dispatch::server::DispatchServer::Start(config);
  if (!server.ok()) {
    spdlog::error("dispatchd: {}", server.error().message);
    return 1;
  }
  int signal = 0;
  for (;;) {
    sigwait(&signals, &signal);
    if (signal != SIGHUP) break;
    (void)(*server)->ReloadTokens();
  }
  spdlog::info("signal {} received: shutting down", signal);
  (*server)->Shutdown();
  return 0;
}
