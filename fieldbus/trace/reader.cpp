#include "fieldbus/trace/reader.hpp"

namespace canmotion::trace {

LineReader::Status LineReader::feed(std::string_view line, can::TimedFrame& out, std::string_view& iface) noexcept {
  can::CandumpLine l;
  const can::CandumpParse r = can::parse_candump_line(line, l);
  switch (r) {
    case can::CandumpParse::kSkip:
      return Status::kSkip;
    case can::CandumpParse::kMalformed:
      ++malformed_;
      reason_ = l.reason;
      return Status::kMalformed;
    case can::CandumpParse::kUnsupported:
      ++unsupported_;
      reason_ = l.reason;
      return Status::kUnsupported;
    case can::CandumpParse::kOk:
      break;
  }
  std::int64_t t = 0;
  if (l.time == can::CandumpTime::kNone) {
    missing_time_ = true;
    t = last_t_;
  } else {
    if (first_) {
      // Count the fraction digits of the first timestamp: "(sec.ffffff...)".
      const std::size_t close = line.find(')');
      const std::size_t dot = line.rfind('.', close);
      if (close != std::string_view::npos && dot != std::string_view::npos && dot < close) {
        digits_ = close - dot - 1 > 6 ? 9 : 6;
      }
    }
    has_time_ = true;
    if (delta_ && l.time == can::CandumpTime::kRelative) {
      t = last_t_ + l.t_ns;
    } else {
      t = l.t_ns;
      if (!first_ && t < last_t_) ++backwards_;
    }
  }
  first_ = false;
  last_t_ = t;
  format_ = l.format;
  out.frame = l.frame;
  out.t_ns = t;
  iface = l.iface;
  ++frames_;
  return Status::kFrame;
}

}  // namespace canmotion::trace
