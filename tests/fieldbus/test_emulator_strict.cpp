// The emulator's profiles (issue 15 item 9): each strict behaviour against a
// permissive drive, and the CiA 301 rules both profiles keep (TPDO
// transmission types, RPDO 254/255 on receipt, EMCY 8210h/8220h/8240h once
// with the error register and 0000h when they clear). The emulator is driven
// frame by frame on a virtual clock; SDO requests are raw expedited frames.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/emulator/emulator.hpp"
#include "test_support.hpp"

using namespace canmotion;
using cia402::State;
using emulator::EmulatorBehaviour;
using emulator::EmulatorConfig;
using fbtest::hex;
using fbtest::VecSink;

namespace {

constexpr std::uint8_t kNode = 2;
constexpr std::int64_t kMs = 1'000'000;

/// One emulated drive on a virtual clock, fed frame by frame.
struct Drive {
  explicit Drive(EmulatorConfig c) : emu([&] {
    c.node = kNode;
    return c;
  }()) {
    emu.power_on(t, out);
  }
  static EmulatorConfig strict() { return EmulatorConfig{}; }
  static EmulatorConfig permissive() {
    EmulatorConfig c;
    c.behaviour = EmulatorBehaviour::permissive();
    return c;
  }

  void feed(const can::Frame& f) {
    emu.set_time(t);
    emu.on_frame(can::TimedFrame{f, t}, out);
  }
  /// Advance the clock by `ns` and run the time-driven duties.
  void advance(std::int64_t ns = kMs) {
    t += ns;
    emu.step(t, out);
  }
  /// SDO request, then the clock on until the reply: the reply's frame.
  can::Frame sdo(const can::Frame& req) {
    out.clear();
    feed(req);
    for (int i = 0; i < 5; ++i) {
      for (const can::Frame& f : out.frames)
        if (f.id == 0x580u + kNode) return f;
      advance();
    }
    ADD_FAILURE() << "no SDO reply";
    return {};
  }
  /// Expedited download; returns the abort code (0 = written).
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t v, std::uint8_t size) {
    can::Frame f;
    f.id = 0x600u + kNode;
    f.len = 8;
    f.data = {static_cast<std::uint8_t>(0x23 | ((4 - size) << 2)), static_cast<std::uint8_t>(index),
              static_cast<std::uint8_t>(index >> 8), sub, static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
              static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)};
    const can::Frame r = sdo(f);
    return r.data[0] == 0x80 ? abort_code(r) : 0;
  }
  /// Expedited upload; returns the abort code (0 = read into `v`).
  std::uint32_t read(std::uint16_t index, std::uint8_t sub, std::uint32_t& v) {
    can::Frame f;
    f.id = 0x600u + kNode;
    f.len = 8;
    f.data = {0x40, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub, 0, 0, 0, 0};
    const can::Frame r = sdo(f);
    if (r.data[0] == 0x80) return abort_code(r);
    v = static_cast<std::uint32_t>(r.data[4] | r.data[5] << 8 | r.data[6] << 16 | r.data[7] << 24);
    return 0;
  }
  static std::uint32_t abort_code(const can::Frame& r) {
    return static_cast<std::uint32_t>(r.data[4] | r.data[5] << 8 | r.data[6] << 16 | r.data[7] << 24);
  }
  void start() { feed(fbtest::frame("000#0100")); }
  void sync(const std::string& frame = "080#") {
    feed(fbtest::frame(frame));
    advance();
  }
  /// Frames sent with identifier `id` since the last out.clear().
  std::vector<std::string> sent(std::uint32_t id) const {
    std::vector<std::string> v;
    for (const can::Frame& f : out.frames)
      if (f.id == id) v.push_back(hex(f));
    return v;
  }
  /// Past the DC bus charging, into Switch on disabled.
  void boot() {
    for (int i = 0; i < 1000 && emu.state() == State::kNotReadyToSwitchOn; ++i) advance();
  }
  /// Controlword over SDO, then SYNCs until the state is `want`.
  bool command(std::uint16_t cw, State want, int syncs = 10) {
    if (write(0x6040, 0, cw, 2) != 0) return false;
    for (int i = 0; i < syncs && emu.state() != want; ++i) sync();
    return emu.state() == want;
  }
  bool enable() {
    return command(0x0006, State::kReadyToSwitchOn) && command(0x000F, State::kOperationEnabled);
  }

  std::int64_t t = 0;
  VecSink out;
  emulator::Emulator emu;
};

constexpr std::uint32_t kNoObject = 0x06020000, kReadOnly = 0x06010002, kDeviceState = 0x08000022,
                        kInvalidValue = 0x06090030;

}  // namespace

