#pragma once
/// \file
/// Small text helpers of the EDS reader (internal to fieldbus/eds).

#include <cctype>
#include <cstdint>
#include <string>
#include <string_view>

namespace canmotion::eds {

/// A CiA 306 integer: optional sign, then decimal, 0x hex or 0 octal.
struct Number {
  bool ok = false;
  bool negative = false;
  int base = 10;
  std::uint64_t magnitude = 0;
};
[[nodiscard]] Number parse_number(std::string_view s);

/// Case-insensitive comparison (ASCII), as CiA 306 keys and section names are.
[[nodiscard]] inline bool iequals(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

[[nodiscard]] inline std::string to_lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

/// `s` without blanks (spaces and tabs), as in "$NODEID + 0x180".
[[nodiscard]] inline std::string strip_spaces(std::string_view s) {
  std::string r;
  for (char c : s)
    if (c != ' ' && c != '\t') r.push_back(c);
  return r;
}

}  // namespace canmotion::eds
