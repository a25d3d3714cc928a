// `sdo_writes` entries with a CiA 301 `type:` (or the object table's type):
// the value's bytes are prepared here, at load, so that the boot on the RT
// thread only references them (cia402::SdoWrite::bytes).
#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "config/load_sections.hpp"
#include "fieldbus/canopen/object_names.hpp"

namespace canmotion::config::load {

namespace {
using canopen::DataType;

std::optional<DataType> type_named(std::string_view name) {
  for (DataType t : canopen::kAllDataTypes)
    if (canopen::data_type_name(t) == name) return t;
  return std::nullopt;
}

void le(std::vector<std::uint8_t>& out, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

/// "01 02 ab" or "0102AB" -> bytes; nullopt on an odd count or a non-hex digit.
std::optional<std::vector<std::uint8_t>> hex_bytes(const std::string& s) {
  std::vector<std::uint8_t> out;
  int hi = -1;
  for (const char c : s) {
    if (c == ' ' || c == ':' || c == '-') continue;
    int d = 0;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
    else return std::nullopt;
    if (hi < 0) {
      hi = d;
    } else {
      out.push_back(static_cast<std::uint8_t>(hi * 16 + d));
      hi = -1;
    }
  }
  if (hi >= 0) return std::nullopt;
  return out;
}
}  // namespace

std::optional<std::vector<std::uint8_t>> utf16le(const std::string& s) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::uint32_t cp = 0;
    std::size_t n = 0;
    if (c < 0x80) cp = c, n = 1;
    else if ((c & 0xE0) == 0xC0) cp = c & 0x1Fu, n = 2;
    else if ((c & 0xF0) == 0xE0) cp = c & 0x0Fu, n = 3;
    else if ((c & 0xF8) == 0xF0) cp = c & 0x07u, n = 4;
    else return std::nullopt;
    if (i + n > s.size()) return std::nullopt;
    for (std::size_t k = 1; k < n; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return std::nullopt;
      cp = (cp << 6) | (cc & 0x3Fu);
    }
    i += n;
    if (cp >= 0x10000) {
      cp -= 0x10000;
      le(out, 0xD800 + (cp >> 10), 2);
      le(out, 0xDC00 + (cp & 0x3FF), 2);
    } else {
      le(out, cp, 2);
    }
  }
  return out;
}

namespace {
/// `file:` relative to the YAML file's folder, read whole; a missing,
/// unreadable or empty file is an error naming `key`.
void read_value_file(Reader& r, const YAML::Node& f, const std::string& key, std::vector<std::uint8_t>& out) {
  const std::filesystem::path fp(f.Scalar());
  const auto full = fp.is_absolute() ? fp : (std::filesystem::path(r.file()).parent_path() / fp).lexically_normal();
  std::ifstream in(full, std::ios::binary);
  if (!in) return r.error(f, key, fmt::format("cannot read '{}'", full.string()));
  out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) r.error(f, key, fmt::format("cannot read '{}'", full.string()));
  else if (out.empty()) r.error(f, key, fmt::format("'{}' is empty", full.string()));
}
/// INTEGERn / UNSIGNEDn (n = 8..64) `v` into `out`, little endian; a value
/// out of the type's range is an error naming the key and the type.
void encode_integer(Reader& r, const YAML::Node& v, const std::string& p, DataType type, std::vector<std::uint8_t>& out) {
  const std::string text = v.Scalar();
  const std::string tn(canopen::data_type_name(type));
  const auto bad = [&](const std::string& why) { r.error(v, p + ".value", fmt::format("{} for {}", why, tn)); };
  const std::size_t size = canopen::data_type_size(type);
  const int bits = static_cast<int>(8 * size);
  if (canopen::data_type_signed(type)) {
    long long x = 0;
    if (!YAML::convert<long long>::decode(v, x)) return bad(fmt::format("'{}' is not an integer", text));
    const long long lo = bits == 64 ? std::numeric_limits<long long>::min() : -(1LL << (bits - 1));
    const long long hi = bits == 64 ? std::numeric_limits<long long>::max() : (1LL << (bits - 1)) - 1;
    if (x < lo || x > hi) return bad(fmt::format("{} is out of range ({} .. {})", text, lo, hi));
    le(out, static_cast<std::uint64_t>(x), size);
  } else {
    unsigned long long x = 0;
    if (!text.empty() && text[0] == '-') return bad(fmt::format("{} is out of range (0 .. {})", text, bits == 64 ? std::numeric_limits<unsigned long long>::max() : (1ULL << bits) - 1));
    if (!YAML::convert<unsigned long long>::decode(v, x)) return bad(fmt::format("'{}' is not an unsigned integer", text));
    const unsigned long long hi = bits == 64 ? std::numeric_limits<unsigned long long>::max() : (1ULL << bits) - 1;
    if (x > hi) return bad(fmt::format("{} is out of range (0 .. {})", text, hi));
    le(out, x, size);
  }
}
}  // namespace