TEST(EmulatorStrict, OptionalObjectsAbsentAndIpIndexReadOnly) {
  Drive s(Drive::strict());
  std::uint32_t v = 0;
  EXPECT_EQ(s.read(0x1016, 1, v), kNoObject);
  for (const int i : {0x2010, 0x2011, 0x2020, 0x2021, 0x2022})
    EXPECT_EQ(s.read(static_cast<std::uint16_t>(i), 0, v), kNoObject) << i;
  EXPECT_EQ(s.write(0x60C2, 2, 0xFD, 1), kReadOnly);
  EXPECT_EQ(s.write(0x60C2, 1, 4, 1), 0u);  // the value (ms) stays writable
  Drive p(Drive::permissive());
  EXPECT_EQ(p.read(0x1016, 1, v), 0u);
  EXPECT_EQ(p.read(0x2020, 0, v), 0u);
  EXPECT_EQ(p.write(0x60C2, 2, 0xFD, 1), 0u);
}

TEST(EmulatorStrict, PdoRemappingOnlyInPreOperational) {
  Drive s(Drive::strict());
  s.start();
  EXPECT_EQ(s.write(0x1400, 1, 0x80000202, 4), kDeviceState);
  EXPECT_EQ(s.write(0x1A00, 0, 0, 1), kDeviceState);
  EXPECT_EQ(s.write(0x1800, 2, 1, 1), kDeviceState);
  s.feed(fbtest::frame("000#8002"));  // enter pre-operational
  EXPECT_EQ(s.write(0x1800, 1, 0x80000182, 4), 0u);
  EXPECT_EQ(s.write(0x1A00, 0, 0, 1), 0u);
  Drive p(Drive::permissive());
  p.start();
  EXPECT_EQ(p.write(0x1800, 1, 0x80000182, 4), 0u);
}

TEST(EmulatorStrict, Cia402PredefinedPdo1IsControlwordAndStatuswordEventDriven) {
  Drive s(Drive::strict());
  std::uint32_t v = 0;
  EXPECT_EQ(s.read(0x1600, 0, v), 0u);
  EXPECT_EQ(v, 1u);
  EXPECT_EQ(s.read(0x1600, 1, v), 0u);
  EXPECT_EQ(v, 0x60400010u);
  EXPECT_EQ(s.read(0x1A00, 0, v), 0u);
  EXPECT_EQ(v, 1u);
  EXPECT_EQ(s.read(0x1A00, 1, v), 0u);
  EXPECT_EQ(v, 0x60410010u);
  EXPECT_EQ(s.read(0x1400, 2, v), 0u);
  EXPECT_EQ(v, 255u);
  EXPECT_EQ(s.read(0x1800, 2, v), 0u);
  EXPECT_EQ(v, 255u);
  Drive p(Drive::permissive());
  EXPECT_EQ(p.read(0x1A00, 2, v), 0u);
  EXPECT_EQ(v, 0x60640020u);
}

// CiA 301 transmission types, in both profiles (they were sent on every SYNC).
TEST(EmulatorPdo, TpdoTransmissionTypesPerCia301) {
  for (const bool strict : {true, false}) {
    SCOPED_TRACE(strict ? "strict" : "permissive");
    Drive d(strict ? Drive::strict() : Drive::permissive());
    d.boot();
    // TPDO1 type 0: at the SYNC after a change only.
    ASSERT_EQ(d.write(0x1800, 2, 0, 1), 0u);
    d.start();
    d.out.clear();
    for (int i = 0; i < 5; ++i) d.sync();
    EXPECT_EQ(d.sent(0x182).size(), 1u) << "type 0: once, then only after a change";
    d.command(0x0006, State::kReadyToSwitchOn);
    d.out.clear();
    for (int i = 0; i < 3; ++i) d.sync();
    EXPECT_EQ(d.sent(0x182).size(), 1u) << "type 0: at the SYNC after the change";
    // Type 3: every third SYNC.
    d.feed(fbtest::frame("000#8002"));
    ASSERT_EQ(d.write(0x1800, 2, 3, 1), 0u);
    d.start();
    d.out.clear();
    for (int i = 0; i < 9; ++i) d.sync();
    EXPECT_EQ(d.sent(0x182).size(), 3u);
    // Type 255: not at SYNC; on a change (even between SYNCs); event timer 5 ms.
    d.feed(fbtest::frame("000#8002"));
    ASSERT_EQ(d.write(0x1800, 2, 255, 1), 0u);
    d.start();
    d.sync();  // the first chance sends it
    d.out.clear();
    for (int i = 0; i < 4; ++i) d.sync();
    EXPECT_TRUE(d.sent(0x182).empty()) << "type 255 without a change or timer";
    d.write(0x6040, 0, 0x0007, 2);  // switch on: the statusword changes
    d.advance();
    d.sync();
    EXPECT_EQ(d.sent(0x182).size(), 1u);
    d.feed(fbtest::frame("000#8002"));
    ASSERT_EQ(d.write(0x1800, 5, 5, 2), 0u);
    d.start();
    d.out.clear();
    for (int i = 0; i < 20; ++i) d.advance();
    EXPECT_EQ(d.sent(0x182).size(), 4u) << "event timer 5 ms over 20 ms (the first at once)";
  }
}

