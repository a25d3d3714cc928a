#include "rt/clock.hpp"

#include <cerrno>
#include <ctime>

namespace canmotion::rt {

namespace {
constexpr std::int64_t kNsPerSec = 1'000'000'000;
}

Nanos MonotonicClock::now() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return Nanos{static_cast<std::int64_t>(ts.tv_sec) * kNsPerSec + ts.tv_nsec};
}

void MonotonicClock::sleep_until(Nanos deadline) noexcept {
  const std::int64_t ns = deadline.count();
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / kNsPerSec);
  ts.tv_nsec = static_cast<long>(ns % kNsPerSec);
  // clock_nanosleep returns the error number (not -1/errno); EINTR restarts
  // with the same absolute deadline, so a signal never shifts the cycle.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void VirtualClock::sleep_until(Nanos deadline) noexcept {
  const std::int64_t now = now_.load(std::memory_order_relaxed);
  if (deadline.count() > now) {
    now_.store(deadline.count() + wake_latency_.load(std::memory_order_relaxed),
               std::memory_order_relaxed);
  }
}

}  // namespace canmotion::rt
