// Issue 29, parts 3 and 4, at the byte level: statusword bits 7, 11, 12, 13
// decoded by mode from TPDO bytes (golden fixtures); 0x6064 unwrapped by
// int32 differences past +-2^31 and 2^32 and re-based at a boot-up; 0x607A
// carrying the low 32 bits of the 64-bit target; the emulator's 0x6064
// wrapping modulo 2^32; in CSP, Operation enabled counted only with bit 12.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/emulator/emulator.hpp"
#include "test_support.hpp"

using namespace canmotion;
using cia402::Mode;
using cia402::State;
using fbtest::frame;
using fbtest::hex;
using fbtest::VecSink;

namespace {

/// Node 3's proxy booted to NMT operational (the SDO configuration answered,
/// then one TPDO1 `first`), as FieldbusGolden.ProxyRpdoAndTpdoBytes does.
struct BootedProxy {
  cia402::DriveNetwork net;
  cia402::DriveProxy* d = nullptr;
  VecSink out;
  std::int64_t t = 0;
  explicit BootedProxy(const std::string& first, std::int64_t transition_timeout_ns = 500'000'000) {
    cia402::DriveConfig dc;
    dc.node = 3;
    dc.producer_heartbeat_ms = 0;
    dc.consumer_heartbeat_ms = 0;
    dc.transition_timeout_ns = transition_timeout_ns;
    d = &net.add_drive(dc);
    net.on_frame(can::TimedFrame{frame("703#00"), 0});
    for (int i = 1; i < 200 && d->phase() != cia402::Phase::kStarting; ++i) {
      out.clear();
      t = i * 1'000'000;
      net.cycle(t, out);
      for (auto& f : out.frames)
        if (f.id == 0x603) {
          const bool upload = f.data[0] == 0x40;
          can::Frame r = frame(upload ? "583#4300000000000000" : "583#6000000000000000");
          r.data[1] = f.data[1], r.data[2] = f.data[2], r.data[3] = f.data[3];
          const auto index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
          const std::uint32_t v = index == 0x1000 ? 0x00020192u : index == 0x6502 ? 0x000003FFu : 8u;
          if (upload)
            for (int k = 0; k < 4; ++k) r.data[4 + k] = static_cast<std::uint8_t>(v >> (8 * k));
          net.on_frame(can::TimedFrame{r, t});
        }
    }
    tpdo(first);
  }
  /// One cycle: TPDO1 `bytes` (statusword, 0x6064; little-endian hex) in, the RPDO1 out.
  std::string tpdo(const std::string& bytes) {
    t += 1'000'000;
    net.on_frame(can::TimedFrame{frame("183#" + bytes), t});
    out.clear();
    net.cycle(t, out);
    for (auto& f : out.frames)
      if (f.id == 0x203) return hex(f);
    return "none";
  }
};

struct BitsCase {
  const char* bytes;  // TPDO1's first two bytes: the statusword, little-endian
  Mode mode;
  cia402::StatusBits want;
  cia402::HomingStatus homing;
};

}  // namespace

// Golden: the statusword bytes as TPDO1 carries them, through the proxy's
// TPDO decoding, then cia402::decode_status_bits() by the mode 0x6061 shows.
TEST(StatuswordGolden, Bits7_11_12_13ByModeFromTpdoBytes) {
  using HS = cia402::HomingStatus;
  const std::vector<BitsCase> cases = {
      // 0x1237: Operation enabled, remote, bit 12
      {"3712", Mode::kCsp, {false, false, true, false}, HS::kAttainedNotReached},
      {"3712", Mode::kCsv, {false, false, true, false}, HS::kAttainedNotReached},
      {"3712", Mode::kCst, {false, false, true, false}, HS::kAttainedNotReached},
      {"3712", Mode::kHoming, {false, false, false, false}, HS::kAttainedNotReached},
      // 0x0237: Operation enabled without bit 12: CSP ignores the target
      {"3702", Mode::kCsp, {false, false, false, false}, HS::kInProgress},
      // 0x12B7: + bit 7 warning (every mode)
      {"B712", Mode::kCsp, {true, false, true, false}, HS::kAttainedNotReached},
      {"B712", Mode::kHoming, {true, false, false, false}, HS::kAttainedNotReached},
      // 0x1A37: + bit 11 internal limit active (every mode)
      {"371A", Mode::kCsp, {false, true, true, false}, HS::kAttainedNotReached},
      {"370A", Mode::kCsv, {false, true, false, false}, HS::kInProgress},
      // 0x3237: bits 12 and 13: CSP following error; CSV/CST bit 13 reserved; homing: invalid
      {"3732", Mode::kCsp, {false, false, true, true}, HS::kInvalid},
      {"3732", Mode::kCsv, {false, false, true, false}, HS::kInvalid},
      {"3732", Mode::kCst, {false, false, true, false}, HS::kInvalid},
      {"3732", Mode::kHoming, {false, false, false, false}, HS::kInvalid},
      // 0x2637: bit 13 + bit 10: homing error (stopped); in PP a following error
      {"3726", Mode::kHoming, {false, false, false, false}, HS::kErrorStopped},
      {"3726", Mode::kProfilePosition, {false, false, false, true}, HS::kErrorStopped},
      // 0x1637: homing completed (bits 12 + 10)
      {"3716", Mode::kHoming, {false, false, false, false}, HS::kCompleted},
      // 0xBEB7: everything at once in CSP
      {"B7BE", Mode::kCsp, {true, true, true, true}, HS::kInvalid},
      // 0x0250: Switch on disabled: no bit set
      {"5002", Mode::kCsp, {false, false, false, false}, HS::kInProgress},
  };
  BootedProxy p("3102FEFFFFFF");
  for (const BitsCase& c : cases) {
    p.tpdo(std::string(c.bytes) + "00000000");
    const std::uint16_t sw = p.d->feedback().statusword;
    EXPECT_EQ(cia402::decode_status_bits(sw, c.mode), c.want) << c.bytes << " in " << cia402::mode_name(c.mode);
    EXPECT_EQ(cia402::decode_homing_status(sw), c.homing) << c.bytes;
  }
}

