// canmotionctl: talk to a running canmotiond over its UNIX socket (the
// line-based protocol of README.md): execute motion instructions, read and
// write tags, show the axes, watch tags, run motion scripts, show statistics.
// Argument parsing and I/O only.
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace {

constexpr const char* kDefaultSocket = "/run/canmotion/canmotiond.sock";

constexpr const char* kUsage = R"(Usage: canmotionctl [options] <command> [arguments]

Talks to a running canmotiond (started with --socket) over its UNIX socket.

Commands:
  'INSTR(operands)'        execute a Logix motion instruction (ST syntax) and
                           print its control tag (EN DN ER PC IP AC ERR EXERR STATE)
  get TAG...               print tag values (one tag: the value; more: TAG=VALUE lines)
  set TAG VALUE            write a writable (numeric) tag
  status                   table of the axes: state, drive, positions, velocity,
                           status bits, faults, last EMCY
  watch TAG... [-i S] [-n N]
                           print `t=<s> TAG=VALUE ...` every S seconds of controller
                           time (default 0.1) until Ctrl-C, or N lines
  run SCRIPT               run a motion script (file, or - for stdin), printing its
                           PRINT lines; exit status 1 if the script fails
  stats                    controller and cycle statistics
  mode [run|program]       print or set the controller mode: program stops every
                           axis by its Programmed Stop Mode, breaks the MDAC links
                           and refuses instructions that start motion (ERR 24)
  send 'LINE'              send one raw protocol line and print the response

Options:
  -s, --socket PATH        canmotiond's socket (default $CANMOTIOND_SOCKET, else
                           /run/canmotion/canmotiond.sock)
  -t, --timeout S          give up waiting for a response after S seconds
                           (default 10; run and watch wait forever unless given)
  -h, --help               this text

Examples:
  canmotionctl 'MSO(X, mso1)'
  canmotionctl 'MAJ(X, maj1, Forward, 10, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2, Trapezoidal, 100, 100, %ofTime, Disabled, Programmed)'
  canmotionctl get X.ActualPosition X.GearingLockStatus maj1.IP
  canmotionctl set Distance 12.5
  canmotionctl status
  canmotionctl watch X.ActualPosition X.ActualVelocity --interval 0.5
  canmotionctl run config/examples/demo.script
  canmotionctl --socket /tmp/canmotiond.sock stats
  canmotionctl mode program

Exit status: 0 when canmotiond answered OK, 1 on ERR (the message goes to
stderr), on a connection failure or a timeout, 2 on bad arguments.
Protocol: see tools/canmotionctl/README.md.
)";

/// A failure to report: message to stderr, exit 1.
struct Failure {
  std::string message;
};

volatile sig_atomic_t g_stop = 0;  ///< SIGINT during watch
void on_sigint(int) { g_stop = 1; }

std::string error_word(int e) {
  switch (e) {
    case ENOENT: return "no such file";
    case ECONNREFUSED: return "connection refused";
    case EACCES: return "permission denied";
    default: return std::strerror(e);
  }
}

