#include "rt/controller/command_server.hpp"

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "rt/controller/script.hpp"

namespace canmotion::rt {
namespace {

using Wall = std::chrono::steady_clock;

std::string errno_text(int e) { return std::strerror(e); }

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

/// Split on whitespace.
std::vector<std::string> words(std::string_view s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    const std::size_t b = i;
    while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i > b) out.emplace_back(s.substr(b, i - b));
  }
  return out;
}

/// Parse a finite double covering the whole word.
std::optional<double> number(const std::string& w) {
  if (w.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(w.c_str(), &end);
  if (end != w.c_str() + w.size() || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// Quote a value that has spaces (STATUS fields); `"` inside becomes `'`.
std::string quoted(std::string_view s) {
  std::string o = "\"";
  for (char c : s) o += (c == '"' || c == '\n' || c == '\r') ? '\'' : c;
  return o + "\"";
}

std::string_view axis_state_name(motion::AxisState s) {
  using motion::AxisState;
  switch (s) {
    case AxisState::Ready: return "Ready";
    case AxisState::DriveEnable: return "DriveEnable";
    case AxisState::ServoControl: return "ServoControl";
    case AxisState::Faulted: return "Faulted";
    case AxisState::Shutdown: return "Shutdown";
    case AxisState::Inhibited: return "Inhibited";
    case AxisState::Ungrouped: return "Ungrouped";
    case AxisState::NoModule: return "NoModule";
    case AxisState::Configuring: return "Configuring";
  }
  return "?";
}

constexpr std::string_view kHelp[] = {
    "requests (one per line; every response ends with a line OK ... or ERR <message>):",
    "  <instruction call>        e.g. MAJ(X, maj1, Forward, 10, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2,",
    "                            Trapezoidal, 100, 100, %ofTime, Disabled, Programmed): execute it, wait until the",
    "                            planner ran it, answer with the control tag: OK|ERR mam1 EN= DN= ER= PC= IP= AC= ERR= EXERR= STATE=",
    "  GET tag...                OK tag=value ...",
    "  SET tag value             write a writable (numeric) tag",
    "  STATUS                    one line per axis (axis=... key=value ...), then OK",
    "  WATCH interval_s tag...   OK, then a line t=<s> tag=value ... every interval (controller time) until UNWATCH",
    "  UNWATCH                   stop watching: OK",
    "  RUN [name]                followed by script lines and a line END: run the motion script, streaming its",
    "                            PRINT lines (t=...), then OK or ERR <script error>",
    "  STATS                     controller statistics, key=value lines, then OK",
    "  MODE [run|program]        the controller mode (OK mode=run|program); program stops every axis by its",
    "                            Programmed Stop Mode, breaks the MDAC links and refuses motion (ERR 24) until run",
    "  HELP                      this text",
    "  QUIT                      OK, then the server closes the connection",
    "tags: X.ActualPosition X.CommandPosition X.ActualVelocity X.CommandVelocity X.PositionError X.MotionStatus",
    "      X.AxisStatus X.AxisFault X.AxisState X.<status bit> mam1.DN .ER .ERR .EXERR .STATE Controller.Time ...",
};

}  // namespace

// ---------------------------------------------------------------------------

struct CommandServer::Impl {
  struct Client;

  /// The ScriptHost of one client's script: delegates to the server's host
  /// but waits only for its own commands and reads the server's cached
  /// status (one snapshot copy per poll, not one per tag).
  class ClientHost final : public script::ScriptHost {
   public:
    explicit ClientHost(Impl& s) : s_(s) {}
    std::optional<std::string> check_call(std::string_view call) override { return s_.host.check_call(call); }
    std::optional<std::string> check_tag(std::string_view tag, bool for_write) override {
      return s_.host.check_tag(tag, for_write);
    }
    std::optional<std::string> execute(std::string_view call, std::string* control_tag) override {
      if (auto e = s_.host.execute(call, control_tag)) return e;
      seq_ = s_.host.last_seq();
      return std::nullopt;
    }
    bool settled() override { return s_.status().done_seq >= seq_; }
    std::optional<double> read(std::string_view tag, std::string* error) override {
      return s_.host.tags().read(s_.status(), tag, error);
    }
    std::optional<std::string> write(std::string_view tag, double value) override {
      const std::uint64_t before = s_.host.last_seq();
      auto e = s_.host.write(tag, value);
      // a write that queued a command (array element): settled() waits for the RT thread
      if (!e && s_.host.last_seq() != before) seq_ = s_.host.last_seq();
      return e;
    }
    void declare(std::string_view tag) override { s_.host.declare(tag); }

   private:
    Impl& s_;
    std::uint64_t seq_ = 0;
  };

  /// A running script: the Script must outlive its Runner (which refers to it).
  struct ScriptRun {
    script::Script script;
    std::unique_ptr<ClientHost> host;
    std::unique_ptr<script::Runner> runner;
  };

  enum class Mode : std::uint8_t { kIdle, kPending, kScriptText, kScript, kWatch };

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
    // kPending: an instruction call
    std::uint64_t seq = 0;
    std::string control;
    std::string reply;  ///< kPending after SET of an array element: the reply once applied
    Wall::time_point since{};
    // kScriptText / kScript
    std::string script_name;
    std::string script_text;
    std::unique_ptr<ScriptRun> run;
    // kWatch
    double interval = 0, next = 0;
    std::vector<std::string> watch;
  };

  Impl(Controller& c, CommandServerOptions o)
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

  void log(const std::string& l) const {
    if (opt.log)
      opt.log(l);
    else
      fmt::print(stderr, "command server: {}\n", l);
  }

  const Status& status() {
    if (!fresh) {
      ctl.read_status(*snap);
      fresh = true;
    }
    return *snap;
  }

  // ---- set-up --------------------------------------------------------------

  void open() {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (opt.path.empty()) throw std::runtime_error("socket path is empty");
    if (opt.path.size() >= sizeof(addr.sun_path))
      throw std::runtime_error(fmt::format("socket path '{}' is too long ({} bytes; at most {})", opt.path,
                                           opt.path.size(), sizeof(addr.sun_path) - 1));
    std::memcpy(addr.sun_path, opt.path.data(), opt.path.size());

    // The group first: nothing is created when it does not exist.
    if (opt.group.empty()) {
      sock_gid = getegid();
      std::vector<char> buf(16384);
      group g{};
      group* r = nullptr;
      group_name = (getgrgid_r(sock_gid, &g, buf.data(), buf.size(), &r) == 0 && r) ? std::string(r->gr_name)
                                                                                 : std::to_string(sock_gid);
    } else {
      std::vector<char> buf(16384);
      group g{};
      group* r = nullptr;
      const int e = getgrnam_r(opt.group.c_str(), &g, buf.data(), buf.size(), &r);
      if (e != 0 || !r)
        throw std::runtime_error(fmt::format("socket group '{}' does not exist{} (create it with `groupadd {}` and "
                                             "add the operators to it, or name an existing group)",
                                             opt.group, e != 0 ? ": " + errno_text(e) : std::string(), opt.group));
      sock_gid = r->gr_gid;
      group_name = opt.group;
    }

    // A socket file left by a daemon that died: replace it only if nobody listens.
    struct stat st {};
    if (lstat(opt.path.c_str(), &st) == 0) {
      if (!S_ISSOCK(st.st_mode))
        throw std::runtime_error(fmt::format("'{}' exists and is not a socket; remove it or choose another --socket path",
                                             opt.path));
      const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
      if (probe >= 0) {
        const bool live = ::connect(probe, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) == 0;
        ::close(probe);
        if (live)
          throw std::runtime_error(fmt::format(
              "another process is already listening on '{}' (is canmotiond already running?)", opt.path));
      }
      ::unlink(opt.path.c_str());
    }

    listen_fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (listen_fd < 0) throw std::runtime_error(fmt::format("cannot create a UNIX socket: {}", errno_text(errno)));
    // Nobody but us may connect before the mode and group are set.
    const mode_t old_mask = ::umask(0177);
    const int b = ::bind(listen_fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr));
    const int bind_errno = errno;
    ::umask(old_mask);
    if (b != 0) {
      ::close(listen_fd);
      listen_fd = -1;
      std::string dir = opt.path.substr(0, opt.path.rfind('/') == std::string::npos ? 0 : opt.path.rfind('/'));
      if (dir.empty()) dir = ".";
      if (bind_errno == ENOENT)
        throw std::runtime_error(fmt::format("cannot create socket '{}': directory '{}' does not exist (the systemd "
                                             "unit creates /run/canmotion with RuntimeDirectory=canmotion; otherwise "
                                             "create it)",
                                             opt.path, dir));
      throw std::runtime_error(fmt::format("cannot create socket '{}': {}", opt.path, errno_text(bind_errno)));
    }
    if (::chown(opt.path.c_str(), static_cast<uid_t>(-1), sock_gid) != 0) {
      const int e = errno;
      close_listen();
      throw std::runtime_error(fmt::format("cannot give socket '{}' to group '{}': {} (the daemon's user must be root "
                                           "or a member of '{}')",
                                           opt.path, group_name, errno_text(e), group_name));
    }
    if (::chmod(opt.path.c_str(), 0660) != 0) {
      const int e = errno;
      close_listen();
      throw std::runtime_error(fmt::format("cannot set mode 0660 on socket '{}': {}", opt.path, errno_text(e)));
    }
    if (::listen(listen_fd, 16) != 0) {
      const int e = errno;
      close_listen();
      throw std::runtime_error(fmt::format("cannot listen on socket '{}': {}", opt.path, errno_text(e)));
    }

    // Register the executive's statistics as Controller.<field> tags (the
    // owner of a shared host registers them there itself).
    if (opt.cycle_stats && !opt.shared_host) {
      for (std::string_view name : stat_tag_names()) {
        auto get = opt.cycle_stats;
        const std::string n(name);
        host.tags().add_statistic(n, [get, n] {
          return static_cast<double>(stat_tag_value(get(), n).value_or(0));
        });
      }
    }
    // Bit names for STATUS, from the tag table (one source of truth).
    if (ctl.axis_count() > 0) {
      const std::string axis = ctl.axis_name(0);
      for (std::string_view m : TagTable::axis_members()) {
        const auto t = host.tags().resolve(axis + "." + std::string(m), nullptr);
        if (!t || t->member >= 32) continue;
        if (t->kind == TagRef::Kind::kMotionBit) motion_bits[t->member] = m;
        if (t->kind == TagRef::Kind::kAxisStatusBit) status_bits[t->member] = m;
        if (t->kind == TagRef::Kind::kAxisFaultBit) fault_bits[t->member] = m;
      }
    }
  }

  void close_listen() {
    if (listen_fd >= 0) {
      ::close(listen_fd);
      listen_fd = -1;
      ::unlink(opt.path.c_str());
    }
  }

  // ---- output --------------------------------------------------------------

  void send_line(Client& c, std::string_view line) {
    if (c.dead || c.closing) return;
    if (c.out.size() + line.size() + 1 > opt.max_output) {
      log(fmt::format("client {} (pid {}): does not read its output ({} bytes waiting); disconnected", c.id,
                      c.cred.pid, c.out.size()));
      c.out.clear();
      c.out += fmt::format("ERR output buffer full ({} bytes): the client does not read; disconnected\n",
                           opt.max_output);
      c.closing = true;
      flush(c);  // best effort
      c.dead = true;
      return;
    }
    c.out.append(line);
    c.out.push_back('\n');
  }

  void fail_and_close(Client& c, const std::string& msg) {
    send_line(c, "ERR " + msg);
    c.closing = true;
  }

  void flush(Client& c) {
    while (!c.out.empty() && c.fd >= 0) {
      const ssize_t n = ::send(c.fd, c.out.data(), c.out.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) {
        c.out.erase(0, static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
      if (n < 0 && errno == EINTR) continue;
      c.out.clear();
      c.dead = true;  // EPIPE / ECONNRESET: the peer is gone
      return;
    }
  }

  // ---- connections ---------------------------------------------------------

  bool peer_allowed(int fd, const ucred& cr) const {
    if (cr.uid == 0 || cr.uid == ::geteuid() || cr.gid == sock_gid) return true;
    std::array<gid_t, 256> groups{};
    socklen_t len = sizeof(groups);
    if (::getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups.data(), &len) == 0) {
      const std::size_t n = len / sizeof(gid_t);
      for (std::size_t i = 0; i < n && i < groups.size(); ++i)
        if (groups[i] == sock_gid) return true;
    }
    return false;
  }

  void accept_all() {
    for (;;) {
      const int fd = ::accept4(listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) {
        if (errno == EINTR || errno == ECONNABORTED) continue;
        if (errno != EAGAIN && errno != EWOULDBLOCK) log(fmt::format("accept: {}", errno_text(errno)));
        return;
      }
      auto c = std::make_unique<Client>();
      c->fd = fd;
      c->id = next_id++;
      socklen_t len = sizeof(c->cred);
      if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &c->cred, &len) != 0) {
        log(fmt::format("client {}: SO_PEERCRED failed ({}); refused", c->id, errno_text(errno)));
        ::close(fd);
        continue;
      }
      if (!peer_allowed(fd, c->cred)) {
        log(fmt::format("client {} refused: pid {} uid {} gid {} is not root, the daemon's user, nor in group '{}'",
                        c->id, c->cred.pid, c->cred.uid, c->cred.gid, group_name));
        fail_and_close(*c, fmt::format("permission denied: uid {} gid {} is not root, the daemon's user, nor in "
                                       "group '{}'",
                                       c->cred.uid, c->cred.gid, group_name));
        flush(*c);
        ::close(fd);
        continue;
      }
      if (clients.size() >= opt.max_clients) {
        log(fmt::format("client {} (pid {}) refused: {} clients already connected", c->id, c->cred.pid,
                        clients.size()));
        fail_and_close(*c, fmt::format("too many clients ({} connected); try again later", clients.size()));
        flush(*c);
        ::close(fd);
        continue;
      }
      log(fmt::format("client {} connected: pid {} uid {} gid {}", c->id, c->cred.pid, c->cred.uid, c->cred.gid));
      clients.push_back(std::move(c));
    }
  }

  void read_from(Client& c) {
    std::array<char, 4096> buf;
    // While busy, stop reading once a line's worth is buffered (back-pressure).
    while (!c.eof && c.in.size() <= opt.max_line) {
      const ssize_t n = ::recv(c.fd, buf.data(), buf.size(), MSG_DONTWAIT);
      if (n > 0) {
        c.in.append(buf.data(), static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0) {
        c.eof = true;
        return;
      }
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) c.dead = true;
      return;
    }
  }

  // ---- requests ------------------------------------------------------------

  /// Handle complete lines while the client is ready for them.
  void handle_input(Client& c) {
    while (!c.dead && !c.closing && (c.mode == Mode::kIdle || c.mode == Mode::kScriptText || c.mode == Mode::kWatch)) {
      const std::size_t nl = c.in.find('\n');
      if (nl == std::string::npos) {
        if (c.in.size() > opt.max_line) {
          log(fmt::format("client {} (pid {}): request longer than {} bytes; disconnected", c.id, c.cred.pid,
                          opt.max_line));
          c.in.clear();
          fail_and_close(c, fmt::format("request line longer than {} bytes; disconnected", opt.max_line));
        }
        return;
      }
      std::string line = c.in.substr(0, nl);
      c.in.erase(0, nl + 1);
      if (line.size() > opt.max_line) {
        fail_and_close(c, fmt::format("request line longer than {} bytes; disconnected", opt.max_line));
        return;
      }
      if (!line.empty() && line.back() == '\r') line.pop_back();
      try {
        handle_line(c, line);
      } catch (const std::exception& e) {
        // Nothing a client sends may take the daemon down: this client goes.
        log(fmt::format("client {}: request failed: {}; disconnected", c.id, e.what()));
        fail_and_close(c, fmt::format("internal error: {}", e.what()));
      }
    }
  }

  void handle_line(Client& c, const std::string& raw) {
    if (c.mode == Mode::kScriptText) {
      if (raw == "END") {  // exactly: a client sends a script line "END" as "END " (see README)
        start_script(c);
        return;
      }
      if (c.script_text.size() + raw.size() + 1 > opt.max_script) {
        c.mode = Mode::kIdle;
        c.script_text.clear();
        fail_and_close(c, fmt::format("script longer than {} bytes", opt.max_script));
        return;
      }
      c.script_text += raw;
      c.script_text += '\n';
      return;
    }
    const std::string_view line = trim(raw);
    if (line.empty() || line.front() == '#') return;  // blank lines and comments: no response
    for (std::size_t i = 0; i < line.size(); ++i) {
      const auto ch = static_cast<unsigned char>(line[i]);
      if ((ch < 0x20 && ch != '\t') || ch == 0x7F) {
        send_line(c, fmt::format("ERR malformed request: control character 0x{:02X} at column {}", ch, i + 1));
        return;
      }
    }
    const std::vector<std::string> w = words(line);
    const std::string& verb = w[0];
    if (c.mode == Mode::kWatch) {
      if (iequals(verb, "UNWATCH")) {
        c.mode = Mode::kIdle;
        c.watch.clear();
        send_line(c, "OK unwatched");
      } else if (iequals(verb, "QUIT")) {
        c.mode = Mode::kIdle;
        send_line(c, "OK bye");
        c.closing = true;
      } else {
        send_line(c, "ERR a WATCH is running: send UNWATCH first");
      }
      return;
    }
    if (iequals(verb, "GET")) return do_get(c, w);
    if (iequals(verb, "SET")) return do_set(c, w);
    if (iequals(verb, "STATUS")) return do_status(c, w);
    if (iequals(verb, "WATCH")) return do_watch(c, w);
    if (iequals(verb, "UNWATCH")) return send_line(c, "ERR no WATCH is running");
    if (iequals(verb, "STATS")) return do_stats(c);
    if (iequals(verb, "MODE")) return do_mode(c, w);
    if (iequals(verb, "HELP")) {
      for (std::string_view h : kHelp) send_line(c, h);
      return send_line(c, "OK");
    }
    if (iequals(verb, "QUIT")) {
      send_line(c, "OK bye");
      c.closing = true;
      return;
    }
    if (iequals(verb, "RUN")) {
      if (w.size() > 2) return send_line(c, "ERR RUN takes at most one word (a name for messages): RUN [name]");
      c.mode = Mode::kScriptText;
      c.script_name = w.size() == 2 ? w[1] : fmt::format("<client {}>", c.id);
      c.script_text.clear();
      return;
    }
    if (iequals(verb, "END")) return send_line(c, "ERR END without RUN");
    if (line.find('(') != std::string_view::npos) return do_call(c, line);
    send_line(c, fmt::format("ERR unknown request '{}': expected an instruction call like MSO(X, mso1), GET, SET, "
                             "STATUS, WATCH, UNWATCH, RUN, STATS, MODE, HELP or QUIT",
                             verb.substr(0, 64)));
  }

  void do_call(Client& c, std::string_view line) {
    std::string call(line);
    if (!call.empty() && call.back() == ';') call.pop_back();
    if (!refusal.empty()) return send_line(c, "ERR " + refusal);
    c.control.clear();
    if (auto e = host.execute(call, &c.control)) {
      send_line(c, "ERR " + *e);
      return;
    }
    c.seq = host.last_seq();
    c.since = Wall::now();
    c.mode = Mode::kPending;
  }

  void finish_call(Client& c) {
    c.mode = Mode::kIdle;
    if (!c.reply.empty()) {  // a SET of an array element
      send_line(c, c.reply);
      c.reply.clear();
      return;
    }
    if (c.control.empty()) return send_line(c, "OK executed");
    const auto id = ctl.find_control(c.control);
    if (!id) return send_line(c, fmt::format("ERR control tag '{}' vanished", c.control));
    const motion::ControlTag& t = status().controls[*id];
    std::string fields = fmt::format("{} EN={} DN={} ER={} PC={} IP={} AC={} ERR={} EXERR={} STATE={}", c.control,
                                     int(t.en()), int(t.dn()), int(t.er()), int(t.pc()), int(t.ip()), int(t.ac()),
                                     t.err, int(t.exerr), int(t.state));
    if (t.er())
      send_line(c, fmt::format("ERR {} ({})", fields, motion::err_name(t.error())));
    else
      send_line(c, "OK " + fields);
  }

  void do_get(Client& c, const std::vector<std::string>& w) {
    if (w.size() < 2) return send_line(c, "ERR GET needs at least one tag: GET X.ActualPosition mam1.DN");
    std::string reply = "OK";
    for (std::size_t i = 1; i < w.size(); ++i) {
      std::string e;
      const auto v = host.tags().read(status(), w[i], &e);
      if (!v) return send_line(c, "ERR " + e);
      reply += fmt::format(" {}={}", w[i], script::format_value(*v));
    }
    send_line(c, reply);
  }

  /// MODE [run|program]: the controller mode (issue 16); a change is answered
  /// once the RT thread applied it.
  void do_mode(Client& c, const std::vector<std::string>& w) {
    auto name = [](motion::ControllerMode m) { return m == motion::ControllerMode::Program ? "program" : "run"; };
    if (w.size() == 1) return send_line(c, fmt::format("OK mode={}", name(status().mode)));
    if (w.size() != 2 || !(iequals(w[1], "run") || iequals(w[1], "program")))
      return send_line(c, "ERR MODE takes run or program (or nothing to read the mode): MODE program");
    const auto m = iequals(w[1], "program") ? motion::ControllerMode::Program : motion::ControllerMode::Run;
    if (auto e = host.set_mode(m)) return send_line(c, "ERR " + *e);
    c.control.clear();
    c.reply = fmt::format("OK mode={}", name(m));
    c.seq = host.last_seq();
    c.since = Wall::now();
    c.mode = Mode::kPending;
  }

  void do_set(Client& c, const std::vector<std::string>& w) {
    if (w.size() != 3) return send_line(c, "ERR SET needs a tag and a value: SET Distance 12.5");
    const auto v = number(w[2]);
    if (!v) return send_line(c, fmt::format("ERR SET {}: '{}' is not a finite number", w[1], w[2]));
    const std::uint64_t before = host.last_seq();
    if (auto e = host.write(w[1], *v)) return send_line(c, "ERR " + *e);
    if (host.last_seq() != before) {  // an array element: reply once the RT thread applied it
      c.control.clear();
      c.reply = fmt::format("OK {}={}", w[1], script::format_value(*v));
      c.seq = host.last_seq();
      c.since = Wall::now();
      c.mode = Mode::kPending;
      return;
    }
    send_line(c, fmt::format("OK {}={}", w[1], script::format_value(*v)));
  }

  std::string bit_names(std::uint32_t bits, const std::array<std::string_view, 32>& names) const {
    std::string s;
    for (unsigned b = 0; b < 32; ++b) {
      if (!((bits >> b) & 1u)) continue;
      if (!s.empty()) s += ',';
      s += names[b].empty() ? fmt::format("bit{}", b) : std::string(names[b]);
    }
    return s.empty() ? "-" : s;
  }

  void do_status(Client& c, const std::vector<std::string>& w) {
    if (w.size() > 1) return send_line(c, "ERR STATUS takes no arguments");
    const Status& s = status();
    const std::size_t n = std::min<std::size_t>(ctl.axis_count(), s.axis_count);
    for (std::size_t a = 0; a < n; ++a) {
      const auto id = static_cast<motion::AxisId>(a);
      const AxisSpec& spec = ctl.axis_spec(id);
      const AxisSnapshot& x = s.axes[a];
      const bool cip = spec.config.type == motion::AxisType::CipDrive;
      std::string l = fmt::format("axis={} type={} node={} state={}", spec.name, cip ? "CIP" : "virtual",
                                  cip ? std::to_string(spec.drive.node) : std::string("-"),
                                  axis_state_name(x.tag.state));
      if (cip)
        l += fmt::format(" drive={} phase={}", quoted(cia402::state_name(x.drive_state)),
                         quoted(cia402::phase_name(x.phase)));
      else
        l += " drive=- phase=-";
      l += fmt::format(" cmd_pos={} act_pos={} cmd_vel={} act_vel={} pos_err={}",
                       script::format_value(x.tag.command_position), script::format_value(x.tag.actual_position),
                       script::format_value(x.tag.command_velocity), script::format_value(x.tag.actual_velocity),
                       script::format_value(x.tag.position_error));
      l += fmt::format(" motion_status=0x{:08X} axis_status=0x{:08X} axis_fault=0x{:08X}", x.tag.motion_status,
                       x.tag.axis_status, x.tag.axis_fault);
      l += fmt::format(" motion_bits={} status_bits={} faults={}", bit_names(x.tag.motion_status, motion_bits),
                       bit_names(x.tag.axis_status, status_bits), bit_names(x.tag.axis_fault, fault_bits));
      if (cip) {
        l += fmt::format(" statusword=0x{:04X} last_emcy=0x{:04X} tpdo_missed={}", x.statusword, x.last_emcy,
                         x.tpdo_missed);
        if (x.failure.kind != cia402::FailureKind::kNone) l += " failure=" + quoted(x.failure.to_string());
      }
      send_line(c, l);
    }
    send_line(c, fmt::format("OK {} axes, cycle {}, t={}", n, s.cycle,
                             script::format_value(static_cast<double>(s.cycle) * ctl.period_s())));
  }

  void do_watch(Client& c, const std::vector<std::string>& w) {
    if (w.size() < 3) return send_line(c, "ERR WATCH needs an interval in seconds and at least one tag: WATCH 0.1 X.ActualPosition");
    const auto iv = number(w[1]);
    if (!iv || *iv <= 0)
      return send_line(c, fmt::format("ERR WATCH interval '{}' is not a positive number of seconds", w[1]));
    constexpr std::size_t kMaxWatch = 64;  // tags per line: a screenful
    if (w.size() - 2 > kMaxWatch) return send_line(c, fmt::format("ERR WATCH takes at most {} tags", kMaxWatch));
    for (std::size_t i = 2; i < w.size(); ++i) {
      std::string e;
      if (!host.tags().resolve(w[i], &e)) return send_line(c, "ERR " + e);
    }
    c.watch.assign(w.begin() + 2, w.end());
    c.interval = std::max(*iv, ctl.period_s());
    c.mode = Mode::kWatch;
    send_line(c, fmt::format("OK watching {} tag{} every {} s", c.watch.size(), c.watch.size() == 1 ? "" : "s",
                             script::format_value(c.interval)));
    c.next = now;
    advance_watch(c);
  }

  void advance_watch(Client& c) {
    // Half a nanosecond of slack absorbs the rounding of cycle * period.
    if (now + 5e-10 < c.next) return;
    const Status& s = status();
    std::string l = fmt::format("t={:.3f}", now);
    for (const std::string& t : c.watch) {
      std::string e;
      const auto v = host.tags().read(s, t, &e);
      l += fmt::format(" {}={}", t, v ? script::format_value(*v) : std::string("?"));
    }
    send_line(c, l);
    c.next += c.interval;
    if (c.next + 5e-10 <= now) c.next = now + c.interval;  // polled late: no burst of stale lines
  }

  void do_stats(Client& c) {
    const Status& s = status();
    send_line(c, fmt::format("cycle={}", s.cycle));  // the controller's; the executive's `cycles` follow
    send_line(c, fmt::format("time_s={}", script::format_value(static_cast<double>(s.cycle) * ctl.period_s())));
    send_line(c, fmt::format("period_ms={}", script::format_value(ctl.period_s() * 1e3)));
    send_line(c, fmt::format("axes={}", ctl.axis_count()));
    send_line(c, fmt::format("commands_deferred={}", s.commands_deferred));
    send_line(c, fmt::format("trace_dropped={}", s.trace_dropped));
    send_line(c, fmt::format("telemetry_dropped={}", s.telemetry_dropped));
    send_line(c, fmt::format("clients={}", clients.size()));
    if (opt.cycle_stats) {
      const CycleStats st = opt.cycle_stats();
      for (std::string_view n : stat_tag_names())
        send_line(c, fmt::format("{}={}", n, stat_tag_value(st, n).value_or(0)));
    }
    send_line(c, "OK");
  }

  void start_script(Client& c) {
    c.mode = Mode::kIdle;
    if (!refusal.empty()) {
      c.script_text.clear();
      return send_line(c, "ERR " + refusal);
    }
    auto run = std::make_unique<ScriptRun>();
    run->host = std::make_unique<ClientHost>(*this);
    try {
      run->script = script::load(c.script_text, c.script_name, *run->host);
    } catch (const std::exception& e) {
      c.script_text.clear();
      return send_line(c, fmt::format("ERR {}", e.what()));
    }
    c.script_text.clear();
    Client* cp = &c;
    run->runner = std::make_unique<script::Runner>(run->script, *run->host,
                                                   [this, cp](const std::string& l) { send_line(*cp, l); });
    c.run = std::move(run);
    c.mode = Mode::kScript;
    advance_script(c);
  }

  void advance_script(Client& c) {
    const auto st = c.run->runner->step(now);
    if (st == script::Runner::Status::kRunning) return;
    c.mode = Mode::kIdle;
    if (st == script::Runner::Status::kDone)
      send_line(c, fmt::format("OK script done ({} statements)", c.run->script.statements.size()));
    else
      send_line(c, "ERR " + c.run->runner->error());
    c.run.reset();
  }

  /// Advance the client's waiting request (no system call).
  void advance(Client& c) {
    try {
      switch (c.mode) {
        case Mode::kPending:
          if (status().done_seq >= c.seq) {
            finish_call(c);
          } else if (std::chrono::duration<double>(Wall::now() - c.since).count() > opt.instruction_timeout_s) {
            c.mode = Mode::kIdle;
            send_line(c, fmt::format("ERR timeout: the controller did not execute the instruction within {} s (is "
                                     "the cycle running?)",
                                     script::format_value(opt.instruction_timeout_s)));
          }
          break;
        case Mode::kScript: advance_script(c); break;
        case Mode::kWatch: advance_watch(c); break;
        default: break;
      }
    } catch (const std::exception& e) {
      log(fmt::format("client {}: request failed: {}; disconnected", c.id, e.what()));
      c.mode = Mode::kIdle;
      c.run.reset();
      fail_and_close(c, fmt::format("internal error: {}", e.what()));
    }
  }

  void drop(Client& c, const char* why) {
    if (c.fd >= 0) {
      log(fmt::format("client {} (pid {}) {}{}", c.id, c.cred.pid, why,
                      c.mode == Mode::kPending   ? " while its instruction was pending (it still executes)"
                      : c.mode == Mode::kScript  ? "; its script was stopped (motion already started continues)"
                                                 : ""));
      ::close(c.fd);
      c.fd = -1;
    }
  }

  void poll_once(double now_s) {
    now = now_s;
    fresh = false;
    for (auto& c : clients)
      if (c->mode == Mode::kPending || c->mode == Mode::kScript || c->mode == Mode::kWatch) {
        advance(*c);
        handle_input(*c);  // lines that waited for this request
      }

    const auto wall = Wall::now();
    if (!first_io && opt.io_interval_s > 0 &&
        std::chrono::duration<double>(wall - last_io).count() < opt.io_interval_s)
      return;
    first_io = false;
    last_io = wall;

    pfds.clear();
    pfds.push_back(pollfd{listen_fd, POLLIN, 0});
    for (auto& c : clients) {
      short ev = POLLRDHUP;
      if (!c->eof && c->in.size() <= opt.max_line) ev = static_cast<short>(ev | POLLIN);
      if (!c->out.empty()) ev = static_cast<short>(ev | POLLOUT);
      pfds.push_back(pollfd{c->fd, ev, 0});
    }
    const int r = ::poll(pfds.data(), static_cast<nfds_t>(pfds.size()), 0);
    if (r < 0 && errno != EINTR) log(fmt::format("poll: {}", errno_text(errno)));
    if (r > 0) {
      for (std::size_t i = 0; i < clients.size(); ++i) {
        Client& c = *clients[i];
        const short re = pfds[i + 1].revents;
        if (re & POLLNVAL) {
          c.dead = true;
          continue;
        }
        if (re & (POLLIN | POLLRDHUP | POLLHUP | POLLERR)) read_from(c);
        if (re & (POLLHUP | POLLERR)) c.dead = true;  // the peer closed its socket: nobody to answer
      }
    }
    for (auto& c : clients) {
      if (c->dead) continue;
      handle_input(*c);
      if (c->eof && c->mode == Mode::kScriptText && c->in.find('\n') == std::string::npos) {
        c->mode = Mode::kIdle;
        c->script_text.clear();
        fail_and_close(*c, "end of input inside RUN: the script text must end with a line END");
      }
    }
    for (auto& c : clients)
      if (!c->dead && !c->out.empty()) flush(*c);
    if (r > 0 && (pfds[0].revents & POLLIN)) accept_all();  // new clients are read at the next poll

    // Remove finished clients.
    for (auto& c : clients) {
      if (c->dead) {
        drop(*c, "disconnected");
      } else if (c->closing && c->out.empty()) {
        drop(*c, "closed");
      } else if (c->eof && c->mode == Mode::kIdle && c->out.empty() && c->in.find('\n') == std::string::npos) {
        drop(*c, "finished");
      }
    }
    std::erase_if(clients, [](const std::unique_ptr<Client>& c) { return c->fd < 0; });
  }
};

