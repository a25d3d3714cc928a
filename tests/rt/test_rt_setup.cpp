// RT set-up: every step reports its own error; "not permitted" degrades with
// one warning; other errors are hard errors. Injected syscalls make the paths
// deterministic; one test drops privileges for real in a child process.
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <grp.h>

#include <cerrno>
#include <cstdio>
#include <thread>

#include "rt/clock.hpp"
#include "rt/cyclic_executive.hpp"
#include "rt/pm_qos.hpp"
#include "rt/rt_setup.hpp"

using namespace canmotion::rt;

namespace {

// Scripted syscalls: each returns the errno stored here and records calls.
struct Script {
  static inline int mlock_err = 0;
  static inline int fifo_err = 0;
  static inline int affinity_err = 0;
  static inline int mlock_calls = 0;
  static inline int fifo_calls = 0;
  static inline int last_priority = -1;
  static inline int last_cpu = -1;
  static inline int order = 0;
  static inline int mlock_order = 0;
  static inline int fifo_order = 0;
  static inline int affinity_order = 0;
  // PM QoS: the "device" is held while qos_fd is open.
  static inline int qos_err = 0;
  static inline int qos_calls = 0;
  static inline int qos_order = 0;
  static inline std::int32_t last_qos_us = -100;
  static inline bool qos_open = false;
  static inline int qos_closed = 0;
  static constexpr int kQosFd = 42;

  static void reset() {
    mlock_err = fifo_err = affinity_err = 0;
    mlock_calls = fifo_calls = 0;
    last_priority = last_cpu = -1;
    order = mlock_order = fifo_order = affinity_order = 0;
    qos_err = qos_calls = qos_order = qos_closed = 0;
    last_qos_us = -100;
    qos_open = false;
  }
  static RtSyscalls syscalls() {
    RtSyscalls s;
    s.mlockall = [](int flags) {
      EXPECT_EQ(flags, MCL_CURRENT | MCL_FUTURE);
      ++mlock_calls;
      mlock_order = ++order;
      return mlock_err;
    };
    s.set_fifo = [](int prio) {
      ++fifo_calls;
      last_priority = prio;
      fifo_order = ++order;
      return fifo_err;
    };
    s.set_affinity = [](const cpu_set_t* set) {
      affinity_order = ++order;
      for (int c = 0; c < CPU_SETSIZE; ++c) {
        if (CPU_ISSET(c, set)) {
          last_cpu = c;
        }
      }
      return affinity_err;
    };
    s.get_affinity = [](cpu_set_t* set) {
      CPU_ZERO(set);
      CPU_SET(0, set);
      CPU_SET(1, set);
      CPU_SET(3, set);
      return 0;
    };
    s.get_rlimit = [](int resource, rlimit* out) {
      out->rlim_cur = resource == RLIMIT_RTPRIO ? 0 : 8u * 1024 * 1024;
      out->rlim_max = out->rlim_cur;
      return 0;
    };
    s.hold_cpu_latency = [](std::int32_t us) {
      ++qos_calls;
      qos_order = ++order;
      last_qos_us = us;
      if (qos_err != 0) return -qos_err;
      qos_open = true;
      return kQosFd;
    };
    s.release_cpu_latency = [](int fd) {
      EXPECT_EQ(fd, kQosFd);
      EXPECT_TRUE(qos_open) << "closed twice";
      qos_open = false;
      ++qos_closed;
    };
    return s;
  }
};

RtSettings full(int prio = 80, int cpu = 1) {
  RtSettings s;
  s.lock_memory = true;
  s.prefault_stack_bytes = 64 * 1024;
  s.priority = prio;
  s.cpu = cpu;
  return s;
}

}  // namespace

