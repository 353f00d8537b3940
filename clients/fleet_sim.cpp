// fleet-sim: N simulated robots in one process, each with its own FleetService.Connect
// stream (SPEC §5). Robots start at the map's parking stations in station order, then at
// lane points spread over the map (the rule of engine/sim/fleet_placement.h), named R1..RN.
// Each robot follows its released timed waypoints (clients/sim_robot.h) on the dispatcher's
// clock: the server's time and time scale come in Welcome, so both clocks agree.
//
//   fleet-sim --server 127.0.0.1:50051 --robots 18
//   fleet-sim --server ... --robots 18 --drop-every 20 --stall R3 --slow R5:0.5 --delay-ms 50
//   fleet-sim --server ... --robots 2 --first 5      # R5 and R6 on start points 5 and 6
//
// --first K: this process runs robots RK..R(K+N-1) on start points K..K+N-1, so several
// fleet-sim processes can make up one fleet (e.g. robots that join later).
//
// Faults: --drop-every S closes one robot's stream every S wall seconds (round robin, muted
// robots skipped) and reconnects it, saying its last applied sequence; --stall and --slow
// change a robot's motion; --delay-ms delays every robot -> server message.
// --mute ID:AFTER: AFTER wall seconds after start, robot ID goes silent for good, as a robot
// that died: it stops moving and stops sending anything (no reports, heartbeats, acks or
// events) but keeps its stream open, so only the server's heartbeat timeout notices it;
// when the server then closes the stream, the robot does not reconnect.
// --control-fd N: reads commands, one a line, from the inherited descriptor N while running
// (tests trigger faults at a chosen moment, not by the clock): "mute ID" (as --mute, now),
// "drop ID" (as one --drop-every drop, for that robot). Unknown commands are reported on
// stderr; EOF just ends the commands.
// --turn-time S: robots turn in place S seconds per 90 degrees before a new heading (run
// dispatchd with the same --turn-time so that its plans count the turns).
// --kinds K1,K2,...: the robots' kinds in their Hellos (differential, four_wheel_steer),
// taken in turn over this process's robots: "four_wheel_steer" makes every robot one,
// "differential,four_wheel_steer" every second one.
// Runs until SIGINT/SIGTERM or --duration wall seconds. --ready-fd N: once every robot has
// been welcomed, writes "connected N" to the inherited descriptor N and closes it (scripts
// wait on it, no polling).
#include <grpcpp/grpcpp.h>
#include <fcntl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "clients/client_security.h"
#include "clients/robot_stream.h"
#include "clients/sim_robot.h"
#include "warehouse/dispatch/v1/map.grpc.pb.h"

namespace dispatch::clients {
namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct Slot {
  std::unique_ptr<SimRobot> robot;
  std::unique_ptr<RobotStream> stream;
  std::unique_ptr<v1::FleetService::Stub> stub;  // its own channel (--robot-certs), else the shared one
  bool welcomed = false;
  double welcome_server_time = 0.0;
  double time_scale = 1.0;
  double heartbeat_interval = 1.0;
  Clock::time_point welcome_wall;
  Clock::time_point last_sent;
  Clock::time_point last_report;
  Clock::time_point next_connect;
  std::uint64_t acked = 0;
  int connects = 0;
  std::string last_error;
  std::optional<Clock::time_point> mute_at;  // --mute

  double Now(Clock::time_point wall) const {
    return welcome_server_time + Seconds(wall - welcome_wall) * time_scale;
  }
};

// What a run measured (printed at exit, --stats-out as JSON).
struct FleetStats {
  std::size_t robots = 0;
  std::size_t connects = 0;
  // Wall ms a robot stood ready to drive on (arrived, planned departure passed, not held)
  // until the Grant or Resume that released it arrived: the dispatcher's release latency as
  // robots see it, from the report to the reply. Waits announced by a Hold are traffic
  // waits and not counted.
  std::vector<double> release_waits_ms;

  double Percentile(double q) const {
    if (release_waits_ms.empty()) return 0.0;
    std::vector<double> v = release_waits_ms;
    const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  }
  std::string Summary() const {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%zu robots, %zu connects; release latency over %zu waits: p50 %.1f ms, p99 %.1f ms, max %.1f ms",
                  robots, connects, release_waits_ms.size(), Percentile(0.5), Percentile(0.99), Percentile(1.0));
    return buf;
  }
  std::string Json() const {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "{\"robots\": %zu, \"connects\": %zu, \"release_latency_ms\": {\"count\": %zu, "
                  "\"p50\": %.3f, \"p90\": %.3f, \"p99\": %.3f, \"max\": %.3f}}",
                  robots, connects, release_waits_ms.size(), Percentile(0.5), Percentile(0.9), Percentile(0.99),
                  Percentile(1.0));
    return buf;
  }
};

