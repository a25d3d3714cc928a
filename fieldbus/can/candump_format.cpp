#include "fieldbus/can/candump_format.hpp"

#include <array>
#include <cstring>

namespace canmotion::can {
namespace {

constexpr char kHexUpper[] = "0123456789ABCDEF";

// "00" "01" ... "99" and "00" "01" ... "FF": two characters per table lookup.
constexpr std::array<char, 200> kDecPairs = [] {
  std::array<char, 200> t{};
  for (int i = 0; i < 100; ++i) {
    t[static_cast<std::size_t>(2 * i)] = static_cast<char>('0' + i / 10);
    t[static_cast<std::size_t>(2 * i + 1)] = static_cast<char>('0' + i % 10);
  }
  return t;
}();
constexpr std::array<char, 512> kHexPairs = [] {
  std::array<char, 512> t{};
  for (int i = 0; i < 256; ++i) {
    t[static_cast<std::size_t>(2 * i)] = kHexUpper[i >> 4];
    t[static_cast<std::size_t>(2 * i + 1)] = kHexUpper[i & 0xF];
  }
  return t;
}();

// Exactly `digits` (even) decimal digits of v (v < 10^digits), two at a time.
inline char* put_dec_fixed(char* p, std::uint64_t v, int digits) noexcept {
  for (int i = digits - 2; i >= 0; i -= 2) {
    const auto pair = static_cast<std::size_t>(v % 100U);
    v /= 100U;
    p[i] = kDecPairs[2 * pair];
    p[i + 1] = kDecPairs[2 * pair + 1];
  }
  return p + digits;
}

inline char* put_hex(char* p, std::uint32_t v, int digits) noexcept {
  for (int i = digits - 1; i >= 0; --i) *p++ = kHexUpper[(v >> (4 * i)) & 0xFU];
  return p;
}

// Longest line: "(" + 10 digits (INT64_MAX ns is 9223372036 s) + "." + 9 +
// ") " + 15 + " " + 8 + "#" + 16 = 64 characters.
constexpr std::size_t kLongestLine = 64;
static_assert(kLongestLine <= kCandumpLineMax);

constexpr int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

constexpr bool is_space(char c) noexcept { return c == ' ' || c == '\t'; }

std::string_view trim_right(std::string_view s) noexcept {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || is_space(s.back()))) s.remove_suffix(1);
  return s;
}

std::string_view skip_spaces(std::string_view s) noexcept {
  std::size_t i = 0;
  while (i < s.size() && is_space(s[i])) ++i;
  return s.substr(i);
}

// Split off the next whitespace-delimited token; `rest` keeps what follows.
std::string_view next_token(std::string_view& rest) noexcept {
  rest = skip_spaces(rest);
  std::size_t i = 0;
  while (i < rest.size() && !is_space(rest[i])) ++i;
  std::string_view tok = rest.substr(0, i);
  rest = rest.substr(i);
  return tok;
}

bool parse_hex(std::string_view s, std::uint32_t& v) noexcept {
  if (s.empty() || s.size() > 8) return false;
  std::uint32_t acc = 0;
  for (char c : s) {
    const int h = hex_value(c);
    if (h < 0) return false;
    acc = (acc << 4) | static_cast<std::uint32_t>(h);
  }
  v = acc;
  return true;
}

bool parse_dec(std::string_view s, std::uint64_t& v, std::size_t max_digits) noexcept {
  if (s.empty() || s.size() > max_digits) return false;
  std::uint64_t acc = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    acc = acc * 10 + static_cast<std::uint64_t>(c - '0');
  }
  v = acc;
  return true;
}

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's algorithm).
constexpr std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) noexcept {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? static_cast<unsigned>(-3) : 9U)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

