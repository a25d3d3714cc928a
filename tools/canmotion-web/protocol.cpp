#include "tools/canmotion-web/protocol.hpp"

#include <cctype>
#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace canmotion::web {

namespace {

bool is_key_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.' || c == '-';
}

std::string at(std::size_t column) { return " at column " + std::to_string(column + 1); }

}  // namespace

std::optional<Fields> parse_fields(std::string_view line, std::string* error) {
  Fields out;
  std::size_t i = 0;
  while (i < line.size()) {
    if (line[i] == ' ') { ++i; continue; }
    const std::size_t key_start = i;
    while (i < line.size() && is_key_char(line[i])) ++i;
    if (i == key_start || i >= line.size() || line[i] != '=') {
      if (error) *error = "malformed field (expected key=value)" + at(key_start);
      return std::nullopt;
    }
    std::string key(line.substr(key_start, i - key_start));
    ++i;  // '='
    std::string value;
    if (i < line.size() && line[i] == '"') {
      const std::size_t close = line.find('"', i + 1);
      if (close == std::string_view::npos) {
        if (error) *error = "unterminated quoted value of '" + key + "'" + at(i);
        return std::nullopt;
      }
      value = std::string(line.substr(i + 1, close - i - 1));
      i = close + 1;
    } else {
      const std::size_t end = std::min(line.find(' ', i), line.size());
      value = std::string(line.substr(i, end - i));
      i = end;
    }
    out.emplace_back(std::move(key), std::move(value));
  }
  return out;
}

std::map<std::string, std::string> parse_stats(const std::vector<std::string>& lines,
                                               std::string* error) {
  std::map<std::string, std::string> out;
  for (const auto& l : lines) {
    const auto eq = l.find('=');
    if (eq == std::string::npos || eq == 0) {
      if (error) *error = "STATS line without key=value: '" + l + "'";
      continue;
    }
    out[l.substr(0, eq)] = l.substr(eq + 1);
  }
  return out;
}

std::string Request::get(const std::string& key) const {
  const auto it = fields.find(key);
  return it == fields.end() ? std::string() : it->second;
}

namespace {

struct Cursor {
  std::string_view s;
  std::size_t i = 0;
  std::string* error;
  bool fail(const std::string& what) {
    if (error) *error = "malformed JSON request: " + what + at(i);
    return false;
  }
  void ws() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r')) ++i;
  }
  bool eat(char c) {
    ws();
    if (i < s.size() && s[i] == c) { ++i; return true; }
    return false;
  }
};

bool parse_escape(Cursor& c, std::string& out) {
  if (c.i >= c.s.size()) return c.fail("unterminated escape");
  const char e = c.s[c.i++];
  switch (e) {
    case '"': out += '"'; return true;
    case '\\': out += '\\'; return true;
    case '/': out += '/'; return true;
    case 'n': out += '\n'; return true;
    case 't': out += '\t'; return true;
    case 'r': out += '\r'; return true;
    case 'b': out += '\b'; return true;
    case 'f': out += '\f'; return true;
    case 'u': {
      if (c.i + 4 > c.s.size()) return c.fail("short \\u escape");
      unsigned v = 0;
      for (int k = 0; k < 4; ++k) {
        const char h = c.s[c.i++];
        if (std::isxdigit(static_cast<unsigned char>(h)) == 0) return c.fail("bad \\u escape");
        v = v * 16 + static_cast<unsigned>(std::isdigit(static_cast<unsigned char>(h)) ? h - '0'
                                           : (std::tolower(static_cast<unsigned char>(h)) - 'a' + 10));
      }
      if (v >= 0x80) return c.fail("non-ASCII \\u escape not accepted");
      out += static_cast<char>(v);
      return true;
    }
    default: --c.i; return c.fail("unknown escape");
  }
}

bool parse_string(Cursor& c, std::string& out) {
  if (!c.eat('"')) return c.fail("expected a string");
  while (c.i < c.s.size()) {
    const char ch = c.s[c.i++];
    if (ch == '"') return true;
    if (static_cast<unsigned char>(ch) < 0x20) { --c.i; return c.fail("control character in string"); }
    if (ch == '\\') {
      if (!parse_escape(c, out)) return false;
    } else {
      out += ch;
    }
  }
  return c.fail("unterminated string");
}

bool parse_scalar(Cursor& c, std::string& out) {
  c.ws();
  if (c.i < c.s.size() && c.s[c.i] == '"') return parse_string(c, out);
  const std::size_t start = c.i;
  while (c.i < c.s.size() && (std::isalnum(static_cast<unsigned char>(c.s[c.i])) != 0 ||
                              c.s[c.i] == '-' || c.s[c.i] == '+' || c.s[c.i] == '.')) ++c.i;
  out = std::string(c.s.substr(start, c.i - start));
  if (out == "null") c.i = start;
  if (out == "true" || out == "false") return true;
  if (out.empty() || out == "null") return c.fail("expected a string, number or boolean value (objects, arrays and null are not accepted)");
  char* end = nullptr;
  (void)std::strtod(out.c_str(), &end);
  if (end != out.c_str() + out.size()) { c.i = start; return c.fail("bad number '" + out + "'"); }
  return true;
}

}  // namespace

std::optional<Request> parse_request(std::string_view text, std::string* error) {
  if (text.size() > max_request_bytes) {
    if (error) *error = "request too long: " + std::to_string(text.size()) + " bytes (at most " +
                        std::to_string(max_request_bytes) + ")";
    return std::nullopt;
  }
  Cursor c{text, 0, error};
  Request r;
  if (!c.eat('{')) { c.fail("expected '{'"); return std::nullopt; }
  if (!c.eat('}')) {
    do {
      std::string key, value;
      if (!parse_string(c, key)) return std::nullopt;
      if (!c.eat(':')) { c.fail("expected ':' after key '" + key + "'"); return std::nullopt; }
      if (!parse_scalar(c, value)) return std::nullopt;
      if (r.fields.count(key) != 0) { c.fail("duplicate key '" + key + "'"); return std::nullopt; }
      if (r.fields.size() == max_request_fields) { c.fail("too many keys"); return std::nullopt; }
      r.fields.emplace(std::move(key), std::move(value));
    } while (c.eat(','));
    if (!c.eat('}')) { c.fail("expected ',' or '}'"); return std::nullopt; }
  }
  c.ws();
  if (c.i != text.size()) { c.fail("trailing characters after the object"); return std::nullopt; }
  if (r.get("type").empty()) {
    if (error) *error = "request without key 'type'";
    return std::nullopt;
  }
  return r;
}

std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') { out += '\\'; out += ch; }
    else if (u < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string fields_to_json(const Fields& fields) {
  std::string out = "{";
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (k != 0) out += ',';
    out += json_string(fields[k].first) + ':' + json_string(fields[k].second);
  }
  return out + "}";
}

}  // namespace canmotion::web