// Robot start points: stations first, then lane points spread evenly (fleet_placement.h).
std::vector<v1::MapPoint> StartPoints(const v1::Map& map, std::size_t count, std::string* error) {
  std::vector<v1::MapPoint> out;
  for (const v1::MapStation& s : map.stations()) {
    if (out.size() == count) break;
    if (s.point_id() < 0 || s.point_id() >= map.points_size()) continue;
    out.push_back(map.points(s.point_id()));
  }
  if (out.size() == count) return out;
  std::vector<int> lanes;
  for (const v1::MapPoint& p : map.points()) {
    if (p.kind() == v1::POINT_KIND_LANE) lanes.push_back(p.id());
  }
  const std::size_t need = count - out.size();
  if (lanes.size() < need) {
    *error = "map '" + map.name() + "' has room for " + std::to_string(out.size() + lanes.size()) +
             " robots, not " + std::to_string(count);
    return {};
  }
  for (std::size_t i = 0; i < need; ++i) out.push_back(map.points(lanes[i * lanes.size() / need]));
  return out;
}

// Non-blocking line reader for --control-fd.
class ControlReader {
 public:
  explicit ControlReader(int fd) : fd_(fd) {
    if (fd_ >= 0) ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK);
  }
  ~ControlReader() {
    if (fd_ >= 0) ::close(fd_);
  }
  ControlReader(const ControlReader&) = delete;
  ControlReader& operator=(const ControlReader&) = delete;
  // Complete lines read so far.
  std::vector<std::string> Poll() {
    std::vector<std::string> lines;
    if (fd_ < 0) return lines;
    char buf[512];
    for (;;) {
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n > 0) {
        pending_.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
        ::close(fd_);  // EOF (or a broken descriptor): no more commands
        fd_ = -1;
      }
      break;
    }
    for (std::size_t nl; (nl = pending_.find('\n')) != std::string::npos;) {
      lines.push_back(pending_.substr(0, nl));
      pending_.erase(0, nl + 1);
    }
    return lines;
  }

 private:
  int fd_;
  std::string pending_;
};

void Mute(Slot& s, const char* how) {
  if (s.robot->muted()) return;
  s.robot->set_muted();
  if (s.stream) s.stream->DiscardPending();
  std::printf("fleet-sim: fault: %s goes silent (%s); its stream stays open\n", s.robot->id().c_str(), how);
  std::fflush(stdout);
}

void Drop(Slot& s) {
  if (s.stream && !s.stream->done()) {
    std::printf("fleet-sim: fault: dropping %s's stream\n", s.robot->id().c_str());
    std::fflush(stdout);
    s.stream->Close();
  }
}

