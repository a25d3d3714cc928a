#pragma once
/// \file
/// The command server's state and its parts (internal to rt/controller):
///   command_server.cpp    CommandServer, the poll loop, pending requests
///   command_socket.cpp    the listening socket, access checks, connections, I/O
///   command_requests.cpp  request lines: framing, parsing, dispatch
///   command_verbs.cpp     the verb table (command_verbs.hpp), HELP
///   command_handlers.cpp  the verbs' handlers
///   command_stream.cpp    the streaming requests: WATCH and RUN scripts
///
/// Non-RT: everything runs in CommandServer::poll() on the owner's thread.

#include <sys/socket.h>  // ucred
#include <sys/un.h>      // sockaddr_un
#include <poll.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rt/controller/command_server.hpp"
#include "rt/controller/command_verbs.hpp"
#include "rt/controller/script.hpp"

namespace canmotion::rt::command {

using Wall = std::chrono::steady_clock;

/// What a client's connection is doing.
enum class Mode : std::uint8_t { kIdle, kPending, kScriptText, kScript, kWatch };

/// The ScriptHost of one client's script: delegates to the server's host
/// but waits only for its own commands and reads the server's cached
/// status (one snapshot copy per poll, not one per tag).
class ClientHost final : public script::ScriptHost {
 public:
  explicit ClientHost(Service& s) : s_(s) {}
  std::optional<std::string> check_call(std::string_view call) override;
  std::optional<std::string> check_tag(std::string_view tag, bool for_write) override;
  std::optional<std::string> execute(std::string_view call, std::string* control_tag) override;
  bool settled() override;
  std::optional<double> read(std::string_view tag, std::string* error) override;
  std::optional<std::string> write(std::string_view tag, double value) override;
  void declare(std::string_view tag) override;

 private:
  Service& s_;
  std::uint64_t seq_ = 0;
};

/// A running script: the Script must outlive its Runner (which refers to it).
struct ScriptRun {
  script::Script script;
  std::unique_ptr<ClientHost> host;
  std::unique_ptr<script::Runner> runner;
};

/// One connection.
struct Client {
  int fd = -1;
  unsigned id = 0;
  ucred cred{};
  std::string in;   ///< received, not yet handled (bounded by max_line while busy)
  std::string out;  ///< waiting to be sent (bounded by max_output)
  bool eof = false;      ///< the peer closed its sending side: finish, then close
  bool closing = false;  ///< close once `out` is sent
  bool dead = false;     ///< close now
  Mode mode = Mode::kIdle;
  // kPending: an instruction call, or a write the RT thread applies
  std::uint64_t seq = 0;
  std::string control;
  std::string reply;  ///< kPending after SET of an array element or MODE: the reply once applied
  Wall::time_point since{};
  // kScriptText / kScript
  std::string script_name;
  std::string script_text;
  std::unique_ptr<ScriptRun> run;
  // kWatch
  double interval = 0, next = 0;
  std::vector<std::string> watch;
};

/// Parse a finite double covering the whole word.
[[nodiscard]] std::optional<double> number(const std::string& w);
/// ASCII case-insensitive equality.
[[nodiscard]] bool iequals(std::string_view a, std::string_view b) noexcept;
/// strerror(e).
[[nodiscard]] std::string errno_text(int e);

/// The server's state. One member function per step; the files above each
/// define one group of them.
struct Service {
  Service(Controller& c, CommandServerOptions o)
      : ctl(c), own_host(c), host(o.shared_host ? *o.shared_host : own_host), opt(std::move(o)) {}

  Controller& ctl;
  ControllerHost own_host;  ///< used unless options.shared_host is set
  ControllerHost& host;
  CommandServerOptions opt;
  std::string refusal;  ///< non-empty: motion is refused (controlled stop)
  int listen_fd = -1;
  gid_t sock_gid = 0;
  std::string group_name;
  std::vector<std::unique_ptr<Client>> clients;
  unsigned next_id = 1;
  double now = 0;
  Wall::time_point last_io{};
  bool first_io = true;
  std::unique_ptr<Status> snap = std::make_unique<Status>();  // large: off the stack
  bool fresh = false;
  std::vector<pollfd> pfds;
  std::array<std::string_view, 32> motion_bits{}, status_bits{}, fault_bits{};

  // command_server.cpp: the poll loop
  void log(const std::string& l) const;
  const Status& status();
  void poll_once(double now_s);
  bool io_due();
  void poll_sockets();
  void remove_finished();
  void advance(Client& c);
  void advance_pending(Client& c);
  void drop(Client& c, const char* why);
  void make_pending(Client& c, std::string reply);

  // command_socket.cpp: set-up, connections, output
  void open();
  void resolve_group();
  void replace_stale_socket(const sockaddr_un& addr);
  void bind_and_listen(const sockaddr_un& addr);
  void register_tags();
  void close_listen();
  void send_line(Client& c, std::string_view line);
  void fail_and_close(Client& c, const std::string& msg);
  void flush(Client& c);
  bool peer_allowed(int fd, const ucred& cr) const;
  void accept_all();
  void refuse(Client& c, const std::string& log_line, const std::string& reply);
  void read_from(Client& c);

  // command_requests.cpp: framing and dispatch
  void handle_input(Client& c);
  void handle_line(Client& c, const std::string& raw);
  void collect_script_line(Client& c, const std::string& raw);

  // command_handlers.cpp: the verbs (rows of command_verbs.cpp)
  void do_call(Client& c, const Request& r);
  void finish_call(Client& c);
  void do_get(Client& c, const Request& r);
  void do_set(Client& c, const Request& r);
  void do_status(Client& c, const Request& r);
  std::string status_line(std::size_t axis, const AxisSnapshot& x);
  void do_stats(Client& c, const Request& r);
  void do_mode(Client& c, const Request& r);
  void do_help(Client& c, const Request& r);
  void do_quit(Client& c, const Request& r);

  // command_stream.cpp: WATCH and RUN
  void do_watch(Client& c, const Request& r);
  void do_unwatch(Client& c, const Request& r);
  void advance_watch(Client& c);
  void do_run(Client& c, const Request& r);
  void do_end(Client& c, const Request& r);
  void start_script(Client& c);
  void advance_script(Client& c);
};

}  // namespace canmotion::rt::command
