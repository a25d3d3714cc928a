// Values of an EDS/DCF (DefaultValue, ParameterValue, LowLimit, HighLimit)
// read for their object's data type (CiA 306 §4.6.3: integers in decimal,
// 0x hex or 0 octal, "$NODEID+" relative values; reals in decimal; strings
// as text, OCTET_STRING and DOMAIN as hex bytes).
#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "fieldbus/canopen/pdo.hpp"  // sign_extend
#include "fieldbus/eds/eds.hpp"
#include "fieldbus/eds/text.hpp"

namespace canmotion::eds {

using canopen::DataType;

namespace {

bool is_string_type(DataType t) {
  return t == DataType::kVisibleString || t == DataType::kUnicodeString;
}
bool is_bytes_type(DataType t) { return t == DataType::kOctetString || t == DataType::kDomain; }
bool is_real(DataType t) { return t == DataType::kReal32 || t == DataType::kReal64; }

std::uint64_t width_mask(std::size_t bytes) {
  return bytes >= 8 ? ~std::uint64_t{0} : (std::uint64_t{1} << (8 * bytes)) - 1;
}

/// The range of an integer type as text, for messages: "(0 .. 255)".
std::string range_text(DataType t) {
  const std::size_t bytes = canopen::data_type_size(t);
  if (t == DataType::kBoolean) return "(0 .. 1)";
  const unsigned bits = static_cast<unsigned>(8 * bytes);
  if (canopen::data_type_signed(t)) {
    const std::int64_t hi = static_cast<std::int64_t>((std::uint64_t{1} << (bits - 1)) - 1);
    return fmt::format("({} .. {})", -hi - 1, hi);
  }
  return fmt::format("(0 .. {})", width_mask(bytes));
}

/// An integer of type `t` from a plain number (no $NODEID).
std::optional<std::uint64_t> integer_bits(std::string_view s, DataType t, std::string& why) {
  const Number n = parse_number(s);
  if (!n.ok) {
    why = fmt::format("'{}' is not a number (decimal, 0x hex or 0 octal)", s);
    return std::nullopt;
  }
  const std::size_t bytes = canopen::data_type_size(t);
  const std::uint64_t mask = t == DataType::kBoolean ? 1 : width_mask(bytes);
  const auto name = canopen::data_type_name(t);
  if (!canopen::data_type_signed(t)) {
    if (n.negative && n.magnitude != 0) {
      why = fmt::format("{} is negative, {} is unsigned {}", s, name, range_text(t));
      return std::nullopt;
    }
    if (n.magnitude > mask) {
      why = fmt::format("{} does not fit {} {}", s, name, range_text(t));
      return std::nullopt;
    }
    return n.magnitude;
  }
  const std::uint64_t half = std::uint64_t{1} << (8 * bytes - 1);  // 2^(n-1)
  if (n.negative) {
    if (n.magnitude > half) {
      why = fmt::format("{} does not fit {} {}", s, name, range_text(t));
      return std::nullopt;
    }
    return (~n.magnitude + 1) & mask;
  }
  // A positive decimal must be in range; hex and octal give the bit pattern
  // (0xFFFF is -1 for an INTEGER16), as vendors' files write negative limits.
  const std::uint64_t max = n.base == 10 ? half - 1 : mask;
  if (n.magnitude > max) {
    why = fmt::format("{} does not fit {} {}", s, name, range_text(t));
    return std::nullopt;
  }
  return n.magnitude;
}

}  // namespace

Number parse_number(std::string_view s) {
  Number n;
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) {
    n.negative = s.front() == '-';
    s.remove_prefix(1);
  }
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    n.base = 16;
    s.remove_prefix(2);
  } else if (s.size() > 1 && s[0] == '0') {
    n.base = 8;
    s.remove_prefix(1);
  }
  if (s.empty()) return n;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), n.magnitude, n.base);
  n.ok = ec == std::errc{} && end == s.data() + s.size();
  return n;
}

std::uint64_t Value::resolve(std::uint8_t node_id, std::size_t bytes) const noexcept {
  const std::uint64_t v = node_id_relative ? bits + node_id : bits;
  return v & width_mask(bytes == 0 ? 8 : bytes);
}

