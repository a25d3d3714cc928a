// Optional boot objects on a strict drive (issue 15 items 5/6, master side):
// 0x1016 from a default, a read-only 0x60C2:2, SLAT 0x2020..0x2022 without
// `direct_control.slat`: each is skipped or falls back, and is said once per
// node and object (DriveProxy::poll_notice -> NodeEvent::kObjectAbsent).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "fieldbus/canopen/device_dictionary.hpp"
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

/// The SDO frames of node 2 about 0x60C2 while the rig boots, as "ID#DATA".
/// The SDO frames (8 bytes) to and from kNode about the objects in
/// [lo, hi], in order, until the drive is operational or failed.
std::vector<std::string> sdo_frames(SimRig& rig, std::uint16_t lo, std::uint16_t hi);

std::vector<std::string> ip_sdo_frames(SimRig& rig) { return sdo_frames(rig, 0x60C2, 0x60C2); }

std::vector<std::string> sdo_frames(SimRig& rig, std::uint16_t lo, std::uint16_t hi) {
  can::SimBus::Endpoint& spy = rig.bus().add_endpoint("spy");
  std::vector<std::string> sdo;
  std::array<can::TimedFrame, 256> buf{};
  rig.power_on();
  for (int i = 0; i < 400 && !rig.network().all_operational() && !rig.network().any_failed(); ++i) {
    rig.step();
    for (std::size_t k; (k = spy.receive(buf)) > 0;)
      for (std::size_t j = 0; j < k; ++j) {
        const can::Frame& f = buf[j].frame;
        const auto index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
        if ((f.id != 0x600u + kNode && f.id != 0x580u + kNode) || f.len != 8 || index < lo || index > hi) continue;
        char s[40];
        std::snprintf(s, sizeof s, "%03X#%02X%02X%02X%02X%02X%02X%02X%02X", f.id, f.data[0], f.data[1], f.data[2],
                      f.data[3], f.data[4], f.data[5], f.data[6], f.data[7]);
        sdo.emplace_back(s);
      }
  }
  return sdo;
}