// ---------------------------------------------------------------------------

CommandServer::CommandServer(Controller& controller, CommandServerOptions options)
    : impl_(std::make_unique<Impl>(controller, std::move(options))) {
  impl_->open();
  impl_->log(fmt::format("listening on {} (mode 0660, group {})", impl_->opt.path, impl_->group_name));
}

CommandServer::~CommandServer() {
  for (auto& c : impl_->clients) {
    if (c->fd < 0) continue;
    if (c->mode != Impl::Mode::kIdle) {
      impl_->send_line(*c, "ERR canmotiond is stopping");
      impl_->flush(*c);
    }
    ::close(c->fd);
    c->fd = -1;
  }
  impl_->close_listen();
}

void CommandServer::poll(double now_s) { impl_->poll_once(now_s); }

void CommandServer::refuse_motion(std::string reason) {
  if (reason.empty()) reason = "motion is refused";
  impl_->refusal = std::move(reason);
  for (auto& c : impl_->clients) {
    if (c->fd < 0 || c->mode != Impl::Mode::kScript) continue;
    c->mode = Impl::Mode::kIdle;
    c->run.reset();
    impl_->send_line(*c, "ERR script stopped: " + impl_->refusal);
  }
}

std::size_t CommandServer::client_count() const noexcept { return impl_->clients.size(); }
const std::string& CommandServer::path() const noexcept { return impl_->opt.path; }
ControllerHost& CommandServer::host() noexcept { return impl_->host; }

}  // namespace canmotion::rt
