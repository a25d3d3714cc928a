// canmotionctl's command table and its handlers (see commands.hpp).
#include "tools/canmotionctl/commands.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>

#include <fmt/format.h>

#include "rt/controller/command_help.hpp"
#include "tools/canmotionctl/connection.hpp"
#include "tools/canmotionctl/output.hpp"

namespace canmotionctl {
namespace {

using Words = std::vector<std::string>;

/// `head` and the words from `from` on, separated by spaces.
std::string joined(std::string head, const Words& w, std::size_t from) {
  for (std::size_t i = from; i < w.size(); ++i) head += " " + w[i];
  return head;
}

int do_call(const Command&, const Options& o, const Words& w) {
  Connection c(o.socket, o.timeout_or_default());
  c.send_line(joined(w[0], w, 1));  // unquoted: MSO(X, mso1) as two words
  fmt::print("{}\n", c.response());
  return 0;
}

int do_get(const Command& cmd, const Options& o, const Words& w) {
  if (w.size() < 2) throw BadArguments{"get: give at least one tag"};
  Connection c(o.socket, o.timeout_or_default());
  c.send_line(joined(request(cmd, 0), w, 1));
  const std::string ok = c.response();
  if (w.size() == 2) {
    fmt::print("{}\n", ok.substr(ok.find('=') + 1));
  } else {
    std::istringstream in(ok);
    std::string tv;
    while (in >> tv) fmt::print("{}\n", tv);
  }
  return 0;
}

int do_set(const Command& cmd, const Options& o, const Words& w) {
  if (w.size() != 3) throw BadArguments{"set: give a tag and a value: set Distance 12.5"};
  Connection c(o.socket, o.timeout_or_default());
  c.send_line(joined(request(cmd, 0), w, 1));
  c.response();
  return 0;
}

/// The data lines of a request that takes no arguments; the OK text in `ok`.
Words data_lines(const Command& cmd, const Options& o, const Words& w, std::string& ok) {
  if (w.size() != 1) throw BadArguments{fmt::format("{} takes no arguments", w[0])};
  Connection c(o.socket, o.timeout_or_default());
  Words lines;
  c.send_line(request(cmd, 0));
  ok = c.response([&](const std::string& l) { lines.push_back(l); });
  return lines;
}

int do_status(const Command& cmd, const Options& o, const Words& w) {
  std::string ok;
  const Words lines = data_lines(cmd, o, w, ok);
  print_status_table(lines, ok);
  return 0;
}

int do_stats(const Command& cmd, const Options& o, const Words& w) {
  std::string ok;
  print_stats(data_lines(cmd, o, w, ok));
  return 0;
}

int do_watch(const Command& cmd, const Options& o, const Words& w) {
  if (w.size() < 2) throw BadArguments{"watch: give at least one tag"};
  Connection c(o.socket, o.timeout.value_or(0));
  install_sigint();
  c.send_line(joined(fmt::format("{} {}", request(cmd, 0), o.interval), w, 1));
  long seen = 0;
  try {
    c.response([&](const std::string& l) { fmt::print("{}\n", l); });  // OK watching ...
    while (!g_stop && (o.count <= 0 || seen < o.count)) {
      const std::string l = c.read_line();
      if (l.rfind("ERR", 0) == 0) throw Failure{l.size() > 4 ? l.substr(4) : l};
      fmt::print("{}\n", l);
      std::fflush(stdout);
      ++seen;
    }
  } catch (const Failure&) {
    if (!g_stop) throw;
  }
  c.send_line(request(cmd, 1));  // UNWATCH
  return 0;
}

std::string read_script(const std::string& file) {
  std::ostringstream ss;
  if (file == "-") {
    ss << std::cin.rdbuf();
  } else {
    std::ifstream f(file);
    if (!f) throw Failure{fmt::format("cannot read script '{}': {}", file, std::strerror(errno))};
    ss << f.rdbuf();
  }
  return ss.str();
}

int do_run(const Command& cmd, const Options& o, const Words& w) {
  if (w.size() != 2) throw BadArguments{"run: give one script file (or - for stdin)"};
  const std::string text = read_script(w[1]);
  std::string name = w[1] == "-" ? "<stdin>" : w[1];
  std::replace(name.begin(), name.end(), ' ', '_');
  const std::string end = request(cmd, 1);  // the line that ends the script text
  std::string req = fmt::format("{} {}\n", request(cmd, 0), name);
  std::istringstream in(text);
  std::string l;
  while (std::getline(in, l)) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    req += (l == end ? end + " " : l) + "\n";  // a script line END is sent as "END "
  }
  req += end + "\n";
  Connection c(o.socket, o.timeout.value_or(0));
  c.send(req);
  c.response([](const std::string& out) {
    fmt::print("{}\n", out);
    std::fflush(stdout);
  });
  return 0;
}

int do_mode(const Command& cmd, const Options& o, const Words& w) {
  if (w.size() > 2) throw BadArguments{"mode: give run or program, or nothing to print the mode"};
  if (w.size() == 2 && w[1] != "run" && w[1] != "program")
    throw BadArguments{"mode: '" + w[1] + "' is not run or program"};
  Connection c(o.socket, o.timeout_or_default());
  c.send_line(joined(request(cmd, 0), w, 1));
  const std::string ok = c.response();
  fmt::print("{}\n", ok.substr(ok.find('=') + 1));
  return 0;
}

int do_send(const Command&, const Options& o, const Words& w) {
  if (w.size() < 2) throw BadArguments{"send: give a protocol line, e.g. send 'GET Controller.Time'"};
  Connection c(o.socket, o.timeout_or_default());
  c.send_line(joined(w[1], w, 2));
  const std::string ok = c.response();
  fmt::print("OK{}{}\n", ok.empty() ? "" : " ", ok);
  return 0;
}

// A data table: one row per command, in --help order (exempt from the function length limit).
constexpr Command kCommands[] = {
    {"", "",
     "execute a Logix motion instruction (ST syntax) and print its control tag (EN DN ER PC IP AC ERR EXERR STATE)", "",
     &do_call},
    {"get", "TAG...", "print tag values (one tag: the value; more: TAG=VALUE lines)", "GET", &do_get},
    {"set", "TAG VALUE", "write a writable tag (numeric user tag or array element)", "SET", &do_set},
    {"status", "", "table of the axes: state, drive, positions, velocity, status bits, faults, last EMCY", "STATUS",
     &do_status},
    {"watch", "TAG... [-i S] [-n N]",
     "print `t=<s> TAG=VALUE ...` every S seconds of controller time (default 0.1) until Ctrl-C, or N lines",
     "WATCH UNWATCH", &do_watch},
    {"run", "SCRIPT", "run a motion script (file, or - for stdin), printing its PRINT lines; exit status 1 if the "
                      "script fails",
     "RUN END", &do_run},
    {"stats", "", "controller and cycle statistics", "STATS", &do_stats},
    {"mode", "[run|program]",
     "print or set the controller mode: program stops every axis by its Programmed Stop Mode, breaks the MDAC links "
     "and refuses instructions that start motion (ERR 24)",
     "MODE", &do_mode},
    {"send", "'LINE'", "send one raw protocol line and print the response (send HELP lists the requests)",
     "HELP QUIT", &do_send},
};

constexpr std::size_t kSyntaxWidth = 25;  // "'INSTR(operands)'" (17) and spaces: help in column 28
constexpr std::size_t kLineWidth = 84;  // as the hand-written usage was

constexpr std::string_view kUsageHead = R"(Usage: canmotionctl [options] <command> [arguments]

Talks to a running canmotiond (started with --socket) over its UNIX socket.

Commands:
)";