/// The SDO frames of the 0x60C2 fallback, byte for byte (CiA 301 expedited
/// transfers): download :2 = -3... refused, upload :2, download :1 in ms.
TEST(OptionalObjects, IpFallbackGoldenSdoBytes) {
  SimRigConfig c = one_drive();
  c.cycle_ns = 4'000'000;  // 4 ms: 4 x 10^-3 s, 0x60C2:2 written as -3 and refused read-only
  SimRig rig(c);
  const std::vector<std::string> sdo = ip_sdo_frames(rig);
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

/// A drive description with these sub-objects (the master asks it only
/// about 0x60C2:2 and optional objects, and for names).
std::shared_ptr<const canopen::DeviceDictionary> dictionary(std::vector<canopen::DeviceDictionary::Entry> entries) {
  return std::make_shared<const canopen::DeviceDictionary>(std::move(entries), "test.eds");
}

// The drive's EDS has 0x60C2:2 read-only: the master does not make the
// write the drive would refuse; it reads the index at once and writes
// 0x60C2:1 in the drive's unit. The notice says why, by the EDS's name.
TEST(OptionalObjects, EdsReadOnlyIpIndexIsReadNotWritten) {
  SimRigConfig c = one_drive();
  c.cycle_ns = 4'000'000;
  c.drive.dictionary = dictionary({{0x60C2, 1, canopen::DataType::kUnsigned8, canopen::Access::kRw, "Zeitraster Wert"},
                                   {0x60C2, 2, canopen::DataType::kInteger8, canopen::Access::kRo, "Zeitraster Exponent"}});
  SimRig rig(c);  // strict: 0x60C2:2 read-only at -3
  const std::vector<std::string> sdo = ip_sdo_frames(rig);
  ASSERT_TRUE(rig.network().all_operational()) << rig.drive(kNode).failure().to_string();
  const std::vector<std::string> golden = {
      "602#2FC2600104000000",  // download 0x60C2:1 = 4
      "582#60C2600100000000",  //   confirmed
      "602#40C2600200000000",  // upload 0x60C2:2 (no download: read-only in the EDS)
      "582#4FC26002FD000000",  //   -3 (1 byte)
      "602#2FC2600104000000",  // download 0x60C2:1 = 4 (ms, the drive's unit)
      "582#60C2600100000000",  //   confirmed
  };
  EXPECT_EQ(sdo, golden);
  const std::vector<canopen::NodeEvent> n = notices(rig);
  ASSERT_EQ(count(n, obj::kInterpolationTimePeriod, 2), 1u);
  for (const auto& e : n) {
    if (e.index != obj::kInterpolationTimePeriod) continue;
    EXPECT_EQ(e.abort, 0u);
    EXPECT_EQ(e.detail, -3);
    const std::string text = cia402::describe_notice(e, c.drive.dictionary.get());
    EXPECT_NE(text.find("0x60C2:2 (Zeitraster Exponent) read-only in the drive's EDS (not written)"), std::string::npos)
        << text;
    EXPECT_NE(text.find("10^-3 s"), std::string::npos) << text;
    // Without the dictionary: CiA 402's name.
    EXPECT_NE(cia402::describe_notice(e).find("0x60C2:2 (Interpolation time period: index)"), std::string::npos);
  }
}

// The drive's EDS has no 0x60C2:2: neither written nor read (the drive
// keeps its own unit; the configuration check warned).
TEST(OptionalObjects, EdsWithoutIpIndexNeitherWritesNorReadsIt) {
  SimRigConfig c = one_drive();
  c.cycle_ns = 4'000'000;
  c.drive.dictionary = dictionary({{0x60C2, 1, canopen::DataType::kUnsigned8, canopen::Access::kRw, ""}});
  SimRig rig(c);
  const std::vector<std::string> sdo = ip_sdo_frames(rig);
  ASSERT_TRUE(rig.network().all_operational()) << rig.drive(kNode).failure().to_string();
  const std::vector<std::string> golden = {"602#2FC2600104000000", "582#60C2600100000000"};
  EXPECT_EQ(sdo, golden);
}

// Failure texts name objects by the drive's EDS where it has a name (what
// canmotionctl status and canmotiond show), by CiA 301/402 otherwise.
TEST(OptionalObjects, FailuresNameObjectsByTheDrivesEds) {
  {
    SimRigConfig c = one_drive();
    c.drive.identity.has_vendor_id = true;
    c.drive.identity.vendor_id = 0x1234;
    c.drive.dictionary = dictionary({{0x1018, 1, canopen::DataType::kUnsigned32, canopen::Access::kRo, "Hersteller-ID"}});
    SimRig rig(c);
    rig.power_on();
    ASSERT_TRUE(rig.run_until([&] { return rig.network().any_failed(); }, 3000));
    const std::string why = rig.drive(kNode).failure().to_string();
    EXPECT_NE(why.find("identity 0x1018:1 (Hersteller-ID) is 0x"), std::string::npos) << why;
  }
  {
    SimRigConfig c = one_drive();
    c.drive.extra_writes = {SdoWrite{0x2100, 0, 4, 7}};
    c.drive.hints.extra = {"axes[0].drive.sdo_writes[0]"};
    c.drive.dictionary = dictionary({{0x2100, 0, canopen::DataType::kUnsigned32, canopen::Access::kRw, "Acme gain"}});
    SimRig rig(c);
    rig.power_on();
    ASSERT_TRUE(rig.run_until([&] { return rig.network().any_failed(); }, 3000));
    const std::string why = rig.drive(kNode).failure().to_string();
    EXPECT_NE(why.find("configuration write to 0x2100:0 (Acme gain) aborted with 0x06020000"), std::string::npos) << why;
    cia402::Failure plain = rig.drive(kNode).failure();
    plain.dictionary = nullptr;
    EXPECT_NE(plain.to_string().find("0x2100:0 (an object canmotion does not know)"), std::string::npos)
        << plain.to_string();
  }
}

}  // namespace
}  // namespace canmotion

