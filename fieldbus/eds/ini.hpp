#pragma once
/// \file
/// The INI layer of the EDS/DCF reader (internal to fieldbus/eds). inih
/// (Debian libinih-dev) reads the INI syntax: sections, key=value lines,
/// comments, the BOM; it hands every key to a callback with its line number
/// (Debian builds it with INI_HANDLER_LINENO). A first pass over the lines
/// records where each [section] header is, so that keys are attributed to the
/// right occurrence of a section given twice and empty sections are seen too
/// (inih calls back only for keys). builder.hpp interprets the sections.
/// Set-up only (allocates, throws).

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fieldbus/eds/text.hpp"

namespace canmotion::eds {

/// Longest line accepted (a DOMAIN or OCTET_STRING value in hex can be long;
/// inih's heap buffer grows up to this).
inline constexpr std::size_t kMaxLine = 65536;

/// Syntax errors listed at most (then one more line says there are more):
/// each costs inih one more pass over the text.
inline constexpr int kMaxSyntaxErrors = 50;

struct RawKey {
  std::string name;
  std::string value;
  int line = 0;
};

struct RawSection {
  std::string name;
  int line = 0;
  std::vector<RawKey> keys;
  [[nodiscard]] const RawKey* get(std::string_view k) const {
    for (const RawKey& x : keys)
      if (iequals(x.name, k)) return &x;
    return nullptr;
  }
};

/// A file as INI text: its sections and what is not a section's key.
struct IniFile {
  std::vector<RawSection> sections;                  // in file order, one per header line
  std::vector<std::pair<int, std::string>> outside;  // keys before the first header (line, name)
  std::vector<std::pair<int, std::string>> syntax_errors;  // (line, message), ascending
};

/// Read `text` (named `file` in diagnostics) as INI. Throws ParseError when
/// a line is too long or holds a NUL (no INI reading then), or when libinih
/// does not pass line numbers; std::bad_alloc when memory runs out.
[[nodiscard]] IniFile read_ini(std::string_view text, const std::string& file);

}  // namespace canmotion::eds