TEST(RtSetup, AllStepsSucceedInOrder) {
  Script::reset();
  const auto r = apply_rt_settings(full(), Script::syscalls());
  EXPECT_TRUE(r.realtime());
  EXPECT_FALSE(r.degraded());
  EXPECT_FALSE(r.hard_error());
  EXPECT_TRUE(r.warning().empty());
  EXPECT_EQ(Script::last_priority, 80);
  EXPECT_EQ(Script::last_cpu, 1);
  EXPECT_LT(Script::mlock_order, Script::fifo_order);
  EXPECT_LT(Script::fifo_order, Script::affinity_order);
  EXPECT_LT(Script::affinity_order, Script::qos_order);
  for (const auto& s : r.steps) {
    EXPECT_TRUE(s.done()) << to_string(s.step);
  }
  EXPECT_NE(r.describe().find("SCHED_FIFO 80: ok"), std::string::npos) << r.describe();
  EXPECT_NE(r.describe().find("cpu_dma_latency 0 us: ok"), std::string::npos) << r.describe();
  // The PM QoS request stays open until released.
  EXPECT_EQ(Script::last_qos_us, 0);
  EXPECT_EQ(r.cpu_latency_fd, Script::kQosFd);
  EXPECT_TRUE(Script::qos_open);
  auto copy = r;
  release_rt_settings(copy, Script::syscalls());
  EXPECT_FALSE(Script::qos_open);
  EXPECT_EQ(copy.cpu_latency_fd, -1);
  release_rt_settings(copy, Script::syscalls());  // twice: nothing more
  EXPECT_EQ(Script::qos_closed, 1);
}

TEST(RtSetup, NothingRequestedMakesNoCalls) {
  Script::reset();
  const auto r = apply_rt_settings(RtSettings::none(), Script::syscalls());
  EXPECT_EQ(Script::mlock_calls, 0);
  EXPECT_EQ(Script::fifo_calls, 0);
  EXPECT_EQ(Script::qos_calls, 0) << "RtSettings::none() leaves /dev/cpu_dma_latency alone";
  EXPECT_EQ(r.cpu_latency_fd, -1);
  EXPECT_TRUE(r.realtime());
  EXPECT_TRUE(r.describe().empty());
}

TEST(RtSetup, SchedulerNotPermittedDegradesWithOneExplainingWarning) {
  Script::reset();
  Script::fifo_err = EPERM;
  const auto r = apply_rt_settings(full(70, -1), Script::syscalls());
  EXPECT_FALSE(r.realtime());
  EXPECT_TRUE(r.degraded());
  EXPECT_FALSE(r.hard_error()) << "EPERM must not stop the engine";
  EXPECT_TRUE(r.outcome(RtStep::scheduler).not_permitted());
  EXPECT_EQ(r.outcome(RtStep::scheduler).error, std::errc::operation_not_permitted);
  EXPECT_TRUE(r.outcome(RtStep::lock_memory).done());
  EXPECT_EQ(r.rlimit_rtprio, 0);
  const std::string w = r.warning();
  // What is lost ...
  EXPECT_NE(w.find("SCHED_FIFO priority 70 not permitted"), std::string::npos) << w;
  EXPECT_NE(w.find("RLIMIT_RTPRIO=0"), std::string::npos) << w;
  EXPECT_NE(w.find("normal priority"), std::string::npos) << w;
  // ... and how to grant it.
  EXPECT_NE(w.find("CAP_SYS_NICE"), std::string::npos) << w;
  EXPECT_NE(w.find("LimitRTPRIO=70"), std::string::npos) << w;
  EXPECT_NE(w.find("rtprio 70"), std::string::npos) << w;
  EXPECT_NE(w.find("/etc/security/limits.conf"), std::string::npos) << w;
  EXPECT_EQ(w.find("CAP_IPC_LOCK"), std::string::npos) << "memory was locked: " << w;
  EXPECT_EQ(w.find('\n'), std::string::npos) << "one message, one line";
}

TEST(RtSetup, MlockallLimitIsNotPermittedAndNamesMemlock) {
  for (int e : {EPERM, ENOMEM, EAGAIN}) {
    Script::reset();
    Script::mlock_err = e;
    const auto r = apply_rt_settings(full(80, -1), Script::syscalls());
    EXPECT_TRUE(r.degraded()) << e;
    EXPECT_FALSE(r.hard_error()) << e;
    EXPECT_TRUE(r.outcome(RtStep::scheduler).done()) << "later steps still run";
    const std::string w = r.warning();
    EXPECT_NE(w.find("mlockall not permitted"), std::string::npos) << w;
    EXPECT_NE(w.find("CAP_IPC_LOCK"), std::string::npos) << w;
    EXPECT_NE(w.find("LimitMEMLOCK=infinity"), std::string::npos) << w;
    EXPECT_NE(w.find("memlock unlimited"), std::string::npos) << w;
    EXPECT_NE(w.find("8388608"), std::string::npos) << "reports the limit: " << w;
  }
}

