// The INI layer of the EDS/DCF reader (see ini.hpp): inih reads the syntax,
// a first pass over the lines finds the [section] headers.
#include "fieldbus/eds/ini.hpp"

#include <algorithm>
#include <mutex>

#include <fmt/format.h>

#ifndef INI_HANDLER_LINENO
#error "fieldbus/eds needs INI_HANDLER_LINENO=1 (set in fieldbus/eds/CMakeLists.txt, as Debian's libinih is built)"
#endif
#include <ini.h>

#include "fieldbus/eds/eds.hpp"

namespace canmotion::eds {
namespace {

struct Collector {
  IniFile file;
  std::vector<int> header_lines;  // file.sections[i].line, ascending
  bool out_of_memory = false;
};

int on_key(void* user, const char* /*section*/, const char* name, const char* value, int lineno) noexcept {
  auto& c = *static_cast<Collector*>(user);
  if (name == nullptr) return 1;  // a new-section call, if the library makes them
  try {
    auto it = std::upper_bound(c.header_lines.begin(), c.header_lines.end(), lineno);
    if (it == c.header_lines.begin()) {
      c.file.outside.emplace_back(lineno, name);
      return 1;
    }
    c.file.sections[static_cast<std::size_t>(it - c.header_lines.begin() - 1)].keys.push_back(
        RawKey{name, value != nullptr ? value : "", lineno});
  } catch (...) {  // bad_alloc: must not cross the C library
    c.out_of_memory = true;
    return 0;
  }
  return 1;
}

int ignore_key(void*, const char*, const char*, const char*, int) noexcept { return 1; }

/// Every INI syntax error of `text` after the one inih reported at `first`
/// (its line), in line order, `first` included. inih goes on after an error
/// (ini_stop_on_first_error is off: the keys are all collected) but returns
/// the first error's line only: each further one is found by parsing again
/// with the lines reported so far blanked (line numbers kept).
std::vector<int> syntax_errors(std::string text, int first) {
  std::vector<int> lines;
  std::size_t from = 0;  // where line `at` starts (errors come in ascending line order)
  int at = 1;
  for (int line = first; line > 0;) {
    lines.push_back(line);
    if (lines.size() > static_cast<std::size_t>(kMaxSyntaxErrors)) break;  // the caller says there are more
    for (; at < line && from != std::string::npos; ++at) {
      from = text.find('\n', from);
      if (from != std::string::npos) ++from;
    }
    if (from == std::string::npos) break;
    const std::size_t end = std::min(text.find('\n', from), text.size());
    std::fill(text.begin() + static_cast<std::ptrdiff_t>(from), text.begin() + static_cast<std::ptrdiff_t>(end), ' ');
    line = ini_parse_string(text.c_str(), ignore_key, nullptr);
    if (line == -2) throw std::bad_alloc();
  }
  return lines;
}

int probe_key(void* user, const char*, const char* name, const char*, int lineno) noexcept {
  if (name != nullptr) *static_cast<int*>(user) = lineno;
  return 1;
}

/// inih's process-wide settings, once: heap line buffer growing to kMaxLine,
/// no multi-line values (an indented line is an error, not a continuation),
/// ';' comments (also after a blank, as Python's configparser reads EDS
/// files). Then a probe that the library passes line numbers.
bool configure_inih() {
  static std::once_flag once;
  static bool lineno_ok = false;
  std::call_once(once, [] {
    ini_use_stack = false;
    ini_allow_realloc = true;
    ini_max_line = static_cast<int>(kMaxLine + 3);
    ini_allow_multiline = false;
    ini_allow_no_value = false;
    ini_stop_on_first_error = false;
    ini_allow_bom = true;
    ini_allow_inline_comments = true;
    int seen = 0;
    ini_parse_string("\n\n[s]\nk=v\n", probe_key, &seen);
    lineno_ok = seen == 4;
  });
  return lineno_ok;
}

}  // namespace

IniFile read_ini(std::string_view text, const std::string& file) {
  if (!configure_inih())
    throw ParseError({Diagnostic{file, 0, "libinih does not pass line numbers (it must be built with INI_HANDLER_LINENO=1)"}});
  // First pass: the lines (length, NUL) and where each [section] header is.
  Collector c;
  std::vector<Diagnostic> early;
  int line = 0;
  for (std::size_t pos = 0; pos <= text.size();) {
    ++line;
    const std::size_t nl = text.find('\n', pos);
    std::string_view l = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    if (l.size() > kMaxLine)
      early.push_back(Diagnostic{file, line, fmt::format("line is longer than {} characters", kMaxLine)});
    if (l.find('\0') != std::string_view::npos)
      early.push_back(Diagnostic{file, line, "NUL character (not a text file?)"});
    if (line == 1 && l.starts_with("\xEF\xBB\xBF")) l.remove_prefix(3);
    l = trim(l);
    if (!l.empty() && l.front() == '[') {
      const std::size_t e = l.find(']');
      if (e != std::string_view::npos) {
        c.file.sections.push_back(RawSection{std::string(trim(l.substr(1, e - 1))), line, {}});
        c.header_lines.push_back(line);
      }
    }
    if (nl == std::string_view::npos) break;
    pos = nl + 1;
  }
  if (!early.empty()) throw ParseError(std::move(early));
  const std::string z(text);  // inih reads a NUL-terminated string
  const int r = ini_parse_string(z.c_str(), on_key, &c);
  if (c.out_of_memory || r == -2) throw std::bad_alloc();
  if (r > 0) {
    const std::vector<int> lines = syntax_errors(z, r);
    for (std::size_t i = 0; i < lines.size(); ++i)
      c.file.syntax_errors.emplace_back(
          lines[i], i < static_cast<std::size_t>(kMaxSyntaxErrors)
                        ? std::string("not a [section] header or a key=value line")
                        : fmt::format("more lines that are not a [section] header or a key=value line (only the "
                                      "first {} are listed)",
                                      kMaxSyntaxErrors));
  }
  return std::move(c.file);
}

}  // namespace canmotion::eds
