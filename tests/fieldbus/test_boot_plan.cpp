// The boot plan (boot_plan.hpp, issue 27 item 1): its rows, and what
// build_boot_transfers makes of them for one drive: the order, the
// configuration's choices (identity, sync_watch, 0x1016, extra writes), what
// the drive's EDS leaves out, which aborts each transfer tolerates, the key
// and sentence that explain a refusal, the note of a fallback. The boot on
// the wire is test_boot_golden.cpp; the fallbacks on an emulated drive are
// test_optional_objects.cpp and test_sync_objects.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fieldbus/canopen/device_dictionary.hpp"
#include "fieldbus/cia402/boot_plan.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion {
namespace {

using cia402::BootWrite;
using cia402::Then;
using cia402::WriteOrigin;
namespace obj = cia402::obj;
using canopen::SdoAbort;

cia402::DriveConfig drive() {
  cia402::DriveConfig d;
  d.node = 2;
  d.hints.interpolation_period = "controller.period_ms";
  d.hints.pdo = "axes[0].drive.pdo";
  d.hints.producer_heartbeat = "axes[0].drive.heartbeat_ms";
  d.hints.consumer_heartbeat = "axes[0].drive.master_heartbeat_timeout_ms";
  d.hints.sync_counter = "buses[0].sync_counter_overflow";
  d.hints.sync_watch = "axes[0].drive.sync_watch";
  return d;
}

std::vector<BootWrite> transfers(const cia402::DriveConfig& d, std::uint8_t sync_counter = 0) {
  canopen::MasterConfig m;
  m.sync_counter_overflow = sync_counter;
  const cia402::DrivePdoSet pdos = cia402::default_drive_pdos(d.pdo_profile, d.node, d.mode);
  return cia402::build_boot_transfers(cia402::BootInputs{d, pdos, m});
}

/// The transfers of index:sub (reads and writes), in order.
std::vector<BootWrite> of(const std::vector<BootWrite>& all, std::uint16_t index, std::uint8_t sub) {
  std::vector<BootWrite> out;
  for (const BootWrite& w : all)
    if (w.w.index == index && w.w.sub == sub) out.push_back(w);
  return out;
}

std::shared_ptr<const canopen::DeviceDictionary> dict(std::vector<canopen::DeviceDictionary::Entry> e) {
  return std::make_shared<const canopen::DeviceDictionary>(std::move(e), "test.eds");
}

TEST(BootPlan, EveryRowExplainsARefusal) {
  for (const cia402::BootRow& r : cia402::boot_plan()) {
    EXPECT_NE(std::strlen(r.hint.without_key), 0u) << std::hex << r.index << ":" << int(r.sub);
    // A sentence that names the key has exactly one %s for it.
    const std::string k = r.hint.with_key;
    const auto s = k.find("%s");
    if (s != std::string::npos) {
      EXPECT_EQ(k.find('%', s + 1), std::string::npos) << k;
    } else {
      EXPECT_EQ(k.find('%'), std::string::npos) << k;
    }
    // A read has a check, and a check its rule.
    if (r.check != cia402::BootCheck::kNone) {
      EXPECT_EQ(r.origin, WriteOrigin::kCheck);
      EXPECT_NE(cia402::boot_check_rule(r.check).verify, nullptr);
      EXPECT_NE(cia402::boot_check_rule(r.check).describe, nullptr);
    }
  }
}

TEST(BootPlan, ReadsFirstWritesThenTheModeReadBack) {
  cia402::DriveConfig d = drive();
  d.identity.has_vendor_id = true;
  d.identity.has_revision = true;
  const std::vector<BootWrite> w = transfers(d);
  ASSERT_GE(w.size(), 6u);
  EXPECT_EQ(w[0].w.index, obj::kDeviceType);
  EXPECT_EQ(w[1].w.index, obj::kIdentity);
  EXPECT_EQ(w[1].w.sub, 1);
  EXPECT_EQ(w[2].w.sub, 3);  // 0x1018:2 not expected: not read
  EXPECT_EQ(w[3].w.index, obj::kSupportedDriveModes);
  EXPECT_TRUE(w[3].is_read());
  EXPECT_EQ(w[4].w.index, obj::kModesOfOperation);
  EXPECT_FALSE(w[4].is_read());
  EXPECT_EQ(w.back().w.index, obj::kModesOfOperationDisplay);
  EXPECT_TRUE(w.back().is_read());
  // Without an identity only 0x1000 is read before 0x6502.
  EXPECT_EQ(transfers(drive())[1].w.index, obj::kSupportedDriveModes);
}

TEST(BootPlan, ConfigurationChoosesTheRows) {
  cia402::DriveConfig d = drive();
  d.consumer_heartbeat_ms = 0;
  EXPECT_TRUE(of(transfers(d), 0x1016, 1).empty());  // 0 leaves 0x1016 out
  d.consumer_heartbeat_ms = 250;
  ASSERT_EQ(of(transfers(d), 0x1016, 1).size(), 1u);
  EXPECT_EQ(of(transfers(d, 0), 0x1016, 1)[0].w.value, (127u << 16) | 250u);
  // 0x1006: 0 always; the period only with sync_watch, after 0x1019.
  EXPECT_EQ(of(transfers(d), obj::kCommunicationCyclePeriod, 0).size(), 1u);
  d.sync_watch = true;
  const std::vector<BootWrite> w = transfers(d, 9);
  const std::vector<BootWrite> p = of(w, obj::kCommunicationCyclePeriod, 0);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].w.value, 0u);
  EXPECT_TRUE(p[0].optional);
  EXPECT_EQ(p[1].w.value, 1000u);  // us
  EXPECT_FALSE(p[1].optional);     // asked for: required
  const std::vector<BootWrite> c = of(w, obj::kSyncCounterOverflow, 0);
  ASSERT_EQ(c.size(), 2u);  // the write, and the read that runs if it is refused
  EXPECT_EQ(c[0].w.value, 9u);
  EXPECT_FALSE(c[0].is_fallback());
  EXPECT_TRUE(c[1].is_read());
  EXPECT_TRUE(c[1].is_fallback());
  EXPECT_EQ(w[static_cast<std::size_t>(c[1].after)].w.index, obj::kSyncCounterOverflow);
  // A counter overflow of 1 is no counter (CiA 301: 0, or 2..240).
  EXPECT_EQ(of(transfers(d, 1), obj::kSyncCounterOverflow, 0)[0].w.value, 0u);
}

