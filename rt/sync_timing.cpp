#include "rt/sync_timing.hpp"

#include <fmt/format.h>

namespace canmotion::rt {

SyncTimingStats SyncTiming::snapshot() const noexcept {
  SyncTimingStats s;
  s.syncs = offset_.count();
  s.offset_min_ns = offset_.min();
  s.offset_p50_ns = offset_.percentile(0.50);
  s.offset_p99_ns = offset_.percentile(0.99);
  s.offset_max_ns = offset_.max();
  s.intervals = jitter_.count();
  s.jitter_p50_ns = jitter_.percentile(0.50);
  s.jitter_p99_ns = jitter_.percentile(0.99);
  s.jitter_max_ns = jitter_.max();
  return s;
}

std::string format_sync_timing(const SyncTimingStats& s) {
  auto us = [](std::int64_t ns) { return static_cast<double>(ns) / 1000.0; };
  return fmt::format(
      "SYNC: {} sent; wake-up -> SYNC min {:.1f} p50 {:.1f} p99 {:.1f} max {:.1f} us; "
      "|interval - period| p50 {:.1f} p99 {:.1f} max {:.1f} us ({} intervals)",
      s.syncs, us(s.offset_min_ns), us(s.offset_p50_ns), us(s.offset_p99_ns), us(s.offset_max_ns),
      us(s.jitter_p50_ns), us(s.jitter_p99_ns), us(s.jitter_max_ns), s.intervals);
}

}  // namespace canmotion::rt
