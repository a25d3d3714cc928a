// SPSC ring and snapshot buffer: single-thread semantics and two-thread
// stress tests (also run under -DCANMOTION_SANITIZE=thread).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>

#include "rt/snapshot.hpp"
#include "rt/spsc_ring.hpp"
#include "tests/support/random_seed.hpp"

using namespace canmotion::rt;
using canmotion::test::test_count;

namespace {
struct Command {
  std::uint64_t seq;
  std::uint32_t axis;
  double value;
  std::uint64_t check;  // seq * 31 + axis: detects torn copies
};
}  // namespace

TEST(RtSpscRing, FifoOrderFullAndEmpty) {
  SpscRing<int, 4> r;
  int out = 0;
  EXPECT_FALSE(r.try_pop(out));
  EXPECT_EQ(r.capacity(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(r.try_push(i));
  }
  EXPECT_FALSE(r.try_push(99)) << "all 4 slots used";
  EXPECT_EQ(r.push_failures(), 1u);
  EXPECT_EQ(r.size_approx(), 4u);
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(r.try_pop(out));
    EXPECT_EQ(out, i);
  }
  EXPECT_FALSE(r.try_pop(out));
  EXPECT_TRUE(r.empty_approx());
}

TEST(RtSpscRing, WrapsAroundManyTimes) {
  SpscRing<std::uint32_t, 8> r;
  std::uint32_t next_in = 0;
  std::uint32_t next_out = 0;
  for (int round = 0; round < 10000; ++round) {
    const int burst = round % 9;  // 0..8
    for (int i = 0; i < burst; ++i) {
      ASSERT_TRUE(r.try_push(next_in++));
    }
    std::uint32_t v = 0;
    while (r.try_pop(v)) {
      ASSERT_EQ(v, next_out++);
    }
  }
  EXPECT_EQ(next_in, next_out);
  EXPECT_EQ(r.push_failures(), 0u);
}

TEST(RtSpscRing, TwoThreadStressKeepsOrderAndContent) {
  const std::uint64_t n = test_count(2'000'000);
  SpscRing<Command, 64> ring;
  std::atomic<bool> failed{false};
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < n; ++i) {
      const auto axis = static_cast<std::uint32_t>(i % 16);
      const Command c{i, axis, static_cast<double>(i) * 0.5, i * 31 + axis};
      while (!ring.try_push(c)) {
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t expected = 0;
  Command c{};
  while (expected < n) {
    if (!ring.try_pop(c)) {
      std::this_thread::yield();
      continue;
    }
    if (c.seq != expected || c.check != c.seq * 31 + c.axis || c.value != static_cast<double>(c.seq) * 0.5) {
      failed = true;
      break;
    }
    ++expected;
  }
  producer.join();
  EXPECT_FALSE(failed) << "out of order or torn at " << expected;
  EXPECT_EQ(expected, n);
}

namespace {
struct Status {
  std::uint64_t cycle;
  std::array<std::int64_t, 32> pos;  // every element = cycle * (i + 1): torn reads show
};
bool consistent(const Status& s) {
  for (std::size_t i = 0; i < s.pos.size(); ++i) {
    if (s.pos[i] != static_cast<std::int64_t>(s.cycle * (i + 1))) {
      return false;
    }
  }
  return true;
}
Status make_status(std::uint64_t cycle) {
  Status s{};
  s.cycle = cycle;
  for (std::size_t i = 0; i < s.pos.size(); ++i) {
    s.pos[i] = static_cast<std::int64_t>(cycle * (i + 1));
  }
  return s;
}
}  // namespace

TEST(RtSnapshot, ReadsNewestAndSequence) {
  SnapshotBuffer<Status> b;
  Status out{};
  out.cycle = 777;
  EXPECT_EQ(b.read(out), 0u) << "nothing published yet";
  EXPECT_EQ(out.cycle, 777u) << "left alone";
  b.publish(make_status(1));
  b.publish(make_status(2));
  b.publish(make_status(3));
  EXPECT_EQ(b.read(out), 3u);
  EXPECT_EQ(out.cycle, 3u);
  EXPECT_EQ(b.read(out), 3u) << "re-reading gives the same newest value";
  EXPECT_EQ(out.cycle, 3u);
  Status& w = b.write_slot();
  w = make_status(4);
  b.commit();
  EXPECT_EQ(b.read(out), 4u);
  EXPECT_TRUE(consistent(out));
  EXPECT_EQ(b.published(), 4u);
}

TEST(RtSnapshot, WriterNeverWaitsReadersNeverSeeTornOrOlderValues) {
  const std::uint64_t n = test_count(1'000'000);
  SnapshotBuffer<Status> b;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> bad{0};
  std::atomic<std::uint64_t> reads{0};
  auto reader = [&] {
    Status s{};
    std::uint64_t last_seq = 0;
    std::uint64_t last_cycle = 0;
    while (!done.load(std::memory_order_acquire)) {
      const std::uint64_t seq = b.read(s);
      if (seq == 0) {
        continue;
      }
      if (!consistent(s) || seq < last_seq || s.cycle < last_cycle || s.cycle + 1 != seq) {
        bad.fetch_add(1);
      }
      last_seq = seq;
      last_cycle = s.cycle;
      reads.fetch_add(1, std::memory_order_relaxed);
    }
  };
  std::thread r1(reader);
  std::thread r2(reader);
  for (std::uint64_t i = 0; i < n; ++i) {
    b.publish(make_status(i));
  }
  done.store(true, std::memory_order_release);
  r1.join();
  r2.join();
  EXPECT_EQ(bad.load(), 0u);
  EXPECT_GT(reads.load(), 0u);
  Status last{};
  EXPECT_EQ(b.read(last), n);
  EXPECT_EQ(last.cycle, n - 1);
}
