// Interpolated position mode (issue 30 part 2): drive.mode ip on the SimBus.
// The same MAM on an emulated drive in CSP and in IP (mode 7, 0x60C1:1 in
// RPDO1, controlword bit 4, statusword bit 12) ends at the same position;
// the boot writes 0x6060 = 7 and 0x60C0 = 0; a drive whose 0x6502 lacks IP
// is refused naming the key; bit 4 drops with the disable; no allocation in
// any cycle.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tests/support/allocation_counter.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt {
namespace {

constexpr std::uint32_t kRpdo1 = 0x200u + test::SimController::kNode;
constexpr std::uint32_t kSdoRx = 0x600u + test::SimController::kNode;

/// What the master sent to the drive: SDO downloads (index, sub, value) and
/// the controlwords of RPDO1.
struct Sent {
  struct Download {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint32_t value;
  };
  std::vector<Download> downloads;
  std::vector<std::array<std::uint8_t, 8>> sdo_frames;  ///< every SDO request, as sent
  std::vector<std::uint16_t> controlwords;
  [[nodiscard]] const Download* find(std::uint16_t index, std::uint8_t sub) const {
    for (const Download& d : downloads)
      if (d.index == index && d.sub == sub) return &d;
    return nullptr;
  }
};

struct IpRig : test::SimHost {
  Sent sent;
  explicit IpRig(cia402::Mode mode, std::uint32_t supported = 0)
      : SimHost([&](AxisSpec& x, emulator::EmulatorConfig& ec) {
          x.drive.mode = mode;
          x.drive.hints.mode = mode == cia402::Mode::kInterpolatedPosition ? "axes[1].drive.mode: ip" : "";
          ec.supported_modes = supported != 0 ? supported : ec.supported_modes | cia402::supported_mode_bit(cia402::Mode::kInterpolatedPosition);
        }) {
    ctl->set_trace(true);
  }
  void step_traced() {
    {
      test::CountAllocationsInScope count;
      world.begin_cycle(now);
      ctl->cycle(now);
      world.end_cycle(now);
    }
    now += kPeriod;
    TraceRecord tr;
    while (ctl->pop_trace(tr)) {
      const can::Frame& f = tr.frame.frame;
      if (!tr.tx) continue;
      if (f.id == kSdoRx && f.len == 8) {
        std::array<std::uint8_t, 8> b{};
        for (std::size_t i = 0; i < 8; ++i) b[i] = f.data[i];
        sent.sdo_frames.push_back(b);
      }
      if (f.id == kSdoRx && (f.data[0] & 0xE0) == 0x20 && (f.data[0] & 0x02) != 0)  // expedited download
        sent.downloads.push_back({static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8)), f.data[3],
                                  static_cast<std::uint32_t>(f.data[4] | (f.data[5] << 8) | (f.data[6] << 16) |
                                                             (static_cast<std::uint32_t>(f.data[7]) << 24))});
      if (f.id == kRpdo1 && f.len >= 2) sent.controlwords.push_back(static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8)));
    }
  }
  bool until(const std::function<bool()>& done, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      step_traced();
      if (done()) return true;
    }
    return false;
  }
  const AxisSnapshot& axis() { return host->refresh().axes[1]; }
  /// Boot, MSO, MAM to `pos` and settle; the drive's final position (counts).
  std::int64_t move(double pos) {
    EXPECT_TRUE(until([&] { return axis().phase == cia402::Phase::kOperational; }, 5000)) << axis().failure.to_string();
    exec("MSO(X, mso1)", false);
    EXPECT_TRUE(until([&] { return read("mso1.DN") != 0.0 || read("mso1.ER") != 0.0; }, 3000));
    EXPECT_EQ(read("mso1.DN"), 1.0) << axis().failure.to_string();
    exec("MAM(X, mam1, 0, " + std::to_string(pos) +
             ", 50, unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 100, 100, %oftime, disabled, "
             "programmed, 0, none, 0, 0)",
         false);
    EXPECT_TRUE(until([&] { return read("mam1.PC") != 0.0 || read("mam1.ER") != 0.0; }, 20000));
    EXPECT_EQ(read("mam1.PC"), 1.0) << "MAM ERR " << read("mam1.ERR");
    for (int i = 0; i < 200; ++i) step_traced();  // the drive settles
    return world.drive(0).position_counts();
  }
};

constexpr std::uint32_t kBit(cia402::Mode m) { return cia402::supported_mode_bit(m); }

