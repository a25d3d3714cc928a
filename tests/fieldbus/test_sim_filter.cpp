// SimBus acceptance filters and the emulator's accepted identifiers
// (fieldbus/can/sim_bus.hpp, Emulator::accepted_ids): SimWorld puts each
// emulated drive behind a filter so that it is not handed the frames it would
// drop; that must never change what the drive does.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "fieldbus/can/sim_bus.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/emulator/emulator.hpp"
#include "test_support.hpp"
#include "tests/support/random_seed.hpp"

namespace {

using canmotion::can::Frame;
using canmotion::can::SimBus;
using canmotion::can::TimedFrame;

SimBus::Endpoint::IdSet ids_of(std::initializer_list<std::uint32_t> ids) {
  SimBus::Endpoint::IdSet s{};
  for (std::uint32_t id : ids) s[id >> 6] |= std::uint64_t{1} << (id & 63u);
  return s;
}

std::vector<std::uint32_t> drain_ids(SimBus::Endpoint& ep) {
  std::vector<std::uint32_t> out;
  std::array<TimedFrame, 8> buf;
  for (std::size_t n; (n = ep.receive(buf)) > 0;)
    for (std::size_t i = 0; i < n; ++i) out.push_back(buf[i].frame.id);
  return out;
}

TEST(SimBusFilter, OnlyAcceptedStandardFramesReachAFilteredEndpoint) {
  SimBus bus("sim0");
  auto& tx = bus.add_endpoint("tx");
  auto& open = bus.add_endpoint("open");
  auto& filtered = bus.add_endpoint("filtered");
  filtered.set_accept(ids_of({0x080, 0x202, 0x7FF}), ids_of({}));
  Frame ext(0x202, {1});
  ext.flags = canmotion::can::kExtended;
  Frame err(0x080, {});
  err.flags = canmotion::can::kError;
  for (const Frame& f : {Frame(0x080, {}), Frame(0x202, {1, 2}), Frame(0x203, {3}), ext, err, Frame(0x7FF, {}),
                         Frame(0x000, {1, 0})})
    ASSERT_EQ(tx.send(f), canmotion::can::SendResult::kOk);
  EXPECT_EQ(drain_ids(open), (std::vector<std::uint32_t>{0x080, 0x202, 0x203, 0x202, 0x080, 0x7FF, 0x000}));
  EXPECT_EQ(drain_ids(filtered), (std::vector<std::uint32_t>{0x080, 0x202, 0x7FF}));
  EXPECT_EQ(bus.counters().delivered, 7u);  // each frame reached the wire once
  filtered.clear_accept();
  ASSERT_EQ(tx.send(Frame(0x203, {})), canmotion::can::SendResult::kOk);
  EXPECT_EQ(drain_ids(filtered), (std::vector<std::uint32_t>{0x203}));
}

TEST(SimBusFilter, AnOpenerLetsEverythingThroughUntilTheRingIsEmptied) {
  // An SDO request may change what the owner listens to: the frames behind
  // it in the same batch must all reach the owner, which then sets the
  // filter again.
  SimBus bus("sim0");
  auto& tx = bus.add_endpoint("tx");
  auto& rx = bus.add_endpoint("rx");
  rx.set_accept(ids_of({0x080, 0x602}), ids_of({0x602}));
  for (std::uint32_t id : {0x081u, 0x080u, 0x602u, 0x081u, 0x203u}) ASSERT_EQ(tx.send(Frame(id, {})), canmotion::can::SendResult::kOk);
  std::array<TimedFrame, 2> two;
  ASSERT_EQ(rx.receive(two), 2u);  // not empty yet: still open
  ASSERT_EQ(tx.send(Frame(0x204, {})), canmotion::can::SendResult::kOk);
  EXPECT_EQ(drain_ids(rx), (std::vector<std::uint32_t>{0x081, 0x203, 0x204}));
  // emptied: filtering again
  for (std::uint32_t id : {0x081u, 0x080u}) ASSERT_EQ(tx.send(Frame(id, {})), canmotion::can::SendResult::kOk);
  EXPECT_EQ(drain_ids(rx), (std::vector<std::uint32_t>{0x080}));
}

TEST(SimBusFilter, RingKeepsOrderWhenItRestartsAfterEmptying) {
  // receive() moves an emptied ring back to its first slot; order and
  // content must be those of a plain FIFO over many partial drains and wraps.
  SimBus bus("sim0");
  auto& tx = bus.add_endpoint("tx");
  auto& rx = bus.add_endpoint("rx", 16);
  std::mt19937_64 rng(canmotion::test::test_seed(7));
  std::uint32_t next_sent = 0, next_seen = 0;
  std::array<TimedFrame, 5> buf;
  for (int round = 0; round < 2000; ++round) {
    const auto burst = static_cast<std::uint32_t>(rng() % 9);
    for (std::uint32_t k = 0; k < burst && rx.pending() < 16; ++k, ++next_sent)
      ASSERT_EQ(tx.send(Frame(next_sent % 0x7FF, {static_cast<std::uint8_t>(next_sent)})), canmotion::can::SendResult::kOk);
    const std::size_t n = rx.receive(std::span<TimedFrame>(buf.data(), 1 + rng() % buf.size()));
    for (std::size_t i = 0; i < n; ++i, ++next_seen) {
      ASSERT_EQ(buf[i].frame.id, next_seen % 0x7FF) << "round " << round;
      ASSERT_EQ(buf[i].frame.data[0], static_cast<std::uint8_t>(next_seen));
    }
  }
  EXPECT_EQ(drain_ids(rx).size(), next_sent - next_seen);
  EXPECT_EQ(rx.counters().rx_dropped, 0u);
}

TEST(SimBusFilter, PeekAndConsumeReadTheRingInPlaceLikeReceive) {
  // peek()/consume() (Emulator::service on a SimBus endpoint) must hand out
  // the same frames in the same order as receive(), across wraps of the ring
  // and partial consumes, and close an opened filter only once emptied.
  SimBus bus("sim0");
  auto& tx = bus.add_endpoint("tx");
  auto& rx = bus.add_endpoint("rx", 16);
  const std::uint64_t seed = canmotion::test::test_seed(11);
  std::mt19937_64 rng(seed);
  std::uint32_t next_sent = 0, next_seen = 0;
  for (int round = 0; round < 2000; ++round) {
    const auto burst = static_cast<std::uint32_t>(rng() % 9);
    for (std::uint32_t k = 0; k < burst && rx.pending() < 16; ++k, ++next_sent)
      ASSERT_EQ(tx.send(Frame(next_sent % 0x7FF, {static_cast<std::uint8_t>(next_sent)})), canmotion::can::SendResult::kOk);
    const auto run = rx.peek();
    ASSERT_LE(run.size(), rx.pending()) << "seed " << seed;
    ASSERT_EQ(run.empty(), rx.pending() == 0) << "seed " << seed;
    const std::size_t take = run.empty() ? 0 : 1 + rng() % run.size();
    for (std::size_t i = 0; i < take; ++i, ++next_seen) {
      ASSERT_EQ(run[i].frame.id, next_seen % 0x7FF) << "seed " << seed << " round " << round;
      ASSERT_EQ(run[i].frame.data[0], static_cast<std::uint8_t>(next_seen)) << "seed " << seed;
    }
    rx.consume(take);
  }
  EXPECT_EQ(drain_ids(rx).size(), next_sent - next_seen);
  EXPECT_EQ(rx.counters().rx_dropped, 0u);
  // The opener rule, with consume() in place of receive().
  rx.set_accept(ids_of({0x080, 0x602}), ids_of({0x602}));
  for (std::uint32_t id : {0x081u, 0x602u, 0x081u}) ASSERT_EQ(tx.send(Frame(id, {})), canmotion::can::SendResult::kOk);
  ASSERT_EQ(rx.peek().size(), 2u);  // 0x081 before the opener was filtered out
  rx.consume(1);
  ASSERT_EQ(tx.send(Frame(0x203, {})), canmotion::can::SendResult::kOk);  // still open: not emptied yet
  EXPECT_EQ(rx.pending(), 2u);
  rx.consume(2);
  ASSERT_EQ(tx.send(Frame(0x203, {})), canmotion::can::SendResult::kOk);  // emptied: filtering again
  EXPECT_EQ(rx.pending(), 0u);
  EXPECT_TRUE(rx.peek().empty());
}

/// One emulated drive on its own bus, with or without the filter SimWorld uses.
struct Rig {
  explicit Rig(bool filter) : bus("sim0"), master(bus.add_endpoint("master")), ep(bus.add_endpoint("node2")) {
    canmotion::emulator::EmulatorConfig cfg;
    cfg.node = 2;
    emu = std::make_unique<canmotion::emulator::Emulator>(cfg);
    filtered = filter;
    canmotion::canopen::TransportSink sink(ep);
    emu->power_on(0, sink);
    refresh();
  }
  void refresh() {
    if (!filtered || emu->accept_generation() == gen) return;
    SimBus::Endpoint::IdSet ids, openers;
    emu->accepted_ids(ids, openers);
    ep.set_accept(ids, openers);
    gen = emu->accept_generation();
  }
  void step(std::int64_t t, const std::vector<Frame>& frames) {
    bus.set_time(t);
    for (const Frame& f : frames) master.send(f);
    emu->service(ep, t);
    refresh();
    std::array<TimedFrame, 16> buf;
    for (std::size_t n; (n = master.receive(buf)) > 0;)
      for (std::size_t i = 0; i < n; ++i)
        out.push_back(std::to_string(buf[i].frame.flags) + ":" + fbtest::hex(buf[i].frame) + "@" + std::to_string(buf[i].t_ns));
  }
  SimBus bus;
  SimBus::Endpoint& master;
  SimBus::Endpoint& ep;
  std::unique_ptr<canmotion::emulator::Emulator> emu;
  bool filtered = false;
  std::uint64_t gen = ~std::uint64_t{0};
  std::vector<std::string> out;
};

Frame sdo_write(std::uint16_t index, std::uint8_t sub, std::uint32_t v) {
  return Frame(0x602, {0x23, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub,
                       static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v >> 16),
                       static_cast<std::uint8_t>(v >> 24)});
}