TEST(RtSetup, EveryStepReportsItsOwnError) {
  Script::reset();
  Script::mlock_err = ENOMEM;
  Script::fifo_err = EPERM;
  Script::affinity_err = EINVAL;
  const auto r = apply_rt_settings(full(80, 2), Script::syscalls());
  EXPECT_EQ(r.outcome(RtStep::lock_memory).error, std::errc::not_enough_memory);
  EXPECT_EQ(r.outcome(RtStep::scheduler).error, std::errc::operation_not_permitted);
  EXPECT_EQ(r.outcome(RtStep::affinity).error, std::errc::invalid_argument);
  EXPECT_TRUE(r.outcome(RtStep::prefault_stack).done());
  // A CPU that is not available is a configuration error, not a permission.
  EXPECT_EQ(r.hard_error(), std::errc::invalid_argument);
  EXPECT_EQ(r.allowed_cpus, "0-1,3");
  const std::string d = r.describe();
  EXPECT_NE(d.find("mlockall: Cannot allocate memory (not permitted)"), std::string::npos) << d;
  EXPECT_NE(d.find("CPU affinity cpu 2: Invalid argument"), std::string::npos) << d;
  EXPECT_EQ(r.error_message(), "cannot pin the real-time thread to CPU 2: Invalid argument (allowed CPUs: 0-1,3)");
}

TEST(RtSetup, InvalidSettingsAreHardErrorsWithoutSyscalls) {
  Script::reset();
  auto s = full(100, -1);
  auto r = apply_rt_settings(s, Script::syscalls());
  EXPECT_EQ(r.hard_error(), std::errc::invalid_argument);
  EXPECT_EQ(Script::fifo_calls, 0);
  EXPECT_NE(r.error_message().find("priority 100 is out of range: valid priorities are 1..99"), std::string::npos)
      << r.error_message();
  EXPECT_TRUE(apply_rt_settings(full(), Script::syscalls()).error_message().empty());
  s = full(-5, -1);
  r = apply_rt_settings(s, Script::syscalls());
  EXPECT_EQ(r.hard_error(), std::errc::invalid_argument);
  s = full(80, -1);
  s.prefault_stack_bytes = RtSettings::kMaxPrefaultBytes + 1;
  r = apply_rt_settings(s, Script::syscalls());
  EXPECT_EQ(r.outcome(RtStep::prefault_stack).error, std::errc::invalid_argument);
  s = full(80, CPU_SETSIZE);
  r = apply_rt_settings(s, Script::syscalls());
  EXPECT_EQ(r.outcome(RtStep::affinity).error, std::errc::invalid_argument);
}

// PM QoS (/dev/cpu_dma_latency): a missing device or a refusal degrades with
// the one warning, which says what it costs and how to get it.
TEST(RtSetup, CpuLatencyUnavailableDegradesWithOneExplainingWarning) {
  for (int e : {ENOENT, ENODEV, EACCES, EPERM, EROFS}) {
    Script::reset();
    Script::qos_err = e;
    const auto r = apply_rt_settings(full(80, -1), Script::syscalls());
    EXPECT_TRUE(r.outcome(RtStep::cpu_latency).not_permitted()) << e;
    EXPECT_EQ(r.outcome(RtStep::cpu_latency).error.value(), e);
    EXPECT_TRUE(r.degraded()) << e;
    EXPECT_FALSE(r.realtime()) << e;
    EXPECT_FALSE(r.hard_error()) << "the engine runs without it: " << e;
    EXPECT_EQ(r.cpu_latency_fd, -1);
    EXPECT_TRUE(r.outcome(RtStep::scheduler).done()) << "the other steps still ran";
    const std::string w = r.warning();
    EXPECT_NE(w.find("/dev/cpu_dma_latency"), std::string::npos) << w;
    EXPECT_NE(w.find("deep idle states"), std::string::npos) << w;
    EXPECT_NE(w.find("controller.cpu_dma_latency_us: -1"), std::string::npos) << w;
    // Only the PM QoS request failed: the cycle still has its real-time priority.
    EXPECT_EQ(w.find("WITHOUT real-time guarantees"), std::string::npos) << w;
    EXPECT_EQ(w.find("CAP_SYS_NICE"), std::string::npos) << w;
    EXPECT_EQ(w.find('\n'), std::string::npos) << "one message, one line";
    if (e == ENOENT || e == ENODEV) {
      EXPECT_NE(w.find("no PM QoS device"), std::string::npos) << w;
      EXPECT_NE(w.find("--device /dev/cpu_dma_latency"), std::string::npos) << w;
    } else {
      EXPECT_NE(w.find("holding /dev/cpu_dma_latency at 0 us not permitted"), std::string::npos) << w;
      EXPECT_NE(w.find("60-canmotion-cpu-dma-latency.rules"), std::string::npos) << w;
      EXPECT_NE(w.find("DeviceAllow=/dev/cpu_dma_latency rw"), std::string::npos) << w;
    }
    EXPECT_NE(r.describe().find("cpu_dma_latency 0 us: "), std::string::npos) << r.describe();
  }
}

