#pragma once
/// \file
/// The command server's table of request verbs (command_verbs.cpp): each
/// verb once, with its argument syntax, its one-line help and its handler.
/// HELP, the dispatch of a request line and the "unknown request" message
/// are generated from it. tools/canmotionctl has the matching table on the
/// client side; tests/ctl/command_tables_test.cpp checks that the two agree.
///
/// Non-RT (the command server's thread).

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace canmotion::rt::command {

struct Service;  // the server's state (command_service.hpp)
struct Client;   // one connection (command_service.hpp)

/// A request line, split.
struct Request {
  std::string_view line;           ///< trimmed, without newline
  std::vector<std::string> words;  ///< split on white space; words[0] is the verb
};

/// A verb's handler: answers the request or makes it pending.
using Handler = void (Service::*)(Client&, const Request&);

/// One row of the table.
struct Verb {
  /// The request's first word, matched case-insensitively. Empty: the
  /// instruction call (a line with '(' whose first word is no verb).
  std::string_view name;
  /// Argument syntax, as HELP shows it.
  std::string_view args;
  /// One line of help (HELP wraps it).
  std::string_view help;
  Handler handler;
  /// Also served while a WATCH runs (every other request gets an ERR then).
  bool while_watching;
};

/// Every row, in HELP order; the instruction call (empty name) is one of them.
[[nodiscard]] std::span<const Verb> verbs() noexcept;
/// The row whose name is `word` (case-insensitive); null if none. Never the call.
[[nodiscard]] const Verb* find_verb(std::string_view word) noexcept;
/// The row of the instruction call.
[[nodiscard]] const Verb& call_verb() noexcept;
/// HELP's data lines.
[[nodiscard]] std::vector<std::string> help_lines();
/// The text after "ERR " for a request whose first word is no verb.
[[nodiscard]] std::string unknown_request(std::string_view word);

}  // namespace canmotion::rt::command