/// One connection to canmotiond, reading lines with a deadline.
class Connection {
 public:
  Connection(const std::string& path, double timeout_s) : path_(path), timeout_s_(timeout_s) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.size() >= sizeof(addr.sun_path))
      throw Failure{fmt::format("socket path '{}' is too long ({} bytes; at most {})", path, path.size(),
                                sizeof(addr.sun_path) - 1)};
    std::memcpy(addr.sun_path, path.data(), path.size());
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw Failure{fmt::format("cannot create a socket: {}", std::strerror(errno))};
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
      const int e = errno;
      ::close(fd_);
      fd_ = -1;
      std::string hint;
      if (e == ENOENT || e == ECONNREFUSED)
        hint = " (is canmotiond running with --socket " + path + "?)";
      else if (e == EACCES)
        hint = " (the socket is mode 0660: add your user to its group, e.g. `sudo usermod -aG canmotion $USER`, "
               "and log in again)";
      throw Failure{fmt::format("cannot connect to {}: {}{}", path, error_word(e), hint)};
    }
  }
  ~Connection() {
    if (fd_ >= 0) ::close(fd_);
  }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  void send(const std::string& data) {
    std::size_t off = 0;
    while (off < data.size()) {
      const ssize_t n = ::send(fd_, data.data() + off, data.size() - off, MSG_NOSIGNAL);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw Failure{fmt::format("lost the connection to {}: {}", path_, std::strerror(errno))};
      off += static_cast<std::size_t>(n);
    }
  }
  void send_line(const std::string& l) { send(l + "\n"); }

  /// The next line (without newline). Throws Failure on timeout or when the
  /// daemon closed the connection.
  std::string read_line() {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s_);
    for (;;) {
      if (const std::size_t nl = buf_.find('\n'); nl != std::string::npos) {
        std::string l = buf_.substr(0, nl);
        buf_.erase(0, nl + 1);
        if (!l.empty() && l.back() == '\r') l.pop_back();
        return l;
      }
      int wait_ms = -1;
      if (timeout_s_ > 0) {
        const auto left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
        if (left <= 0) throw Failure{fmt::format("no answer from canmotiond within {} s", timeout_s_)};
        wait_ms = static_cast<int>(std::min(left * 1000.0 + 1.0, 1e9));
      }
      pollfd p{fd_, POLLIN, 0};
      const int r = ::poll(&p, 1, wait_ms);
      if (r < 0 && errno == EINTR && g_stop) throw Failure{"interrupted"};
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) throw Failure{fmt::format("poll: {}", std::strerror(errno))};
      if (r == 0) continue;  // the deadline check above reports it
      char tmp[4096];
      const ssize_t n = ::recv(fd_, tmp, sizeof(tmp), 0);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw Failure{fmt::format("lost the connection to {}: {}", path_, std::strerror(errno))};
      if (n == 0) throw Failure{fmt::format("canmotiond closed the connection on {} before answering", path_)};
      buf_.append(tmp, static_cast<std::size_t>(n));
    }
  }

  /// Read until the final line; data lines go to `data` (called as they come).
  /// Returns the text after OK; throws Failure with the text after ERR.
  template <typename F>
  std::string response(F&& data) {
    for (;;) {
      std::string l = read_line();
      if (l == "OK" || l.rfind("OK ", 0) == 0) return l.size() > 3 ? l.substr(3) : std::string();
      if (l == "ERR" || l.rfind("ERR ", 0) == 0) throw Failure{l.size() > 4 ? l.substr(4) : std::string("error")};
      data(l);
    }
  }
  std::string response() {
    return response([](const std::string& l) { fmt::print("{}\n", l); });
  }

 private:
  std::string path_;
  double timeout_s_;
  int fd_ = -1;
  std::string buf_;
};

/// key=value fields of a STATUS line (values may be "quoted").
std::map<std::string, std::string> fields(const std::string& line) {
  std::map<std::string, std::string> m;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && line[i] == ' ') ++i;
    const std::size_t eq = line.find('=', i);
    if (eq == std::string::npos) break;
    const std::string key = line.substr(i, eq - i);
    std::size_t j = eq + 1;
    std::string value;
    if (j < line.size() && line[j] == '"') {
      const std::size_t end = line.find('"', j + 1);
      value = line.substr(j + 1, end == std::string::npos ? std::string::npos : end - j - 1);
      j = end == std::string::npos ? line.size() : end + 1;
    } else {
      const std::size_t end = line.find(' ', j);
      value = line.substr(j, end == std::string::npos ? std::string::npos : end - j);
      j = end == std::string::npos ? line.size() : end;
    }
    m[key] = value;
    i = j;
  }
  return m;
}

void print_status_table(const std::vector<std::string>& lines, const std::string& footer) {
  const std::vector<std::pair<const char*, const char*>> cols = {
      {"AXIS", "axis"},       {"TYPE", "type"},       {"NODE", "node"},       {"STATE", "state"},
      {"DRIVE", "drive"},     {"CMD_POS", "cmd_pos"}, {"ACT_POS", "act_pos"}, {"CMD_VEL", "cmd_vel"},
      {"ACT_VEL", "act_vel"}, {"POS_ERR", "pos_err"}, {"EMCY", "last_emcy"},  {"MOTION", "motion_bits"},
  };
  std::vector<std::map<std::string, std::string>> rows;
  for (const auto& l : lines) rows.push_back(fields(l));
  std::vector<std::size_t> width;
  for (const auto& [head, key] : cols) {
    std::size_t w = std::strlen(head);
    for (auto& r : rows) w = std::max(w, r.count(key) ? r[key].size() : 1);
    width.push_back(w);
  }
  auto cell = [](const std::string& v, std::size_t w) { return fmt::format("{:<{}}  ", v, w); };
  std::string head;
  for (std::size_t c = 0; c < cols.size(); ++c) head += cell(cols[c].first, c + 1 == cols.size() ? 0 : width[c]);
  fmt::print("{}\n", head.substr(0, head.find_last_not_of(' ') + 1));
  for (auto& r : rows) {
    std::string l;
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const std::string v = r.count(cols[c].second) ? r[cols[c].second] : "-";
      l += cell(v, c + 1 == cols.size() ? 0 : width[c]);
    }
    fmt::print("{}\n", l.substr(0, l.find_last_not_of(' ') + 1));
  }
  // Status and fault bits and failures: long, one line each under the table.
  for (auto& r : rows) {
    const std::string name = r["axis"];
    if (r.count("status_bits") && r["status_bits"] != "-") fmt::print("  {}: AxisStatus {}\n", name, r["status_bits"]);
    if (r.count("faults") && r["faults"] != "-") fmt::print("  {}: AxisFault {}\n", name, r["faults"]);
    if (r.count("failure")) fmt::print("  {}: drive failure: {}\n", name, r["failure"]);
  }
  if (!footer.empty()) fmt::print("({})\n", footer);
}

