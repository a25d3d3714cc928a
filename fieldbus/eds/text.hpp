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

[[nodiscard]] inline bool is_space(char c) noexcept { return std::isspace(static_cast<unsigned char>(c)) != 0; }

/// `s` without leading and trailing white space.
[[nodiscard]] inline std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

/// Whether `s` starts with four hex digits (an index, as in a section name "1A00sub1").
[[nodiscard]] inline bool is_hex4(std::string_view s) noexcept {
  if (s.size() < 4) return false;
  for (std::size_t i = 0; i < 4; ++i)
    if (std::isxdigit(static_cast<unsigned char>(s[i])) == 0) return false;
  return true;
}
/// The four hex digits `s` starts with (is_hex4(s) must hold).
[[nodiscard]] inline std::uint16_t hex4(std::string_view s) {
  return static_cast<std::uint16_t>(std::stoul(std::string(s.substr(0, 4)), nullptr, 16));
}

}  // namespace canmotion::eds
