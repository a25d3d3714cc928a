#pragma once
/// \file
/// CommandServer: the canmotionctl socket. A UNIX stream socket that serves
/// the line-based text protocol of tools/canmotionctl/README.md to several
/// clients at once: instruction calls, GET/SET of tags, STATUS, WATCH, RUN
/// (motion scripts), STATS, HELP. The verbs are one table
/// (command_verbs.hpp); the parts of the server are listed in
/// command_service.hpp.
///
/// Non-RT. Everything happens in poll(), which the owner calls from its non-RT
/// housekeeping (once per cycle: between cycles in --sim, half a period
/// after the cycle's deadline in real time). poll()
/// never blocks: sockets are non-blocking, a request that waits for the
/// planner (an instruction call, a script, a WATCH) is per-client state that
/// poll() advances, and every per-client buffer is bounded, so a slow, dead or
/// malicious client is disconnected and never delays the cycle or other
/// clients.
///
/// Access: the socket file is mode 0660, owned by the configured group (or
/// the daemon's group), and every peer is checked with SO_PEERCRED: root, the
/// daemon's user and members of the socket's group (primary or
/// supplementary, SO_PEERGROUPS) are served; others get one ERR line and are
/// disconnected.
///
/// Not thread-safe: one thread owns a server (the same thread that owns the
/// other ControllerHosts of the controller, or any other non-RT thread:
/// Controller::submit is thread-safe).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "rt/controller/controller.hpp"
#include "rt/controller/host.hpp"
#include "rt/cycle_stats.hpp"

namespace canmotion::rt {

namespace command {
struct Service;  // the server's state and its parts (command_service.hpp)
}

/// How a CommandServer is set up.
struct CommandServerOptions {
  /// Socket path (at most 107 bytes, the sun_path limit). Its directory must exist.
  std::string path;
  /// Group that owns the socket (the socket is chowned to it); empty: the
  /// daemon's effective group. Peers in this group are served.
  std::string group;
  /// Clients served at once; more are told so and disconnected. Bound: a
  /// handful of operators, scripts and dashboards; 16 leaves room.
  std::size_t max_clients = 16;
  /// Longest request line in bytes; a longer one disconnects the client with
  /// an ERR line. Bound: instruction calls are < 300 bytes; 4096 leaves room.
  std::size_t max_line = 4096;
  /// Output waiting for a client that does not read (bytes). Beyond it the
  /// client is disconnected. Bound: 10 s of a 1 ms WATCH of 8 tags.
  std::size_t max_output = 1u << 20;
  /// Largest script accepted by RUN (bytes).
  std::size_t max_script = 1u << 20;
  /// Wall time between two socket polls (accept/read/write system calls).
  /// 0 = at every poll() call. Use ~1 ms for --sim, where poll() is called
  /// once per simulated cycle, so the simulation is not slowed by system
  /// calls. Pending requests, scripts and WATCH lines are advanced at every
  /// poll() call regardless (they need no system call).
  double io_interval_s = 0.0;
  /// Wall time an instruction call may wait for the planner before the
  /// client gets `ERR timeout` (the cycle is not running).
  double instruction_timeout_s = 5.0;
  /// Log sink for connections, refusals and disconnections (one line, no
  /// newline). Default: stderr with the prefix "command server: ".
  std::function<void(const std::string&)> log;
  /// The cyclic executive's statistics (wake-up latency, execution time,
  /// period, overruns), if the owner has them: shown by STATS and readable as
  /// tags `Controller.<field>` (e.g. Controller.latency_max_ns). Empty: STATS
  /// shows the controller's counters only.
  std::function<CycleStats()> cycle_stats;
  /// Execute through this host instead of an own one, so that clients and the
  /// owner (e.g. the daemon's `--script`) share user tags (`SET t 1` is seen
  /// by `WAIT UNTIL t`). Must outlive the server and be used on the server's
  /// thread only. Null: the server has its own host.
  ControllerHost* shared_host = nullptr;
};

/// The socket server. Construction creates the socket; destruction closes
/// every connection and removes the socket file.
class CommandServer {
 public:
  /// Create, bind and listen. Throws std::runtime_error with a message that
  /// names the path or group and says what to do (directory missing, path
  /// too long, another daemon listening, unknown group, chown refused).
  /// A stale socket file (nobody listening) is replaced. Not realtime.
  CommandServer(Controller& controller, CommandServerOptions options);
  ~CommandServer();
  CommandServer(const CommandServer&) = delete;
  CommandServer& operator=(const CommandServer&) = delete;

  /// Serve: accept, read, execute, advance pending requests, write. `now_s`
  /// is the controller time (cycle * period), the time base of WAITs in
  /// scripts, WATCH intervals and `t=` stamps. Never blocks; never throws
  /// for anything a client does (a client whose request raises is
  /// disconnected with an ERR line). Not realtime.
  void poll(double now_s);

  /// From now on refuse motion: instruction calls and RUN get `ERR <reason>`,
  /// and running client scripts are stopped with that line (motion they
  /// already started is the owner's to stop). GET, SET, STATUS, WATCH and
  /// STATS still work. Used by canmotiond's controlled stop. Not realtime.
  void refuse_motion(std::string reason);

  /// Clients currently connected.
  [[nodiscard]] std::size_t client_count() const noexcept;
  /// The socket path.
  [[nodiscard]] const std::string& path() const noexcept;
  /// The host the server executes through (its user tags are the ones SET writes).
  [[nodiscard]] ControllerHost& host() noexcept;

 private:
  std::unique_ptr<command::Service> impl_;
};

}  // namespace canmotion::rt