TEST(PositionWire, Low32AndUnwrap32Golden) {
  EXPECT_EQ(cia402::low32(0), 0);
  EXPECT_EQ(cia402::low32(2147483647), 2147483647);
  EXPECT_EQ(cia402::low32(2147483648LL), -2147483648);
  EXPECT_EQ(cia402::low32(4294967296LL), 0);
  EXPECT_EQ(cia402::low32(4294967301LL), 5);
  EXPECT_EQ(cia402::low32(-1), -1);
  EXPECT_EQ(cia402::low32(-2147483649LL), 2147483647);
  EXPECT_EQ(cia402::low32(74057158285LL), static_cast<std::int32_t>(74057158285LL - 17 * 4294967296LL));
  EXPECT_EQ(cia402::unwrap32(2147483646, -2147483646), 2147483650LL);
  EXPECT_EQ(cia402::unwrap32(4294967295LL, 1), 4294967297LL);
  EXPECT_EQ(cia402::unwrap32(-2147483646, 2147483646), -2147483650LL);
  EXPECT_EQ(cia402::unwrap32(0, -5), -5);
  EXPECT_EQ(cia402::unwrap32(100, cia402::low32(100 + 2147483647LL)), 100 + 2147483647LL);  // the largest step forward
  EXPECT_EQ(cia402::unwrap32(100, cia402::low32(100 - 2147483648LL)), 100 - 2147483648LL);  // and back
  for (std::int64_t base : {0LL, 4294967296LL * 3 + 17, -4294967296LL * 5 - 3})
    for (std::int64_t step : {0LL, 1LL, -1LL, 20000LL, -2147483648LL, 2147483647LL})
      EXPECT_EQ(cia402::unwrap32(base, cia402::low32(base + step)), base + step) << base << " " << step;
}

// 0x6064 from TPDO bytes: unwrapped past +2^31 and 2^32, re-based by a
// boot-up; 0x607A: the low 32 bits of the 64-bit target.
TEST(PositionWire, ProxyUnwrapsTpdoBytesAndSendsTheLow32Bits) {
  BootedProxy p("3102FEFFFF7F");  // Ready to switch on, 0x6064 = 2147483646
  ASSERT_EQ(p.d->phase(), cia402::Phase::kOperational);
  EXPECT_EQ(p.d->feedback().position, 2147483646);
  EXPECT_EQ(p.tpdo("310202000080"), "203#000002000080");  // 0x80000002: 2^31 + 2; disabled, the target follows
  EXPECT_EQ(p.d->feedback().position_raw, -2147483646);
  EXPECT_EQ(p.d->feedback().position, 2147483650LL);
  EXPECT_EQ(p.d->target_position(), 2147483650LL);
  p.tpdo("3102FFFFFFFF");  // 0xFFFFFFFF: 2^32 - 1
  EXPECT_EQ(p.d->feedback().position, 4294967295LL);
  p.tpdo("310201000000");  // 0x00000001: 2^32 + 1
  EXPECT_EQ(p.d->feedback().position, 4294967297LL);
  // Enabled: the target in the 64-bit frame, 0x607A its low 32 bits.
  p.d->enable();
  p.tpdo("330201000000");  // Switched on
  p.tpdo("371201000000");  // Operation enabled, bit 12
  ASSERT_TRUE(p.d->enabled());
  p.d->set_target_position(4294967296LL * 2 + 0x12345678);
  EXPECT_EQ(p.tpdo("371201000000"), "203#0F0078563412");
  p.d->set_target_position(-2147483649LL);  // one below -2^31: 0x7FFFFFFF on the wire
  EXPECT_EQ(p.tpdo("371201000000"), "203#0F00FFFFFF7F");
  // A boot-up: the drive counts afresh, its next TPDO sets the base.
  p.net.on_frame(can::TimedFrame{frame("703#00"), p.t});
  p.out.clear();
  p.net.cycle(p.t, p.out);  // the boot-up reaches the proxy (DriveNetwork::update)
  p.net.on_frame(can::TimedFrame{frame("183#310205000000"), p.t});
  EXPECT_EQ(p.d->feedback().position, 5);
}