int Main(int argc, char** argv) {
  CLI::App app{"fleet-sim: simulated robots on real gRPC streams"};
  std::string server = "127.0.0.1:50051";
  std::size_t count = 18;
  double speed = 1.0, report_hz = 10.0, tick_hz = 50.0, duration = 0.0, drop_every = 0.0, turn_time = 0.0;
  int delay_ms = 0;
  int ready_fd = -1, control_fd = -1;
  std::size_t first = 1;
  std::vector<std::string> stall, slow, mute, kinds{"differential"};
  std::string stats_out, robot_tokens_file;
  FleetStats stats;
  ClientSecurity security;
  app.add_option("--server", server, "dispatchd gRPC address HOST:PORT")->capture_default_str();
  AddSecurityOptions(app, security);
  app.add_option("--robot-tokens", robot_tokens_file,
                 "JSON object of robot id -> its own bearer token (robot role); others use --token-file");
  std::string robot_certs;
  app.add_option("--robot-certs", robot_certs,
                 "Folder of robots' client certificates (mTLS): <id>.crt and <id>.key per robot, each robot "
                 "on a channel of its own (needs --tls-ca)");
  app.add_option("--robots", count, "Number of robots")->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
  app.add_option("--first", first, "Number of the first robot: runs R<first>.. on start points <first>..")
      ->capture_default_str()->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
  app.add_option("--speed", speed, "Robot speed, m/s")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--report-hz", report_hz, "State reports per wall second")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--tick-hz", tick_hz, "Motion steps per wall second")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--duration", duration, "Stop after this many wall seconds (0: until a signal)");
  app.add_option("--drop-every", drop_every, "Fault: drop and reconnect one stream every S s");
  app.add_option("--delay-ms", delay_ms, "Fault: delay every robot message by this many ms")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--ready-fd", ready_fd, "Write 'connected N' to this inherited fd once all robots are in")
      ->check(CLI::Range(3, 65535));
  app.add_option("--stall", stall, "Fault: these robots never move (ids, repeat)");
  app.add_option("--slow", slow, "Fault: ID:FACTOR drives at FACTOR x speed (repeat)");
  app.add_option("--turn-time", turn_time, "Seconds per 90 degrees a robot turns in place before a new heading")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--kinds", kinds, "Robot kinds, taken in turn over R1, R2, ...: differential, four_wheel_steer")
      ->delimiter(',')->capture_default_str()->check(CLI::IsMember({"differential", "four_wheel_steer"}));
  app.add_option("--mute", mute,
                 "Fault: ID:AFTER - after AFTER wall seconds robot ID stops moving and sending anything, "
                 "keeping its stream open (the server's heartbeat timeout must notice); it never "
                 "reconnects once the server closes the stream (repeat)");
  app.add_option("--stats-out", stats_out,
                 "At exit write JSON figures here: release latency (ms a robot stood ready waiting for "
                 "a Grant or Resume, Holds excluded), robots, reconnects");
  app.add_option("--control-fd", control_fd,
                 "Read fault commands from this inherited fd, one a line: 'mute ID', 'drop ID'")
      ->check(CLI::Range(3, 65535));
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  grpc::ChannelArguments channel_args;
  channel_args.SetMaxReceiveMessageSize(512 << 20);  // GetMap of a large grid floor is many MB
  std::string error;
  if (!Resolve(security, error)) return std::fprintf(stderr, "fleet-sim: %s\n", error.c_str()), 2;
  std::map<std::string, std::string> robot_tokens;
  if (!robot_tokens_file.empty() && !ReadRobotTokens(robot_tokens_file, robot_tokens, error)) {
    return std::fprintf(stderr, "fleet-sim: --robot-tokens: %s\n", error.c_str()), 2;
  }
  auto channel = grpc::CreateCustomChannel(server, Credentials(security), channel_args);
  v1::GetMapResponse map;
  {
    grpc::ClientContext ctx;
    Authorize(ctx, robot_tokens.empty() ? security.token : robot_tokens.begin()->second);
    ctx.set_wait_for_ready(true);
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    const grpc::Status s = v1::MapService::NewStub(channel)->GetMap(&ctx, {}, &map);
    if (!s.ok()) {
      std::fprintf(stderr, "fleet-sim: GetMap from %s failed: %s\n", server.c_str(),
                   s.error_message().c_str());
      return 1;
    }
  }
  std::vector<v1::MapPoint> starts = StartPoints(map.map(), first - 1 + count, &error);
  if (!error.empty()) {
    std::fprintf(stderr, "fleet-sim: %s\n", error.c_str());
    return 1;
  }
  starts.erase(starts.begin(), starts.begin() + static_cast<std::ptrdiff_t>(first - 1));
  auto fleet_stub = v1::FleetService::NewStub(channel);
  if (!robot_certs.empty() && security.tls_ca.empty()) {
    return std::fprintf(stderr, "fleet-sim: --robot-certs needs --tls-ca\n"), 2;
  }
  std::vector<Slot> slots(count);
  std::map<std::string, std::size_t> by_id;
  for (std::size_t i = 0; i < count; ++i) {
    const std::string id = "R" + std::to_string(first + i);
    slots[i].robot = std::make_unique<SimRobot>(
        id, Eigen::Vector2d(starts[i].position().x(), starts[i].position().y()), speed);
    by_id[id] = i;
  }
  for (std::size_t i = 0; i < slots.size(); ++i) {
    slots[i].robot->set_turn_time(turn_time);
    const bool steer = !kinds.empty() && kinds[i % kinds.size()] == "four_wheel_steer";
    slots[i].robot->set_kind(steer ? v1::ROBOT_KIND_FOUR_WHEEL_STEER : v1::ROBOT_KIND_DIFFERENTIAL);
  }
  if (!robot_certs.empty()) {  // each robot shows its own certificate: a channel each
    for (auto& slot : slots) {
      ClientSecurity own = security;
      own.tls_cert = robot_certs + "/" + slot.robot->id() + ".crt";
      own.tls_key = robot_certs + "/" + slot.robot->id() + ".key";
      if (!Resolve(own, error)) return std::fprintf(stderr, "fleet-sim: --robot-certs: %s\n", error.c_str()), 2;
      slot.stub = v1::FleetService::NewStub(grpc::CreateCustomChannel(server, Credentials(own), channel_args));
    }
  }
  for (const std::string& id : stall) {
    if (!by_id.count(id)) return std::fprintf(stderr, "fleet-sim: --stall: no robot %s\n", id.c_str()), 1;
    slots[by_id[id]].robot->set_stalled(true);
  }
  for (const std::string& spec : slow) {
    const auto colon = spec.find(':');
    const std::string id = spec.substr(0, colon);
    double factor = 0.0;
    try {
      factor = colon == std::string::npos ? 0.0 : std::stod(spec.substr(colon + 1));
    } catch (const std::exception&) {
    }
    if (!by_id.count(id) || !(factor > 0.0)) {
      std::fprintf(stderr, "fleet-sim: --slow wants ID:FACTOR with a known id and FACTOR > 0, got '%s'\n",
                   spec.c_str());
      return 1;
    }
    slots[by_id[id]].robot->set_slow_factor(factor);
  }
  const Clock::time_point start = Clock::now();
  for (const std::string& spec : mute) {
    const auto colon = spec.find(':');
    const std::string id = spec.substr(0, colon);
    double after = -1.0;
    try {
      after = colon == std::string::npos ? -1.0 : std::stod(spec.substr(colon + 1));
    } catch (const std::exception&) {
    }
    if (!by_id.count(id) || !(after >= 0.0)) {
      std::fprintf(stderr, "fleet-sim: --mute wants ID:AFTER with a known id and AFTER >= 0 seconds, got '%s'\n",
                   spec.c_str());
      return 1;
    }
    slots[by_id[id]].mute_at =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(after));
  }
  ControlReader control(control_fd);
  std::printf("fleet-sim: %zu robots on map '%s' (version %s), server %s\n", count,
              map.map().name().c_str(), map.version().c_str(), server.c_str());
  std::fflush(stdout);

  // Every robot steps tick_hz times a second, in kPhases staggered groups (robot i in
  // pass i % kPhases): robots are not synchronised, so their events reach the server spread
  // over the tick rather than in one burst of the whole fleet.
  constexpr std::size_t kPhases = 4;
  const auto tick = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / tick_hz / static_cast<double>(kPhases)));
  std::size_t pass = 0;
  const auto report_every = std::chrono::duration<double>(1.0 / report_hz);
  Clock::time_point next_tick = start, next_drop = start + std::chrono::duration_cast<Clock::duration>(
                                                                std::chrono::duration<double>(drop_every));
  std::size_t drop_cursor = 0;
  std::vector<v1::RobotMessage> events;
  std::size_t connected_reported = 0;
  while (!g_stop) {
    const Clock::time_point now = Clock::now();
    if (duration > 0.0 && Seconds(now - start) >= duration) break;
    for (const std::string& line : control.Poll()) {
      std::istringstream words(line);
      std::string verb, id, extra;
      words >> verb >> id >> extra;
      if (verb.empty()) continue;
      auto it = by_id.find(id);
      if ((verb != "mute" && verb != "drop") || it == by_id.end() || !extra.empty()) {
        std::fprintf(stderr, "fleet-sim: --control-fd: ignored '%s' (want 'mute ID' or 'drop ID')\n",
                     line.c_str());
        continue;
      }
      if (verb == "mute") {
        Mute(slots[it->second], "control command");
      } else if (!slots[it->second].robot->muted()) {
        Drop(slots[it->second]);
      }
    }
    for (Slot& s : slots) {
      if (s.mute_at && now >= *s.mute_at) {
        Mute(s, "--mute");
        s.mute_at.reset();
      }
    }
    if (drop_every > 0.0 && now >= next_drop) {
      for (std::size_t tries = 0; tries < count; ++tries) {
        Slot& s = slots[drop_cursor++ % count];
        if (s.robot->muted()) continue;
        Drop(s);
        break;
      }
      next_drop = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(drop_every));
    }
    std::size_t connected = 0;
    const std::size_t phase = pass++ % kPhases;
    for (std::size_t index = 0; index < slots.size(); ++index) {
      Slot& s = slots[index];
      if (index % kPhases != phase) {  // not its pass: only counted
        connected += s.stream && s.welcomed && !s.robot->muted();
        continue;
      }
      if (s.robot->muted()) {
        // Dead: reads nothing, sends nothing, never reconnects; the stream ends when the
        // server gives up on it (heartbeat timeout).
        if (s.stream) {
          s.stream->TakeReceived();
          if (s.stream->done()) {
            std::printf("fleet-sim: %s (silent): the server closed its stream: %s\n",
                        s.robot->id().c_str(), s.stream->status().error_message().c_str());
            std::fflush(stdout);
            s.stream.reset();
          }
        }
        continue;
      }
      if (s.stream && s.stream->done()) {
        const grpc::Status st = s.stream->status();
        if (!st.ok() && st.error_code() != grpc::StatusCode::CANCELLED &&
            st.error_message() != s.last_error) {
          std::fprintf(stderr, "fleet-sim: %s: stream ended: %s\n", s.robot->id().c_str(),
                       st.error_message().c_str());
          s.last_error = st.error_message();
        }
        s.stream.reset();
        s.welcomed = false;
        s.next_connect = now + std::chrono::milliseconds(200);  // reconnect pacing
      }
      if (!s.stream) {
        if (now < s.next_connect) continue;
        const auto own = robot_tokens.find(s.robot->id());
        s.stream = std::make_unique<RobotStream>(s.stub ? *s.stub : *fleet_stub, s.robot->Hello(), std::chrono::milliseconds(delay_ms),
                                                 own != robot_tokens.end() ? own->second : security.token);
        s.last_sent = now;
        ++s.connects;
      }
      for (const RobotStream::Received& received : s.stream->TakeReceived()) {
        const v1::ServerMessage& m = received.message;
        if (m.has_welcome()) {
          s.welcomed = true;
          s.welcome_server_time = m.welcome().server_time();
          s.time_scale = m.welcome().time_scale() > 0.0 ? m.welcome().time_scale() : 1.0;
          s.heartbeat_interval = m.welcome().heartbeat_interval() > 0.0 ? m.welcome().heartbeat_interval() : 1.0;
          s.welcome_wall = now;
        }
        std::optional<double> waited;
        s.robot->Apply(m, s.welcomed ? s.Now(received.time) : -1.0, &waited);
        if (waited) stats.release_waits_ms.push_back(*waited / s.time_scale * 1000.0);
      }
      if (!s.welcomed) continue;
      ++connected;
      if (s.robot->last_applied_sequence() > s.acked) {
        v1::RobotMessage ack;
        ack.mutable_ack()->set_sequence(s.robot->last_applied_sequence());
        s.stream->Send(ack);
        s.acked = s.robot->last_applied_sequence();
        s.last_sent = now;
      }
      events.clear();
      s.robot->Step(s.Now(now), events);
      for (const v1::RobotMessage& e : events) s.stream->Send(e);
      if (!events.empty()) s.last_sent = now;
      if (now - s.last_report >= report_every) {
        s.stream->Send(s.robot->Report());
        s.last_report = s.last_sent = now;
      } else if (Seconds(now - s.last_sent) >= s.heartbeat_interval / 2) {
        v1::RobotMessage hb;
        hb.mutable_heartbeat()->set_robot_unix_ms(
            std::chrono::duration_cast<std::chrono::milliseconds>(
                std::chrono::system_clock::now().time_since_epoch()).count());
        s.stream->Send(hb);
        s.last_sent = now;
      }
      s.stream->Pump();
    }
    if (connected != connected_reported && (connected == count || connected == 0)) {
      std::printf("fleet-sim: %zu of %zu robots connected\n", connected, count);
      std::fflush(stdout);
      connected_reported = connected;
      if (connected == count && ready_fd >= 0) {
        const std::string line = "connected " + std::to_string(count) + "\n";
        if (::write(ready_fd, line.data(), line.size()) != static_cast<ssize_t>(line.size())) {
          std::fprintf(stderr, "fleet-sim: cannot write to --ready-fd %d\n", ready_fd);
        }
        ::close(ready_fd);
        ready_fd = -1;
      }
    }
    next_tick += tick;
    if (next_tick < Clock::now()) next_tick = Clock::now();  // overloaded: do not spiral
    std::this_thread::sleep_until(next_tick);  // pacing of the motion loop
  }
  for (Slot& s : slots) {
    if (s.stream) s.stream->Close();
  }
  for (Slot& s : slots) {
    if (s.stream) s.stream->WaitDone();
  }
  stats.robots = count;
  for (const Slot& s : slots) stats.connects += static_cast<std::size_t>(s.connects);
  std::printf("fleet-sim: %s\n", stats.Summary().c_str());
  if (!stats_out.empty()) {
    std::ofstream out(stats_out, std::ios::trunc);
    out << stats.Json() << "\n";
    if (!out) {
      std::fprintf(stderr, "fleet-sim: cannot write --stats-out %s\n", stats_out.c_str());
      return 1;
    }
  }
  std::printf("fleet-sim: stopped\n");
  return 0;
}

}  // namespace
}  // namespace dispatch::clients

int main(int argc, char** argv) { return dispatch::clients::Main(argc, argv); }
