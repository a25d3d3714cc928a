#pragma once
/// \file
/// Time sources for the cyclic loop: the real CLOCK_MONOTONIC with absolute
/// deadlines, and a virtual clock that runs the same loop without sleeping.

#include <atomic>
#include <chrono>
#include <cstdint>

namespace canmotion::rt {

/// Time in nanoseconds on a clock's own time base.
using Nanos = std::chrono::nanoseconds;

/// A time source for the cyclic loop. The loop only calls now() and
/// sleep_until(); it never reads any other clock, so the same loop code runs
/// on real time (daemon) and on virtual time (`--sim`).
class Clock {
 public:
  virtual ~Clock() = default;
  /// Current time. Realtime-safe.
  virtual Nanos now() noexcept = 0;
  /// Returns when now() >= deadline (absolute time); returns at once if the
  /// deadline has passed. Realtime-safe (blocks only in clock_nanosleep).
  virtual void sleep_until(Nanos deadline) noexcept = 0;
  /// True for a clock that does not follow the wall (no sleeping).
  virtual bool is_virtual() const noexcept = 0;
};

/// CLOCK_MONOTONIC; sleep_until() is clock_nanosleep(TIMER_ABSTIME), retried
/// on EINTR, so a deadline is never drifted by the time spent computing it.
class MonotonicClock final : public Clock {
 public:
  /// clock_gettime(CLOCK_MONOTONIC). Realtime-safe.
  Nanos now() noexcept override;
  /// clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME). Realtime-safe.
  void sleep_until(Nanos deadline) noexcept override;
  bool is_virtual() const noexcept override { return false; }
};

/// Deterministic time for `--sim` and tests: sleep_until() jumps to the
/// deadline at once, so the loop runs as fast as the CPU allows and every run
/// with the same inputs produces the same times. Tests inject a cycle's
/// execution cost with advance() and wake-up latency with set_wake_latency().
/// now() may be read from any thread; advance() and sleep_until() are meant
/// for the loop thread.
class VirtualClock final : public Clock {
 public:
  /// Starts at `start` (default 0).
  explicit VirtualClock(Nanos start = Nanos{0}) noexcept : now_(start.count()) {}
  /// Realtime-safe.
  Nanos now() noexcept override { return Nanos{now_.load(std::memory_order_relaxed)}; }
  /// If the deadline is in the future, time jumps to deadline + wake latency;
  /// otherwise time is unchanged. Realtime-safe, never sleeps.
  void sleep_until(Nanos deadline) noexcept override;
  bool is_virtual() const noexcept override { return true; }
  /// Let `d` of virtual time pass (simulates work done by a cycle). Realtime-safe.
  void advance(Nanos d) noexcept { now_.fetch_add(d.count(), std::memory_order_relaxed); }
  /// Every later wake-up from sleep_until() lands `latency` after its deadline.
  /// Realtime-safe.
  void set_wake_latency(Nanos latency) noexcept {
    wake_latency_.store(latency.count(), std::memory_order_relaxed);
  }

 private:
  std::atomic<std::int64_t> now_;
  std::atomic<std::int64_t> wake_latency_{0};
};

}  // namespace canmotion::rt