TEST(EmulatorPdo, TpdoInhibitTimeDelaysAChange) {
  Drive d(Drive::strict());
  d.boot();
  ASSERT_EQ(d.write(0x1800, 3, 100, 2), 0u);  // 10 ms
  d.start();
  d.advance();
  d.out.clear();
  d.write(0x6040, 0, 0x0006, 2);  // a change within 10 ms of the first TPDO
  for (int i = 0; i < 5; ++i) d.advance();
  EXPECT_TRUE(d.sent(0x182).empty()) << "inhibited";
  for (int i = 0; i < 7; ++i) d.advance();
  const auto tpdos = d.sent(0x182);
  ASSERT_EQ(tpdos.size(), 1u);
  EXPECT_EQ(tpdos[0], "182#3102");  // ready to switch on + voltage enabled + remote
}

TEST(EmulatorPdo, EventRpdoAppliedOnReceiptSynchronousAtSync) {
  for (const bool strict : {true, false}) {
    SCOPED_TRACE(strict ? "strict" : "permissive");
    Drive d(strict ? Drive::strict() : Drive::permissive());
    d.boot();
    ASSERT_EQ(d.write(0x1400, 2, 255, 1), 0u);
    d.start();
    const std::string rpdo = strict ? "202#0600" : "202#060000000000";
    d.feed(fbtest::frame(rpdo));
    EXPECT_EQ(d.emu.state(), State::kReadyToSwitchOn) << "type 255: applied on receipt";
    d.feed(fbtest::frame("000#8002"));
    ASSERT_EQ(d.write(0x1400, 2, 1, 1), 0u);
    d.start();
    d.feed(fbtest::frame(strict ? "202#0000" : "202#000000000000"));
    EXPECT_EQ(d.emu.state(), State::kReadyToSwitchOn) << "type 1: waits for the SYNC";
    d.sync();
    EXPECT_EQ(d.emu.state(), State::kSwitchOnDisabled);
  }
}

TEST(EmulatorPdo, RpdoLengthErrorEmcyOnceWithRegisterThenReset) {
  for (const bool strict : {true, false}) {
    SCOPED_TRACE(strict ? "strict" : "permissive");
    Drive d(strict ? Drive::strict() : Drive::permissive());
    d.start();
    d.out.clear();
    d.feed(fbtest::frame("202#0F"));
    d.feed(fbtest::frame("202#0F"));
    d.sync();
    EXPECT_EQ(d.sent(0x082), std::vector<std::string>{"082#1082110000000000"}) << "once, generic + communication";
    EXPECT_EQ(d.emu.read_int(0x1001), 0x11);
    d.out.clear();
    d.feed(fbtest::frame(strict ? "202#0000" : "202#000000000000"));
    EXPECT_EQ(d.sent(0x082), std::vector<std::string>{"082#0000000000000000"}) << "reset when a right one follows";
    EXPECT_EQ(d.emu.read_int(0x1001), 0);
  }
}

TEST(EmulatorStrict, OverLongRpdoGivesEmcy8220) {
  Drive s(Drive::strict());
  s.start();
  s.out.clear();
  s.feed(fbtest::frame("202#060000"));
  EXPECT_EQ(s.sent(0x082), std::vector<std::string>{"082#2082110000000000"});
  EXPECT_EQ(s.emu.read_int(0x6040), 6) << "the mapped bytes are used";
  Drive p(Drive::permissive());
  p.start();
  p.out.clear();
  p.feed(fbtest::frame("202#06000000000000"));
  EXPECT_TRUE(p.sent(0x082).empty());
}

TEST(EmulatorStrict, SyncLengthCheckedAgainst1019) {
  Drive s(Drive::strict());
  s.start();
  s.out.clear();
  const auto syncs = s.emu.counters().syncs;
  s.sync("080#01");
  s.sync("080#02");
  EXPECT_EQ(s.emu.counters().syncs, syncs) << "not processed";
  EXPECT_EQ(s.sent(0x082), std::vector<std::string>{"082#4082110000000000"});
  s.out.clear();
  s.sync();
  EXPECT_EQ(s.sent(0x082), std::vector<std::string>{"082#0000000000000000"});
  EXPECT_EQ(s.write(0x1019, 0, 1, 1), kInvalidValue);
  EXPECT_EQ(s.write(0x1019, 0, 241, 1), kInvalidValue);
  ASSERT_EQ(s.write(0x1019, 0, 10, 1), 0u);
  s.out.clear();
  s.sync();
  EXPECT_EQ(s.sent(0x082), std::vector<std::string>{"082#4082110000000000"}) << "0x1019 > 0 needs the counter";
  Drive p(Drive::permissive());
  p.start();
  p.out.clear();
  p.sync("080#01");
  EXPECT_TRUE(p.sent(0x082).empty());
}