// "<sec>.<frac>" with 1..9 fraction digits -> ns. Integer digits decide absolute/relative.
bool parse_seconds(std::string_view s, std::int64_t& t_ns, CandumpTime& kind, const char*& reason) noexcept {
  const std::size_t dot = s.find('.');
  if (dot == std::string_view::npos) {
    reason = "timestamp has no '.' (expected (seconds.fraction))";
    return false;
  }
  std::uint64_t sec = 0;
  std::uint64_t frac = 0;
  const std::string_view isec = s.substr(0, dot);
  const std::string_view ifrac = s.substr(dot + 1);
  // 12 integer digits reach year 33658: enough, and keeps sec * 1e9 inside int64.
  if (!parse_dec(isec, sec, 12)) {
    reason = "timestamp seconds are not 1..12 decimal digits";
    return false;
  }
  if (!parse_dec(ifrac, frac, 9)) {
    reason = "timestamp fraction is not 1..9 decimal digits";
    return false;
  }
  for (std::size_t i = ifrac.size(); i < 9; ++i) frac *= 10;
  t_ns = static_cast<std::int64_t>(sec) * 1'000'000'000LL + static_cast<std::int64_t>(frac);
  kind = isec.size() >= 9 ? CandumpTime::kAbsolute : CandumpTime::kRelative;
  return true;
}

// "YYYY-MM-DD HH:MM:SS.frac" (candump -t A, local time; converted as UTC).
bool parse_date(std::string_view s, std::int64_t& t_ns, const char*& reason) noexcept {
  reason = "timestamp is not YYYY-MM-DD HH:MM:SS.ffffff";
  if (s.size() < 21 || s[4] != '-' || s[7] != '-' || s[10] != ' ' || s[13] != ':' || s[16] != ':' ||
      s[19] != '.') {
    return false;
  }
  std::uint64_t y = 0, mo = 0, d = 0, h = 0, mi = 0, se = 0;
  if (!parse_dec(s.substr(0, 4), y, 4) || !parse_dec(s.substr(5, 2), mo, 2) || !parse_dec(s.substr(8, 2), d, 2) ||
      !parse_dec(s.substr(11, 2), h, 2) || !parse_dec(s.substr(14, 2), mi, 2) || !parse_dec(s.substr(17, 2), se, 2)) {
    return false;
  }
  if (mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || se > 60) return false;
  std::int64_t frac_ns = 0;
  CandumpTime ignored{};
  // Reuse the seconds parser for the fraction: "0.<frac>".
  std::array<char, 16> buf{};
  const std::string_view frac = s.substr(20);
  if (frac.empty() || frac.size() > 9) return false;
  buf[0] = '0';
  buf[1] = '.';
  for (std::size_t i = 0; i < frac.size(); ++i) buf[2 + i] = frac[i];
  if (!parse_seconds(std::string_view(buf.data(), 2 + frac.size()), frac_ns, ignored, reason)) return false;
  const std::int64_t days =
      days_from_civil(static_cast<std::int64_t>(y), static_cast<unsigned>(mo), static_cast<unsigned>(d));
  const auto secs = days * 86400 + static_cast<std::int64_t>(h * 3600 + mi * 60 + se);
  t_ns = secs * 1'000'000'000LL + frac_ns;
  return true;
}

// Parses an optional leading "(...)" timestamp. `rest` advances past it.
bool parse_leading_time(std::string_view& rest, CandumpLine& out) noexcept {
  rest = skip_spaces(rest);
  out.time = CandumpTime::kNone;
  out.t_ns = 0;
  if (rest.empty() || rest.front() != '(') return true;
  const std::size_t close = rest.find(')');
  if (close == std::string_view::npos) {
    out.reason = "timestamp '(' without ')'";
    return false;
  }
  const std::string_view inner = rest.substr(1, close - 1);
  rest = rest.substr(close + 1);
  if (inner.size() > 4 && inner[4] == '-') {
    out.time = CandumpTime::kDate;
    return parse_date(inner, out.t_ns, out.reason);
  }
  return parse_seconds(inner, out.t_ns, out.time, out.reason);
}

bool valid_iface(std::string_view s) noexcept {
  if (s.empty() || s.size() > 15) return false;
  for (char c : s) {
    if (static_cast<unsigned char>(c) < 0x21 || c == '#' || c == '(' || c == ')' || c == '[') return false;
  }
  return true;
}

