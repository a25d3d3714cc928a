#pragma once
/// \file
/// Texts generated from a command table, shared by the command server
/// (command_verbs.cpp: HELP, the unknown-request message) and canmotionctl
/// (tools/canmotionctl/commands.cpp: --help, the unknown-command message):
/// the layout of a help row and the list of a table's names. Header-only: the tool
/// does not link the runtime for it. Not realtime (allocates).

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace canmotion::rt::command {

/// Appends "  <syntax>  <help>" to `out`: the syntax padded to `syntax_width`
/// (one that leaves less than two spaces gets a line of its own), the help wrapped at spaces into the
/// column after it so that lines stay within `line_width` (a single word
/// longer than that stays whole).
inline void help_row(std::vector<std::string>& out, std::string_view syntax, std::string_view help,
                     std::size_t syntax_width, std::size_t line_width) {
  const std::size_t indent = 2 + syntax_width;
  std::string line = "  " + std::string(syntax);
  if (line.size() + 2 > indent) {
    out.push_back(line);
    line.clear();
  }
  line.resize(indent, ' ');
  std::size_t pos = 0;
  while (pos < help.size()) {
    std::size_t end = help.find(' ', pos);
    if (end == std::string_view::npos) end = help.size();
    const std::string_view word = help.substr(pos, end - pos);
    if (line.size() > indent && line.size() + 1 + word.size() > line_width) {
      out.push_back(line);
      line.assign(indent, ' ');
    }
    if (line.size() > indent) line += ' ';
    line += word;
    pos = end + 1;
  }
  out.push_back(line);
}

/// "a, b, c or d" of the non-empty names (the rows of a command table; the
/// empty name is the instruction call, which the messages name themselves).
template <typename Rows, typename Name>
std::string name_list(const Rows& rows, Name name) {
  std::vector<std::string_view> names;
  for (const auto& r : rows)
    if (!name(r).empty()) names.push_back(name(r));
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? " or " : ", ";
    out += names[i];
  }
  return out;
}

}  // namespace canmotion::rt::command