// The soak (issue 28) checks the master's SYNC counter through this count:
// 1 .. 0x1019 then 1 again, every step +1; a jump, 0 or a value past 0x1019
// is counted (the SYNC is still processed); the first after a reset is taken
// as it is.
TEST(EmulatorStrict, SyncCounterSequenceChecked) {
  Drive s(Drive::strict());
  ASSERT_EQ(s.write(0x1019, 0, 3, 1), 0u);
  s.start();
  const auto syncs = s.emu.counters().syncs;
  for (const char* f : {"080#02", "080#03", "080#01", "080#02", "080#03", "080#01"}) s.sync(f);
  EXPECT_EQ(s.emu.counters().sync_counter_errors, 0u) << "starts anywhere, wraps after 3";
  EXPECT_EQ(s.emu.counters().syncs, syncs + 6);
  s.sync("080#03");  // 2 skipped
  EXPECT_EQ(s.emu.counters().sync_counter_errors, 1u);
  s.sync("080#01");  // after 3: 1, fine
  s.sync("080#01");  // repeated
  EXPECT_EQ(s.emu.counters().sync_counter_errors, 2u);
  s.sync("080#04");  // past 0x1019
  s.sync("080#00");  // 0 is never a counter value
  EXPECT_EQ(s.emu.counters().sync_counter_errors, 4u);
  EXPECT_EQ(s.emu.counters().syncs, syncs + 11) << "counted, still processed";
  s.feed(fbtest::frame("000#8202"));  // reset communication: 0x1019 back to 0, the sequence starts again
  ASSERT_EQ(s.write(0x1019, 0, 3, 1), 0u);
  s.start();
  const auto before = s.emu.counters().syncs;
  s.sync("080#02");
  s.sync("080#03");
  EXPECT_EQ(s.emu.counters().syncs, before + 2);
  EXPECT_EQ(s.emu.counters().sync_counter_errors, 4u);
}

TEST(EmulatorStrict, ErrorBehaviour1029OnLostMasterHeartbeat) {
  for (const int behaviour : {0, 1, 2}) {
    SCOPED_TRACE(behaviour);
    EmulatorConfig c;
    c.behaviour.optional_objects_absent = false;  // 0x1016 present
    c.heartbeat_loss_reaction = emulator::HeartbeatLossReaction::kNone;
    Drive d(c);
    ASSERT_EQ(d.write(0x1016, 1, (1u << 16) | 10, 4), 0u);
    ASSERT_EQ(d.write(0x1029, 1, static_cast<std::uint32_t>(behaviour), 1), 0u);
    d.start();
    d.feed(fbtest::frame("701#05"));
    for (int i = 0; i < 15; ++i) d.advance();
    const canopen::NmtState want = behaviour == 0   ? canopen::NmtState::kPreOperational
                                   : behaviour == 1 ? canopen::NmtState::kOperational
                                                    : canopen::NmtState::kStopped;
    EXPECT_EQ(d.emu.nmt_state(), want);
  }
  Drive p(Drive::permissive());
  std::uint32_t v = 0;
  EXPECT_EQ(p.read(0x1029, 1, v), kNoObject);
}

TEST(EmulatorStrict, BootStaysNotReadyToSwitchOnWhileTheDcBusCharges) {
  EmulatorConfig c;
  c.behaviour.boot_ns = 50 * kMs;
  Drive d(c);
  d.start();
  d.out.clear();
  d.sync();
  EXPECT_EQ(d.sent(0x182), std::vector<std::string>{"182#0002"}) << "Not ready to switch on, remote";
  d.write(0x6040, 0, 0x0006, 2);
  for (int i = 0; i < 40; ++i) d.sync();
  EXPECT_EQ(d.emu.state(), State::kNotReadyToSwitchOn);
  for (int i = 0; i < 15; ++i) d.sync();
  EXPECT_EQ(d.emu.state(), State::kReadyToSwitchOn) << "transition 1 after 50 ms, then the held Shutdown (2)";
  Drive p(Drive::permissive());
  EXPECT_EQ(p.emu.state(), State::kSwitchOnDisabled);
}

TEST(EmulatorStrict, SdoReplyNotInTheSameCall) {
  Drive s(Drive::strict());
  s.out.clear();
  s.feed(fbtest::frame("602#4000100000000000"));
  s.emu.step(s.t, s.out);  // the same call (time) as the request
  EXPECT_TRUE(s.sent(0x582).empty());
  s.advance(1);
  EXPECT_EQ(s.sent(0x582), std::vector<std::string>{"582#4300100092010200"});
  EmulatorConfig c;
  c.behaviour.sdo_reply_delay_ns = 5 * kMs;
  Drive slow(c);
  slow.out.clear();
  slow.feed(fbtest::frame("602#4000100000000000"));
  slow.advance(4 * kMs);
  EXPECT_TRUE(slow.sent(0x582).empty());
  slow.advance(kMs);
  EXPECT_EQ(slow.sent(0x582).size(), 1u);
  Drive p(Drive::permissive());
  p.out.clear();
  p.feed(fbtest::frame("602#4000100000000000"));
  EXPECT_EQ(p.sent(0x582).size(), 1u);
}