TEST(RtSetup, CpuLatencyJoinsTheOtherRefusalsInTheOneWarning) {
  Script::reset();
  Script::fifo_err = EPERM;
  Script::qos_err = EACCES;
  const auto r = apply_rt_settings(full(80, -1), Script::syscalls());
  const std::string w = r.warning();
  EXPECT_NE(w.find("WITHOUT real-time guarantees"), std::string::npos) << w;
  EXPECT_NE(w.find("SCHED_FIFO priority 80 not permitted"), std::string::npos) << w;
  EXPECT_NE(w.find("holding /dev/cpu_dma_latency at 0 us not permitted"), std::string::npos) << w;
  EXPECT_NE(w.find("LimitRTPRIO=80"), std::string::npos) << w;
  EXPECT_NE(w.find("for /dev/cpu_dma_latency:"), std::string::npos) << w;
  EXPECT_EQ(w.find('\n'), std::string::npos) << w;
}

TEST(RtSetup, CpuLatencyValueIsCheckedAndMinusOneMeansLeaveIt) {
  Script::reset();
  auto s = full(80, -1);
  s.cpu_dma_latency_us = 75;
  auto r = apply_rt_settings(s, Script::syscalls());
  EXPECT_EQ(Script::last_qos_us, 75);
  EXPECT_NE(r.describe().find("cpu_dma_latency 75 us: ok"), std::string::npos) << r.describe();
  release_rt_settings(r, Script::syscalls());

  Script::reset();
  s.cpu_dma_latency_us = -1;
  r = apply_rt_settings(s, Script::syscalls());
  EXPECT_EQ(Script::qos_calls, 0);
  EXPECT_FALSE(r.outcome(RtStep::cpu_latency).requested);
  EXPECT_TRUE(r.realtime());

  for (std::int32_t bad : {-2, -1000}) {
    Script::reset();
    s.cpu_dma_latency_us = bad;
    r = apply_rt_settings(s, Script::syscalls());
    EXPECT_EQ(Script::qos_calls, 0) << bad;
    EXPECT_EQ(r.hard_error(), std::errc::invalid_argument) << "a configuration error: " << bad;
    EXPECT_NE(r.error_message().find("valid: 0 .. 2000000000 us, -1 = leave"), std::string::npos)
        << r.error_message();
  }
}

