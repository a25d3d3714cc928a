#pragma once
/// \file
/// Human-readable and JSON renderings of decoded frames. Not realtime-safe
/// (fmt buffers may grow); meant for tools and trace post-processing.

#include <cstdint>
#include <string_view>

#include <fmt/format.h>

#include <array>

#include "fieldbus/canopen/device_dictionary.hpp"
#include "fieldbus/trace/decoder.hpp"

namespace canmotion::trace {

/// How to print times.
/// Per node-ID, the node's object dictionary from its EDS (cantrace --eds),
/// or null: objects are then named from canopen's CiA 301/402 table.
using NodeDictionaries = std::array<const canopen::DeviceDictionary*, 128>;

struct FormatOptions {
  bool has_time = true;  ///< false: the trace had no timestamps; print "-"
  int time_digits = 6;   ///< 6 (us) or 9 (ns) fractional digits
  const NodeDictionaries* names = nullptr;  ///< object names from EDS files (null: none)
};

/// Append `t_ns` as seconds ("1700000000.123456") to `out`.
void append_time(fmt::memory_buffer& out, std::int64_t t_ns, int digits);

/// Append one text line (with '\n'): time, interface, raw frame as ID#DATA
/// and the decoded description.
void format_text(const Decoded& d, std::string_view iface, const FormatOptions& opt, fmt::memory_buffer& out);

/// Append the description only (no time, no raw frame, no newline), e.g.
/// "TPDO1 node 1: Statusword=0x0637 [Operation enabled], Position actual value=100000".
void format_description(const Decoded& d, fmt::memory_buffer& out, const NodeDictionaries* names = nullptr);

/// Append one JSON object on one line (with '\n'), for `cantrace --json`.
void format_json(const Decoded& d, std::string_view iface, const FormatOptions& opt, fmt::memory_buffer& out);

/// Append `s` as a JSON string literal (quotes, escapes).
void append_json_string(fmt::memory_buffer& out, std::string_view s);

/// An EMCY's code and error register as text, the one rendering for the
/// decoded line and the report: "0x2310 Continuous over-current; error
/// register 0x03 (generic, current)" (the bit list only when a bit is set).
void append_emcy(fmt::memory_buffer& out, std::uint16_t code, std::uint8_t error_register);
/// The same as JSON members: `,"code":N,"error_register":N,"text":"..."`.
void append_emcy_json(fmt::memory_buffer& out, std::uint16_t code, std::uint8_t error_register);

/// "Operation enabled" etc. for a statusword.
std::string_view statusword_state_name(std::uint16_t statusword) noexcept;
/// "Enable operation" etc. for a controlword.
std::string_view controlword_command_name(std::uint16_t controlword) noexcept;
/// Error-frame class names (CAN_ERR_* bits of the id), comma separated, appended to out.
void append_error_classes(fmt::memory_buffer& out, std::uint32_t err_class);
/// Error-frame classes with the controller-problem details of the payload
/// (as candump -e prints them) and the error counters, appended to out.
void append_error_details(fmt::memory_buffer& out, std::uint32_t err_class, const std::array<std::uint8_t, 8>& data,
                          std::uint8_t len);
/// Name of error-frame class bit `bit` (0..8), "" beyond.
std::string_view error_class_name(unsigned bit) noexcept;
/// Lower-case kind name used in JSON ("nmt", "sync", "tpdo", ...).
std::string_view event_kind_name(const Decoded& d) noexcept;

}  // namespace canmotion::trace