TEST(EmulatorStrict, RemoteBitConfigurableAndLocalControlIgnoresTheBus) {
  EmulatorConfig c;
  c.remote = false;
  Drive d(c);
  d.boot();
  EXPECT_EQ(d.emu.statusword() & cia402::sw::kRemote, 0);
  EXPECT_FALSE(d.command(0x0006, State::kReadyToSwitchOn));
  d.emu.set_remote(true);
  EXPECT_NE(d.emu.statusword() & cia402::sw::kRemote, 0);
  EXPECT_TRUE(d.command(0x0006, State::kReadyToSwitchOn));
}

TEST(EmulatorStrict, TransitionsThreeAndFourInTwoSyncs) {
  Drive s(Drive::strict());
  s.boot();
  s.start();
  ASSERT_TRUE(s.command(0x0006, State::kReadyToSwitchOn));
  s.write(0x6040, 0, 0x000F, 2);
  EXPECT_EQ(s.emu.state(), State::kSwitchedOn) << "3 only";
  s.sync();
  EXPECT_EQ(s.emu.state(), State::kOperationEnabled) << "4 at the next SYNC";
  Drive p(Drive::permissive());
  p.start();
  p.write(0x6040, 0, 0x0006, 2);
  p.write(0x6040, 0, 0x000F, 2);
  EXPECT_EQ(p.emu.state(), State::kOperationEnabled) << "permissive: 3 and 4 in one call";
}

// The CiA 402 application does not depend on the NMT state (CiA 301: NMT
// gates communication objects): in pre-operational a controlword written over
// SDO goes on from 3 to 4 at the next SYNC, and 0x6061 follows 0x6060. Found
// by tests/peers/conformance.py against cia402-emu (vcan.peer.conformance_emu):
// the strict drive stopped in Switched on and kept showing the old mode.
TEST(EmulatorStrict, ApplicationRunsInPreOperational) {
  Drive s(Drive::strict());
  s.boot();
  ASSERT_EQ(s.emu.nmt_state(), canopen::NmtState::kPreOperational);
  ASSERT_TRUE(s.command(0x0006, State::kReadyToSwitchOn));
  s.write(0x6040, 0, 0x000F, 2);
  EXPECT_EQ(s.emu.state(), State::kSwitchedOn) << "3 only";
  s.sync();
  EXPECT_EQ(s.emu.state(), State::kOperationEnabled) << "4 at the next SYNC, in pre-operational";
  ASSERT_TRUE(s.command(0x0000, State::kSwitchOnDisabled));
  ASSERT_EQ(s.write(0x6060, 0, 0, 1), 0u);
  for (int i = 0; i < 3; ++i) s.sync();
  EXPECT_EQ(s.emu.mode_display(), 0) << "0x6061 follows 0x6060 = 0 in pre-operational";
  ASSERT_EQ(s.write(0x6060, 0, 8, 1), 0u);
  for (int i = 0; i < 3; ++i) s.sync();
  EXPECT_EQ(s.emu.mode_display(), 8);
}

TEST(EmulatorStrict, FaultResetRefusedWhileTheCauseRemains) {
  Drive s(Drive::strict());
  s.boot();
  s.start();
  s.emu.inject_fault(0x2310);
  s.sync();
  s.sync();
  ASSERT_EQ(s.emu.state(), State::kFault);
  s.write(0x6040, 0, 0x0000, 2);
  s.write(0x6040, 0, 0x0080, 2);  // within 20 SYNCs: refused
  s.sync();
  EXPECT_EQ(s.emu.state(), State::kFault);
  EXPECT_EQ(s.emu.counters().refused_fault_resets, 1u);
  for (int i = 0; i < 20; ++i) s.sync();
  EXPECT_TRUE(s.command(0x0000, State::kFault));
  EXPECT_TRUE(s.command(0x0080, State::kSwitchOnDisabled)) << "the cause has gone";
  // Held cause (e.g. DC bus under-voltage): refused until released.
  s.emu.hold_fault_cause(true);
  s.emu.inject_fault(0x3220);
  for (int i = 0; i < 30; ++i) s.sync();
  EXPECT_TRUE(s.command(0x0000, State::kFault));
  EXPECT_FALSE(s.command(0x0080, State::kSwitchOnDisabled));
  s.emu.hold_fault_cause(false);
  EXPECT_TRUE(s.command(0x0000, State::kFault));
  EXPECT_TRUE(s.command(0x0080, State::kSwitchOnDisabled));
  // Permissive: at once.
  Drive p(Drive::permissive());
  p.start();
  p.emu.inject_fault(0x2310);
  p.sync();
  p.sync();
  EXPECT_TRUE(p.command(0x0000, State::kFault));
  EXPECT_TRUE(p.command(0x0080, State::kSwitchOnDisabled, 1));
}