TEST(SimBusFilter, EmulatorBehindItsFilterBehavesAsWithout) {
  // Random traffic, weighted towards what changes the accepted identifiers
  // (0x1005, the RPDO COB-IDs, NMT resets) and what they gate (SYNC, RPDOs,
  // heartbeats, SDO): the drive's replies, its counters and its motor must be
  // the same with and without the filter.
  const std::uint64_t seed = canmotion::test::test_seed(20261121);
  const std::uint64_t steps = canmotion::test::test_count(20000);
  std::mt19937_64 rng(seed);
  Rig a(true), b(false);
  const std::vector<Frame> special = {
      Frame(0x000, {0x01, 0x02}), Frame(0x000, {0x01, 0x00}), Frame(0x000, {0x80, 0x02}), Frame(0x000, {0x82, 0x02}),
      Frame(0x000, {0x81, 0x02}), sdo_write(0x1005, 0, 0x80), sdo_write(0x1005, 0, 0x81), sdo_write(0x1005, 0, 0x202),
      sdo_write(0x1400, 1, 0x80000202), sdo_write(0x1400, 1, 0x80000203), sdo_write(0x1400, 1, 0x203),
      sdo_write(0x1400, 1, 0x202), sdo_write(0x1401, 1, 0x302), sdo_write(0x1401, 1, 0x80000302),
      sdo_write(0x1016, 1, (1u << 16) | 50u), sdo_write(0x1017, 0, 20), Frame(0x701, {0x05}), Frame(0x705, {0x05}),
      Frame(0x602, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0})};
  std::int64_t t = 0;
  for (std::uint64_t s = 0; s < steps; ++s) {
    std::vector<Frame> frames;
    const int n = static_cast<int>(rng() % 4);
    for (int k = 0; k < n; ++k) {
      const unsigned pick = static_cast<unsigned>(rng() % 100);
      Frame f;
      if (pick < 10) {
        f = special[rng() % special.size()];
      } else if (pick < 40) {
        f = Frame(rng() % 4 == 0 ? 0x081u : 0x080u, {});
      } else if (pick < 65) {
        static constexpr std::uint32_t kRpdo[] = {0x202, 0x203, 0x302, 0x182};
        f.id = kRpdo[rng() % 4];
        f.len = static_cast<std::uint8_t>(rng() % 9);
        // controlword: mostly the enable sequence, sometimes anything
        static constexpr std::uint16_t kCw[] = {0x06, 0x07, 0x0F, 0x0F, 0x0F, 0x80, 0x00, 0x02};
        const std::uint16_t cw = rng() % 8 == 0 ? static_cast<std::uint16_t>(rng()) : kCw[rng() % 8];
        const auto target = static_cast<std::int32_t>(rng() % 2001) - 1000;
        const std::uint64_t v = cw | (static_cast<std::uint64_t>(static_cast<std::uint32_t>(target)) << 16);
        for (std::size_t i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(v >> (8 * i));
      } else {
        f.id = static_cast<std::uint32_t>(rng() % 0x800);
        f.len = static_cast<std::uint8_t>(rng() % 9);
        for (auto& d : f.data) d = static_cast<std::uint8_t>(rng());
        const unsigned fl = static_cast<unsigned>(rng() % 20);
        if (fl == 0) f.flags = canmotion::can::kExtended;
        if (fl == 1) f.flags = canmotion::can::kError;
        if (fl == 2) f.flags = canmotion::can::kRemote;
      }
      frames.push_back(f);
    }
    t += 1'000'000;
    a.step(t, frames);
    b.step(t, frames);
    ASSERT_EQ(a.out.size(), b.out.size()) << "step " << s << canmotion::test::seed_note(seed);
  }
  ASSERT_EQ(a.out, b.out) << canmotion::test::seed_note(seed);
  const auto& ca = a.emu->counters();
  const auto& cb = b.emu->counters();
  EXPECT_EQ(ca.syncs, cb.syncs);
  EXPECT_EQ(ca.rpdos, cb.rpdos);
  EXPECT_EQ(ca.tpdos, cb.tpdos);
  EXPECT_EQ(ca.sdo_requests, cb.sdo_requests);
  EXPECT_EQ(ca.emcys, cb.emcys);
  EXPECT_EQ(ca.boot_ups, cb.boot_ups);
  EXPECT_EQ(a.emu->position_exact(), b.emu->position_exact());
  // The traffic did what it is for: the filter changed and filtered something.
  EXPECT_GT(ca.syncs, steps / 8);
  EXPECT_GT(ca.rpdos, 0u);
  EXPECT_GT(ca.boot_ups, 1u);
  EXPECT_GT(a.gen, 3u);
  EXPECT_LT(a.ep.counters().rx_frames, b.ep.counters().rx_frames) << canmotion::test::seed_note(seed);
}

}  // namespace
