// The cyclic loop on the virtual clock: deadlines, latency/exec/period
// statistics, the SKIP overrun policy, stop at a cycle boundary, determinism.
#include <gtest/gtest.h>

#include <vector>

#include "rt/clock.hpp"
#include "rt/cyclic_executive.hpp"

using namespace canmotion::rt;

namespace {

constexpr Nanos kT{1'000'000};  // 1 ms

ExecutiveConfig sim_config(Nanos period = kT) {
  ExecutiveConfig cfg;
  cfg.period = period;
  cfg.rt = RtSettings::none();
  cfg.warn = [](std::string_view w) { ADD_FAILURE() << "unexpected warning: " << w; };
  return cfg;
}

}  // namespace

TEST(RtClock, VirtualSleepJumpsToDeadlineAndNeverBackwards) {
  VirtualClock c{Nanos{100}};
  EXPECT_EQ(c.now(), Nanos{100});
  c.sleep_until(Nanos{500});
  EXPECT_EQ(c.now(), Nanos{500});
  c.sleep_until(Nanos{200});  // in the past: no change
  EXPECT_EQ(c.now(), Nanos{500});
  c.set_wake_latency(Nanos{7});
  c.sleep_until(Nanos{1000});
  EXPECT_EQ(c.now(), Nanos{1007});
  c.advance(Nanos{3});
  EXPECT_EQ(c.now(), Nanos{1010});
}