std::optional<Value> parse_value(std::string_view text, DataType t, std::string& why) {
  Value v;
  v.text = std::string(text);
  if (is_string_type(t)) {
    v.data = v.text;
    return v;
  }
  if (is_bytes_type(t)) {
    std::string digits;
    for (char c : text)
      if (c != ' ' && c != '\t') digits.push_back(c);
    if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) digits.erase(0, 2);
    if (digits.size() % 2 != 0 ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); })) {
      why = fmt::format("'{}' is not hex bytes (two hex digits per byte) for {}", text, canopen::data_type_name(t));
      return std::nullopt;
    }
    for (std::size_t i = 0; i < digits.size(); i += 2) {
      unsigned b = 0;
      std::from_chars(digits.data() + i, digits.data() + i + 2, b, 16);
      v.data.push_back(static_cast<char>(b));
    }
    return v;
  }
  const std::string compact = strip_spaces(text);
  if (compact.empty()) {
    why = fmt::format("empty value for {}", canopen::data_type_name(t));
    return std::nullopt;
  }
  if (is_real(t)) {
    const bool r32 = t == DataType::kReal32;
    if (compact.size() > 2 && compact[0] == '0' && (compact[1] == 'x' || compact[1] == 'X')) {
      // The IEEE 754 bit pattern, as some tools write it.
      const Number n = parse_number(compact);
      if (!n.ok || (r32 && n.magnitude > 0xFFFFFFFFu)) {
        why = fmt::format("'{}' is not a {} bit pattern", text, canopen::data_type_name(t));
        return std::nullopt;
      }
      v.bits = n.magnitude;
      return v;
    }
    double d = 0;
    const auto [end, ec] = std::from_chars(compact.data(), compact.data() + compact.size(), d);
    if (ec != std::errc{} || end != compact.data() + compact.size()) {
      why = fmt::format("'{}' is not a decimal number for {}", text, canopen::data_type_name(t));
      return std::nullopt;
    }
    if (r32) {
      if (std::isfinite(d) && std::fabs(d) > static_cast<double>(std::numeric_limits<float>::max())) {
        why = fmt::format("{} does not fit REAL32", text);
        return std::nullopt;
      }
      v.bits = std::bit_cast<std::uint32_t>(static_cast<float>(d));
    } else {
      v.bits = std::bit_cast<std::uint64_t>(d);
    }
    return v;
  }
  // Integers (BOOLEAN, INTEGERn, UNSIGNEDn, TIME_OF_DAY, TIME_DIFFERENCE).
  std::string upper = compact;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const std::size_t at = upper.find("$NODEID");
  if (at != std::string::npos) {
    std::string rest;
    if (upper == "$NODEID") {
      rest = "0";
    } else if (at == 0 && upper.size() > 8 && upper[7] == '+') {
      rest = compact.substr(8);
    } else if (at > 1 && at + 7 == upper.size() && upper[at - 1] == '+') {
      rest = compact.substr(0, at - 1);
    } else {
      why = fmt::format("'{}': a node-ID relative value is $NODEID, $NODEID+<number> or <number>+$NODEID", text);
      return std::nullopt;
    }
    if (canopen::data_type_signed(t) || t == DataType::kBoolean) {
      why = fmt::format("'{}': $NODEID is only allowed for UNSIGNED types, not {}", text, canopen::data_type_name(t));
      return std::nullopt;
    }
    const auto b = integer_bits(rest, t, why);
    if (!b) return std::nullopt;
    v.node_id_relative = true;
    v.bits = *b;
    return v;
  }
  const auto b = integer_bits(compact, t, why);
  if (!b) return std::nullopt;
  v.bits = *b;
  return v;
}

int compare_values(DataType t, std::uint64_t a, std::uint64_t b) noexcept {
  if (t == DataType::kReal32 || t == DataType::kReal64) {
    const double x = t == DataType::kReal32 ? std::bit_cast<float>(static_cast<std::uint32_t>(a)) : std::bit_cast<double>(a);
    const double y = t == DataType::kReal32 ? std::bit_cast<float>(static_cast<std::uint32_t>(b)) : std::bit_cast<double>(b);
    return x < y ? -1 : (x > y ? 1 : 0);
  }
  const std::size_t bytes = canopen::data_type_size(t);
  if (bytes == 0) return 0;
  if (canopen::data_type_signed(t)) {
    const auto bits = static_cast<unsigned>(8 * bytes);
    const std::int64_t x = canopen::sign_extend(a, bits);
    const std::int64_t y = canopen::sign_extend(b, bits);
    return x < y ? -1 : (x > y ? 1 : 0);
  }
  return a < b ? -1 : (a > b ? 1 : 0);
}

std::string format_number(DataType t, std::uint64_t bits) {
  if (t == DataType::kReal32) return fmt::format("{}", std::bit_cast<float>(static_cast<std::uint32_t>(bits)));
  if (t == DataType::kReal64) return fmt::format("{}", std::bit_cast<double>(bits));
  const std::size_t bytes = canopen::data_type_size(t);
  if (canopen::data_type_signed(t)) return fmt::format("{}", canopen::sign_extend(bits, static_cast<unsigned>(8 * bytes)));
  return fmt::format("{}", bits);
}

}  // namespace canmotion::eds
