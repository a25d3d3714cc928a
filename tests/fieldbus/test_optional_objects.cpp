// Optional boot objects on a strict drive (issue 15 items 5/6, master side):
// 0x1016 from a default, a read-only 0x60C2:2, SLAT 0x2020..0x2022 without
// `direct_control.slat`: each is skipped or falls back, and is said once per
// node and object (DriveProxy::poll_notice -> NodeEvent::kObjectAbsent).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "fieldbus/canopen/master.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/emulator/sim_rig.hpp"

namespace canmotion {
namespace {

using cia402::SdoWrite;
using emulator::SimRig;
using emulator::SimRigConfig;
namespace obj = cia402::obj;

constexpr std::uint8_t kNode = 2;

SimRigConfig one_drive() {
  SimRigConfig c;
  c.nodes = {kNode};
  c.drive.hints.interpolation_period = "controller.period_ms";
  return c;
}

/// The kObjectAbsent events the network gave, in order.
std::vector<canopen::NodeEvent> notices(SimRig& rig) {
  std::vector<canopen::NodeEvent> out;
  canopen::NodeEvent e;
  while (rig.network().poll_event(e))
    if (e.kind == canopen::NodeEvent::Kind::kObjectAbsent) out.push_back(e);
  return out;
}

bool boot(SimRig& rig) {
  return rig.run_until([&] { return rig.network().all_operational() || rig.network().any_failed(); }, 3000) &&
         !rig.network().any_failed();
}

std::size_t count(const std::vector<canopen::NodeEvent>& v, std::uint16_t index, std::uint8_t sub) {
  std::size_t n = 0;
  for (const auto& e : v) n += e.index == index && e.sub == sub ? 1 : 0;
  return n;
}

TEST(OptionalObjects, StrictDriveBootsAndEachFallbackIsSaidOnce) {
  SimRig rig(one_drive());  // strict: no 0x1016, 0x60C2:2 read-only at -3
  rig.power_on();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  std::vector<canopen::NodeEvent> n = notices(rig);
  ASSERT_EQ(count(n, 0x1016, 1), 1u);
  ASSERT_EQ(count(n, obj::kInterpolationTimePeriod, 2), 1u);
  for (const auto& e : n) {
    EXPECT_EQ(e.node, kNode);
    const std::string text = cia402::describe_notice(e);
    EXPECT_NE(text.find("node 2"), std::string::npos) << text;
    if (e.index == 0x1016) {
      EXPECT_EQ(e.abort, static_cast<std::uint32_t>(canopen::SdoAbort::kNoObject));
      EXPECT_NE(text.find("0x1016:1"), std::string::npos) << text;
      EXPECT_NE(text.find("does not watch the master's heartbeat"), std::string::npos) << text;
    } else {
      EXPECT_EQ(e.abort, static_cast<std::uint32_t>(canopen::SdoAbort::kReadOnly));
      EXPECT_EQ(e.detail, -3);
      EXPECT_NE(text.find("0x60C2:2"), std::string::npos) << text;
      EXPECT_NE(text.find("read-only"), std::string::npos) << text;
      EXPECT_NE(text.find("10^-3 s"), std::string::npos) << text;
    }
  }
  EXPECT_EQ(rig.emulator(kNode).read_int(obj::kInterpolationTimePeriod, 1), 1);
  EXPECT_EQ(rig.emulator(kNode).read_int(obj::kInterpolationTimePeriod, 2), -3);
  // Booted again (NMT reset node): the same fallbacks, not said again.
  rig.drive(kNode).reboot_node();
  for (int i = 0; i < 5; ++i) rig.step();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  EXPECT_GE(rig.drive(kNode).tolerated_aborts(), 2u);
  EXPECT_TRUE(notices(rig).empty());
}

TEST(OptionalObjects, DriveWithConsumerHeartbeatGetsItWritten) {
  SimRigConfig c = one_drive();
  c.emulator.behaviour.optional_objects_absent = false;
  c.emulator.behaviour.ip_index_read_only = false;
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  EXPECT_EQ(rig.emulator(kNode).read_int(0x1016, 1), (127 << 16) | 300);
  EXPECT_TRUE(notices(rig).empty());
}

TEST(OptionalObjects, ConsumerHeartbeatAskedForByTheConfigurationIsRequired) {
  SimRigConfig c = one_drive();
  c.drive.consumer_heartbeat_optional = false;  // canmotiond: master_heartbeat_timeout_ms set in the file
  c.drive.hints.consumer_heartbeat = "axes[0].drive.master_heartbeat_timeout_ms";
  SimRig rig(c);
  rig.power_on();
  ASSERT_FALSE(boot(rig));
  const std::string why = rig.drive(kNode).failure().to_string();
  EXPECT_NE(why.find("0x1016:1"), std::string::npos) << why;
  EXPECT_NE(why.find("master_heartbeat_timeout_ms"), std::string::npos) << why;
}

TEST(OptionalObjects, ReadOnlyIpIndexGetsThePeriodInTheDrivesUnit) {
  SimRigConfig c = one_drive();
  c.cycle_ns = 10'000'000;  // 10 ms: the master's encoding is 1 x 10^-2 s, the drive takes only 10^-3 s
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
  EXPECT_EQ(rig.emulator(kNode).read_int(obj::kInterpolationTimePeriod, 1), 10);
  EXPECT_EQ(rig.emulator(kNode).read_int(obj::kInterpolationTimePeriod, 2), -3);
}

TEST(OptionalObjects, PeriodTheDrivesUnitCannotExpressFailsNamingObjectValueAndPeriod) {
  SimRigConfig c = one_drive();
  c.cycle_ns = 500'000;  // 0.5 ms: 5 x 10^-4 s; the drive's unit is 1 ms
  SimRig rig(c);
  rig.power_on();
  ASSERT_TRUE(rig.run_until([&] { return rig.network().any_failed(); }, 3000));
  const cia402::Failure& f = rig.drive(kNode).failure();
  EXPECT_EQ(f.kind, cia402::FailureKind::kBootCheck);
  EXPECT_EQ(f.check, cia402::BootCheck::kInterpolationIndex);
  const std::string why = f.to_string();
  EXPECT_NE(why.find("node 2"), std::string::npos) << why;
  EXPECT_NE(why.find("0x60C2:2"), std::string::npos) << why;
  EXPECT_NE(why.find("read-only at -3"), std::string::npos) << why;
  EXPECT_NE(why.find("0.5 ms"), std::string::npos) << why;
  EXPECT_NE(why.find("controller.period_ms"), std::string::npos) << why;
}

/// The SDO frames of the 0x60C2 fallback, byte for byte (CiA 301 expedited
/// transfers): download :2 = -3... refused, upload :2, download :1 in ms.
TEST(OptionalObjects, IpFallbackGoldenSdoBytes) {
  SimRigConfig c = one_drive();
  c.cycle_ns = 4'000'000;  // 4 ms: 4 x 10^-3 s, 0x60C2:2 written as -3 and refused read-only
  SimRig rig(c);
  can::SimBus::Endpoint& spy = rig.bus().add_endpoint("spy");
  std::vector<std::string> sdo;
  std::array<can::TimedFrame, 256> buf{};
  rig.power_on();
  for (int i = 0; i < 400 && !rig.network().all_operational(); ++i) {
    rig.step();
    for (std::size_t k; (k = spy.receive(buf)) > 0;)
      for (std::size_t j = 0; j < k; ++j) {
        const can::Frame& f = buf[j].frame;
        if ((f.id != 0x600u + kNode && f.id != 0x580u + kNode) || f.len != 8 || f.data[1] != 0xC2 || f.data[2] != 0x60)
          continue;
        char s[40];
        std::snprintf(s, sizeof s, "%03X#%02X%02X%02X%02X%02X%02X%02X%02X", f.id, f.data[0], f.data[1], f.data[2],
                      f.data[3], f.data[4], f.data[5], f.data[6], f.data[7]);
        sdo.emplace_back(s);
      }
  }
  ASSERT_TRUE(rig.network().all_operational()) << rig.drive(kNode).failure().to_string();
  const std::vector<std::string> golden = {
      "602#2FC2600104000000",  // download 0x60C2:1 = 4
      "582#60C2600100000000",  //   confirmed
      "602#2FC26002FD000000",  // download 0x60C2:2 = -3
      "582#80C2600202000106",  //   abort 0x06010002 (read-only)
      "602#40C2600200000000",  // upload 0x60C2:2
      "582#4FC26002FD000000",  //   -3 (1 byte)
      "602#2FC2600104000000",  // download 0x60C2:1 = 4 (ms, the drive's unit)
      "582#60C2600100000000",  //   confirmed
  };
  EXPECT_EQ(sdo, golden);
}

TEST(OptionalObjects, OptionalExtraWriteSkippedRequiredOneNamesItsKey) {
  {
    SimRigConfig c = one_drive();
    SdoWrite slat{obj::kSlatConfiguration, 0, 1, 0};
    slat.optional = true;  // SLAT disabled from the default (no direct_control.slat)
    c.drive.extra_writes = {slat};
    c.drive.hints.extra = {"axes[0].direct_control.slat.configuration"};
    SimRig rig(c);
    rig.power_on();
    ASSERT_TRUE(boot(rig)) << rig.drive(kNode).failure().to_string();
    const std::vector<canopen::NodeEvent> n = notices(rig);
    ASSERT_EQ(count(n, obj::kSlatConfiguration, 0), 1u);
    for (const auto& e : n)
      if (e.index == obj::kSlatConfiguration) {
        const std::string text = cia402::describe_notice(e);
        EXPECT_NE(text.find("0x2020:0"), std::string::npos) << text;
        EXPECT_NE(text.find("no SLAT"), std::string::npos) << text;
      }
  }
  {
    SimRigConfig c = one_drive();
    c.drive.extra_writes = {SdoWrite{obj::kRampVelocityLimit, obj::kRampVelocityPositiveSub, 4, 1000}};
    c.drive.hints.extra = {"axes[0].direct_control.ramp.velocity_positive"};
    SimRig rig(c);
    rig.power_on();
    ASSERT_FALSE(boot(rig));
    const std::string why = rig.drive(kNode).failure().to_string();
    EXPECT_NE(why.find("0x2010:1"), std::string::npos) << why;
    EXPECT_NE(why.find("direct_control.ramp.velocity_positive"), std::string::npos) << why;
  }
}

}  // namespace
}  // namespace canmotion
