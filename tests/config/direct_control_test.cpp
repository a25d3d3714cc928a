// `direct_control:` (MDS, issue 5): the direct command kind, the drive-side
// ramps and SLAT of a CIP axis, validated with file:line:column:key messages
// and turned into the boot SDO writes (standard 0x6083/0x6084, manufacturer
// 0x2010..0x2022 from cia402.hpp) in drive units; the mode-switch timeout
// reaches the drive proxy.
#include <gtest/gtest.h>

#include "tests/config/config_errors.hpp"

#include <string>

#include "config/runtime.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::config {
namespace {

const char* kYaml = R"(controller: {period_ms: 2}  # three csp_csv_cst nodes need 2 ms at 1 Mbit/s
buses:
  - {name: can0, interface: sim}
drives:
  pdo: csp_csv_cst
  timeouts: {mode_switch_ms: 40}
axes:
  - name: V
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    conversion_constant: 1000
    direct_control:
      mode: velocity
      ramp:
        acceleration: 50
        deceleration: 100
        velocity_positive: 60
        velocity_negative: 40.5
        jerk_control: 25
  - name: T
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 3
    conversion_constant: 1000
    direct_control:
      mode: torque
      max_torque: 1500
      velocity_command: -8
      slat: {configuration: SLAT Max Speed/Torque, set_point: 2.5, time_delay_ms: 7}
  - name: P
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 4
)";

using test::errors_of;

std::string replaced(std::string y, const std::string& from, const std::string& to) {
  const auto i = y.find(from);
  EXPECT_NE(i, std::string::npos) << from;
  if (i != std::string::npos) y.replace(i, from.size(), to);
  return y;
}

bool has_write(const std::vector<cia402::SdoWrite>& w, std::uint16_t index, std::uint8_t sub, std::uint8_t size,
               std::uint32_t value) {
  for (const auto& x : w)
    if (x.index == index && x.sub == sub && x.size == size && x.value == value) return true;
  return false;
}