TEST(RtClock, MonotonicSleepUntilReachesTheDeadline) {
  MonotonicClock c;
  const Nanos t0 = c.now();
  const Nanos deadline = t0 + Nanos{200'000};
  c.sleep_until(deadline);
  EXPECT_GE(c.now(), deadline);
  c.sleep_until(t0);  // past: returns at once
  EXPECT_GE(c.now(), deadline);
}

TEST(RtLoop, DeadlinesAreAbsoluteMultiplesOfThePeriod) {
  VirtualClock clock{Nanos{5'000'000}};
  CyclicExecutive exec(sim_config(), clock);
  std::vector<CycleInfo> seen;
  seen.reserve(100);
  exec.set_cycle([&](const CycleInfo& c) noexcept {
    seen.push_back(c);
    clock.advance(Nanos{300'000});  // each cycle "costs" 0.3 ms: must not drift the grid
  });
  ASSERT_FALSE(exec.run(100));
  ASSERT_EQ(seen.size(), 100u);
  for (std::size_t k = 0; k < seen.size(); ++k) {
    EXPECT_EQ(seen[k].cycle, k);
    EXPECT_EQ(seen[k].deadline, Nanos{5'000'000} + kT * static_cast<std::int64_t>(k + 1));
    EXPECT_EQ(seen[k].wake, seen[k].deadline);
    EXPECT_EQ(seen[k].missed, 0u);
    EXPECT_EQ(seen[k].period, kT);
  }
  const CycleStats s = exec.stats();
  EXPECT_EQ(s.cycles, 100u);
  EXPECT_EQ(s.overruns, 0u);
  EXPECT_EQ(s.exec_min_ns, 300'000);
  EXPECT_EQ(s.exec_max_ns, 300'000);
  EXPECT_EQ(s.latency_max_ns, 0);
  EXPECT_EQ(s.measured_period_min_ns, kT.count());
  EXPECT_EQ(s.measured_period_max_ns, kT.count());
  EXPECT_EQ(exec.stop_reason(), StopReason::max_cycles);
}

TEST(RtLoop, InjectedWakeLatencyIsMeasured) {
  VirtualClock clock;
  CyclicExecutive exec(sim_config(), clock);
  exec.set_cycle([&](const CycleInfo& c) noexcept {
    // The NEXT wake-up lands (c.cycle % 10) us late.
    clock.set_wake_latency(Nanos{static_cast<std::int64_t>((c.cycle + 1) % 10) * 1000});
  });
  ASSERT_FALSE(exec.run(1000));
  const CycleStats s = exec.stats();
  EXPECT_EQ(s.latency_min_ns, 0);
  EXPECT_EQ(s.latency_max_ns, 9000);
  EXPECT_EQ(s.latency_mean_ns, 4500);
  EXPECT_NEAR(static_cast<double>(s.latency_p50_ns), 4000.0, 4000.0 / 64 + 1);
  EXPECT_EQ(s.latency_p99_ns, 9000);
  // Wake times move with the latency, the grid does not.
  EXPECT_EQ(s.measured_period_min_ns, kT.count() - 9000);
  EXPECT_EQ(s.measured_period_max_ns, kT.count() + 1000);
}

// Overrun policy: SKIP. A cycle that ends after the next deadline drops the
// deadlines already in the past and resumes on the original grid.
TEST(RtLoop, OverrunSkipsMissedDeadlinesAndKeepsThePhase) {
  VirtualClock clock;
  CyclicExecutive exec(sim_config(), clock);
  std::vector<CycleInfo> seen;
  seen.reserve(20);
  exec.set_cycle([&](const CycleInfo& c) noexcept {
    seen.push_back(c);
    if (c.cycle == 5) {
      clock.advance(kT * 5 / 2);  // 2.5 periods: deadlines 6 and 7 pass
    }
    if (c.cycle == 10) {
      clock.advance(kT * 2);  // ends exactly on deadline +2: only +1 is missed
    }
    if (c.cycle == 12) {
      clock.advance(kT);  // ends exactly on the next deadline: NOT an overrun
    }
  });
  ASSERT_FALSE(exec.run(15));
  const Nanos t0 = seen[0].deadline - kT;
  auto slot = [&](std::size_t k) { return (seen[k].deadline - t0) / kT; };
  EXPECT_EQ(slot(5), 6);
  EXPECT_EQ(slot(6), 9) << "grid slots 7 and 8 were skipped";
  EXPECT_EQ(seen[6].missed, 2u);
  EXPECT_EQ(seen[6].cycle, 6u) << "the cycle counter counts executed cycles";
  EXPECT_EQ(slot(10), 13);
  EXPECT_EQ(slot(11), 15);
  EXPECT_EQ(seen[11].missed, 1u);
  EXPECT_EQ(slot(13), 17);
  EXPECT_EQ(seen[13].missed, 0u);
  for (std::size_t k = 0; k < seen.size(); ++k) {
    EXPECT_EQ((seen[k].deadline - t0) % kT, Nanos{0}) << "phase kept at cycle " << k;
    EXPECT_EQ(seen[k].wake, seen[k].deadline) << "never run late to catch up, cycle " << k;
  }
  const CycleStats s = exec.stats();
  EXPECT_EQ(s.overruns, 2u);
  EXPECT_EQ(s.missed_deadlines, 3u);
  EXPECT_EQ(s.exec_max_ns, (kT * 5 / 2).count());
}

TEST(RtLoop, CallableStopEndsAfterThatCycle) {
  VirtualClock clock;
  CyclicExecutive exec(sim_config(), clock);
  exec.set_cycle([](const CycleInfo& c) noexcept {
    return c.cycle == 41 ? CycleResult::stop : CycleResult::run_on;
  });
  ASSERT_FALSE(exec.run());
  EXPECT_EQ(exec.cycle_count(), 42u);
  EXPECT_EQ(exec.stop_reason(), StopReason::callable);
  EXPECT_FALSE(exec.running());
}

TEST(RtLoop, StopRequestIsHonouredAtTheCycleBoundary) {
  VirtualClock clock;
  CyclicExecutive exec(sim_config(), clock);
  int after_request = 0;
  bool requested = false;
  exec.set_cycle([&](const CycleInfo& c) noexcept {
    if (requested) {
      ++after_request;
    }
    if (c.cycle == 7) {
      exec.request_stop();  // mid-cycle: this cycle completes, no further one starts
      requested = true;
    }
  });
  ASSERT_FALSE(exec.run());
  EXPECT_EQ(exec.cycle_count(), 8u);
  EXPECT_EQ(after_request, 0);
  EXPECT_EQ(exec.stop_reason(), StopReason::requested);
  // The request was consumed: the next run goes on, the cycle index continues.
  ASSERT_FALSE(exec.run(3));
  EXPECT_EQ(exec.cycle_count(), 11u);
}

TEST(RtLoop, RunWithoutCallableOrWithBadPeriodFails) {
  VirtualClock clock;
  CyclicExecutive exec(sim_config(), clock);
  EXPECT_EQ(exec.run(1), ExecutiveError::no_callable);
  CyclicExecutive bad(sim_config(Nanos{0}), clock);
  bad.set_cycle([](const CycleInfo&) noexcept {});
  EXPECT_EQ(bad.run(1), ExecutiveError::bad_period);
  EXPECT_FALSE(std::string(make_error_code(ExecutiveError::bad_period).message()).empty());
}

TEST(RtLoop, VirtualRunsAreDeterministic) {
  auto trace = [] {
    VirtualClock clock;
    CyclicExecutive exec(sim_config(Nanos{250'000}), clock);
    std::vector<std::int64_t> out;
    out.reserve(3 * 500);
    std::uint64_t x = 12345;
    exec.set_cycle([&](const CycleInfo& c) noexcept {
      x = x * 6364136223846793005ULL + 1442695040888963407ULL;
      clock.advance(Nanos{static_cast<std::int64_t>((x >> 33) % 600'000)});  // sometimes overruns
      out.push_back(c.deadline.count());
      out.push_back(c.wake.count());
      out.push_back(c.missed);
    });
    EXPECT_FALSE(exec.run(500));
    const CycleStats s = exec.stats();
    out.push_back(static_cast<std::int64_t>(s.overruns));
    out.push_back(s.exec_p99_ns);
    return out;
  };
  const auto a = trace();
  const auto b = trace();
  EXPECT_EQ(a, b);
  EXPECT_GT(a[a.size() - 2], 0) << "the workload was meant to overrun sometimes";
}
