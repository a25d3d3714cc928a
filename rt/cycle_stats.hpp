#pragma once
/// \file
/// Cycle statistics as IgH's dc_user example keeps them: wake-up latency,
/// execution time and period, plus overruns. The RT thread records into
/// CycleStatistics (lock-free, no allocation); any thread reads a CycleStats,
/// a plain struct whose fields are also readable by name as tags.

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "rt/clock.hpp"
#include "rt/histogram.hpp"

namespace canmotion::rt {

/// A plain copy of the statistics (all times in ns). Trivially copyable.
struct CycleStats {
  std::int64_t period_ns = 0;            ///< configured period
  std::uint64_t cycles = 0;              ///< cycles executed
  std::uint64_t overruns = 0;            ///< cycles that ended after the next deadline
  std::uint64_t missed_deadlines = 0;    ///< deadlines skipped because of overruns
  std::int64_t latency_min_ns = 0;       ///< wake-up latency = wake time - deadline
  std::int64_t latency_mean_ns = 0;
  std::int64_t latency_p50_ns = 0;
  std::int64_t latency_p99_ns = 0;
  std::int64_t latency_p999_ns = 0;
  std::int64_t latency_max_ns = 0;
  std::int64_t exec_min_ns = 0;          ///< execution time = end of cycle - wake time
  std::int64_t exec_mean_ns = 0;
  std::int64_t exec_p99_ns = 0;
  std::int64_t exec_max_ns = 0;
  std::int64_t measured_period_min_ns = 0;   ///< wake time - previous wake time
  std::int64_t measured_period_mean_ns = 0;
  std::int64_t measured_period_max_ns = 0;
  std::int64_t last_latency_ns = 0;      ///< of the most recent cycle
  std::int64_t last_exec_ns = 0;
};

/// Tag names of CycleStats, in field order (e.g. "latency_p99_ns"). A tag
/// path is "<prefix>.<name>" in the daemon, e.g. "rt.latency_max_ns".
std::span<const std::string_view> stat_tag_names() noexcept;
/// Value of the field called `name`, or nullopt if there is no such tag.
std::optional<std::int64_t> stat_tag_value(const CycleStats& s, std::string_view name) noexcept;

/// Multi-line summary like dc_user's, times in microseconds:
///   cycles 20000  overruns 0  missed deadlines 0  period 1000.0 us
///   latency  min 2.1  mean 3.0  p50 2.9  p99 5.2  p99.9 8.8  max 14.0 us
///   exec     min ...
///   period   min ...  mean ...  max ...
std::string format_summary(const CycleStats& s);
/// One line for printing once a second.
std::string format_line(const CycleStats& s);

/// Live statistics: one writer (the loop thread), any number of readers.
class CycleStatistics {
 public:
  explicit CycleStatistics(Nanos period) noexcept : period_(period) {}
  /// Record one cycle. `measured_period` is negative for the first cycle
  /// (no previous wake-up). Realtime-safe: wait-free, no allocation.
  void record(Nanos latency, Nanos exec, Nanos measured_period) noexcept;
  /// Record an overrun that skipped `missed` deadlines. Realtime-safe.
  void record_overrun(std::uint64_t missed) noexcept;
  /// A consistent-enough copy with percentiles. Not realtime-safe
  /// (scans the histograms, ~10 us); call from non-RT threads.
  CycleStats snapshot() const noexcept;

  const Histogram& latency() const noexcept { return latency_; }
  const Histogram& exec() const noexcept { return exec_; }
  const Histogram& period() const noexcept { return period_hist_; }

 private:
  Nanos period_;
  Histogram latency_;
  Histogram exec_;
  Histogram period_hist_;
  std::atomic<std::uint64_t> overruns_{0};
  std::atomic<std::uint64_t> missed_{0};
  std::atomic<std::int64_t> last_latency_{0};
  std::atomic<std::int64_t> last_exec_{0};
};

}  // namespace canmotion::rt