TEST(EmulatorStrict, ModeSwitchDelayedAndUnsupportedModesRefused) {
  EmulatorConfig c;
  c.supported_modes = cia402::supported_mode_bit(cia402::Mode::kCsp) | cia402::supported_mode_bit(cia402::Mode::kHoming);
  Drive s(c);
  s.boot();
  EXPECT_EQ(s.write(0x6060, 0, 9, 1), kInvalidValue) << "CSV is not in 0x6502";
  std::uint32_t v = 0;
  ASSERT_EQ(s.read(0x6502, 0, v), 0u);
  EXPECT_EQ(v, c.supported_modes);
  s.start();
  // Outside Operation enabled an SDO-written mode is taken at once (issue 26
  // item 3: a master may set it before it produces SYNC); 0x6061 shows it.
  ASSERT_EQ(s.write(0x6060, 0, 6, 1), 0u);
  EXPECT_EQ(s.emu.mode_display(), 6);
  ASSERT_EQ(s.read(0x6061, 0, v), 0u);
  EXPECT_EQ(v, 6u);
  ASSERT_EQ(s.write(0x6060, 0, 8, 1), 0u);
  EXPECT_EQ(s.emu.mode_display(), 8);
  // While enabled the switch hands the motion over at the drive's cycle.
  ASSERT_TRUE(s.enable());
  ASSERT_EQ(s.write(0x6060, 0, 6, 1), 0u);
  EXPECT_EQ(s.emu.mode_display(), 8);
  s.sync();
  s.sync();
  EXPECT_EQ(s.emu.mode_display(), 8) << "2 SYNCs later";
  s.sync();
  EXPECT_EQ(s.emu.mode_display(), 6);
  // An RPDO carrying a mode the drive lacks: 0x6061 stays.
  s.feed(fbtest::frame("000#8002"));
  ASSERT_EQ(s.write(0x1400, 1, 0x80000202, 4), 0u);
  ASSERT_EQ(s.write(0x1600, 0, 0, 1), 0u);
  ASSERT_EQ(s.write(0x1600, 1, 0x60600008, 4), 0u);
  ASSERT_EQ(s.write(0x1600, 0, 1, 1), 0u);
  ASSERT_EQ(s.write(0x1400, 1, 0x00000202, 4), 0u);
  s.start();
  s.feed(fbtest::frame("202#0A"));
  for (int i = 0; i < 5; ++i) s.sync();
  EXPECT_EQ(s.emu.mode_display(), 6);
}

namespace {
struct HomingRun {
  int syncs = 0;
  std::uint16_t sw = 0;
  double max_distance = 0;  // farthest from the start
};
HomingRun home(Drive& d, std::int8_t method, std::int32_t offset = 0, int limit = 5000) {
  HomingRun r;
  EXPECT_EQ(d.write(0x6098, 0, static_cast<std::uint8_t>(method), 1), 0u);
  EXPECT_EQ(d.write(0x607C, 0, static_cast<std::uint32_t>(offset), 4), 0u);
  EXPECT_EQ(d.write(0x6060, 0, 6, 1), 0u);
  d.start();
  EXPECT_TRUE(d.enable());
  for (int i = 0; i < 5; ++i) d.sync();  // 0x6061 shows 6
  const double start = d.emu.position_exact();
  d.write(0x6040, 0, 0x001F, 2);  // homing start (bit 4)
  for (; r.syncs < limit; ++r.syncs) {
    d.sync();
    r.sw = d.emu.statusword();
    if ((r.sw & (cia402::sw::kHomingAttained | cia402::sw::kHomingError)) != 0) break;
    r.max_distance = std::max(r.max_distance, std::abs(d.emu.position_exact() - start));  // travel, not the new origin
  }
  return r;
}
EmulatorConfig at(std::int32_t position) {
  EmulatorConfig c;
  c.initial_position = position;
  c.behaviour.boot_ns = 0;
  return c;
}
}  // namespace

