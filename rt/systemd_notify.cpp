#include "rt/systemd_notify.hpp"

#include <fmt/format.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <system_error>

namespace canmotion::rt {

// The sd_notify protocol (sd_notify(3), "Standalone implementations"):
// one datagram with the state text to the AF_UNIX socket named by
// $NOTIFY_SOCKET ('/' = a path, '@' = the abstract namespace). systemd
// documents it as stable and recommends reimplementing it instead of linking
// libsystemd: linking it cost canmotiond 3.4 MB of locked memory (libsystemd
// pulls libgcrypt, libzstd, liblzma, liblz4, libgpg-error and libcap, and
// mlockall locks every page of every mapped library; BENCHMARKS.md).
int SdNotifier::notify(std::string_view state) {
  const char* env = std::getenv("NOTIFY_SOCKET");
  if (env == nullptr || *env == '\0') return 0;  // not run by systemd (sd_notify: 0)
  const std::string_view path(env);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if ((path[0] != '/' && path[0] != '@') || path.size() < 2) return -EAFNOSUPPORT;  // e.g. vsock: not used
  if (path.size() >= sizeof(addr.sun_path)) return -E2BIG;
  path.copy(addr.sun_path, path.size());
  if (path[0] == '@') addr.sun_path[0] = '\0';  // abstract: no terminating NUL counted
  const auto len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + path.size() + (path[0] == '/' ? 1 : 0));
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -errno;
  ssize_t n;
  do {
    n = ::sendto(fd, state.data(), state.size(), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&addr), len);
  } while (n < 0 && errno == EINTR);
  const int e = errno;
  ::close(fd);
  if (n < 0) return -e;
  return 1;
}

int SdNotifier::status(std::string_view text) { return notify(fmt::format("STATUS={}", text)); }

std::optional<Nanos> SdNotifier::watchdog_interval() {
  // As sd_watchdog_enabled(): $WATCHDOG_USEC, meant for this process when
  // $WATCHDOG_PID is unset or names it.
  const char* usec = std::getenv("WATCHDOG_USEC");
  if (usec == nullptr || *usec == '\0') return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const unsigned long long us = std::strtoull(usec, &end, 10);
  if (errno != 0 || end == usec || *end != '\0' || us == 0 || us > 9'000'000'000'000ULL) return std::nullopt;
  if (const char* pid = std::getenv("WATCHDOG_PID"); pid != nullptr && *pid != '\0') {
    char* pend = nullptr;
    const long long p = std::strtoll(pid, &pend, 10);
    if (pend == pid || *pend != '\0' || p != static_cast<long long>(::getpid())) return std::nullopt;
  }
  return Nanos{static_cast<std::int64_t>(us) * 1000};
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
  // A small stack: the daemon is mlockall'ed, and a std::thread's 8 MiB
  // would all be locked (it calls fmt::format and sendto: a few KiB).
  if (thread_.start(kStackBytes, [this] { run(); })) {
    throw std::system_error(std::make_error_code(std::errc::resource_unavailable_try_again),
                            "cannot start the watchdog thread");
  }
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
