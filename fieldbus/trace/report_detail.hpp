#pragma once
/// \file
/// Internal to fieldbus/trace's renderings (format.cpp, report*.cpp): the
/// helpers the text and JSON summaries share. Not realtime-safe.

#include <array>
#include <cstddef>
#include <string_view>

#include <fmt/format.h>

namespace canmotion::trace::detail {

using Out = fmt::memory_buffer;

/// Append `s` to `out`.
inline void put(Out& out, std::string_view s) { out.append(s.data(), s.data() + s.size()); }

/// The summary's label of an EventKind (indexes BusSummary::kind_counts).
inline std::string_view kind_label(std::size_t k) {
  constexpr std::array<std::string_view, 12> names = {"NMT",       "SYNC", "TIME", "EMCY", "boot-up", "heartbeat",
                                                      "node guard", "SDO",  "PDO",  "LSS",  "error",   "unknown"};
  return k < names.size() ? names[k] : "?";
}

/// Nanoseconds as microseconds.
inline double us(double ns) { return ns / 1000.0; }

}  // namespace canmotion::trace::detail