TEST(EmulatorStrict, HomingTakesTimePerMethodFamily) {
  {  // 35: current position, no motion, a few SYNCs.
    Drive d(at(5000));
    const HomingRun r = home(d, 35, 77);
    EXPECT_EQ(cia402::decode_homing_status(r.sw), cia402::HomingStatus::kCompleted);
    EXPECT_GE(r.syncs, 2);
    EXPECT_EQ(r.max_distance, 0.0);
    EXPECT_EQ(d.emu.position(), 77);
  }
  {  // 17..30: switch at 0, fast 100000/s then slow back onto the edge.
    Drive d(at(20000));
    const HomingRun r = home(d, 19, 5);
    EXPECT_EQ(cia402::decode_homing_status(r.sw), cia402::HomingStatus::kCompleted);
    EXPECT_GE(r.syncs, 200) << "20000 counts at 100000 counts/s is 200 SYNCs of 1 ms";
    EXPECT_GE(r.max_distance, 20000.0);
    EXPECT_EQ(d.emu.position(), 5);
  }
  {  // 1..14: the switch, then on to the next index pulse (4096) beyond it.
    Drive d(at(20000));
    const HomingRun r17 = home(d, 3);
    EXPECT_EQ(cia402::decode_homing_status(r17.sw), cia402::HomingStatus::kCompleted);
    EXPECT_GE(r17.max_distance, 20000.0 + 4096.0 - 1.0);
  }
  {  // 33/34: index pulse only, slow (10000 counts/s).
    Drive d(at(1000));
    const HomingRun r = home(d, 34);
    EXPECT_EQ(cia402::decode_homing_status(r.sw), cia402::HomingStatus::kCompleted);
    EXPECT_NEAR(r.max_distance, 3096.0, 1.0);
    EXPECT_GE(r.syncs, 300);
  }
  {  // No switch within the travel limit: homing error, stopped.
    EmulatorConfig c = at(20000);
    c.homing_max_travel = 1000;
    Drive d(c);
    const HomingRun r = home(d, 19);
    EXPECT_EQ(cia402::decode_homing_status(r.sw), cia402::HomingStatus::kErrorStopped);
  }
  {  // A method the drive lacks is refused; the permissive drive takes any.
    Drive d(at(0));
    EXPECT_EQ(d.write(0x6098, 0, 36, 1), kInvalidValue);
    EXPECT_EQ(d.write(0x6098, 0, 15, 1), kInvalidValue);
    Drive p(Drive::permissive());
    EXPECT_EQ(p.write(0x6098, 0, 36, 1), 0u);
  }
  {  // Permissive: 35 in one SYNC.
    EmulatorConfig c = Drive::permissive();
    c.initial_position = 5000;
    Drive p(c);
    const HomingRun r = home(p, 35, 77);
    EXPECT_EQ(r.syncs, 0);
    EXPECT_EQ(p.emu.position(), 77);
  }
}

// CiA 301 0x1019 (as CANopenNode's CO_ODF_1019): written only while 0x1006
// is 0 (0x08000022 otherwise), and only 0 or 2..240 (issue 15 item 5).
TEST(EmulatorStrict, SyncCounterOverflowWrittenOnlyWhile1006IsZero) {
  Drive s(Drive::strict());
  ASSERT_EQ(s.write(0x1006, 0, 1000, 4), 0u);
  EXPECT_EQ(s.write(0x1019, 0, 5, 1), kDeviceState);
  EXPECT_EQ(s.emu.read_int(0x1019), 0);
  ASSERT_EQ(s.write(0x1006, 0, 0, 4), 0u);
  EXPECT_EQ(s.write(0x1019, 0, 5, 1), 0u);
  EXPECT_EQ(s.emu.read_int(0x1019), 5);
  ASSERT_EQ(s.write(0x1006, 0, 1000, 4), 0u);  // 0x1006 itself may change at any time
  EXPECT_EQ(s.write(0x1019, 0, 0, 1), kDeviceState);
  // A drive whose 0x1006 is set from power-on (EmulatorConfig::presets).
  EmulatorConfig c = Drive::strict();
  c.presets = {emulator::ObjectPreset{0x1006, 0, 2000}};
  Drive preset(c);
  EXPECT_EQ(preset.emu.read_int(0x1006), 2000);
  EXPECT_EQ(preset.write(0x1019, 0, 5, 1), kDeviceState);
  // A read-only preset.
  c.presets = {emulator::ObjectPreset{0x1019, 0, 5, true}};
  Drive fixed(c);
  EXPECT_EQ(fixed.emu.read_int(0x1019), 5);
  EXPECT_EQ(fixed.write(0x1019, 0, 5, 1), kReadOnly);
  Drive p(Drive::permissive());
  ASSERT_EQ(p.write(0x1006, 0, 1000, 4), 0u);
  EXPECT_EQ(p.write(0x1019, 0, 5, 1), 0u);
}