// Sets id and flags from a 3- or 8-digit candump id.
bool set_id(std::string_view digits, Frame& f, const char*& reason) noexcept {
  std::uint32_t id = 0;
  if ((digits.size() != 3 && digits.size() != 8) || !parse_hex(digits, id)) {
    reason = "CAN id is not 3 or 8 hex digits";
    return false;
  }
  f.flags = 0;
  if (digits.size() == 3) {
    if (id > 0x7FF) {
      reason = "11-bit CAN id above 7FF";
      return false;
    }
    f.id = id;
    return true;
  }
  if ((id & kCandumpErrorFlag) != 0) {
    if ((id & 0xC0000000U) != 0) {
      reason = "error frame id has EFF/RTR bits set";
      return false;
    }
    f.id = id & 0x1FFFFFFFU;
    f.flags = kError;
    return true;
  }
  if (id > 0x1FFFFFFFU) {
    reason = "29-bit CAN id above 1FFFFFFF";
    return false;
  }
  f.id = id;
  f.flags = kExtended;
  return true;
}

// "ID#DATA", "ID#R", "ID#R<len>", "ID##<flags><data>" (FD: unsupported).
CandumpParse parse_frame_token(std::string_view tok, CandumpLine& out) noexcept {
  const std::size_t hash = tok.find('#');
  if (hash == std::string_view::npos) {
    out.reason = "no '#' between CAN id and data";
    return CandumpParse::kMalformed;
  }
  Frame& f = out.frame;
  f = Frame{};
  if (!set_id(tok.substr(0, hash), f, out.reason)) return CandumpParse::kMalformed;
  std::string_view data = tok.substr(hash + 1);
  if (!data.empty() && data.front() == '#') {
    out.reason = "CAN FD frame (##) not supported";
    return CandumpParse::kUnsupported;
  }
  if (!data.empty() && (data.front() == 'R' || data.front() == 'r')) {
    if (f.error()) {
      out.reason = "error frame marked as remote request";
      return CandumpParse::kMalformed;
    }
    f.flags = static_cast<std::uint8_t>(f.flags | kRemote);
    data.remove_prefix(1);
    if (data.size() == 1 && data[0] >= '0' && data[0] <= '8') {
      f.len = static_cast<std::uint8_t>(data[0] - '0');
    } else if (!data.empty()) {
      out.reason = "remote request length is not one digit 0..8";
      return CandumpParse::kMalformed;
    }
    return CandumpParse::kOk;
  }
  // Optional raw DLC suffix "_<dlc>" (can-utils >= 2021 for 8-byte frames with DLC 9..F).
  const std::size_t us = data.find('_');
  if (us != std::string_view::npos) {
    const std::string_view dlc = data.substr(us + 1);
    if (dlc.size() != 1 || hex_value(dlc[0]) < 9) {
      out.reason = "raw DLC suffix is not _9.._F";
      return CandumpParse::kMalformed;
    }
    data = data.substr(0, us);
  }
  std::size_t i = 0;
  std::uint8_t n = 0;
  while (i < data.size()) {
    if (data[i] == '.') {  // optional byte separator
      ++i;
      continue;
    }
    if (i + 1 >= data.size()) {
      out.reason = "odd number of hex digits in data";
      return CandumpParse::kMalformed;
    }
    const int hi = hex_value(data[i]);
    const int lo = hex_value(data[i + 1]);
    if (hi < 0 || lo < 0) {
      out.reason = "data is not hex";
      return CandumpParse::kMalformed;
    }
    if (n >= kMaxPayload) {
      out.reason = "more than 8 data bytes in a classic CAN frame";
      return CandumpParse::kMalformed;
    }
    f.data[n++] = static_cast<std::uint8_t>((hi << 4) | lo);
    i += 2;
  }
  f.len = n;
  return CandumpParse::kOk;
}

}  // namespace