constexpr std::string_view kUsageTail = R"(
Options:
  -s, --socket PATH        canmotiond's socket (default $CANMOTIOND_SOCKET, else
                           /run/canmotion/canmotiond.sock)
  -t, --timeout S          give up waiting for a response after S seconds
                           (default 10; run and watch wait forever unless given)
  -i, --interval S         watch: seconds of controller time between lines
                           (default 0.1)
  -n, --count N            watch: stop after N lines (default: until Ctrl-C)
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

}  // namespace

std::span<const Command> commands() noexcept { return kCommands; }

const Command* find_command(std::string_view word) noexcept {
  for (const Command& c : kCommands)
    if (!c.name.empty() && c.name == word) return &c;
  if (word.find('(') == std::string_view::npos) return nullptr;
  static_assert(kCommands[0].name.empty(), "the first row is the instruction call");
  return &kCommands[0];
}

std::string request(const Command& c, std::size_t i) {
  std::size_t pos = 0;
  for (; i > 0 && pos != std::string_view::npos; --i) {
    pos = c.requests.find(' ', pos);
    if (pos != std::string_view::npos) ++pos;
  }
  if (pos == std::string_view::npos || pos >= c.requests.size()) return {};
  return std::string(c.requests.substr(pos, c.requests.find(' ', pos) - pos));
}

std::string usage() {
  std::vector<std::string> rows;
  for (const Command& c : kCommands) {
    const std::string syntax = c.name.empty()   ? std::string("'INSTR(operands)'")
                               : c.args.empty() ? std::string(c.name)
                                                : fmt::format("{} {}", c.name, c.args);
    canmotion::rt::command::help_row(rows, syntax, c.help, kSyntaxWidth, kLineWidth);
  }
  std::string text(kUsageHead);
  for (const std::string& r : rows) text += r + "\n";
  return text + std::string(kUsageTail);
}

std::string unknown_command(std::string_view word) {
  return fmt::format("unknown command '{}': expected an instruction like 'MSO(X, mso1)', {} (see --help)", word,
                     canmotion::rt::command::name_list(kCommands, [](const Command& c) { return c.name; }));
}

int run_command(const Options& o, const std::vector<std::string>& words) {
  const Command* c = find_command(words.at(0));
  if (!c) throw BadArguments{unknown_command(words[0])};
  return c->handler(*c, o, words);
}

}  // namespace canmotionctl