// The MDS objects at other indices (EmulatorConfig::mds_objects, issue 15
// item 6): served there with their types and checks, nothing at 0x2010..0x2022.
TEST(EmulatorStrict, MdsObjectsServedWhereConfigured) {
  EmulatorConfig c = Drive::strict();
  c.behaviour.optional_objects_absent = false;
  using cia402::MdsObject;
  c.mds_objects[MdsObject::kRampVelocityPositive] = {0x3000, 1};
  c.mds_objects[MdsObject::kRampVelocityNegative] = {0x3000, 2};
  c.mds_objects[MdsObject::kRampJerkControl] = {0x3001, 0};
  c.mds_objects[MdsObject::kSlatConfiguration] = {0x2000, 0};  // the emulator's fault injection object becomes it
  c.mds_objects[MdsObject::kSlatSetPoint] = {0x3011, 0};
  c.mds_objects[MdsObject::kSlatTimeDelay] = {0x3012, 0};
  Drive s(c);
  std::uint32_t v = 0;
  for (const int i : {0x2010, 0x2011, 0x2020, 0x2021, 0x2022})
    EXPECT_EQ(s.read(static_cast<std::uint16_t>(i), 0, v), kNoObject) << std::hex << i;
  ASSERT_EQ(s.read(0x3000, 0, v), 0u);
  EXPECT_EQ(v, 2u) << "the record's highest sub-index";
  EXPECT_EQ(s.write(0x3000, 0, 3, 1), kReadOnly);
  EXPECT_EQ(s.write(0x3000, 1, 60'000, 4), 0u);
  EXPECT_EQ(s.write(0x3000, 2, 60'000, 2), 0x06070013u) << "UNSIGNED32: 2 bytes are too few";
  EXPECT_EQ(s.write(0x3001, 0, 101, 1), 0x06090031u) << "jerk control 0..100";
  EXPECT_EQ(s.write(0x3001, 0, 50, 1), 0u);
  EXPECT_EQ(s.write(0x2000, 0, 3, 1), kInvalidValue) << "SLAT configuration 0..2";
  EXPECT_EQ(s.write(0x2000, 0, 2, 1), 0u);
  EXPECT_EQ(s.write(0x3012, 0, 7, 2), 0u);
  EXPECT_EQ(s.emu.read_int(0x3000, 1), 60'000);
  EXPECT_EQ(s.emu.read_int(0x2000), 2);
  for (int i = 0; i < 3; ++i) s.sync();
  EXPECT_NE(s.emu.state(), State::kFault) << "no fault injected by the SLAT write";
  EXPECT_NE(s.emu.state(), State::kFaultReactionActive);
  EXPECT_EQ(s.emu.counters().emcys, 0u);
  // Strict (optional objects absent): none of them, nowhere.
  c.behaviour.optional_objects_absent = true;
  Drive a(c);
  for (const int i : {0x3000, 0x3001, 0x3011, 0x3012, 0x2010})
    EXPECT_EQ(a.read(static_cast<std::uint16_t>(i), 0, v), kNoObject) << std::hex << i;
}

// Interpolated position mode (issue 30 part 2): 0x60C0 takes 0 (linear) only;
// in mode 7 the 0x60C1:1 set points are followed only while controlword bit
// 4 "enable ip mode" is set in Operation enabled (statusword bit 12 then).
TEST(EmulatorStrict, InterpolatedPositionFollowsTheDataRecordOnlyWithBit4) {
  EmulatorConfig c;
  c.supported_modes |= cia402::supported_mode_bit(cia402::Mode::kInterpolatedPosition);
  Drive s(c);
  s.boot();
  EXPECT_EQ(s.write(0x60C0, 0, 1, 2), kInvalidValue) << "only sub-mode 0 is modelled";
  ASSERT_EQ(s.write(0x60C0, 0, 0, 2), 0u);
  ASSERT_EQ(s.write(0x6060, 0, 7, 1), 0u);
  EXPECT_EQ(s.emu.mode_display(), 7);
  s.start();
  ASSERT_TRUE(s.enable());
  EXPECT_EQ(s.emu.statusword() & cia402::sw::kIpModeActive, 0u) << "bit 4 not set yet";
  ASSERT_EQ(s.write(0x60C1, 1, 5000, 4), 0u);
  for (int i = 0; i < 10; ++i) s.sync();
  EXPECT_EQ(s.emu.position(), 0) << "set points ignored without bit 4";
  ASSERT_EQ(s.write(0x60C1, 1, 0, 4), 0u);
  ASSERT_EQ(s.write(0x6040, 0, 0x001F, 2), 0u);
  s.sync();
  EXPECT_NE(s.emu.statusword() & cia402::sw::kIpModeActive, 0u);
  for (std::uint32_t k = 1; k <= 10; ++k) {  // a ramp of 100 counts per period
    ASSERT_EQ(s.write(0x60C1, 1, 100 * k, 4), 0u);
    s.sync();
  }
  for (int i = 0; i < 60; ++i) s.sync();
  EXPECT_EQ(s.emu.position(), 1000);
  ASSERT_EQ(s.write(0x6040, 0, 0x000F, 2), 0u);  // bit 4 cleared: held, bit 12 clear
  ASSERT_EQ(s.write(0x60C1, 1, 9000, 4), 0u);
  for (int i = 0; i < 20; ++i) s.sync();
  EXPECT_EQ(s.emu.position(), 1000);
  EXPECT_EQ(s.emu.statusword() & cia402::sw::kIpModeActive, 0u);
  EXPECT_EQ(s.emu.state(), State::kOperationEnabled);
}