// The executive holds the request exactly while its loop runs.
TEST(RtSetup, ExecutiveHoldsCpuLatencyWhileTheLoopRuns) {
  Script::reset();
  VirtualClock clock;
  ExecutiveConfig cfg;
  cfg.rt = full(80, -1);
  cfg.syscalls = Script::syscalls();
  int warnings = 0;
  cfg.warn = [&](std::string_view) { ++warnings; };
  CyclicExecutive exec(cfg, clock);
  int held_cycles = 0;
  exec.set_cycle([&held_cycles](const CycleInfo&) noexcept { held_cycles += Script::qos_open ? 1 : 0; });
  ASSERT_FALSE(exec.run(7));
  EXPECT_EQ(held_cycles, 7);
  EXPECT_FALSE(Script::qos_open) << "released when the loop ended";
  EXPECT_EQ(Script::qos_closed, 1);
  EXPECT_EQ(warnings, 0);
  EXPECT_TRUE(exec.setup_report().outcome(RtStep::cpu_latency).done());

  // On a thread, and when a hard error stops the start: released at once.
  Script::reset();
  Script::affinity_err = EINVAL;
  cfg.rt = full(80, 3);
  cfg.syscalls = Script::syscalls();
  CyclicExecutive refused(cfg, clock);
  refused.set_cycle([](const CycleInfo&) noexcept {});
  EXPECT_EQ(refused.start(), std::errc::invalid_argument);
  EXPECT_EQ(Script::qos_calls, 1);
  EXPECT_FALSE(Script::qos_open);
}

#if !defined(__SANITIZE_THREAD__) && !defined(__SANITIZE_ADDRESS__)
// The real device, when this process may open it (root): the kernel's
// aggregate constraint reads our value while the loop runs and goes back
// afterwards. Skipped without the device, or when another process (say a
// cyclictest) already holds a constraint at or below ours.
TEST(RtSetup, RealCpuDmaLatencyIsHeldAndReleased) {
  const auto before = read_cpu_latency();
  if (!before) GTEST_SKIP() << "cannot read " << kCpuDmaLatencyPath << " (not root, or no device)";
  constexpr std::int32_t kOurs = 1234;
  if (*before <= kOurs) GTEST_SKIP() << "another process holds " << *before << " us";
  RtSettings s = RtSettings::none();
  s.cpu_dma_latency_us = kOurs;
  VirtualClock clock;
  ExecutiveConfig cfg;
  cfg.rt = s;
  CyclicExecutive exec(cfg, clock);
  std::int32_t during = -1;
  exec.set_cycle([&during](const CycleInfo&) noexcept { during = read_cpu_latency().value_or(-1); });
  ASSERT_FALSE(exec.run(1));
  ASSERT_TRUE(exec.setup_report().outcome(RtStep::cpu_latency).done()) << exec.setup_report().describe();
  EXPECT_EQ(during, kOurs);
  const auto after = read_cpu_latency();
  ASSERT_TRUE(after);
  EXPECT_GT(*after, kOurs) << "closing the file dropped the request";
}
#endif

// The executive runs anyway when a step is not permitted, and says so ONCE.
TEST(RtSetup, ExecutiveRunsDegradedWithExactlyOneWarning) {
  Script::reset();
  Script::fifo_err = EPERM;
  Script::mlock_err = EPERM;
  VirtualClock clock;
  ExecutiveConfig cfg;
  cfg.period = Nanos{1'000'000};
  cfg.rt = full(80, -1);
  cfg.syscalls = Script::syscalls();
  int warnings = 0;
  std::string text;
  cfg.warn = [&](std::string_view w) {
    ++warnings;
    text = w;
  };
  CyclicExecutive exec(cfg, clock);
  exec.set_cycle([](const CycleInfo&) noexcept {});
  ASSERT_FALSE(exec.run(10));
  EXPECT_EQ(exec.cycle_count(), 10u);
  EXPECT_EQ(warnings, 1);
  EXPECT_NE(text.find("CAP_SYS_NICE"), std::string::npos);
  EXPECT_NE(text.find("CAP_IPC_LOCK"), std::string::npos);
  EXPECT_TRUE(exec.setup_report().degraded());
}

TEST(RtSetup, ExecutiveRefusesToStartOnHardError) {
  Script::reset();
  Script::affinity_err = EINVAL;
  VirtualClock clock;
  ExecutiveConfig cfg;
  cfg.rt = full(80, 7);
  cfg.syscalls = Script::syscalls();
  int warnings = 0;
  cfg.warn = [&](std::string_view) { ++warnings; };
  CyclicExecutive exec(cfg, clock);
  int calls = 0;
  exec.set_cycle([&calls](const CycleInfo&) noexcept { ++calls; });
  EXPECT_EQ(exec.start(), std::errc::invalid_argument);
  EXPECT_EQ(exec.run(5), std::errc::invalid_argument);
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(exec.running());
  EXPECT_EQ(warnings, 0);
}

