#pragma once
/// \file
/// The layout of a help row, shared by the command server's HELP
/// (command_verbs.cpp) and canmotionctl's --help (tools/canmotionctl), which
/// both generate their text from their command tables. Header-only: the tool
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

}  // namespace canmotion::rt::command
