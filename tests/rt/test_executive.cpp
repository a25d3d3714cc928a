// The cyclic executive on a real thread with the real clock, and the proof
// that its RT thread allocates nothing while it moves commands, events,
// snapshots and statistics (with the counter's negative control).
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <tuple>

#include <pthread.h>

#include "rt/clock.hpp"
#include "rt/cyclic_executive.hpp"
#include "rt/snapshot.hpp"
#include "rt/spsc_ring.hpp"
#include "tests/support/allocation_counter.hpp"

using namespace canmotion::rt;
using namespace canmotion::test;

namespace {

ExecutiveConfig real_config(Nanos period) {
  ExecutiveConfig cfg;
  cfg.period = period;
  cfg.rt = RtSettings::none();
  cfg.rt.prefault_stack_bytes = 64 * 1024;
#if !defined(__SANITIZE_THREAD__) && !defined(__SANITIZE_ADDRESS__)
  if (geteuid() == 0) {
    cfg.rt.priority = 20;  // real SCHED_FIFO when permitted (mlockall left off: whole test process)
  }
#endif
  cfg.warn = [](std::string_view w) { std::fprintf(stderr, "rt warning: %s\n", w.data()); };
  cfg.on_loop_start = [] { count_allocations_on_this_thread(true); };
  return cfg;
}

struct Cmd {
  std::uint64_t id;
  double target;
};
struct Event {
  std::uint64_t cycle;
  std::uint64_t cmd_id;
};
struct Status {
  std::uint64_t cycle;
  double position;
  std::int64_t latency_ns;
};

// A representative RT-side workload on SPSC rings and a snapshot.
struct Workload {
  SpscRing<Cmd, 256> commands;   // bound: the test pushes at most 256 ahead
  SpscRing<Event, 1024> events;  // bound: events per cycle (<= 4) x reader lag
  SnapshotBuffer<Status> status;
  double position = 0;
  std::uint64_t handled = 0;
  bool allocate_in_cycle = false;  // the negative control

