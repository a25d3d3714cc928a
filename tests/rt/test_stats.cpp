// Histogram bucket maths, percentiles against exact order statistics
// (seeded property test), statistics tags and printing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "rt/cycle_stats.hpp"
#include "rt/histogram.hpp"
#include "tests/support/random_seed.hpp"

using namespace canmotion::rt;
using canmotion::test::seed_note;
using canmotion::test::test_count;
using canmotion::test::test_seed;

TEST(RtHistogram, BucketsAreContiguousMonotoneAndNarrow) {
  EXPECT_EQ(Histogram::bucket_of(0), 0u);
  EXPECT_EQ(Histogram::bucket_of(127), 127u);
  EXPECT_EQ(Histogram::bucket_of(128), 128u);
  EXPECT_EQ(Histogram::bucket_of(129), 128u);  // width 2 from 128 to 255
  EXPECT_EQ(Histogram::bucket_lower(0), 0u);
  for (std::size_t i = 0; i + 1 < Histogram::kBuckets; ++i) {
    const auto lo = Histogram::bucket_lower(i);
    const auto hi = Histogram::bucket_upper(i);
    ASSERT_LE(lo, hi) << i;
    ASSERT_EQ(hi + 1, Histogram::bucket_lower(i + 1)) << i;
    ASSERT_EQ(Histogram::bucket_of(lo), i) << i;
    ASSERT_EQ(Histogram::bucket_of(hi), i) << i;
    // Relative width at most 1/64.
    ASSERT_LE(static_cast<double>(hi - lo + 1), std::max(1.0, static_cast<double>(lo) / 64.0)) << i;
  }
  EXPECT_EQ(Histogram::bucket_upper(Histogram::kBuckets - 1), (1ULL << 63) - 1);
}

TEST(RtHistogram, EmptyAndNegative) {
  Histogram h;
  EXPECT_EQ(h.count(), 0u);
  EXPECT_EQ(h.min(), 0);
  EXPECT_EQ(h.max(), 0);
  EXPECT_EQ(h.mean(), 0);
  EXPECT_EQ(h.percentile(0.99), 0);
  h.record(-5);
  EXPECT_EQ(h.count(), 1u);
  EXPECT_EQ(h.min(), 0);
  EXPECT_EQ(h.bucket_count(0), 1u);
}

