#pragma once
// canmotionctl's command table (commands.cpp): each command once, with its
// argument syntax, its one-line help, the protocol requests it sends and its
// handler. --help, the dispatch and the "unknown command" message are
// generated from it. The command server has the matching table
// (rt/controller/command_verbs.hpp); tests/ctl/command_tables_test.cpp checks
// that every request verb of the server is sent by a command here and that
// every request sent here is a verb of the server.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace canmotionctl {

/// Bad command-line arguments: message to stderr with "Try --help", exit 2.
struct BadArguments {
  std::string message;
};

/// The options every command may use.
struct Options {
  std::string socket;                 ///< canmotiond's socket
  std::optional<double> timeout;      ///< -t; run and watch wait forever without it
  double interval = 0.1;              ///< -i (watch)
  long count = 0;                     ///< -n (watch); 0: until Ctrl-C
  [[nodiscard]] double timeout_or_default() const { return timeout.value_or(10.0); }
};

struct Command;
/// A command's handler: `words` are the command-line words, words[0] the
/// command. Returns the exit status; throws BadArguments or Failure.
using Handler = int (*)(const Command&, const Options&, const std::vector<std::string>& words);

/// One row of the table.
struct Command {
  /// The first word, exactly. Empty: an instruction call (a first word with '(').
  std::string_view name;
  /// Argument syntax for --help.
  std::string_view args;
  /// One line of help (--help wraps it).
  std::string_view help;
  /// The protocol request verbs the command sends, space-separated, the main
  /// one first (the handler takes them from here). Empty for the instruction
  /// call (the line is the call); for `send`, the verbs that canmotionctl
  /// reaches only through it.
  std::string_view requests;
  Handler handler;
};

/// Every row, in --help order.
[[nodiscard]] std::span<const Command> commands() noexcept;
/// The row for a first word: by name, else the instruction call if the word has '('; null if none.
[[nodiscard]] const Command* find_command(std::string_view word) noexcept;
/// The i-th verb of `requests` (empty if there are fewer).
[[nodiscard]] std::string request(const Command& c, std::size_t i);
/// The --help text.
[[nodiscard]] std::string usage();
/// The message for a first word that is no command.
[[nodiscard]] std::string unknown_command(std::string_view word);
/// Runs the command `words` (words[0] names it). Throws BadArguments or Failure.
int run_command(const Options& o, const std::vector<std::string>& words);

}  // namespace canmotionctl