TEST(DirectControlConfig, LoadsAndBecomesDriveWritesInCounts) {
  const Config c = load_string(kYaml, "mds.yaml");
  const AxisSettings& v = c.axes[0];
  EXPECT_TRUE(v.direct.present);
  EXPECT_EQ(v.axis.direct_mode, motion::AxisConfig::DirectMode::Velocity);
  EXPECT_DOUBLE_EQ(*v.direct.ramp_acceleration, 50);
  EXPECT_EQ(*v.direct.ramp_jerk_control, 25);
  namespace obj = cia402::obj;
  const auto wv = direct_control_writes(v);
  EXPECT_TRUE(has_write(wv, obj::kProfileAcceleration, 0, 4, 50'000));
  EXPECT_TRUE(has_write(wv, obj::kProfileDeceleration, 0, 4, 100'000));
  EXPECT_TRUE(has_write(wv, obj::kRampVelocityLimit, 1, 4, 60'000));
  EXPECT_TRUE(has_write(wv, obj::kRampVelocityLimit, 2, 4, 40'500));
  EXPECT_TRUE(has_write(wv, obj::kRampJerkControl, 0, 1, 25));
  EXPECT_TRUE(has_write(wv, obj::kSlatConfiguration, 0, 1, 0));
  const AxisSettings& t = c.axes[1];
  EXPECT_EQ(t.axis.direct_mode, motion::AxisConfig::DirectMode::Torque);
  EXPECT_DOUBLE_EQ(t.axis.max_torque, 1500);
  EXPECT_DOUBLE_EQ(t.axis.direct_velocity_command, -8);
  const auto wt = direct_control_writes(t);
  EXPECT_TRUE(has_write(wt, obj::kSlatConfiguration, 0, 1, 2));
  EXPECT_TRUE(has_write(wt, obj::kSlatSetPoint, 0, 4, 2'500));
  EXPECT_TRUE(has_write(wt, obj::kSlatTimeDelay, 0, 2, 7));
  for (const auto& w : wt) EXPECT_NE(w.index, obj::kProfileAcceleration) << "ramps not given are not written";
  EXPECT_TRUE(direct_control_writes(c.axes[2]).empty());
  // issue 16: MDS is validated only on an axis with direct_control: (ERR 86
  // otherwise), and SLAT makes MDS's Speed the velocity command
  EXPECT_TRUE(v.axis.direct_control);
  EXPECT_FALSE(v.axis.direct_slat);
  EXPECT_TRUE(t.axis.direct_control);
  EXPECT_TRUE(t.axis.direct_slat);
  EXPECT_FALSE(c.axes[2].axis.direct_control);
  // The writes and the mode-switch timeout reach the drive proxy's configuration.
  const cia402::DriveConfig d = drive_config(v, c.buses[0], 0.002);
  EXPECT_EQ(d.mode_switch_timeout_ns, 40'000'000);
  EXPECT_TRUE(has_write(d.extra_writes, obj::kProfileAcceleration, 0, 4, 50'000));
  EXPECT_EQ(drive_config(c.axes[2], c.buses[0], 0.002).mode_switch_timeout_ns, 40'000'000);
}

TEST(DirectControlConfig, WriteSizesAreTheObjectTableSizes) {
  // One axis with every direct_control object: ramps, jerk and SLAT.
  const Config c = load_string(replaced(kYaml, "        jerk_control: 25\n",
                                        "        jerk_control: 25\n      slat: {set_point: 1, time_delay_ms: 3}\n"
                                        "    drive: {following_error_window: 900}\n"),
                               "mds.yaml");
  namespace obj = cia402::obj;
  // index, sub and the size (bytes) of the object's type: CiA 402 for 0x6083
  // and 0x6084 (UNSIGNED32), our manufacturer objects' documented types
  // otherwise (fieldbus/README.md).
  struct Expected {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint8_t size;
  };
  const std::vector<Expected> all = {
      {obj::kProfileAcceleration, 0, 4}, {obj::kProfileDeceleration, 0, 4}, {obj::kRampVelocityLimit, 1, 4},
      {obj::kRampVelocityLimit, 2, 4},   {obj::kRampJerkControl, 0, 1},     {obj::kSlatConfiguration, 0, 1},
      {obj::kSlatSetPoint, 0, 4},        {obj::kSlatTimeDelay, 0, 2}};
  const auto w = direct_control_writes(c.axes[0]);
  ASSERT_EQ(w.size(), all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(w[i].index, all[i].index) << i;
    EXPECT_EQ(w[i].sub, all[i].sub) << i;
    EXPECT_EQ(w[i].size, all[i].size) << std::hex << "0x" << all[i].index << ":" << int{all[i].sub};
  }
  // They reach the drive configuration with 0x6065 (UNSIGNED32).
  const cia402::DriveConfig d = drive_config(c.axes[0], c.buses[0], 0.002);
  ASSERT_EQ(d.extra_writes.size(), all.size() + 1);
  EXPECT_TRUE(has_write(d.extra_writes, obj::kFollowingErrorWindow, 0, 4, 900));
}

TEST(DirectControlConfig, ErrorsNameFileLineColumnAndKey) {
  std::string e = errors_of(replaced(kYaml, "        jerk_control: 25", "        jerk_contrl: 25"));
  EXPECT_NE(e.find("test.yaml:20:9: error: axes[0].direct_control.ramp.jerk_contrl: unknown key 'jerk_contrl'; did "
                   "you mean 'jerk_control'?"),
            std::string::npos)
      << e;
  e = errors_of(replaced(kYaml, "jerk_control: 25", "jerk_control: 150"));
  EXPECT_NE(e.find("test.yaml:20:23: error: axes[0].direct_control.ramp.jerk_control: must be 0 .. 100 % of the ramp "
                   "time, got 150"),
            std::string::npos)
      << e;
  e = errors_of(replaced(kYaml, "configuration: SLAT Max Speed/Torque", "configuration: 3"));
  EXPECT_NE(e.find("axes[1].direct_control.slat.configuration: '3' is not one of: SLAT disabled (0), SLAT Min "
                   "Speed/Torque (1), SLAT Max Speed/Torque (2)"),
            std::string::npos)
      << e;
  e = errors_of(replaced(kYaml, "      mode: torque", "      mode: velocity"));
  EXPECT_NE(e.find("test.yaml:30:29: error: axes[1].direct_control.slat.configuration: SLAT 2 needs the direct "
                   "command in torque"),
            std::string::npos)
      << e;
  e = errors_of(replaced(kYaml, "acceleration: 50\n", "acceleration: 5000000\n"));
  EXPECT_NE(e.find("axes[0].direct_control.ramp.acceleration: 5000000 units/s^2 x conversion_constant 1000 = "
                   "5000000000 counts does not fit 0x6083 profile acceleration (UNSIGNED32, 1 .. 4294967295)"),
            std::string::npos)
      << e;
  e = errors_of(replaced(kYaml, "      mode: velocity", "      mode: speed"));
  EXPECT_NE(e.find("axes[0].direct_control.mode: 'speed' is not one of: velocity (0), torque (1)"), std::string::npos)
      << e;
  e = errors_of(replaced(kYaml, "drives:\n  pdo: csp_csv_cst\n", "drives:\n  pdo: csp\n"));
  EXPECT_NE(e.find("test.yaml:14:7: error: axes[0].direct_control: MDS sends 0x60FF/0x6071 and switches 0x6060 "
                   "cyclically: set drive.pdo: csp_csv_cst"),
            std::string::npos)
      << e;
  e = errors_of(std::string(kYaml) + "  - {name: Vir, type: AXIS_VIRTUAL, direct_control: {mode: velocity}}\n");
  EXPECT_NE(e.find("axes[3].direct_control: only an AXIS_CIP_DRIVE axis has a drive"), std::string::npos) << e;
}

}  // namespace
}  // namespace canmotion::config