bool typed_sdo_write(Reader& r, const YAML::Node& e, const std::string& p, const canopen::ObjectInfo* known,
                     SdoWrite& s) {
  std::optional<DataType> type;
  if (const YAML::Node t = e["type"]) {
    type = type_named(t.Scalar());
    if (!type || *type == DataType::kTimeOfDay || *type == DataType::kTimeDifference) {
      r.error(t, p + ".type",
              fmt::format("unknown type '{}': BOOLEAN, INTEGER8/16/24/32/40/48/56/64, UNSIGNED8..64, REAL32, REAL64, "
                          "VISIBLE_STRING, OCTET_STRING, UNICODE_STRING or DOMAIN", t.Scalar()));
      return true;  // reported; not read again as an integer
    }
    if (known != nullptr && known->type != *type) {
      r.error(t, p + ".type", fmt::format("0x{:04X}:{:02X} ({}) is {}, got {}", s.index, s.sub, known->name,
                                          canopen::data_type_name(known->type), t.Scalar()));
      return true;
    }
  } else if (e["file"] && known == nullptr) {
    type = DataType::kDomain;
  } else {
    return false;  // the integer path (size/value) of load_drive.cpp
  }
  s.type = std::string(canopen::data_type_name(*type));
  const std::string tn = s.type;
  std::vector<std::uint8_t>& out = s.bytes;
  const YAML::Node v = e["value"];
  const YAML::Node f = e["file"];
  if (f) {
    if (*type != DataType::kDomain && *type != DataType::kOctetString)
      r.error(f, p + ".file", fmt::format("a file is for DOMAIN or OCTET_STRING, not {}", tn));
    else if (v)
      r.error(f, p + ".file", "give value or file, not both");
    else
      read_value_file(r, f, p + ".file", out);
    return true;
  }
  if (!v || !v.IsScalar()) {
    r.error(e, p, fmt::format("needs a value (or, for DOMAIN and OCTET_STRING, a file) of type {}", tn));
    return true;
  }
  const std::string text = v.Scalar();
  const auto bad = [&](const std::string& why) { r.error(v, p + ".value", fmt::format("{} for {}", why, tn)); };
  switch (*type) {
    case DataType::kBoolean: {
      bool b = false;
      if (!YAML::convert<bool>::decode(v, b)) return bad(fmt::format("'{}' is not true or false", text)), true;
      out.push_back(b ? 1 : 0);
      return true;
    }
    case DataType::kReal32: case DataType::kReal64: {
      double d = 0;
      if (!YAML::convert<double>::decode(v, d)) return bad(fmt::format("'{}' is not a number", text)), true;
      if (*type == DataType::kReal32) {
        if (std::isfinite(d) && std::fabs(d) > std::numeric_limits<float>::max())
          return bad(fmt::format("{} is out of range (+-{})", text, std::numeric_limits<float>::max())), true;
        const auto fl = static_cast<float>(d);
        std::uint32_t u = 0;
        std::memcpy(&u, &fl, 4);
        le(out, u, 4);
      } else {
        std::uint64_t u = 0;
        std::memcpy(&u, &d, 8);
        le(out, u, 8);
      }
      return true;
    }
    case DataType::kVisibleString:
      for (const char c : text)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7E)
          return bad("only printable ASCII (0x20..0x7E) is allowed"), true;
      if (text.empty()) return bad("an empty string cannot be written"), true;
      out.assign(text.begin(), text.end());
      return true;
    case DataType::kUnicodeString: {
      auto u = utf16le(text);
      if (!u || u->empty()) return bad("not UTF-8 text (or empty)"), true;
      out = std::move(*u);
      return true;
    }
    case DataType::kOctetString: case DataType::kDomain: {
      auto h = hex_bytes(text);
      if (!h || h->empty()) return bad(fmt::format("'{}' is not hex bytes such as \"01 a2 ff\"", text)), true;
      out = std::move(*h);
      return true;
    }
    default: break;
  }
  encode_integer(r, v, p, *type, out);
  return true;
}

}  // namespace canmotion::config::load
