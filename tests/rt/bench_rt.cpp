// Costs of the RT building blocks on the cyclic path (figures for
// BENCHMARKS.md; never a test).
#include <benchmark/benchmark.h>

#include <array>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

#include "rt/clock.hpp"
#include "rt/cycle_stats.hpp"
#include "rt/cyclic_executive.hpp"
#include "rt/histogram.hpp"
#include "rt/snapshot.hpp"
#include "rt/spsc_ring.hpp"
#include "rt/text_output.hpp"

using namespace canmotion::rt;

namespace {
struct Cmd {
  std::uint64_t id;
  double a, b, c;
};
struct Status16 {  // ~16 axes x 8 values
  std::array<double, 16 * 8> v;
  std::uint64_t cycle;
};
}  // namespace

static void BM_SpscPushPop(benchmark::State& state) {
  SpscRing<Cmd, 1024> ring;
  Cmd c{1, 2, 3, 4};
  Cmd out{};
  for (auto _ : state) {
    ring.try_push(c);
    ring.try_pop(out);
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_SpscPushPop);

static void BM_SpscTwoThreads(benchmark::State& state) {
  SpscRing<Cmd, 1024> ring;
  std::atomic<bool> stop{false};
  std::thread consumer([&] {
    Cmd out{};
    while (!stop.load(std::memory_order_relaxed)) {
      while (ring.try_pop(out)) {
      }
    }
  });
  Cmd c{1, 2, 3, 4};
  for (auto _ : state) {
    while (!ring.try_push(c)) {
    }
  }
  stop = true;
  consumer.join();
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SpscTwoThreads)->UseRealTime();

static void BM_SnapshotPublish1KiB(benchmark::State& state) {
  SnapshotBuffer<Status16> buf;
  Status16 s{};
  for (auto _ : state) {
    ++s.cycle;
    buf.publish(s);
  }
  benchmark::DoNotOptimize(buf.published());
}
BENCHMARK(BM_SnapshotPublish1KiB);

static void BM_HistogramRecord(benchmark::State& state) {
  Histogram h;
  std::int64_t v = 1234;
  for (auto _ : state) {
    h.record(v);
    v = (v * 1103515245 + 12345) & 0xFFFFF;
  }
  benchmark::DoNotOptimize(h.count());
}
BENCHMARK(BM_HistogramRecord);

static void BM_StatsSnapshotWithPercentiles(benchmark::State& state) {
  CycleStatistics st(Nanos{1'000'000});
  for (int i = 0; i < 100000; ++i) {
    st.record(Nanos{1000 + i % 5000}, Nanos{2000}, Nanos{1'000'000});
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(st.snapshot());
  }
}
BENCHMARK(BM_StatsSnapshotWithPercentiles);

// Loop overhead per cycle on the virtual clock (empty cycle): the ceiling of
// --sim speed before any motion or bus work.
static void BM_VirtualLoopEmptyCycle(benchmark::State& state) {
  constexpr std::uint64_t kCycles = 100000;
  for (auto _ : state) {
    VirtualClock clock;
    ExecutiveConfig cfg;
    cfg.period = Nanos{1'000'000};
    cfg.rt = RtSettings::none();
    CyclicExecutive exec(cfg, clock);
    exec.set_cycle([](const CycleInfo&) noexcept {});
    exec.run(kCycles);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kCycles));
}
BENCHMARK(BM_VirtualLoopEmptyCycle)->Unit(benchmark::kMillisecond);

// The CSV's "%.6f" three ways (issue 18): format_fixed6, std::to_chars alone,
// snprintf (what canmotiond used before). Positions of +-5000 mm.
namespace {
std::vector<double> positions() {
  std::vector<double> v(4096);
  std::mt19937_64 rng(18);
  std::uniform_real_distribution<double> d(-5000.0, 5000.0);
  for (auto& x : v) x = d(rng);
  return v;
}
}  // namespace

static void BM_Fixed6(benchmark::State& state) {
  const auto v = positions();
  std::array<char, canmotion::rt::kFixed6Max> buf{};
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(canmotion::rt::format_fixed6(buf.data(), v[i++ & 4095]));
}
BENCHMARK(BM_Fixed6);

static void BM_Fixed6ToChars(benchmark::State& state) {
  const auto v = positions();
  std::array<char, canmotion::rt::kFixed6Max> buf{};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        std::to_chars(buf.data(), buf.data() + buf.size(), v[i++ & 4095], std::chars_format::fixed, 6).ptr);
  }
}
BENCHMARK(BM_Fixed6ToChars);

static void BM_Fixed6Snprintf(benchmark::State& state) {
  const auto v = positions();
  std::array<char, canmotion::rt::kFixed6Max + 1> buf{};
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(std::snprintf(buf.data(), buf.size(), "%.6f", v[i++ & 4095]));
}
BENCHMARK(BM_Fixed6Snprintf);

BENCHMARK_MAIN();
