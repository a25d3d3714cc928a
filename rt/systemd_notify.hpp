#pragma once
/// \file
/// systemd readiness (Type=notify) and watchdog (WatchdogSec): the sd_notify
/// protocol implemented here (a datagram to $NOTIFY_SOCKET), not linked from
/// libsystemd, whose dependencies cost 3.4 MB of locked memory. Nothing here
/// runs on the RT thread: the watchdog is a non-RT thread that pings only
/// while the RT cycle counter advances.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "rt/clock.hpp"
#include "rt/sized_thread.hpp"

namespace canmotion::rt {

/// The sd_notify(3) protocol. Not realtime-safe.
class SdNotifier {
 public:
  /// Like sd_notify(0, state): > 0 sent, 0 not run by systemd (no
  /// $NOTIFY_SOCKET), < 0 -errno (-EAFNOSUPPORT for a socket address that is
  /// neither a path nor '@abstract').
  static int notify(std::string_view state);
  static int ready() { return notify("READY=1"); }
  static int stopping() { return notify("STOPPING=1"); }
  static int watchdog() { return notify("WATCHDOG=1"); }
  /// "STATUS=<text>" (shown by systemctl status).
  static int status(std::string_view text);
  /// The watchdog interval systemd expects pings within (WatchdogSec), read
  /// like sd_watchdog_enabled(): $WATCHDOG_USEC, when $WATCHDOG_PID is unset
  /// or this process; nullopt when no watchdog is configured.
  static std::optional<Nanos> watchdog_interval();
};

/// Decision logic of the watchdog, free of threads and clocks: call check()
/// every half watchdog interval with the current cycle count.
class CycleWatchdog {
 public:
  enum class Verdict : std::uint8_t {
    ping = 0,        ///< the cycle advanced: send WATCHDOG=1
    stalled = 1,     ///< it did not advance since the last check: first check of a stall
    still_stalled = 2,  ///< it still does not advance: keep silent (systemd will act)
  };
  /// The first check after construction pings (the loop may not have run yet).
  Verdict check(std::uint64_t cycle_count) noexcept;
  std::uint64_t last_count() const noexcept { return last_; }

 private:
  std::uint64_t last_ = 0;
  bool first_ = true;
  bool stalled_ = false;
};

/// A non-RT thread that checks the cycle counter every `check_every` and
/// sends WATCHDOG=1 only when it advanced. When the cycle stalls it sends
/// STATUS=... once and stops pinging, so systemd (WatchdogSec) restarts the
/// service. `send` defaults to SdNotifier::notify.
class WatchdogThread {
 public:
  using Progress = std::function<std::uint64_t()>;
  using Send = std::function<int(std::string_view)>;

  /// Stack of the watchdog thread: it formats one STATUS line and sends a
  /// datagram (a std::thread's 8 MiB would all be locked by mlockall).
  static constexpr std::size_t kStackBytes = 128 * 1024;

  WatchdogThread(Progress progress, Nanos check_every, Send send = {});
  ~WatchdogThread();
  WatchdogThread(const WatchdogThread&) = delete;
  WatchdogThread& operator=(const WatchdogThread&) = delete;

  /// Start the thread (once). Throws std::system_error if it cannot be created.
  void start();
  /// Stop and join it.
  void stop();
  /// WATCHDOG=1 pings sent so far.
  std::uint64_t pings() const noexcept { return pings_.load(std::memory_order_relaxed); }
  /// Stalls detected so far.
  std::uint64_t stalls() const noexcept { return stalls_.load(std::memory_order_relaxed); }

 private:
  void run();

  Progress progress_;
  Nanos check_every_;
  Send send_;
  CycleWatchdog logic_;
  SizedThread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::atomic<std::uint64_t> pings_{0};
  std::atomic<std::uint64_t> stalls_{0};
};

}  // namespace canmotion::rt
