#pragma once
/// \file
/// Turns candump text lines (either candump format, any timestamp style)
/// into timed frames, keeping the time base consistent across the trace:
/// absolute (-L, -t a, -t A), zero-based (-t z), delta (-t d, with the
/// `delta` option) or none (screen format without -t).

#include <cstdint>
#include <string_view>

#include "fieldbus/can/candump_format.hpp"
#include "fieldbus/can/frame.hpp"

namespace canmotion::trace {

/// Line-by-line candump parser with a consistent time base. No allocation,
/// no exceptions; the interface view points into the caller's line.
class LineReader {
 public:
  enum class Status : std::uint8_t { kFrame, kSkip, kMalformed, kUnsupported };

  /// `delta`: timestamps of relative form are deltas to the previous frame
  /// (candump -t d) and are accumulated.
  explicit LineReader(bool delta = false) noexcept : delta_(delta) {}

  /// Parse one line (with or without the trailing newline).
  Status feed(std::string_view line, can::TimedFrame& out, std::string_view& iface) noexcept;

  /// Why the last line was kMalformed/kUnsupported (static text).
  [[nodiscard]] const char* reason() const noexcept { return reason_; }
  /// True once a timestamped line was seen and no frame without one.
  [[nodiscard]] bool has_time() const noexcept { return has_time_ && !missing_time_; }
  /// Fraction digits of the first timestamp (6 or 9; 6 if none).
  [[nodiscard]] int time_digits() const noexcept { return digits_; }
  /// Number of times the time went backwards (for a warning: maybe -t d without --delta).
  [[nodiscard]] std::uint64_t backwards() const noexcept { return backwards_; }
  [[nodiscard]] std::uint64_t frames() const noexcept { return frames_; }
  [[nodiscard]] std::uint64_t malformed() const noexcept { return malformed_; }
  [[nodiscard]] std::uint64_t unsupported() const noexcept { return unsupported_; }
  [[nodiscard]] can::CandumpFormat format() const noexcept { return format_; }

 private:
  bool delta_;
  bool has_time_ = false;
  bool missing_time_ = false;
  bool first_ = true;
  int digits_ = 6;
  std::int64_t last_t_ = 0;
  std::uint64_t backwards_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t malformed_ = 0;
  std::uint64_t unsupported_ = 0;
  can::CandumpFormat format_ = can::CandumpFormat::kLog;
  const char* reason_ = "";
};

}  // namespace canmotion::trace