std::size_t format_candump_line(std::span<char> out, const Frame& frame, std::int64_t t_ns, std::string_view iface,
                                int frac_digits) noexcept {
  // Written straight into `out` when it surely has room, else into a local
  // line that is copied only if it fits (no partial line is ever left).
  std::array<char, kLongestLine> local;
  char* const start = out.size() > kLongestLine ? out.data() : local.data();
  char* p = start;
  if (t_ns < 0) t_ns = 0;
  const auto t = static_cast<std::uint64_t>(t_ns);
  const std::uint64_t sec = t / 1'000'000'000ULL;  // < 10^10
  const std::uint64_t ns = t % 1'000'000'000ULL;
  *p++ = '(';
  p = put_dec_fixed(p, sec, 10);
  *p++ = '.';
  if (frac_digits == 9) {
    p = put_dec_fixed(p, ns / 10U, 8);
    *p++ = static_cast<char>('0' + ns % 10U);
  } else {
    p = put_dec_fixed(p, ns / 1000U, 6);
  }
  *p++ = ')';
  *p++ = ' ';
  const std::string_view name = iface.substr(0, 15);
  if (!name.empty()) std::memcpy(p, name.data(), name.size());
  p += name.size();
  *p++ = ' ';
  if (frame.error()) {
    p = put_hex(p, (frame.id & 0x1FFFFFFFU) | kCandumpErrorFlag, 8);
  } else if (frame.extended()) {
    p = put_hex(p, frame.id & 0x1FFFFFFFU, 8);
  } else {
    p = put_hex(p, frame.id & 0x7FFU, 3);
  }
  *p++ = '#';
  const std::size_t len = frame.len <= kMaxPayload ? frame.len : kMaxPayload;
  if (frame.remote() && !frame.error()) {
    *p++ = 'R';
    if (len != 0) *p++ = static_cast<char>('0' + len);
  } else {
    for (std::size_t i = 0; i < len; ++i) {
      std::memcpy(p, &kHexPairs[2 * static_cast<std::size_t>(frame.data[i])], 2);
      p += 2;
    }
  }
  const auto n = static_cast<std::size_t>(p - start);
  if (n >= out.size()) {  // no room for the line and its NUL
    if (!out.empty()) out[0] = '\0';
    return 0;
  }
  if (start == local.data()) std::memcpy(out.data(), local.data(), n);
  out[n] = '\0';
  return n;
}

namespace {
/// The start both formats share: the optional timestamp, then the interface.
bool parse_time_and_iface(std::string_view& rest, CandumpLine& out) noexcept {
  if (!parse_leading_time(rest, out)) return false;
  const std::string_view iface = next_token(rest);
  if (!valid_iface(iface)) {
    out.reason = iface.empty() ? "missing interface name" : "bad interface name";
    return false;
  }
  out.iface = iface;
  return true;
}
}  // namespace

CandumpParse parse_candump_log_line(std::string_view line, CandumpLine& out) noexcept {
  out.reason = "";
  out.format = CandumpFormat::kLog;
  std::string_view rest = trim_right(line);
  if (!parse_time_and_iface(rest, out)) return CandumpParse::kMalformed;
  const std::string_view tok = next_token(rest);
  if (tok.empty()) {
    out.reason = "missing ID#DATA";
    return CandumpParse::kMalformed;
  }
  const CandumpParse r = parse_frame_token(tok, out);
  if (r != CandumpParse::kOk) return r;
  // Newer can-utils may append a direction flag (" R"/" T"); anything else is an error.
  const std::string_view extra = next_token(rest);
  if (!extra.empty() && extra != "R" && extra != "T") {
    out.reason = "unexpected text after ID#DATA";
    return CandumpParse::kMalformed;
  }
  if (!skip_spaces(rest).empty()) {
    out.reason = "unexpected text after ID#DATA";
    return CandumpParse::kMalformed;
  }
  return CandumpParse::kOk;
}

