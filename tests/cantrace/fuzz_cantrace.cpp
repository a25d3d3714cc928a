// libFuzzer target: the candump line parsers and the frame decoders.
// Input: text; every line goes through LineReader -> Decoder -> text and
// JSON rendering -> Analyzer. Inputs starting with 0xFF are read as raw
// frames instead (id, flags, len, 8 data bytes), reaching decoder states
// that well-formed text rarely produces.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "fieldbus/can/candump_format.hpp"
#include "fieldbus/trace/analyzer.hpp"
#include "fieldbus/trace/decoder.hpp"
#include "fieldbus/trace/format.hpp"
#include "fieldbus/trace/reader.hpp"

namespace tr = canmotion::trace;
namespace can = canmotion::can;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Reused across inputs: decoder and analyzer state carry over, like one long trace.
  static tr::Decoder* dec = new tr::Decoder();
  static tr::Analyzer* analyzer = new tr::Analyzer(tr::AnalyzerOptions{});
  static unsigned runs = 0;
  tr::Analyzer& an = *analyzer;
  const bool finish = (++runs % 256) == 0;
  fmt::memory_buffer out;
  if (size > 0 && data[0] == 0xFF) {
    std::size_t i = 1;
    while (i + 14 <= size) {
      can::TimedFrame f;
      std::memcpy(&f.frame.id, data + i, 4);
      f.frame.flags = data[i + 4];
      f.frame.len = data[i + 5];
      std::memcpy(f.frame.data.data(), data + i + 6, 8);
      f.t_ns = static_cast<std::int64_t>(i);
      const tr::Decoded& d = dec->decode(f);
      out.clear();
      tr::format_text(d, "vcan0", {}, out);
      tr::format_json(d, "vcan0", {}, out);
      an.feed(d, *dec, nullptr);
      i += 14;
    }
    if (finish) an.finish(*dec);
    return 0;
  }
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  tr::LineReader reader(size > 0 && (data[0] & 1) != 0);
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(start, end - start);
    // Both parsers directly too, and the formatter on what they return.
    can::CandumpLine l;
    can::parse_candump_log_line(line, l);
    can::parse_candump_screen_line(line, l);
    can::TimedFrame f;
    std::string_view iface;
    if (reader.feed(line, f, iface) == tr::LineReader::Status::kFrame) {
      char buf[can::kCandumpLineMax + 1];
      if (can::format_candump_line(buf, f.frame, f.t_ns, iface, 9) == 0 && !iface.empty() && iface.size() <= 15) __builtin_trap();
      const tr::Decoded& d = dec->decode(f);
      out.clear();
      tr::format_text(d, iface, {}, out);
      tr::format_json(d, iface, {}, out);
      an.feed(d, *dec, nullptr);
    }
    start = end + 1;
  }
  if (finish) an.finish(*dec);
  return 0;
}
