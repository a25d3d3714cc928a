// canmotionctl: talk to a running canmotiond over its UNIX socket (the
// line-based protocol of README.md): execute motion instructions, read and
// write tags, show the axes, watch tags, run motion scripts, show statistics.
// Argument parsing here; the commands are the table of commands.cpp.
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "tools/canmotionctl/commands.hpp"
#include "tools/canmotionctl/connection.hpp"

int main(int argc, char** argv) {
  using namespace canmotionctl;
  Options o;
  if (const char* env = std::getenv("CANMOTIOND_SOCKET"); env && *env) o.socket = env;
  if (o.socket.empty()) o.socket = "/run/canmotion/canmotiond.sock";
  std::vector<std::string> words;
  bool help = false;

  CLI::App app{"canmotionctl: talk to a running canmotiond", "canmotionctl"};
  app.set_help_flag();
  app.add_flag("-h,--help", help);
  app.add_option("-s,--socket", o.socket);
  app.add_option("-t,--timeout", o.timeout)->check(CLI::NonNegativeNumber);
  app.add_option("-i,--interval", o.interval)->check(CLI::PositiveNumber);
  app.add_option("-n,--count", o.count)->check(CLI::NonNegativeNumber);
  app.add_option("command", words);
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
    std::fputs(usage().c_str(), stdout);
    return 0;
  }
  if (words.empty()) {
    fmt::print(stderr, "canmotionctl: no command given\n\n{}", usage());
    return 2;
  }
  std::signal(SIGPIPE, SIG_IGN);
  try {
    return run_command(o, words);
  } catch (const BadArguments& e) {
    fmt::print(stderr, "canmotionctl: {}\nTry 'canmotionctl --help'.\n", e.message);
    return 2;
  } catch (const Failure& f) {
    fmt::print(stderr, "canmotionctl: {}\n", f.message);
    return 1;
  }
}