TEST(BootPlan, PdosFollowTheCia301Procedure) {
  const std::vector<BootWrite> w = transfers(drive());  // csp: RPDO1 and TPDO1
  std::vector<std::uint16_t> rpdo;
  for (const BootWrite& b : w)
    if (b.origin == WriteOrigin::kPdo && b.w.index < 0x1800) rpdo.push_back(b.w.index);
  ASSERT_GE(rpdo.size(), 5u);
  EXPECT_EQ(rpdo.front(), 0x1400);  // COB-ID invalid first
  EXPECT_EQ(rpdo[1], 0x1600);       // mapping count 0
  EXPECT_EQ(rpdo.back(), 0x1400);   // COB-ID valid last
  // PDOs 2..4 each way written invalid, optional, quiet when absent.
  int unused = 0;
  for (const BootWrite& b : w) {
    if (b.origin != WriteOrigin::kUnusedPdo) continue;
    ++unused;
    EXPECT_TRUE(b.optional);
    EXPECT_NE(b.w.value & canopen::kPdoInvalid, 0u);
    EXPECT_EQ(b.on_abort.of(SdoAbort::kNoObject), Then::kQuiet);
    EXPECT_EQ(b.on_abort.of(SdoAbort::kReadOnly), Then::kFail);
  }
  EXPECT_EQ(unused, 6);
}

TEST(BootPlan, RequiredTransfersFailOnAnAbsentObjectOptionalOnesSayIt) {
  cia402::DriveConfig d = drive();
  cia402::SdoWrite slat{obj::kSlatConfiguration, 0, 1, 0};
  slat.optional = true;
  d.extra_writes = {slat, cia402::SdoWrite{0x2100, 0, 4, 7}};
  d.hints.extra = {"slat", "axes[0].drive.sdo_writes[0]"};
  std::vector<BootWrite> w = transfers(d);
  const BootWrite s = of(w, obj::kSlatConfiguration, 0).at(0);
  EXPECT_TRUE(s.optional);
  EXPECT_EQ(s.on_abort.of(SdoAbort::kNoObject), Then::kNotice);
  EXPECT_EQ(s.on_abort.of(SdoAbort::kNoSubindex), Then::kNotice);
  EXPECT_STREQ(cia402::boot_note(s, cia402::Fallback::kAbsent),
               "the drive has no SLAT: MDS runs without it (direct_control.slat is not set)");
  const BootWrite x = of(w, 0x2100, 0).at(0);
  EXPECT_FALSE(x.optional);
  EXPECT_EQ(x.on_abort.of(SdoAbort::kNoObject), Then::kFail);
  EXPECT_EQ(x.item, 1);
  EXPECT_EQ(*cia402::write_hint_key(d.hints, x), "axes[0].drive.sdo_writes[0]");
  EXPECT_EQ(cia402::boot_note(x, cia402::Fallback::kAbsent), nullptr);  // the default sentence
  // 0x1016 from a default is optional; asked for by the file, required.
  EXPECT_EQ(of(w, 0x1016, 1).at(0).on_abort.of(SdoAbort::kNoObject), Then::kNotice);
  d.consumer_heartbeat_optional = false;
  w = transfers(d);
  EXPECT_EQ(of(w, 0x1016, 1).at(0).on_abort.of(SdoAbort::kNoObject), Then::kFail);
  // No transfer tolerates a timeout but by failing as what it falls back from.
  for (const BootWrite& b : w) {
    const Then t = b.on_abort.of(SdoAbort::kTimeout);
    EXPECT_TRUE(t == Then::kFail || (t == Then::kFailAsTrigger && b.is_fallback())) << std::hex << b.w.index;
  }
}

