// sd_notify readiness and the cycle watchdog: the decision logic, the thread
// with a fake sink, and real sd_notify datagrams on a $NOTIFY_SOCKET.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rt/systemd_notify.hpp"

using namespace canmotion::rt;

TEST(RtWatchdog, LogicPingsOnlyWhileTheCounterAdvances) {
  CycleWatchdog w;
  using V = CycleWatchdog::Verdict;
  EXPECT_EQ(w.check(0), V::ping) << "first check pings";
  EXPECT_EQ(w.check(10), V::ping);
  EXPECT_EQ(w.check(10), V::stalled);
  EXPECT_EQ(w.check(10), V::still_stalled);
  EXPECT_EQ(w.check(10), V::still_stalled);
  EXPECT_EQ(w.check(11), V::ping) << "recovers";
  EXPECT_EQ(w.check(11), V::stalled) << "a new stall is reported again";
  EXPECT_EQ(w.last_count(), 11u);
}

TEST(RtWatchdog, ThreadStopsPingingWhenTheCycleStalls) {
  // The "cycle" advances in the watchdog's own reads while `moving` is set,
  // so that every check before the stall sees progress and every check
  // after it sees none, however the test thread is scheduled (the former
  // version advanced the counter from this thread every 500 us: descheduled
  // for 2 ms, it caused a stall of its own, and the wait for "the" stall
  // could then hang).
  std::atomic<bool> moving{true};
  std::atomic<std::uint64_t> counter{0};
  std::atomic<std::uint64_t> checks{0};
  std::mutex m;
  std::vector<std::string> sent;
  WatchdogThread wd(
      [&] {
        checks.fetch_add(1);
        return moving.load() ? counter.fetch_add(1) + 1 : counter.load();
      },
      Nanos{2'000'000}, [&](std::string_view s) {
        std::lock_guard lock(m);
        sent.emplace_back(s);
        return 1;
      });
  // Waits on the watchdog thread's progress, polled: the thread runs on the
  // real clock (its decision logic is tested without one above).
  auto wait_for = [](auto done) {
    while (!done()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  wd.start();
  wait_for([&] { return wd.pings() >= 5; });
  EXPECT_EQ(wd.stalls(), 0u) << "no stall while the cycle advances";
  moving = false;
  wait_for([&] { return wd.stalls() == 1; });
  const std::uint64_t pings_at_stall = wd.pings();
  const std::uint64_t checks_at_stall = checks.load();
  wait_for([&] { return checks.load() >= checks_at_stall + 5; });  // five more checks, still stalled
  EXPECT_EQ(wd.pings(), pings_at_stall) << "no ping while stalled";
  EXPECT_EQ(wd.stalls(), 1u) << "one stall reported once";
  // The cycle advances again: pings resume.
  moving = true;
  wait_for([&] { return wd.pings() > pings_at_stall; });
  wd.stop();
  std::lock_guard lock(m);
  std::size_t status_lines = 0;
  for (const auto& s : sent) {
    if (s.rfind("STATUS=", 0) == 0) {
      ++status_lines;
      EXPECT_NE(s.find("stalled at cycle"), std::string::npos) << s;
    } else {
      EXPECT_EQ(s, "WATCHDOG=1");
    }
  }
  EXPECT_EQ(status_lines, 1u) << "one STATUS line per stall";
}

namespace {
// A datagram socket standing in for systemd's notify socket.
class FakeSystemd {
 public:
  FakeSystemd() {
    path_ = "/tmp/canmotion-notify-" + std::to_string(getpid()) + ".sock";
    ::unlink(path_.c_str());
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    path_.copy(addr.sun_path, sizeof(addr.sun_path) - 1);
    ok_ = fd_ >= 0 && ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0;
    timeval tv{2, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    ::setenv("NOTIFY_SOCKET", path_.c_str(), 1);
  }
  ~FakeSystemd() {
    ::unsetenv("NOTIFY_SOCKET");
    ::unsetenv("WATCHDOG_USEC");
    ::unsetenv("WATCHDOG_PID");
    if (fd_ >= 0) ::close(fd_);
    ::unlink(path_.c_str());
  }
  bool ok() const { return ok_; }
  std::string receive() {
    char buf[512];
    const ssize_t n = ::recv(fd_, buf, sizeof(buf), 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string("<nothing>");
  }

 private:
  std::string path_;
  int fd_ = -1;
  bool ok_ = false;
};
}  // namespace

TEST(RtSdNotify, SendsReadyWatchdogAndStatusToNotifySocket) {
  FakeSystemd systemd;
  ASSERT_TRUE(systemd.ok());
  EXPECT_GT(SdNotifier::ready(), 0);
  EXPECT_EQ(systemd.receive(), "READY=1");
  EXPECT_GT(SdNotifier::status("running, cycle 1 ms"), 0);
  EXPECT_EQ(systemd.receive(), "STATUS=running, cycle 1 ms");
  EXPECT_GT(SdNotifier::watchdog(), 0);
  EXPECT_EQ(systemd.receive(), "WATCHDOG=1");
  EXPECT_GT(SdNotifier::stopping(), 0);
  EXPECT_EQ(systemd.receive(), "STOPPING=1");
}

TEST(RtSdNotify, WatchdogIntervalComesFromTheEnvironment) {
  ::unsetenv("WATCHDOG_USEC");
  EXPECT_FALSE(SdNotifier::watchdog_interval().has_value());
  ::setenv("WATCHDOG_USEC", "2000000", 1);
  ::setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);
  const auto interval = SdNotifier::watchdog_interval();
  ASSERT_TRUE(interval.has_value());
  EXPECT_EQ(*interval, Nanos{2'000'000'000});
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");
}

TEST(RtSdNotify, NotRunBySystemdIsANoOp) {
  ::unsetenv("NOTIFY_SOCKET");
  EXPECT_EQ(SdNotifier::ready(), 0);
}

TEST(RtWatchdog, ThreadRealSdNotifyPings) {
  FakeSystemd systemd;
  ASSERT_TRUE(systemd.ok());
  std::atomic<std::uint64_t> counter{1};
  WatchdogThread wd([&] { return counter.fetch_add(1); }, Nanos{5'000'000});
  wd.start();
  EXPECT_EQ(systemd.receive(), "WATCHDOG=1");
  EXPECT_EQ(systemd.receive(), "WATCHDOG=1");
  wd.stop();
}

// The protocol details libsystemd handled before issue 18: an abstract
// socket ('@name'), a watchdog meant for another process, bad addresses.
TEST(RtSdNotify, AbstractSocketAndAddressChecks) {
  const std::string name = "canmotion-notify-abstract-" + std::to_string(getpid());
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  name.copy(addr.sun_path + 1, sizeof(addr.sun_path) - 2);  // sun_path[0] = 0: abstract
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr),
                   static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + name.size())),
            0);
  timeval tv{2, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  ::setenv("NOTIFY_SOCKET", ("@" + name).c_str(), 1);
  EXPECT_GT(SdNotifier::ready(), 0);
  char buf[64];
  const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
  EXPECT_EQ(std::string(buf, n > 0 ? static_cast<std::size_t>(n) : 0), "READY=1");
  ::close(fd);

  ::setenv("NOTIFY_SOCKET", "vsock:2:1234", 1);
  EXPECT_EQ(SdNotifier::ready(), -EAFNOSUPPORT);
  ::setenv("NOTIFY_SOCKET", "/nonexistent/notify.sock", 1);
  EXPECT_EQ(SdNotifier::ready(), -ENOENT);
  ::unsetenv("NOTIFY_SOCKET");

  ::setenv("WATCHDOG_USEC", "500000", 1);
  ::setenv("WATCHDOG_PID", std::to_string(getpid() + 1).c_str(), 1);
  EXPECT_FALSE(SdNotifier::watchdog_interval().has_value()) << "meant for another process";
  ::unsetenv("WATCHDOG_PID");
  EXPECT_EQ(SdNotifier::watchdog_interval(), Nanos{500'000'000}) << "no WATCHDOG_PID: ours";
  ::setenv("WATCHDOG_USEC", "2s", 1);
  EXPECT_FALSE(SdNotifier::watchdog_interval().has_value()) << "not a number";
  ::unsetenv("WATCHDOG_USEC");
}

// The watchdog thread runs on a small stack of its own (mlockall would lock
// all of a std::thread's 8 MiB).
TEST(RtWatchdog, ThreadHasASmallStack) {
  std::atomic<std::size_t> size{0};
  WatchdogThread wd(
      [&size] {
        pthread_attr_t attr;
        std::size_t s = 0;
        if (pthread_getattr_np(pthread_self(), &attr) == 0) {
          pthread_attr_getstacksize(&attr, &s);
          pthread_attr_destroy(&attr);
        }
        size = s;
        return std::uint64_t{1};
      },
      Nanos{1'000'000}, [](std::string_view) { return 1; });
  wd.start();
  while (size.load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  wd.stop();
  EXPECT_EQ(size.load(), WatchdogThread::kStackBytes);
}
