// `drive.mode: ip` (issue 30 part 2): loaded and carried to the drive proxy
// (mode 7, the key named in its messages), refused with direct_control (MDS
// switches to CSV/CST and back to CSP), and checked against the drive's EDS:
// 0x6502 bit 6 and a mappable 0x60C1:1, naming the EDS file:line and the key.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "config/runtime.hpp"
#include "tests/config/config_errors.hpp"

namespace canmotion::config {
namespace {

const std::string kEdsDir = CANMOTION_IP_EDS_DIR;
const std::string kExamples = CANMOTION_EXAMPLES_DIR;

std::string yaml(const std::string& drive_keys, const std::string& axis_keys = "") {
  return "controller: {period_ms: 1}\n"
         "buses:\n"
         "  - {name: can0, interface: sim}\n"
         "axes:\n"
         "  - name: X\n"
         "    type: AXIS_CIP_DRIVE\n"
         "    bus: can0\n"
         "    node: 2\n" +
         axis_keys + "    drive:\n" + drive_keys;
}
const std::string kFile = kExamples + "/ip-test.yaml";

TEST(IpModeConfig, ModeIpReachesTheProxyWithItsKey) {
  Config c;
  ASSERT_NO_THROW(c = load_string(yaml("      mode: ip\n"), kFile));
  EXPECT_EQ(c.axes[0].drive.mode, cia402::Mode::kInterpolatedPosition);
  EXPECT_EQ(c.axes[0].drive.mode_where.line, 10);
  const Runtime rt = simulated_runtime(c);
  const cia402::DriveConfig& d = rt.controller->axis_spec(0).drive;
  EXPECT_EQ(d.mode, cia402::Mode::kInterpolatedPosition);
  EXPECT_EQ(d.hints.mode, "axes[0].drive.mode: ip (or drives.mode)");
  Config def;
  ASSERT_NO_THROW(def = load_string(yaml("      heartbeat_ms: 50\n"), kFile));
  EXPECT_EQ(def.axes[0].drive.mode, cia402::Mode::kCsp);
}

TEST(IpModeConfig, UnknownModeIsRefusedNamingTheKey) {
  const std::string e = test::errors_of(yaml("      mode: pp\n"), kFile);
  EXPECT_NE(e.find("axes[0].drive.mode"), std::string::npos) << e;
  EXPECT_NE(e.find("ip"), std::string::npos) << e;
}

TEST(IpModeConfig, DirectControlWithIpIsRefusedAtTheModeLine) {
  const std::string e = test::errors_of(
      yaml("      mode: ip\n", "    conversion_constant: 1000\n    direct_control: {mode: velocity}\n"), kFile);
  EXPECT_NE(e.find("ip-test.yaml:12"), std::string::npos) << e;
  EXPECT_NE(e.find("axes[0].drive.mode"), std::string::npos) << e;
  EXPECT_NE(e.find("cannot be used with axes[0].direct_control"), std::string::npos) << e;
}

TEST(IpModeConfig, IpOnlyEdsPassesWithIpAndRefusesCspNamingFileLineAndKey) {
  const std::string eds = kEdsDir + "/ip-only-drive.eds";
  Config c;
  ASSERT_NO_THROW(c = load_string(yaml("      eds: " + eds + "\n      mode: ip\n"), kFile));
  const std::string e = test::errors_of(yaml("      eds: " + eds + "\n"), kFile);
  EXPECT_NE(e.find(eds + ":"), std::string::npos) << e;
  EXPECT_NE(e.find("0x6502"), std::string::npos) << e;
  EXPECT_NE(e.find("axes[0].drive.mode: csp (or drives.mode)"), std::string::npos) << e;
}

TEST(IpModeConfig, CspOnlyEdsRefusesIpNamingTheBitAndTheDataRecord) {
  // minimal-drive.eds: 0x6502 without IP, no 0x60C1.
  const std::string e = test::errors_of(yaml("      eds: minimal-drive.eds\n      mode: ip\n"), kFile);
  EXPECT_NE(e.find("minimal-drive.eds:"), std::string::npos) << e;
  EXPECT_NE(e.find("0x6502"), std::string::npos) << e;
  EXPECT_NE(e.find("axes[0].drive.mode: ip (or drives.mode)"), std::string::npos) << e;
  EXPECT_NE(e.find("0x60C1:01"), std::string::npos) << e;
}

}  // namespace
}  // namespace canmotion::config
