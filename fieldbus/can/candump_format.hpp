#pragma once
/// \file
/// The candump text formats (can-utils): the log format written by
/// `candump -L` / `candump -l` and read by `canplayer`,
///
///     (1700000000.123456) vcan0 181#3706A0860100
///
/// and candump's default screen format, with or without `-t a|d|z|A`:
///
///       vcan0  181   [6]  37 06 A0 86 01 00
///     (1700000000.123456)  vcan0  181   [6]  37 06 A0 86 01 00
///
/// The formatter writes into a caller buffer and is realtime-safe, so the
/// cyclic thread (or a trace writer fed from it) can produce trace lines.
/// The parsers never allocate, never throw and never read outside the given
/// line; on failure they return a short static reason text.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "fieldbus/can/frame.hpp"

namespace canmotion::can {

/// CAN_ERR_FLAG as it appears in the 8-digit id of an error frame in candump
/// text ("20000004#..."). Frame::id of an error frame holds only the class bits.
inline constexpr std::uint32_t kCandumpErrorFlag = 0x20000000U;

/// Longest line format_candump_line() writes, without the terminating NUL:
/// "(" + 20 digit seconds + "." + 9 digits + ") " + 15 char interface name
/// (IFNAMSIZ - 1) + " " + 8 digit id + "#" + 16 hex digits = 76; rounded up.
inline constexpr std::size_t kCandumpLineMax = 80;

/// Format one frame as a `candump -L` line without a newline, e.g.
/// `(1700000000.123456) vcan0 181#3706A0860100`. `t_ns` is the receive time in
/// nanoseconds since the epoch (negative values are clamped to 0);
/// `frac_digits` is 6 (candump's microseconds) or 9 (nanoseconds).
/// Interface names longer than 15 characters are truncated. Error frames are
/// written with CAN_ERR_FLAG set in the 8-digit id, RTR frames as `R` or `R<len>`.
/// Returns the number of characters written, or 0 if `out` is too small (no
/// partial line is left behind: out[0] is set to NUL when out is not empty).
/// Writes a terminating NUL when there is room for it.
/// Realtime-safe: no allocation, no locks, no exceptions, no system calls.
std::size_t format_candump_line(std::span<char> out, const Frame& frame, std::int64_t t_ns,
                                std::string_view iface, int frac_digits = 6) noexcept;

/// The text format a line was recognised as.
enum class CandumpFormat : std::uint8_t {
  kLog,     ///< `(sec.frac) iface ID#DATA` (candump -L / -l, canplayer input)
  kScreen,  ///< `  iface  ID   [n]  DD DD ...` (candump default output)
};

/// What the timestamp of a parsed line means.
enum class CandumpTime : std::uint8_t {
  kNone,      ///< no timestamp (screen format without -t)
  kAbsolute,  ///< seconds since the epoch (-L, -t a; 9 or more integer digits)
  kRelative,  ///< seconds since start (-t z) or since the previous frame (-t d); fewer than 9 integer digits
  kDate,      ///< `-t A` date and time (`2023-11-14 22:13:20.123456`), converted as UTC
};

/// Result of parsing one line.
enum class CandumpParse : std::uint8_t {
  kOk = 0,           ///< `frame`, `t_ns`, `time`, `format`, `iface` are set
  kSkip = 1,         ///< blank line, comment (`#`, `;`) or an error-frame detail continuation line
  kMalformed = 2,    ///< not a candump line; `reason` says why
  kUnsupported = 3,  ///< a well-formed line this decoder does not handle (CAN FD `##`, payload > 8); `reason` says what
};

/// One parsed candump line. `iface` views the input line.
struct CandumpLine {
  Frame frame{};
  std::int64_t t_ns = 0;  ///< timestamp in ns (meaning given by `time`); 0 if none
  CandumpTime time = CandumpTime::kNone;
  CandumpFormat format = CandumpFormat::kLog;
  std::string_view iface;
  const char* reason = "";  ///< static text when the result is not kOk
};

/// Parse one line in either format (detected from its shape). A trailing
/// '\r' or '\n' is ignored. Never throws, never allocates, never reads
/// outside `line`. Realtime-safe.
CandumpParse parse_candump_line(std::string_view line, CandumpLine& out) noexcept;

/// Parse only the `candump -L` log format. Realtime-safe.
CandumpParse parse_candump_log_line(std::string_view line, CandumpLine& out) noexcept;

/// Parse only candump's screen format. Realtime-safe.
CandumpParse parse_candump_screen_line(std::string_view line, CandumpLine& out) noexcept;

}  // namespace canmotion::can