namespace canmotion {
namespace {

// Drive units read at boot (README "Drive units"; DriveUnits::read_at_boot):
// 0x60A8, 0x608F:1/2, 0x6091:1/2, 0x6092:1/2, 0x60A9, 0x60AA, byte for byte. The strict drive
// has none of them: each abort is taken, the drive works in increments, and
// the two unit objects are said once each.
TEST(OptionalObjects, DriveUnitsReadAtBootFromADriveWithoutThem) {
  SimRigConfig c = one_drive();
  c.drive.units.read_at_boot = true;
  c.drive.units.velocity_needed_by = "axes[0].direct_control (MDS in CSV)";
  SimRig rig(c);
  const std::vector<std::string> sdo = sdo_frames(rig, 0x608F, 0x60AA);
  ASSERT_TRUE(rig.network().all_operational()) << rig.drive(kNode).failure().to_string();
  const std::vector<std::string> golden = {
      "602#40A8600000000000", "582#80A8600000000206",  // upload 0x60A8: abort 0x06020000
      "602#408F600100000000", "582#808F600100000206",  // 0x608F:1
      "602#408F600200000000", "582#808F600200000206",  // 0x608F:2
      "602#4091600100000000", "582#8091600100000206",  // 0x6091:1
      "602#4091600200000000", "582#8091600200000206",  // 0x6091:2
      "602#4092600100000000", "582#8092600100000206",  // 0x6092:1
      "602#4092600200000000", "582#8092600200000206",  // 0x6092:2
      "602#40A9600000000000", "582#80A9600000000206",  // 0x60A9
      "602#40AA600000000000", "582#80AA600000000206",  // 0x60AA
  };
  EXPECT_EQ(sdo, golden);
  EXPECT_DOUBLE_EQ(rig.drive(kNode).velocity_counts(), 1.0);
  EXPECT_DOUBLE_EQ(rig.drive(kNode).acceleration_counts(), 1.0);
  const std::vector<canopen::NodeEvent> n = notices(rig);
  EXPECT_EQ(count(n, 0x608F, 1) + count(n, 0x6091, 1), 0u);  // quiet: only the units are said
  ASSERT_EQ(count(n, 0x60A9, 0), 1u);
  ASSERT_EQ(count(n, 0x60AA, 0), 1u);
  for (const auto& e : n) {
    if (e.index != 0x60A9) continue;
    EXPECT_NE(cia402::describe_notice(e).find("0x60A9:0 (SI unit velocity) absent (SDO abort 0x06020000"),
              std::string::npos) << cia402::describe_notice(e);
  }
}

// A unit read at boot that nothing needs and canmotiond cannot interpret is
// said once as read, with its code, not as a left-out write.
TEST(OptionalObjects, UninterpretedUnitNothingNeedsIsSaidAsRead) {
  const cia402::BootRow* row = nullptr;
  for (const cia402::BootRow& r : cia402::boot_plan())
    if (r.check == cia402::BootCheck::kVelocityUnit) row = &r;
  ASSERT_NE(row, nullptr);
  cia402::BootWrite w;
  w.row = row;
  w.w.index = 0x60A9;
  canopen::NodeEvent e;
  e.kind = canopen::NodeEvent::Kind::kObjectAbsent;
  e.node = kNode;
  e.index = 0x60A9;
  e.detail = static_cast<std::int32_t>(0xFD010300u);  // mm/s: not interpreted here
  e.note = cia402::boot_note_id(w, cia402::Fallback::kHeld);
  EXPECT_TRUE(cia402::boot_note_of_read(e.note));
  EXPECT_EQ(cia402::describe_notice(e),
            "node 2: 0x60A9:0 (SI unit velocity) read at boot: its velocity unit 0xFD010300 is not one canmotiond "
            "interprets; nothing configured needs it, so velocities of this axis are not shown");
}

}  // namespace
}  // namespace canmotion
