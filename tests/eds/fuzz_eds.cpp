// libFuzzer target: arbitrary text into the EDS/DCF reader. A file it
// accepts must be well-formed data (objects and sub-indices ascending and
// found by find(), lines inside the file), and the checker runs on it with
// every object used every way; a file it refuses must come with at least
// one error, each inside the file. The first byte also picks a data type
// for parse_value() on the whole text.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/eds/check.hpp"
#include "fieldbus/eds/eds.hpp"

namespace eds = canmotion::eds;
namespace co = canmotion::canopen;

namespace {
void require(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  int lines = 1;
  for (char c : text) lines += c == '\n' ? 1 : 0;
  if (size > 0) {
    const co::DataType t = co::kAllDataTypes[data[0] % std::size(co::kAllDataTypes)];
    std::string why;
    const auto v = eds::parse_value(text.substr(1), t, why);
    require(v.has_value() || !why.empty());
    if (v) (void)eds::format_number(t, v->resolve(static_cast<std::uint8_t>(size & 0x7F), co::data_type_size(t)));
  }
  try {
    const eds::Eds e = eds::parse(text, "fuzz.eds");
    eds::Requirements req;
    req.rpdos = static_cast<std::uint16_t>(size % 5);
    req.tpdos = static_cast<std::uint16_t>((size / 5) % 5);
    int prev = -1;
    for (const eds::Object& o : e.objects) {
      require(static_cast<int>(o.index) > prev);
      prev = o.index;
      require(e.find(o.index) == &o);
      require(o.line >= 1 && o.line <= lines);
      int prev_sub = -1;
      for (const eds::SubObject& s : o.subs) {
        require(static_cast<int>(s.sub) > prev_sub);
        prev_sub = s.sub;
        require(e.find(o.index, s.sub) == &s);
        require(s.line >= 1 && s.line <= lines);
        if (req.uses.size() >= 256) continue;
        eds::Use u;
        u.index = o.index;
        u.sub = s.sub;
        u.usage = static_cast<eds::Usage>(req.uses.size() % 4);
        u.size = static_cast<std::uint8_t>(s.size());
        if (s.default_value) {
          u.value = static_cast<std::int64_t>(s.default_value->bits);
          u.required_bits = s.default_value->bits;
        }
        u.optional = (req.uses.size() & 1) != 0;
        req.uses.push_back(u);
      }
    }
    eds::Use absent;
    absent.index = 0x1016;
    absent.sub = 1;
    req.uses.push_back(absent);
    const eds::CheckResult r = eds::check(e, req);
    for (const eds::Refusal& x : r.refusals) require(!x.to_string().empty() && x.line >= 0 && x.line <= lines);
    for (const eds::Diagnostic& w : e.warnings) require(w.line >= 0 && w.line <= lines);
  } catch (const eds::ParseError& err) {
    require(!err.errors().empty());
    for (const eds::Diagnostic& d : err.errors()) require(d.line >= 0 && d.line <= lines && !d.message.empty());
  }
  return 0;
}
