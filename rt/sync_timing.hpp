#pragma once
/// \file
/// When a cycle's SYNC frames are handed to their transports, on the cycle's
/// own clock (CLOCK_MONOTONIC in real time): the offset from the cycle's
/// wake-up to each SYNC, and how far each bus's interval between two SYNCs
/// is from the period (issue 28: drives lock their control loop to the SYNC,
/// so its jitter is theirs). Recorded by the RT thread, read by any thread,
/// like rt/cycle_stats.hpp.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#include "rt/clock.hpp"
#include "rt/histogram.hpp"

namespace canmotion::rt {

/// A plain copy of SyncTiming (all times in ns).
struct SyncTimingStats {
  std::uint64_t syncs = 0;          ///< SYNCs recorded (every bus)
  std::int64_t offset_min_ns = 0;   ///< wake-up -> SYNC handed to the transport
  std::int64_t offset_p50_ns = 0;
  std::int64_t offset_p99_ns = 0;
  std::int64_t offset_max_ns = 0;
  std::uint64_t intervals = 0;      ///< intervals between two SYNCs of one bus
  std::int64_t jitter_p50_ns = 0;   ///< |interval - period|
  std::int64_t jitter_p99_ns = 0;
  std::int64_t jitter_max_ns = 0;
};

/// One line, times in microseconds:
///   SYNC: 16000 sent; wake-up -> SYNC min 1.2 p50 1.5 p99 3.0 max 9.9 us; |interval - period| p50 ... us (15998 intervals)
std::string format_sync_timing(const SyncTimingStats& s);

/// The histograms (two rt::Histogram, ~58 KiB: build it at set-up).
class SyncTiming {
 public:
  /// Bound: the controller's buses (rt::kMaxBuses is 8).
  static constexpr std::size_t kMaxBuses = 8;
  /// `clock` (outliving this) is read once per SYNC; `period_ns` is the cycle period.
  SyncTiming(Clock& clock, std::int64_t period_ns) noexcept : clock_(clock), period_ns_(period_ns) {
    for (auto& l : last_) l = -1;
  }
  /// The SYNC of bus `bus` was just handed to its transport in the cycle that
  /// woke at `wake_ns` (same clock). Single writer; realtime-safe: one
  /// clock read, no allocation.
  void record(std::size_t bus, std::int64_t wake_ns) noexcept {
    const std::int64_t t = clock_.now().count();
    offset_.record(t - wake_ns);
    if (bus >= kMaxBuses) return;
    if (last_[bus] >= 0) {
      const std::int64_t d = t - last_[bus] - period_ns_;
      jitter_.record(d < 0 ? -d : d);
    }
    last_[bus] = t;
  }
  /// A copy with percentiles. Not realtime-safe (scans the histograms).
  SyncTimingStats snapshot() const noexcept;
  const Histogram& offset() const noexcept { return offset_; }
  const Histogram& jitter() const noexcept { return jitter_; }

 private:
  Clock& clock_;
  std::int64_t period_ns_;
  std::array<std::int64_t, kMaxBuses> last_{};  // RT thread only
  Histogram offset_;
  Histogram jitter_;
};

}  // namespace canmotion::rt
