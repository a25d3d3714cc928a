// The drives' SYNC consumer objects at boot (issue 15 item 5): 0x1006 = 0,
// then 0x1019 = the master's SYNC counter overflow value, then (with
// DriveConfig::sync_watch) 0x1006 = the period. A strict drive (its SYNC
// length checked against 0x1019, 0x1019 refused with 0x08000022 while its
// 0x1006 is not 0, as CANopenNode's CO_ODF_1019) then takes every SYNC of a
// master whose SYNC carries a counter; a drive without the objects boots and
// each is said once; a read-only 0x1019 with another value fails the boot
// naming node, object, abort and the YAML key.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/master.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/emulator/sim_rig.hpp"
#include "test_support.hpp"

namespace canmotion {
namespace {

using emulator::ObjectPreset;
using emulator::SimRig;
using emulator::SimRigConfig;

constexpr std::uint8_t kNode = 2;
constexpr const char* kCounterKey = "buses[0].sync_counter_overflow";

SimRigConfig one_drive(std::uint8_t counter) {
  SimRigConfig c;
  c.nodes = {kNode};
  c.master.sync_counter_overflow = counter;
  c.drive.hints.sync_counter = kCounterKey;
  c.drive.hints.sync_watch = "axes[0].drive.sync_watch";
  return c;
}

bool boot(SimRig& rig) {
  return rig.run_until([&] { return rig.network().all_operational() || rig.network().any_failed(); }, 3000) &&
         !rig.network().any_failed();
}

std::vector<canopen::NodeEvent> events(SimRig& rig) {
  std::vector<canopen::NodeEvent> out;
  canopen::NodeEvent e;
  while (rig.network().poll_event(e)) out.push_back(e);
  return out;
}

std::size_t notices_of(const std::vector<canopen::NodeEvent>& v, std::uint16_t index) {
  std::size_t n = 0;
  for (const auto& e : v) n += e.kind == canopen::NodeEvent::Kind::kObjectAbsent && e.index == index ? 1 : 0;
  return n;
}

/// The boot's SDO frames (requests and responses) of 0x1006 and 0x1019, in bus order.
std::vector<std::string> sync_object_sdo(SimRig& rig, can::SimBus::Endpoint& spy, int cycles) {
  std::vector<std::string> sdo;
  std::array<can::TimedFrame, 256> buf{};
  for (int i = 0; i < cycles && !rig.network().all_operational() && !rig.network().any_failed(); ++i) {
    rig.step();
    for (std::size_t k; (k = spy.receive(buf)) > 0;)
      for (std::size_t j = 0; j < k; ++j) {
        const can::Frame& f = buf[j].frame;
        if ((f.id != 0x600u + kNode && f.id != 0x580u + kNode) || f.len != 8 || f.data[2] != 0x10 ||
            (f.data[1] != 0x06 && f.data[1] != 0x19))
          continue;
        sdo.push_back(fbtest::hex(f));
      }
  }
  return sdo;
}

TEST(SyncObjects, CounterOnAStrictDriveEverySyncTakenAndMotionFollows) {
  SimRigConfig c = one_drive(10);
  c.nodes = {2, 3};
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(boot(rig)) << rig.drive(2).failure().to_string() << " / " << rig.drive(3).failure().to_string();
  // Until 0x1019 is written the drive drops the SYNCs with a counter (EMCY
  // 8240h once, 0000h when they fit): from the configuration on, none.
  (void)events(rig);
  std::array<std::uint64_t, 2> dropped{rig.emulator(2).counters().sync_length_errors,
                                        rig.emulator(3).counters().sync_length_errors};
  std::array<std::uint64_t, 2> taken{rig.emulator(2).counters().syncs, rig.emulator(3).counters().syncs};
  const std::uint64_t booted = rig.cycles();
  for (const std::uint8_t n : {std::uint8_t{2}, std::uint8_t{3}}) {
    EXPECT_EQ(rig.emulator(n).read_int(cia402::obj::kSyncCounterOverflow), 10) << int{n};
    EXPECT_EQ(rig.emulator(n).read_int(cia402::obj::kCommunicationCyclePeriod), 0) << "sync_watch is off";
  }
  rig.network().enable_all();
  ASSERT_TRUE(rig.run_until([&] { return rig.network().all_enabled(); }, 2000)) << rig.drive(2).failure().to_string();
  // A ramp of 20 counts per cycle for 500 cycles on both drives.
  const std::int64_t p2 = rig.drive(2).feedback().position, p3 = rig.drive(3).feedback().position;
  for (int i = 1; i <= 500; ++i) {
    rig.drive(2).set_target_position(p2 + 20 * i);
    rig.drive(3).set_target_position(p3 - 20 * i);
    rig.step();
  }
  for (int i = 0; i < 20; ++i) rig.step();
  EXPECT_NEAR(static_cast<double>(rig.emulator(2).position_counts() - p2), 10'000, 2);
  EXPECT_NEAR(static_cast<double>(rig.emulator(3).position_counts() - p3), -10'000, 2);
  for (const std::uint8_t n : {std::uint8_t{2}, std::uint8_t{3}}) {
    const emulator::EmulatorCounters& k = rig.emulator(n).counters();
    EXPECT_EQ(k.sync_length_errors, dropped[n - 2u]) << int{n};
    EXPECT_EQ(k.sync_counter_errors, 0u) << "the counter ran 1..10 and wrapped, node " << int{n};
    EXPECT_EQ(k.syncs - taken[n - 2u], rig.cycles() - booted) << "every SYNC since the boot, node " << int{n};
  }
  for (const canopen::NodeEvent& e : events(rig)) {
    if (e.kind == canopen::NodeEvent::Kind::kEmcy) {
      EXPECT_NE(e.emcy.code, canopen::emcy_code::kUnexpectedSyncLength) << "node " << int{e.node};
    }
  }
  EXPECT_FALSE(rig.network().any_failed());
}

TEST(SyncObjects, GoldenBootFramesZeroThenCounterThenPeriod) {
  {
    SimRigConfig c = one_drive(5);
    c.cycle_ns = 2'000'000;
    c.drive.sync_watch = true;
    SimRig rig(c);
    can::SimBus::Endpoint& spy = rig.bus().add_endpoint("spy");
    rig.power_on();
    const std::vector<std::string> sdo = sync_object_sdo(rig, spy, 1000);
    ASSERT_TRUE(rig.network().all_operational()) << rig.drive(kNode).failure().to_string();
    const std::vector<std::string> golden = {
        "602#2306100000000000",  // download 0x1006 = 0 (4 bytes)
        "582#6006100000000000",  //   confirmed
        "602#2F19100005000000",  // download 0x1019 = 5 (1 byte)
        "582#6019100000000000",  //   confirmed
        "602#23061000D0070000",  // download 0x1006 = 2000 us (sync_watch)
        "582#6006100000000000",  //   confirmed
    };
    EXPECT_EQ(sdo, golden);
    EXPECT_EQ(rig.emulator(kNode).read_int(cia402::obj::kCommunicationCyclePeriod), 2000);
  }
  {
    SimRigConfig c = one_drive(0);  // no counter, no SYNC watch: 0x1006 stays 0
    SimRig rig(c);
    can::SimBus::Endpoint& spy = rig.bus().add_endpoint("spy");
    rig.power_on();
    const std::vector<std::string> sdo = sync_object_sdo(rig, spy, 1000);
    ASSERT_TRUE(rig.network().all_operational()) << rig.drive(kNode).failure().to_string();
    const std::vector<std::string> golden = {"602#2306100000000000", "582#6006100000000000", "602#2F19100000000000",
                                             "582#6019100000000000"};
    EXPECT_EQ(sdo, golden);
  }
}

TEST(SyncObjects, DriveWithout1006And1019BootsEachSaidOnce) {
  SimRigConfig c = one_drive(0);
  c.emulator.absent_objects = {cia402::obj::kCommunicationCyclePeriod, cia402::obj::kSyncCounterOverflow};
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  std::vector<canopen::NodeEvent> ev = events(rig);
  ASSERT_EQ(notices_of(ev, 0x1006), 1u);
  ASSERT_EQ(notices_of(ev, 0x1019), 1u);
  for (const auto& e : ev) {
    if (e.kind != canopen::NodeEvent::Kind::kObjectAbsent || (e.index != 0x1006 && e.index != 0x1019)) continue;
    EXPECT_EQ(e.abort, static_cast<std::uint32_t>(canopen::SdoAbort::kNoObject));
    const std::string text = cia402::describe_notice(e);
    EXPECT_NE(text.find("node 2"), std::string::npos) << text;
    EXPECT_NE(text.find(e.index == 0x1006 ? "0x1006:0" : "0x1019:0"), std::string::npos) << text;
    EXPECT_NE(text.find("absent"), std::string::npos) << text;
    if (e.index == 0x1019) {
      EXPECT_NE(text.find("sync_counter_overflow"), std::string::npos) << text;
    }
  }
  // Booted again: not said again.
  rig.drive(kNode).reboot_node();
  for (int i = 0; i < 5; ++i) rig.step();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  ev = events(rig);
  EXPECT_EQ(notices_of(ev, 0x1006) + notices_of(ev, 0x1019), 0u);
}

TEST(SyncObjects, DriveWith1006SetTakes1019OnlyAfterItIsWrittenZero) {
  // A drive that watches the SYNC from power-on (0x1006 = 1000 us preset).
  SimRigConfig c = one_drive(7);
  c.emulator.presets = {ObjectPreset{0x1006, 0, 1000}};
  {
    // Without the master: the drive refuses 0x1019 while 0x1006 is not 0.
    emulator::EmulatorConfig e = c.emulator;
    e.node = kNode;
    emulator::Emulator emu(e);
    const std::uint8_t seven[1] = {7};
    const std::uint8_t zero[4] = {0, 0, 0, 0};
    EXPECT_EQ(emu.sdo_write(0x1019, 0, seven), canopen::SdoAbort::kDeviceState);
    EXPECT_EQ(emu.read_int(0x1019), 0);
    ASSERT_EQ(emu.sdo_write(0x1006, 0, zero), canopen::SdoAbort::kNone);
    EXPECT_EQ(emu.sdo_write(0x1019, 0, seven), canopen::SdoAbort::kNone);
    EXPECT_EQ(emu.read_int(0x1019), 7);
  }
  // The master writes 0x1006 = 0 first: 0x1019 is taken, every SYNC too.
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  EXPECT_EQ(rig.emulator(kNode).read_int(0x1006), 0);
  EXPECT_EQ(rig.emulator(kNode).read_int(0x1019), 7);
  const std::uint64_t dropped = rig.emulator(kNode).counters().sync_length_errors;  // before 0x1019 was written
  for (int i = 0; i < 100; ++i) rig.step();
  EXPECT_EQ(rig.emulator(kNode).counters().sync_length_errors, dropped);
  EXPECT_EQ(notices_of(events(rig), 0x1019), 0u);
}

TEST(SyncObjects, ReadOnly1019WithAnotherValueFailsNamingNodeObjectAbortAndKey) {
  SimRigConfig c = one_drive(10);
  c.emulator.presets = {ObjectPreset{0x1019, 0, 0, true}};  // fixed: SYNC without counter
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(rig.run_until([&] { return rig.network().any_failed(); }, 3000));
  const cia402::Failure& f = rig.drive(kNode).failure();
  EXPECT_EQ(f.kind, cia402::FailureKind::kBootCheck);
  EXPECT_EQ(f.check, cia402::BootCheck::kSyncCounter);
  EXPECT_EQ(f.sdo_abort, static_cast<std::uint32_t>(canopen::SdoAbort::kReadOnly));
  const std::string why = f.to_string();
  for (const char* part : {"node 2", "0x1019", "0x06010002", "holds 0", "would drop every SYNC", kCounterKey})
    EXPECT_NE(why.find(part), std::string::npos) << part << " in: " << why;
  EXPECT_EQ(rig.drive(kNode).phase(), cia402::Phase::kFailed);
}

TEST(SyncObjects, ReadOnly1019WithTheMastersValueIsFine) {
  SimRigConfig c = one_drive(10);
  c.emulator.presets = {ObjectPreset{0x1019, 0, 10, true}};
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  EXPECT_EQ(rig.emulator(kNode).counters().sync_length_errors, 0u) << "0x1019 fits from power-on";
  for (int i = 0; i < 100; ++i) rig.step();
  EXPECT_EQ(rig.emulator(kNode).counters().sync_length_errors, 0u);
  std::vector<canopen::NodeEvent> ev = events(rig);
  ASSERT_EQ(notices_of(ev, 0x1019), 1u);
  for (const auto& e : ev)
    if (e.kind == canopen::NodeEvent::Kind::kObjectAbsent && e.index == 0x1019) {
      const std::string text = cia402::describe_notice(e);
      EXPECT_NE(text.find("read-only"), std::string::npos) << text;
      EXPECT_NE(text.find("already holds 10"), std::string::npos) << text;
    }
}

TEST(SyncObjects, Refused1019WhileAReadOnly1006WatchesFailsWithTheAbort) {
  // 0x1006 read-only at 1000 us: the zero write is refused (said once), and
  // 0x1019 stays refused with 0x08000022 (CiA 301): it holds 0, the bus wants 5.
  SimRigConfig c = one_drive(5);
  c.emulator.presets = {ObjectPreset{0x1006, 0, 1000, true}};
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(rig.run_until([&] { return rig.network().any_failed(); }, 3000));
  const cia402::Failure& f = rig.drive(kNode).failure();
  const std::string why = f.to_string();
  EXPECT_EQ(f.check, cia402::BootCheck::kSyncCounter) << why;
  for (const char* part : {"node 2", "0x1019", "0x08000022", "present device state", kCounterKey})
    EXPECT_NE(why.find(part), std::string::npos) << part << " in: " << why;
  EXPECT_EQ(notices_of(events(rig), 0x1006), 1u);
}

TEST(SyncObjects, SyncWatchOnADriveWithout1006FailsNamingTheKey) {
  SimRigConfig c = one_drive(0);
  c.drive.sync_watch = true;
  c.emulator.absent_objects = {cia402::obj::kCommunicationCyclePeriod};
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(rig.run_until([&] { return rig.network().any_failed(); }, 3000));
  const std::string why = rig.drive(kNode).failure().to_string();
  for (const char* part : {"node 2", "write to 0x1006:0", "0x06020000", "axes[0].drive.sync_watch"})
    EXPECT_NE(why.find(part), std::string::npos) << part << " in: " << why;
}

/// With drive.sync_watch the drive watches the SYNC at 1.5 x 0x1006 (the
/// emulator as CANopenNode): a master that stalls for more than half a period
/// makes it send EMCY 8100h and leave Operational (0x1029:1 = 0), which is
/// why sync_watch is off by default; without it the same stall is harmless.
TEST(SyncObjects, SyncWatchAStalledMasterTakesTheDriveOutOfOperational) {
  for (const bool watch : {true, false}) {
    SimRigConfig c = one_drive(0);
    c.drive.sync_watch = watch;
    SimRig rig(c);
    rig.power_on();
    ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
    rig.network().enable_all();
    ASSERT_TRUE(rig.run_until([&] { return rig.network().all_enabled(); }, 2000));
    emulator::Emulator& emu = rig.emulator(kNode);
    EXPECT_EQ(emu.read_int(0x1006), watch ? 1000 : 0);
    // The last SYNC came at rig.now_ns(); the master stalls (no frames), the
    // drive's own timers go on.
    const std::int64_t t = rig.now_ns();
    fbtest::VecSink out;
    emu.step(t + 1'500'000, out);  // 1.5 periods: not yet
    EXPECT_EQ(emu.nmt_state(), canopen::NmtState::kOperational);
    emu.step(t + 1'600'000, out);
    std::vector<std::string> emcy;
    for (const can::Frame& f : out.frames)
      if (f.id == 0x080u + kNode) emcy.push_back(fbtest::hex(f));
    if (!watch) {
      EXPECT_TRUE(emcy.empty()) << emcy.size() << " EMCY";
      EXPECT_EQ(emu.nmt_state(), canopen::NmtState::kOperational);
      EXPECT_EQ(emu.counters().sync_timeouts, 0u);
      continue;
    }
    EXPECT_EQ(emcy, std::vector<std::string>{"082#0081110000000000"}) << "EMCY 8100h, error register 0x11";
    EXPECT_EQ(emu.nmt_state(), canopen::NmtState::kPreOperational) << "0x1029:1 = 0";
    EXPECT_EQ(emu.counters().sync_timeouts, 1u);
    // The next SYNC clears it (EMCY 0000h); the NMT state stays until the master starts it again.
    out.clear();
    emu.set_time(t + 1'700'000);
    emu.on_frame(can::TimedFrame{fbtest::frame("080#"), t + 1'700'000}, out);
    emcy.clear();
    for (const can::Frame& f : out.frames)
      if (f.id == 0x080u + kNode) emcy.push_back(fbtest::hex(f));
    EXPECT_EQ(emcy, std::vector<std::string>{"082#0000000000000000"});
  }
}

}  // namespace
}  // namespace canmotion