CandumpParse parse_candump_screen_line(std::string_view line, CandumpLine& out) noexcept {
  out.reason = "";
  out.format = CandumpFormat::kScreen;
  std::string_view rest = trim_right(line);
  if (!parse_time_and_iface(rest, out)) return CandumpParse::kMalformed;
  std::string_view id_tok = next_token(rest);
  if (id_tok == "RX" || id_tok == "TX") {  // candump -x: "RX - -" / "TX B E"
    next_token(rest);
    next_token(rest);
    id_tok = next_token(rest);
  }
  Frame& f = out.frame;
  f = Frame{};
  if (!set_id(id_tok, f, out.reason)) return CandumpParse::kMalformed;
  const std::string_view len_tok = next_token(rest);
  if (len_tok.size() < 3 || len_tok.front() != '[' || len_tok.back() != ']') {
    out.reason = "missing [length] after CAN id";
    return CandumpParse::kMalformed;
  }
  std::uint64_t len = 0;
  if (!parse_dec(len_tok.substr(1, len_tok.size() - 2), len, 2)) {
    out.reason = "[length] is not a number";
    return CandumpParse::kMalformed;
  }
  if (len_tok.size() == 4) {  // "[nn]": candump prints CAN FD lengths with two digits
    out.reason = "CAN FD frame ([nn] length) not supported";
    return CandumpParse::kUnsupported;
  }
  if (len > kMaxPayload) {
    out.reason = "length above 8 in a classic CAN frame";
    return CandumpParse::kMalformed;
  }
  f.len = static_cast<std::uint8_t>(len);
  std::string_view after = skip_spaces(rest);
  if (after.starts_with("remote request")) {
    if (f.error()) {
      out.reason = "error frame marked as remote request";
      return CandumpParse::kMalformed;
    }
    f.flags = static_cast<std::uint8_t>(f.flags | kRemote);
    return CandumpParse::kOk;
  }
  for (std::size_t i = 0; i < len; ++i) {
    const std::string_view b = next_token(rest);
    if (b.size() == 2) {
      const int hi = hex_value(b[0]);
      const int lo = hex_value(b[1]);
      if (hi < 0 || lo < 0) {
        out.reason = "data byte is not two hex digits";
        return CandumpParse::kMalformed;
      }
      f.data[i] = static_cast<std::uint8_t>((hi << 4) | lo);
    } else if (b.size() == 8 && b.find_first_not_of("01") == std::string_view::npos) {  // candump -i
      std::uint8_t v = 0;
      for (char c : b) v = static_cast<std::uint8_t>((v << 1) | (c == '1' ? 1 : 0));
      f.data[i] = v;
    } else {
      out.reason = b.empty() ? "fewer data bytes than [length]" : "data byte is not two hex digits";
      return CandumpParse::kMalformed;
    }
  }
  // Allowed trailers: "ERRORFRAME" (error frames), '...' ASCII view (-a).
  after = skip_spaces(rest);
  if (!after.empty() && !after.starts_with("ERRORFRAME") && after.front() != '\'' && after.front() != '`') {
    out.reason = "more data bytes than [length]";
    return CandumpParse::kMalformed;
  }
  return CandumpParse::kOk;
}

CandumpParse parse_candump_line(std::string_view line, CandumpLine& out) noexcept {
  out.reason = "";
  const std::string_view t = trim_right(line);
  if (t.empty()) return CandumpParse::kSkip;
  if (t.front() == '\t') return CandumpParse::kSkip;  // candump -e error-frame detail line
  const std::string_view s = skip_spaces(t);
  if (s.empty() || s.front() == '#' || s.front() == ';') return CandumpParse::kSkip;
  // Log lines hold "ID#DATA" as the token after the interface; screen lines have no '#'.
  std::string_view rest = s;
  if (!rest.empty() && rest.front() == '(') {
    const std::size_t close = rest.find(')');
    if (close == std::string_view::npos) {
      out.reason = "timestamp '(' without ')'";
      return CandumpParse::kMalformed;
    }
    rest = rest.substr(close + 1);
  }
  next_token(rest);  // interface
  const std::string_view tok = next_token(rest);
  if (tok.find('#') != std::string_view::npos) return parse_candump_log_line(t, out);
  return parse_candump_screen_line(t, out);
}

}  // namespace canmotion::can