TEST(BootPlan, IpIndexFallsBackOnARefusalTheEdsDecidesBefore) {
  // No EDS: 0x60C2:2 written; read-only or absent, its index is read and
  // 0x60C2:1 written again (the two fallbacks, in that order).
  std::vector<BootWrite> w = transfers(drive());
  std::vector<BootWrite> ip2 = of(w, obj::kInterpolationTimePeriod, 2);
  ASSERT_EQ(ip2.size(), 2u);
  EXPECT_FALSE(ip2[0].is_read());
  EXPECT_EQ(ip2[0].on_abort.of(SdoAbort::kReadOnly), Then::kFallBack);
  EXPECT_EQ(ip2[0].on_abort.of(SdoAbort::kNoSubindex), Then::kFallBack);
  EXPECT_EQ(ip2[0].on_abort.of(SdoAbort::kInvalidValue), Then::kFail);
  EXPECT_TRUE(ip2[1].is_read());
  EXPECT_EQ(ip2[1].check, cia402::BootCheck::kInterpolationIndex);
  const std::vector<BootWrite> ip1 = of(w, obj::kInterpolationTimePeriod, 1);
  ASSERT_EQ(ip1.size(), 2u);
  EXPECT_FALSE(ip1[0].is_fallback());
  EXPECT_TRUE(ip1[1].is_fallback());
  EXPECT_EQ(ip1[1].after, ip2[1].after);  // both fall back from the write of 0x60C2:2
  // EDS read-only: not written, the fallbacks run at once.
  cia402::DriveConfig d = drive();
  d.dictionary = dict({{0x60C2, 2, canopen::DataType::kInteger8, canopen::Access::kRo, ""}});
  w = transfers(d);
  ip2 = of(w, obj::kInterpolationTimePeriod, 2);
  ASSERT_EQ(ip2.size(), 1u);
  EXPECT_TRUE(ip2[0].is_read());
  EXPECT_EQ(ip2[0].after, BootWrite::kAtOnce);
  EXPECT_EQ(of(w, obj::kInterpolationTimePeriod, 1).size(), 2u);
  // EDS without 0x60C2:2: neither written nor read.
  d.dictionary = dict({{0x60C2, 1, canopen::DataType::kUnsigned8, canopen::Access::kRw, ""}});
  w = transfers(d);
  EXPECT_TRUE(of(w, obj::kInterpolationTimePeriod, 2).empty());
  EXPECT_EQ(of(w, obj::kInterpolationTimePeriod, 1).size(), 1u);
}

TEST(BootPlan, EdsLeavesOutOptionalObjectsItLacksNeverRequiredOnes) {
  cia402::DriveConfig d = drive();
  d.consumer_heartbeat_optional = false;  // 0x1016 asked for: stays although the EDS lacks it
  d.dictionary = dict({{0x60C2, 1, canopen::DataType::kUnsigned8, canopen::Access::kRw, ""}});
  const std::vector<BootWrite> w = transfers(d);
  for (const BootWrite& b : w) EXPECT_FALSE(b.optional) << std::hex << b.w.index << ":" << int(b.w.sub);
  EXPECT_EQ(of(w, 0x1016, 1).size(), 1u);
  EXPECT_TRUE(of(w, obj::kSupportedDriveModes, 0).empty());
  EXPECT_TRUE(of(w, obj::kSyncCounterOverflow, 0).empty());  // the write, and so its fallback read
  EXPECT_EQ(of(w, obj::kDeviceType, 0).size(), 1u);  // required reads stay
}