// Property: for random latency-like data, every percentile lies within one
// bucket (<= 1/64 relative) ABOVE the exact order statistic, never below,
// and min/max/mean are exact.
// The text of --histogram (rt-latency, canmotiond): the non-empty buckets,
// "lower_ns upper_ns count", in order, after one header line.
TEST(RtHistogram, TextListsTheNonEmptyBuckets) {
  Histogram h;
  EXPECT_EQ(histogram_text(h), "# lower_ns upper_ns count\n");
  h.record(5);
  h.record(5);
  h.record(40'000);  // 2^15 <= v < 2^16: buckets 512 ns wide
  h.record(40'100);
  EXPECT_EQ(histogram_text(h), "# lower_ns upper_ns count\n5 5 2\n39936 40447 2\n");
}

TEST(RtHistogram, PercentilesMatchExactOrderStatistics) {
  const std::uint64_t seed = test_seed(20261121);
  const std::uint64_t rounds = test_count(50);
  std::mt19937_64 rng(seed);
  for (std::uint64_t round = 0; round < rounds; ++round) {
    Histogram h;
    std::lognormal_distribution<double> body(std::log(3000.0), 0.4);
    std::uniform_int_distribution<std::int64_t> spike(50'000, 2'000'000);
    std::uniform_int_distribution<int> n_dist(1, 20000);
    const int n = n_dist(rng);
    std::vector<std::int64_t> values;
    values.reserve(static_cast<std::size_t>(n));
    std::int64_t sum = 0;
    for (int i = 0; i < n; ++i) {
      const std::int64_t v = (rng() % 500 == 0) ? spike(rng) : static_cast<std::int64_t>(body(rng));
      values.push_back(v);
      sum += v;
      h.record(v);
    }
    std::sort(values.begin(), values.end());
    ASSERT_EQ(h.min(), values.front()) << seed_note(seed);
    ASSERT_EQ(h.max(), values.back()) << seed_note(seed);
    ASSERT_EQ(h.mean(), static_cast<std::int64_t>(sum / n)) << seed_note(seed);
    for (double q : {0.5, 0.9, 0.99, 0.999, 1.0}) {
      const auto rank = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(q * n)));
      const std::int64_t exact = values[rank - 1];
      const std::int64_t got = h.percentile(q);
      ASSERT_GE(got, exact) << "q=" << q << " n=" << n << " round " << round << seed_note(seed);
      ASSERT_LE(static_cast<double>(got - exact), std::max(1.0, static_cast<double>(exact) / 64.0))
          << "q=" << q << " n=" << n << " round " << round << seed_note(seed);
    }
  }
}

TEST(RtStats, LiveSnapshotFillsEveryField) {
  CycleStatistics st(Nanos{1'000'000});
  for (int i = 0; i < 1000; ++i) {
    st.record(Nanos{1000 + i}, Nanos{20'000 + i}, i == 0 ? Nanos{-1} : Nanos{999'000 + 2 * i});
  }
  st.record_overrun(3);
  const CycleStats s = st.snapshot();
  EXPECT_EQ(s.period_ns, 1'000'000);
  EXPECT_EQ(s.cycles, 1000u);
  EXPECT_EQ(s.overruns, 1u);
  EXPECT_EQ(s.missed_deadlines, 3u);
  EXPECT_EQ(s.latency_min_ns, 1000);
  EXPECT_EQ(s.latency_max_ns, 1999);
  EXPECT_EQ(s.latency_mean_ns, 1499);
  EXPECT_GE(s.latency_p99_ns, 1989);
  EXPECT_LE(s.latency_p99_ns, 1999);
  EXPECT_GE(s.latency_p999_ns, s.latency_p99_ns);
  EXPECT_GE(s.latency_p50_ns, 1499);
  EXPECT_EQ(s.exec_min_ns, 20'000);
  EXPECT_EQ(s.exec_max_ns, 20'999);
  EXPECT_EQ(s.measured_period_min_ns, 999'002);  // the first cycle has no period
  EXPECT_EQ(s.measured_period_max_ns, 999'000 + 2 * 999);
  EXPECT_EQ(s.last_latency_ns, 1999);
  EXPECT_EQ(s.last_exec_ns, 20'999);
}

TEST(RtStats, EveryFieldIsATag) {
  CycleStats s;
  s.latency_p999_ns = 8123;
  s.overruns = 4;
  s.cycles = 77;
  const auto names = stat_tag_names();
  EXPECT_EQ(names.size() * 8, sizeof(CycleStats));
  EXPECT_EQ(stat_tag_value(s, "latency_p999_ns"), 8123);
  EXPECT_EQ(stat_tag_value(s, "overruns"), 4);
  EXPECT_EQ(stat_tag_value(s, "cycles"), 77);
  EXPECT_FALSE(stat_tag_value(s, "latency_p42_ns").has_value());
  for (auto n : names) {
    EXPECT_TRUE(stat_tag_value(s, n).has_value()) << n;
  }
}

TEST(RtStats, SummaryPrintsMicroseconds) {
  CycleStats s;
  s.cycles = 20000;
  s.period_ns = 1'000'000;
  s.latency_min_ns = 2100;
  s.latency_p999_ns = 8800;
  s.latency_max_ns = 14'000;
  s.overruns = 2;
  const std::string text = format_summary(s);
  EXPECT_NE(text.find("cycles 20000"), std::string::npos) << text;
  EXPECT_NE(text.find("overruns 2"), std::string::npos) << text;
  EXPECT_NE(text.find("period 1000.0 us"), std::string::npos) << text;
  EXPECT_NE(text.find("min 2.1"), std::string::npos) << text;
  EXPECT_NE(text.find("p99.9 8.8"), std::string::npos) << text;
  EXPECT_NE(text.find("max 14.0 us"), std::string::npos) << text;
  const std::string line = format_line(s);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_NE(line.find("Max:   14.0"), std::string::npos) << line;
}
