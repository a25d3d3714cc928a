#include "rt/systemd_notify.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <string>

#if defined(CANMOTION_HAVE_LIBSYSTEMD)
#include <systemd/sd-daemon.h>
#endif

namespace canmotion::rt {

bool SdNotifier::compiled_in() noexcept {
#if defined(CANMOTION_HAVE_LIBSYSTEMD)
  return true;
#else
  return false;
#endif
}

int SdNotifier::notify(std::string_view state) {
#if defined(CANMOTION_HAVE_LIBSYSTEMD)
  const std::string text{state};
  return sd_notify(0, text.c_str());
#else
  (void)state;
  return -ENOSYS;
#endif
}

int SdNotifier::status(std::string_view text) { return notify(fmt::format("STATUS={}", text)); }

std::optional<Nanos> SdNotifier::watchdog_interval() {
#if defined(CANMOTION_HAVE_LIBSYSTEMD)
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
    return Nanos{static_cast<std::int64_t>(usec) * 1000};
  }
#endif
  return std::nullopt;
}

CycleWatchdog::Verdict CycleWatchdog::check(std::uint64_t cycle_count) noexcept {
  if (first_ || cycle_count != last_) {
    first_ = false;
    stalled_ = false;
    last_ = cycle_count;
    return Verdict::ping;
  }
  if (!stalled_) {
    stalled_ = true;
    return Verdict::stalled;
  }
  return Verdict::still_stalled;
}

WatchdogThread::WatchdogThread(Progress progress, Nanos check_every, Send send)
    : progress_(std::move(progress)),
      check_every_(check_every.count() > 0 ? check_every : Nanos{1'000'000}),
      send_(std::move(send)) {
  if (!send_) {
    send_ = [](std::string_view s) { return SdNotifier::notify(s); };
  }
}

WatchdogThread::~WatchdogThread() { stop(); }

void WatchdogThread::start() {
  if (thread_.joinable()) {
    return;
  }
  {
    std::lock_guard lock(mutex_);
    stop_ = false;
  }
  thread_ = std::thread([this] { run(); });
}

void WatchdogThread::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
  }
}

void WatchdogThread::run() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    const std::uint64_t count = progress_();
    switch (logic_.check(count)) {
      case CycleWatchdog::Verdict::ping:
        send_("WATCHDOG=1");
        pings_.fetch_add(1, std::memory_order_relaxed);
        break;
      case CycleWatchdog::Verdict::stalled:
        stalls_.fetch_add(1, std::memory_order_relaxed);
        send_(fmt::format("STATUS=real-time cycle stalled at cycle {}; watchdog pings stopped", count));
        break;
      case CycleWatchdog::Verdict::still_stalled:
        break;
    }
    wake_.wait_for(lock, check_every_, [this] { return stop_; });
  }
}

}  // namespace canmotion::rt