#if !defined(__SANITIZE_THREAD__) && !defined(__SANITIZE_ADDRESS__)
// Real syscalls on a separate thread (SCHED_FIFO is per thread). Runs the
// real thing when permitted (root / CAP_SYS_NICE); otherwise checks that the
// refusal is classified as "not permitted".
TEST(RtSetup, RealSyscallsOnAThread) {
  RtSettings s;
  s.lock_memory = false;  // would lock the whole test process
  s.prefault_stack_bytes = 128 * 1024;
  s.priority = 10;
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  ASSERT_EQ(sched_getaffinity(0, sizeof(allowed), &allowed), 0);
  s.cpu = 0;
  while (s.cpu < CPU_SETSIZE && !CPU_ISSET(s.cpu, &allowed)) {
    ++s.cpu;  // the first CPU this process may use (containers restrict the set)
  }
  RtSetupReport r;
  int policy = -1;
  sched_param param{};
  std::thread t([&] {
    r = apply_rt_settings(s);
    policy = sched_getscheduler(0);
    sched_getparam(0, &param);
  });
  t.join();
  release_rt_settings(r);
  EXPECT_FALSE(r.hard_error()) << r.describe();
  if (r.outcome(RtStep::scheduler).done()) {
    EXPECT_EQ(policy, SCHED_FIFO);
    EXPECT_EQ(param.sched_priority, 10);
  } else {
    EXPECT_TRUE(r.outcome(RtStep::scheduler).not_permitted()) << r.describe();
  }
  EXPECT_TRUE(r.outcome(RtStep::prefault_stack).done());
}
#endif

// A child process drops privileges for real (setuid nobody when root; in any
// case RLIMIT_RTPRIO=0 and RLIMIT_MEMLOCK=0), then runs the real set-up and
// a short real-time-clock run of the executive. Exit codes tell what failed.
TEST(RtSetup, UnprivilegedProcessRunsDegradedWithOneWarning) {
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    rlimit zero{0, 0};
    if (setrlimit(RLIMIT_RTPRIO, &zero) != 0) _exit(10);
    if (setrlimit(RLIMIT_MEMLOCK, &zero) != 0) _exit(11);
    if (geteuid() == 0) {
      if (setgroups(0, nullptr) != 0 || setgid(65534) != 0 || setuid(65534) != 0) _exit(12);
    }
    ExecutiveConfig cfg;
    cfg.period = Nanos{500'000};
    cfg.rt.lock_memory = true;
    cfg.rt.priority = 80;
    int warnings = 0;
    std::string text;
    cfg.warn = [&](std::string_view w) {
      ++warnings;
      text = w;
    };
    MonotonicClock clock;
    CyclicExecutive exec(cfg, clock);
    exec.set_cycle([](const CycleInfo& c) noexcept {
      return c.cycle + 1 >= 20 ? CycleResult::stop : CycleResult::run_on;
    });
    if (exec.start()) _exit(20);
    exec.join();
    const auto& r = exec.setup_report();
    std::fprintf(stderr, "child (uid %d) set-up:\n%s", static_cast<int>(getuid()), r.describe().c_str());
    if (exec.cycle_count() != 20) _exit(21);
    if (!r.outcome(RtStep::scheduler).not_permitted()) _exit(22);
#if !defined(__SANITIZE_THREAD__) && !defined(__SANITIZE_ADDRESS__)
    // (The sanitizers intercept mlockall() and make it a successful no-op.)
    if (!r.outcome(RtStep::lock_memory).not_permitted()) _exit(23);
    if (text.find("LimitMEMLOCK") == std::string::npos) _exit(26);
#endif
    // /dev/cpu_dma_latency is root's (0600): refused, and part of the one warning.
    if (access(kCpuDmaLatencyPath, F_OK) == 0) {
      if (!r.outcome(RtStep::cpu_latency).not_permitted()) _exit(27);
      if (text.find("/dev/cpu_dma_latency") == std::string::npos) _exit(28);
    }
    if (warnings != 1) _exit(24);
    if (text.find("CAP_SYS_NICE") == std::string::npos) _exit(25);
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "child step failed (see exit codes in the test)";
}