TEST(IpMode, SameMoveEndsWhereCspEndsIt) {
  test::reset_allocation_count();
  IpRig csp(cia402::Mode::kCsp);
  const std::int64_t end_csp = csp.move(12.345);
  IpRig ip(cia402::Mode::kInterpolatedPosition);
  const std::int64_t end_ip = ip.move(12.345);
  RecordProperty("end_csp_counts", std::to_string(end_csp));
  RecordProperty("end_ip_counts", std::to_string(end_ip));
  EXPECT_NEAR(static_cast<double>(end_csp), 12345.0, 1.0);
  EXPECT_LE(std::llabs(end_ip - end_csp), 1) << "CSP ended at " << end_csp << ", IP at " << end_ip;
  EXPECT_EQ(test::counted_allocations(), 0u) << test::counted_bytes() << " bytes allocated in the cycle";

  // The boot: 0x6060 = 7 and 0x60C0 = 0 (linear) in IP; CSP writes 8 and no 0x60C0.
  ASSERT_NE(ip.sent.find(0x6060, 0), nullptr);
  EXPECT_EQ(ip.sent.find(0x6060, 0)->value & 0xFF, 7u);
  ASSERT_NE(ip.sent.find(0x60C0, 0), nullptr);
  EXPECT_EQ(ip.sent.find(0x60C0, 0)->value & 0xFFFF, 0u);
  EXPECT_EQ(csp.sent.find(0x6060, 0)->value & 0xFF, 8u);
  EXPECT_EQ(csp.sent.find(0x60C0, 0), nullptr);
  // RPDO1 mapping entry 2: 0x60C1:01, 32 bits (0x60C10120) in IP, 0x607A0020 in CSP.
  ASSERT_NE(ip.sent.find(0x1600, 2), nullptr);
  EXPECT_EQ(ip.sent.find(0x1600, 2)->value, 0x60C10120u);
  EXPECT_EQ(csp.sent.find(0x1600, 2)->value, 0x607A0020u);
  // Controlword bit 4 "enable ip mode" with Operation enabled (0x001F) in IP, never in CSP.
  auto has = [](const Sent& s, std::uint16_t cw) {
    for (const std::uint16_t c : s.controlwords)
      if (c == cw) return true;
    return false;
  };
  EXPECT_TRUE(has(ip.sent, 0x001F));
  EXPECT_FALSE(has(csp.sent, 0x001F));
  EXPECT_EQ(ip.world.drive(0).mode_display(), 7);
  EXPECT_NE(ip.world.drive(0).statusword() & cia402::sw::kIpModeActive, 0u);
  EXPECT_EQ(ip.axis().drive_state, cia402::State::kOperationEnabled);
}

// Golden bytes of the IP boot rows (CiA 301 expedited downloads to node 2, COB-ID 0x602).
TEST(IpMode, BootRowsGoldenBytes) {
  IpRig ip(cia402::Mode::kInterpolatedPosition);
  ASSERT_TRUE(ip.until([&] { return ip.axis().phase == cia402::Phase::kOperational; }, 5000));
  using B = std::array<std::uint8_t, 8>;
  const std::vector<B> want = {
      {0x2F, 0x60, 0x60, 0x00, 0x07, 0x00, 0x00, 0x00},  // 0x6060 = 7 (1 byte)
      {0x2B, 0xC0, 0x60, 0x00, 0x00, 0x00, 0x00, 0x00},  // 0x60C0 = 0 linear (2 bytes)
      {0x2F, 0xC2, 0x60, 0x01, 0x01, 0x00, 0x00, 0x00},  // 0x60C2:1 = 1
      {0x2F, 0xC2, 0x60, 0x02, 0xFD, 0x00, 0x00, 0x00},  // 0x60C2:2 = -3 (ms)
      {0x23, 0x00, 0x16, 0x02, 0x20, 0x01, 0xC1, 0x60},  // 0x1600:2 = 0x60C10120
  };
  std::size_t at = 0;  // in this order among the requests
  for (const B& f : ip.sent.sdo_frames)
    if (at < want.size() && f == want[at]) ++at;
  EXPECT_EQ(at, want.size()) << "row " << at << " not sent in order";
}

TEST(IpMode, DisableClearsBit4AndTheDriveStopsFollowing) {
  IpRig ip(cia402::Mode::kInterpolatedPosition);
  ip.move(2.0);
  ip.exec("MSF(X, msf1)", false);
  ASSERT_TRUE(ip.until([&] { return ip.axis().drive_state != cia402::State::kOperationEnabled; }, 3000));
  ip.sent.controlwords.clear();
  for (int i = 0; i < 5; ++i) ip.step_traced();
  ASSERT_FALSE(ip.sent.controlwords.empty());
  for (const std::uint16_t c : ip.sent.controlwords) EXPECT_EQ(c & cia402::cw::kEnableIpMode, 0u) << std::hex << c;
  EXPECT_EQ(ip.world.drive(0).statusword() & cia402::sw::kIpModeActive, 0u);
}

TEST(IpMode, DriveWithoutIpIsRefusedNamingTheKey) {
  IpRig ip(cia402::Mode::kInterpolatedPosition, kBit(cia402::Mode::kCsp) | kBit(cia402::Mode::kHoming));
  ASSERT_TRUE(ip.until([&] { return ip.axis().phase == cia402::Phase::kFailed; }, 5000));
  const std::string why = ip.axis().failure.to_string();
  EXPECT_NE(why.find("does not support mode 7"), std::string::npos) << why;
  EXPECT_NE(why.find("axes[1].drive.mode: ip"), std::string::npos) << why;
  EXPECT_EQ(ip.sent.find(0x6060, 0), nullptr) << "nothing is written before the checks pass";
}

TEST(IpMode, IpOnlyDriveRefusesCspAndRunsIp) {
  const std::uint32_t ip_only = kBit(cia402::Mode::kInterpolatedPosition) | kBit(cia402::Mode::kHoming);
  IpRig csp(cia402::Mode::kCsp, ip_only);
  ASSERT_TRUE(csp.until([&] { return csp.axis().phase == cia402::Phase::kFailed; }, 5000));
  EXPECT_NE(csp.axis().failure.to_string().find("does not support mode 8"), std::string::npos)
      << csp.axis().failure.to_string();
  IpRig ip(cia402::Mode::kInterpolatedPosition, ip_only);
  EXPECT_NEAR(static_cast<double>(ip.move(-3.5)), -3500.0, 1.0);
}

}  // namespace
}  // namespace canmotion::rt