int run(const std::string& socket_path, double timeout, std::optional<double> user_timeout,
        const std::vector<std::string>& cmd, double interval, long count) {
  const std::string& verb = cmd[0];
  if (verb == "get") {
    if (cmd.size() < 2) throw CLI::ValidationError("get: give at least one tag");
    Connection c(socket_path, timeout);
    std::string line = "GET";
    for (std::size_t i = 1; i < cmd.size(); ++i) line += " " + cmd[i];
    c.send_line(line);
    const std::string ok = c.response();
    if (cmd.size() == 2) {
      fmt::print("{}\n", ok.substr(ok.find('=') + 1));
    } else {
      std::istringstream in(ok);
      std::string w;
      while (in >> w) fmt::print("{}\n", w);
    }
    return 0;
  }
  if (verb == "set") {
    if (cmd.size() != 3) throw CLI::ValidationError("set: give a tag and a value: set Distance 12.5");
    Connection c(socket_path, timeout);
    c.send_line("SET " + cmd[1] + " " + cmd[2]);
    c.response();
    return 0;
  }
  if (verb == "status" || verb == "stats") {
    if (cmd.size() != 1) throw CLI::ValidationError(verb + " takes no arguments");
    Connection c(socket_path, timeout);
    std::vector<std::string> lines;
    c.send_line(verb == "status" ? "STATUS" : "STATS");
    const std::string ok = c.response([&](const std::string& l) { lines.push_back(l); });
    if (verb == "status") {
      print_status_table(lines, ok);
    } else {
      for (const auto& l : lines) {
        const std::size_t eq = l.find('=');
        const std::string k = l.substr(0, eq), v = eq == std::string::npos ? "" : l.substr(eq + 1);
        if (k.size() > 3 && k.compare(k.size() - 3, 3, "_ns") == 0 && k != "period_ns")
          fmt::print("{:<26} {:>12.1f} us\n", k.substr(0, k.size() - 3), std::strtod(v.c_str(), nullptr) / 1e3);
        else
          fmt::print("{:<26} {:>12}\n", k, v);
      }
    }
    return 0;
  }
  if (verb == "watch") {
    if (cmd.size() < 2) throw CLI::ValidationError("watch: give at least one tag");
    Connection c(socket_path, user_timeout.value_or(0));
    std::string line = fmt::format("WATCH {}", interval);
    for (std::size_t i = 1; i < cmd.size(); ++i) line += " " + cmd[i];
    struct sigaction sa {};
    sa.sa_handler = on_sigint;
    sigaction(SIGINT, &sa, nullptr);  // no SA_RESTART: poll returns EINTR
    c.send_line(line);
    long seen = 0;
    try {
      c.response([&](const std::string& l) { fmt::print("{}\n", l); });  // OK watching ...
      while (!g_stop && (count <= 0 || seen < count)) {
        const std::string l = c.read_line();
        if (l.rfind("ERR", 0) == 0) throw Failure{l.size() > 4 ? l.substr(4) : l};
        fmt::print("{}\n", l);
        std::fflush(stdout);
        ++seen;
      }
    } catch (const Failure&) {
      if (!g_stop) throw;
    }
    c.send_line("UNWATCH");
    return 0;
  }
  if (verb == "run") {
    if (cmd.size() != 2) throw CLI::ValidationError("run: give one script file (or - for stdin)");
    std::string text;
    if (cmd[1] == "-") {
      std::ostringstream ss;
      ss << std::cin.rdbuf();
      text = ss.str();
    } else {
      std::ifstream f(cmd[1]);
      if (!f) throw Failure{fmt::format("cannot read script '{}': {}", cmd[1], std::strerror(errno))};
      std::ostringstream ss;
      ss << f.rdbuf();
      text = ss.str();
    }
    std::string name = cmd[1] == "-" ? "<stdin>" : cmd[1];
    std::replace(name.begin(), name.end(), ' ', '_');
    std::string req = "RUN " + name + "\n";
    std::istringstream in(text);
    std::string l;
    while (std::getline(in, l)) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      req += (l == "END" ? "END " : l) + "\n";  // a bare END line ends the script text
    }
    req += "END\n";
    Connection c(socket_path, user_timeout.value_or(0));
    c.send(req);
    c.response([](const std::string& out) {
      fmt::print("{}\n", out);
      std::fflush(stdout);
    });
    return 0;
  }
  if (verb == "mode") {
    if (cmd.size() > 2) throw CLI::ValidationError("mode: give run or program, or nothing to print the mode");
    if (cmd.size() == 2 && cmd[1] != "run" && cmd[1] != "program")
      throw CLI::ValidationError("mode: '" + cmd[1] + "' is not run or program");
    Connection c(socket_path, timeout);
    c.send_line(cmd.size() == 2 ? "MODE " + cmd[1] : std::string("MODE"));
    const std::string ok = c.response();
    fmt::print("{}\n", ok.substr(ok.find('=') + 1));
    return 0;
  }
  if (verb == "send") {
    if (cmd.size() < 2) throw CLI::ValidationError("send: give a protocol line, e.g. send 'GET Controller.Time'");
    std::string line = cmd[1];
    for (std::size_t i = 2; i < cmd.size(); ++i) line += " " + cmd[i];
    Connection c(socket_path, timeout);
    c.send_line(line);
    const std::string ok = c.response();
    fmt::print("OK{}{}\n", ok.empty() ? "" : " ", ok);
    return 0;
  }
  if (verb.find('(') != std::string::npos) {
    std::string call = verb;
    for (std::size_t i = 1; i < cmd.size(); ++i) call += " " + cmd[i];  // unquoted: MSO(X, mso1) as two words
    Connection c(socket_path, timeout);
    c.send_line(call);
    const std::string ok = c.response();
    fmt::print("{}\n", ok);
    return 0;
  }
  throw CLI::ValidationError(fmt::format(
      "unknown command '{}': expected an instruction like 'MSO(X, mso1)', get, set, status, watch, run, stats or "
      "send (see --help)",
      verb));
}

}  // namespace