TEST(BootPlan, KeysAndNotesComeFromTheRows) {
  const cia402::DriveConfig d = drive();
  const std::vector<BootWrite> w = transfers(d, 5);
  for (const BootWrite& b : w) {
    const std::string* k = cia402::write_hint_key(d.hints, b);
    switch (b.origin) {
      case WriteOrigin::kMode: EXPECT_EQ(k, &d.hints.mode) << std::hex << b.w.index; break;  // drive.mode
      case WriteOrigin::kUnusedPdo:
      case WriteOrigin::kCheck: EXPECT_EQ(k, nullptr) << std::hex << b.w.index; break;
      default: ASSERT_NE(k, nullptr) << std::hex << b.w.index; EXPECT_FALSE(k->empty());
    }
  }
  EXPECT_EQ(*cia402::write_hint_key(d.hints, of(w, obj::kSyncCounterOverflow, 0)[0]), "buses[0].sync_counter_overflow");
  const BootWrite read = of(w, obj::kSyncCounterOverflow, 0).at(1);
  EXPECT_STREQ(cia402::boot_note(read, cia402::Fallback::kHeld), "it already holds %d, the master's SYNC counter overflow value");
  EXPECT_EQ(read.on_abort.of(SdoAbort::kDeviceState), Then::kFailAsTrigger);
  const BootWrite zero = of(w, obj::kCommunicationCyclePeriod, 0).at(0);
  EXPECT_STREQ(cia402::boot_note(zero, cia402::Fallback::kReadOnly), "the drive keeps its own SYNC watch period");
  EXPECT_EQ(zero.on_abort.of(SdoAbort::kReadOnly), Then::kNotice);
}

}  // namespace
}  // namespace canmotion

namespace canmotion {
namespace {
// drive.mode: ip (issue 30 part 2): 0x6060 = 7, then 0x60C0 = 0 (INTEGER16,
// optional: a drive without it interpolates linearly), 0x60C1:1 in RPDO1
// where 0x607A is; the same rows in CSP write 8 and no 0x60C0.
TEST(BootPlan, IpModeWritesModeSevenSubModeZeroAndMapsTheDataRecord) {
  cia402::DriveConfig d = drive();
  d.mode = cia402::Mode::kInterpolatedPosition;
  d.hints.mode = "axes[0].drive.mode: ip";
  const std::vector<BootWrite> w = transfers(d);
  std::size_t mode_at = w.size(), sub_at = w.size();
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (w[i].w.index == obj::kModesOfOperation && !w[i].is_read()) mode_at = i;
    if (w[i].w.index == obj::kInterpolationSubModeSelect) sub_at = i;
  }
  ASSERT_LT(mode_at, w.size());
  ASSERT_LT(sub_at, w.size());
  EXPECT_EQ(sub_at, mode_at + 1);
  EXPECT_EQ(w[mode_at].w.value, 7u);
  EXPECT_EQ(w[mode_at].w.size, 1u);
  EXPECT_EQ(w[sub_at].w.value, 0u);
  EXPECT_EQ(w[sub_at].w.size, 2u);
  EXPECT_TRUE(w[sub_at].optional);
  EXPECT_EQ(*cia402::write_hint_key(d.hints, w[sub_at]), "axes[0].drive.mode: ip");
  EXPECT_NE(std::string(cia402::boot_note(w[sub_at], cia402::Fallback::kAbsent)).find("linear interpolation"),
            std::string::npos);
  ASSERT_EQ(of(w, 0x1600, 2).size(), 1u);
  EXPECT_EQ(of(w, 0x1600, 2)[0].w.value, 0x60C10120u);  // 0x60C1:01, 32 bits
  // CSP: 8, no 0x60C0, 0x607A mapped.
  const std::vector<BootWrite> c = transfers(drive());
  EXPECT_TRUE(of(c, obj::kInterpolationSubModeSelect, 0).empty());
  EXPECT_EQ(of(c, 0x1600, 2)[0].w.value, 0x607A0020u);
  // An EDS without 0x60C0: left out (the drive's default, linear, is taken).
  d.dictionary = dict({{0x60C2, 1, canopen::DataType::kUnsigned8, canopen::Access::kRw, ""}});
  EXPECT_TRUE(of(transfers(d), obj::kInterpolationSubModeSelect, 0).empty());
}
}  // namespace
}  // namespace canmotion