  CycleResult cycle(const CycleInfo& c, std::uint64_t stop_after) noexcept {
    Cmd cmd{};
    int n = 0;
    while (n < 4 && commands.try_pop(cmd)) {
      position += (cmd.target - position) * 0.5;
      (void)events.try_push(Event{c.cycle, cmd.id});
      ++handled;
      ++n;
    }
    Status& s = status.write_slot();
    s.cycle = c.cycle;
    s.position = position;
    s.latency_ns = (c.wake - c.deadline).count();
    status.commit();
    if (allocate_in_cycle && c.cycle == 3) {
      auto* p = new int(static_cast<int>(c.cycle));
      asm volatile("" : : "g"(p) : "memory");
      delete p;
    }
    return c.cycle + 1 >= stop_after ? CycleResult::stop : CycleResult::run_on;
  }
};

// Non-RT side: feeds commands, drains events, reads snapshots and stats
// while the RT thread runs.
std::uint64_t drive_non_rt_side(CyclicExecutive& exec, Workload& w) {
  std::uint64_t next_id = 0;
  std::uint64_t events = 0;
  Status st{};
  while (exec.running()) {
    for (int i = 0; i < 3; ++i) {
      if (w.commands.try_push(Cmd{next_id, static_cast<double>(next_id % 100)})) {
        ++next_id;
      }
    }
    Event e{};
    while (w.events.try_pop(e)) {
      ++events;
    }
    (void)w.status.read(st);
    (void)exec.stats();  // percentiles on the non-RT side
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  Event e{};
  while (w.events.try_pop(e)) {
    ++events;
  }
  return events;
}

}  // namespace

TEST(RtExecutive, StartRunsOnItsThreadAndStopsAtABoundary) {
  MonotonicClock clock;
  CyclicExecutive exec(real_config(Nanos{200'000}), clock);
  std::atomic<std::thread::id> rt_id{};
  std::atomic<bool> in_cycle{false};
  std::atomic<int> overlapped{0};
  exec.set_cycle([&](const CycleInfo&) noexcept {
    rt_id = std::this_thread::get_id();
    if (in_cycle.exchange(true)) {
      ++overlapped;
    }
    in_cycle = false;
  });
  ASSERT_FALSE(exec.start());
  EXPECT_TRUE(exec.running());
  EXPECT_EQ(exec.start(), ExecutiveError::already_running);
  while (exec.cycle_count() < 50) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  exec.stop();
  EXPECT_FALSE(exec.running());
  EXPECT_EQ(exec.stop_reason(), StopReason::requested);
  EXPECT_NE(rt_id.load(), std::this_thread::get_id());
  EXPECT_EQ(overlapped, 0);
  const auto s = exec.stats();
  EXPECT_EQ(s.cycles, exec.cycle_count());
  EXPECT_GE(s.latency_min_ns, 0);
  EXPECT_GE(s.measured_period_min_ns, 0);
  EXPECT_EQ(s.period_ns, 200'000);
  // The thread is gone: ten more periods pass without a cycle.
  const auto after = exec.cycle_count();
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  EXPECT_EQ(exec.cycle_count(), after) << "no cycle after stop()";
  EXPECT_EQ(exec.stats().cycles, after);
}

TEST(RtExecutive, RtThreadAllocatesNothingWithQueuesSnapshotsAndStats) {
  MonotonicClock clock;
  CyclicExecutive exec(real_config(Nanos{250'000}), clock);
  Workload w;
  constexpr std::uint64_t kCycles = 2000;
  exec.set_cycle([&w](const CycleInfo& c) noexcept { return w.cycle(c, kCycles); });
  reset_allocation_count();
  ASSERT_FALSE(exec.start());
  const std::uint64_t events = drive_non_rt_side(exec, w);
  exec.join();
  EXPECT_EQ(exec.cycle_count(), kCycles);
  EXPECT_GT(w.handled, 100u) << "the workload really moved commands";
  EXPECT_EQ(events, w.handled);
  EXPECT_EQ(counted_allocations(), 0u) << counted_bytes() << " bytes allocated on the RT thread";
}

// Negative control: the same run with one `new` in cycle 3 is seen.
TEST(RtExecutive, AllocationOnTheRtThreadIsDetected) {
  MonotonicClock clock;
  CyclicExecutive exec(real_config(Nanos{250'000}), clock);
  Workload w;
  w.allocate_in_cycle = true;
  exec.set_cycle([&w](const CycleInfo& c) noexcept { return w.cycle(c, 20); });
  reset_allocation_count();
  ASSERT_FALSE(exec.start());
  (void)drive_non_rt_side(exec, w);
  exec.join();
  EXPECT_EQ(counted_allocations(), 1u);
}

// --sim: the same workload on the virtual clock on the calling thread.
TEST(RtExecutive, SimRunAllocatesNothingEither) {
  VirtualClock clock;
  ExecutiveConfig cfg = real_config(Nanos{1'000'000});
  cfg.rt = RtSettings::none();
  CyclicExecutive exec(cfg, clock);
  Workload w;
  for (std::uint64_t i = 0; i < 200; ++i) {
    ASSERT_TRUE(w.commands.try_push(Cmd{i, 1.0}));
  }
  exec.set_cycle([&](const CycleInfo& c) noexcept {
    clock.advance(Nanos{10'000});
    return w.cycle(c, 100'000);
  });
  reset_allocation_count();
  ASSERT_FALSE(exec.run());
  count_allocations_on_this_thread(false);
  EXPECT_EQ(exec.cycle_count(), 100'000u);
  EXPECT_EQ(w.handled, 200u);
  EXPECT_EQ(counted_allocations(), 0u);
  EXPECT_EQ(clock.now(), Nanos{100'000LL * 1'000'000 + 10'000});
}

namespace {
// Size of the calling thread's stack (pthread_getattr_np).
std::size_t own_stack_size() {
  pthread_attr_t attr;
  std::size_t size = 0;
  if (pthread_getattr_np(pthread_self(), &attr) == 0) {
    pthread_attr_getstacksize(&attr, &size);
    pthread_attr_destroy(&attr);
  }
  return size;
}
}  // namespace

// The RT thread gets the configured stack, not std::thread's 8 MiB (which
// mlockall would lock in full), and never less than twice the prefault.
// (glibc may hand a new thread a cached stack up to 4x the size asked for:
// the earlier tests' threads leave 512 KiB ones.)
TEST(RtExecutive, RtThreadHasTheConfiguredStack) {
  MonotonicClock clock;
  for (const auto& [stack, prefault, expect] :
       {std::tuple<std::size_t, std::size_t, std::size_t>{256 * 1024, 64 * 1024, 256 * 1024},
        {512 * 1024, 256 * 1024, 512 * 1024},
        {128 * 1024, 1024 * 1024, 2048 * 1024}}) {
    ExecutiveConfig cfg = real_config(Nanos{200'000});
    cfg.on_loop_start = {};
    cfg.stack_bytes = stack;
    cfg.rt.prefault_stack_bytes = prefault;
    CyclicExecutive exec(cfg, clock);
    std::atomic<std::size_t> seen{0};
    exec.set_cycle([&seen](const CycleInfo& c) noexcept {
      seen = own_stack_size();
      return c.cycle >= 2 ? CycleResult::stop : CycleResult::run_on;
    });
    ASSERT_FALSE(exec.start());
    exec.join();
    EXPECT_GE(seen.load(), expect) << "stack_bytes " << stack << ", prefault " << prefault;
    EXPECT_LE(seen.load(), 4 * expect) << "stack_bytes " << stack << ", prefault " << prefault;
    EXPECT_TRUE(exec.setup_report().outcome(RtStep::prefault_stack).done()) << "the prefault fits";
  }
  EXPECT_EQ(ExecutiveConfig{}.stack_bytes, 512u * 1024u);
}
