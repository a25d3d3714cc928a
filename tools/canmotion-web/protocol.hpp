// canmotion-web's protocol layer, free of I/O so that it can be unit-tested
// and fuzzed: parsing the daemon's STATUS and STATS lines, and parsing the
// browser's JSON requests.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace canmotion::web {

// A STATUS data line: `key=value` fields separated by one space, a value with
// spaces in double quotes (tools/canmotionctl/README.md, "STATUS lines").
// Fields keep their order. Returns nullopt and sets *error on a malformed line.
using Fields = std::vector<std::pair<std::string, std::string>>;
std::optional<Fields> parse_fields(std::string_view line, std::string* error);

// STATS data lines (`key=value`, one per line) into a map; lines without '='
// are reported in *error and skipped.
std::map<std::string, std::string> parse_stats(const std::vector<std::string>& lines,
                                               std::string* error);

// A browser request: a flat JSON object whose values are strings, numbers or
// booleans (kept as their text), e.g. {"type":"command","verb":"MSO","axis":"X"}.
struct Request {
  std::map<std::string, std::string> fields;
  std::string get(const std::string& key) const;
};

inline constexpr std::size_t max_request_bytes = 4096;
inline constexpr std::size_t max_request_fields = 32;

// Parses one WebSocket text message. Never throws; on error returns nullopt
// and *error names what is wrong and where (column, key).
std::optional<Request> parse_request(std::string_view text, std::string* error);

// JSON string literal (with quotes) of s; control characters escaped.
std::string json_string(std::string_view s);

// {"key":"value",...} of fields, in order.
std::string fields_to_json(const Fields& fields);

}  // namespace canmotion::web