int main(int argc, char** argv) {
  std::string socket_path;
  if (const char* env = std::getenv("CANMOTIOND_SOCKET"); env && *env) socket_path = env;
  if (socket_path.empty()) socket_path = kDefaultSocket;
  std::optional<double> user_timeout;
  double interval = 0.1;
  long count = 0;
  std::vector<std::string> cmd;
  bool help = false;

  CLI::App app{"canmotionctl: talk to a running canmotiond", "canmotionctl"};
  app.set_help_flag();
  app.add_flag("-h,--help", help);
  app.add_option("-s,--socket", socket_path);
  app.add_option("-t,--timeout", user_timeout)->check(CLI::NonNegativeNumber);
  app.add_option("-i,--interval", interval)->check(CLI::PositiveNumber);
  app.add_option("-n,--count", count)->check(CLI::NonNegativeNumber);
  app.add_option("command", cmd);
  app.positionals_at_end(false);
  app.allow_extras(false);
  // Negative numbers (set Offset -5) are values, not options.
  std::vector<std::string> args;
  for (int i = argc - 1; i >= 1; --i) args.emplace_back(argv[i]);
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "canmotionctl: {}\nTry 'canmotionctl --help'.\n", e.what());
    return 2;
  }
  if (help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (cmd.empty()) {
    fmt::print(stderr, "canmotionctl: no command given\n\n{}", kUsage);
    return 2;
  }
  ::signal(SIGPIPE, SIG_IGN);
  try {
    return run(socket_path, user_timeout.value_or(10.0), user_timeout, cmd, interval, count);
  } catch (const CLI::ValidationError& e) {
    fmt::print(stderr, "canmotionctl: {}\nTry 'canmotionctl --help'.\n", e.what());
    return 2;
  } catch (const Failure& f) {
    fmt::print(stderr, "canmotionctl: {}\n", f.message);
    return 1;
  }
}
