#pragma once
/// \file
/// Internal to fieldbus/trace's renderings (format.cpp, report*.cpp): the
/// helpers the text and JSON summaries share. Not realtime-safe.

#include <array>
#include <cstddef>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "fieldbus/trace/analyzer.hpp"
#include "fieldbus/trace/report.hpp"

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

/// What a summary of one bus renders (TextSummary, JsonSummary): the
/// analysis, its options, the report options and the buffer it appends to.
class Summary {
 protected:
  Summary(const Analyzer& a, const ReportOptions& opt, Out& out)
      : a_(a), b_(a.bus()), ao_(a.options()), opt_(opt), out_(out) {}

  template <typename... Args>
  void print(fmt::format_string<Args...> f, Args&&... args) {
    fmt::format_to(fmt::appender(out_), f, std::forward<Args>(args)...);
  }

  const Analyzer& a_;
  const BusSummary& b_;
  const AnalyzerOptions& ao_;
  const ReportOptions& opt_;
  Out& out_;
};

}  // namespace canmotion::trace::detail