// In CSP, Operation enabled without bit 12 is not enabled: the proxy waits,
// and after the transition timeout records a failure naming bit 12.
TEST(FollowGate, CspOperationEnabledCountsOnlyWithBit12) {
  BootedProxy p("310200000000", 20'000'000);  // transition timeout 20 ms
  p.d->enable();
  p.tpdo("330200000000");  // Switched on
  for (int i = 0; i < 10; ++i) p.tpdo("370200000000");  // Operation enabled, bit 12 = 0
  EXPECT_EQ(p.d->state(), State::kOperationEnabled);
  EXPECT_TRUE(p.d->awaiting_follow());
  EXPECT_FALSE(p.d->enabled());
  EXPECT_FALSE(p.d->failed());
  p.tpdo("371200000000");  // bit 12: the drive follows
  EXPECT_FALSE(p.d->awaiting_follow());
  EXPECT_TRUE(p.d->enabled());
  p.tpdo("370200000000");  // bit 12 dropping later is reported, not an un-enable
  EXPECT_TRUE(p.d->enabled());
  EXPECT_FALSE(p.d->failed());
}

TEST(FollowGate, NeverBit12FailsWithTheTransitionTimeoutNamingBit12) {
  BootedProxy p("310200000000", 20'000'000);
  p.d->enable();
  p.tpdo("330200000000");
  for (int i = 0; i < 30 && !p.d->failed(); ++i) p.tpdo("370200000000");
  ASSERT_TRUE(p.d->failed());
  const cia402::Failure& f = p.d->failure();
  EXPECT_EQ(f.kind, cia402::FailureKind::kTransitionTimeout);
  EXPECT_TRUE(f.follow_missing);
  EXPECT_EQ(f.transition, 4);
  EXPECT_EQ(f.timeout_ns, 20'000'000);
  const std::string text = f.to_string();
  EXPECT_NE(text.find("bit 12"), std::string::npos) << text;
  EXPECT_NE(text.find("0x607A"), std::string::npos) << text;
  EXPECT_FALSE(p.d->enabled());
}

// The emulator's 0x6064 and 0x607A are 32 bits that wrap like a real drive's:
// a CSP ramp through +2^31 followed exactly, its TPDO bytes the low 32 bits.
TEST(PositionWire, EmulatorWrapsModulo2To32) {
  emulator::EmulatorConfig ec;
  ec.node = 2;
  ec.initial_position = 2147483647LL - 50'000;
  ec.behaviour = emulator::EmulatorBehaviour::permissive();
  ec.lag_cycles = 0;
  emulator::Emulator emu(ec);
  VecSink out;
  emu.power_on(0, out);
  emu.on_frame(can::TimedFrame{frame("000#0102"), 0}, out);
  auto rpdo = [&](unsigned cw, std::int64_t target) {
    const auto w = static_cast<std::uint32_t>(cia402::low32(target));
    char buf[32];
    std::snprintf(buf, sizeof buf, "202#%02X%02X%02X%02X%02X%02X", cw & 0xFF, cw >> 8, w & 0xFF, (w >> 8) & 0xFF,
                  (w >> 16) & 0xFF, w >> 24);
    emu.on_frame(can::TimedFrame{frame(buf), 0}, out);
    out.clear();
    emu.on_frame(can::TimedFrame{frame("080#"), 0}, out);
  };
  std::int64_t target = ec.initial_position;
  for (unsigned cw : {0x06u, 0x07u, 0x0Fu}) rpdo(cw, target);
  ASSERT_EQ(emu.state(), State::kOperationEnabled);
  for (int k = 0; k < 200; ++k) {
    target += 1000;  // 1000 counts per SYNC, through +2^31 after 50
    rpdo(0x0F, target);
  }
  for (int k = 0; k < 2000; ++k) rpdo(0x0F, target);  // settled (permissive: 0.5 of the error per SYNC)
  EXPECT_EQ(emu.position_counts(), target);
  EXPECT_EQ(emu.position(), cia402::low32(target));
  EXPECT_LT(emu.position(), 0);  // 0x6064 wrapped, not held at 2^31 - 1
  ASSERT_FALSE(out.frames.empty());
  const std::string tpdo = hex(out.frames.back());
  const auto w = static_cast<std::uint32_t>(cia402::low32(target));
  char want[16];
  std::snprintf(want, sizeof want, "%02X%02X%02X%02X", w & 0xFF, (w >> 8) & 0xFF, (w >> 16) & 0xFF, w >> 24);
  EXPECT_EQ(tpdo.substr(tpdo.size() - 8), want) << tpdo;
  EXPECT_EQ(emu.state(), State::kOperationEnabled);  // no following error on the way
}
