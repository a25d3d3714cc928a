// The configuration keys behind the drive's boot writes (issue 12): when a
// drive refuses one, the message names the key that sets or avoids it, and
// 0x1016 is written only when the drive is to watch the master.
#include <gtest/gtest.h>

#include <string>

#include "config/runtime.hpp"
#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::config {
namespace {

const char* kYaml = R"(controller: {period_ms: 2}
buses:
  - {name: can0, interface: sim}
drives:
  master_heartbeat_timeout_ms: 0
axes:
  - {name: M, type: AXIS_VIRTUAL}
  - name: X
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    conversion_constant: 1000
    drive:
      pdo: csp_csv_cst
      following_error_window: 900
      sdo_writes:
        - {index: 0x2100, sub: 1, size: 4, value: 7}
        - {index: 0x2101, sub: 0, size: 2, value: 3}
    direct_control:
      ramp: {acceleration: 50}
  - name: Y
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 3
    drive: {master_heartbeat_timeout_ms: 250}
)";

TEST(DriveWriteHints, EveryBootWriteNamesItsKey) {
  Config c;
  ASSERT_NO_THROW(c = load_string(kYaml, "hints.yaml"));
  const Runtime rt = simulated_runtime(c);
  const cia402::DriveConfig& x = rt.controller->axis_spec(1).drive;
  EXPECT_EQ(x.hints.interpolation_period, "controller.period_ms");
  EXPECT_EQ(x.hints.pdo, "axes[1].drive.pdo (or drives.pdo)");
  EXPECT_EQ(x.hints.producer_heartbeat, "axes[1].drive.heartbeat_ms (or drives.heartbeat_ms)");
  EXPECT_EQ(x.hints.consumer_heartbeat,
            "axes[1].drive.master_heartbeat_timeout_ms (or drives.master_heartbeat_timeout_ms)");
  // One hint per extra write, in order: 0x6065, direct_control (the ramp
  // given, SLAT always), sdo_writes.
  ASSERT_EQ(x.extra_writes.size(), 7u);
  ASSERT_EQ(x.hints.extra.size(), x.extra_writes.size());
  EXPECT_EQ(x.extra_writes[0].index, cia402::obj::kFollowingErrorWindow);
  EXPECT_EQ(x.hints.extra[0], "axes[1].drive.following_error_window (or drives.following_error_window) (0 leaves it out)");
  EXPECT_EQ(x.extra_writes[1].index, cia402::obj::kProfileAcceleration);
  EXPECT_EQ(x.hints.extra[1], "axes[1].direct_control.ramp.acceleration");
  EXPECT_EQ(x.hints.extra[2], "axes[1].direct_control.slat.configuration");
  EXPECT_EQ(x.hints.extra[3], "axes[1].direct_control.slat.set_point");
  EXPECT_EQ(x.hints.extra[4], "axes[1].direct_control.slat.time_delay_ms");
  EXPECT_EQ(x.extra_writes[6].index, 0x2101);
  EXPECT_EQ(x.hints.extra[5], "axes[1].drive.sdo_writes[0] (line 17)");
  EXPECT_EQ(x.hints.extra[6], "axes[1].drive.sdo_writes[1] (line 18)");
  // master_heartbeat_timeout_ms: 0 (the drives: default) leaves 0x1016 out; Y asks for it.
  EXPECT_EQ(x.consumer_heartbeat_ms, 0);
  EXPECT_EQ(rt.controller->axis_spec(2).drive.consumer_heartbeat_ms, 250);
  EXPECT_EQ(rt.controller->axis_spec(2).drive.hints.pdo, "axes[2].drive.pdo (or drives.pdo)");
}

}  // namespace
}  // namespace canmotion::config

namespace canmotion::config {
namespace {
// drive.identity, drive.quick_stop_option, drive.timeouts.homing_ms,
// homing.offset and the modes an axis needs (issue 15 items 1, 4, 7, 8).
TEST(DriveWriteHints, IdentityQuickStopHomingAndNeededModes) {
  Config c;
  ASSERT_NO_THROW(c = load_string(R"(controller: {period_ms: 2}
buses:
  - {name: can0, interface: sim}
axes:
  - name: X
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    conversion_constant: 1000
    homing: {mode: Active, sequence: Switch, method: 19, position: 5, offset: 1.5}
    drive:
      pdo: csp_csv_cst
      identity: {vendor_id: 0x9A, product_code: 0x30924}
      quick_stop_option: 6
      timeouts: {homing_ms: 20000}
    direct_control: {mode: torque}
)",
                                  "id.yaml"));
  const Runtime rt = simulated_runtime(c);
  const cia402::DriveConfig& x = rt.controller->axis_spec(0).drive;
  EXPECT_TRUE(x.identity.has_vendor_id);
  EXPECT_EQ(x.identity.vendor_id, 0x9Au);
  EXPECT_TRUE(x.identity.has_product_code);
  EXPECT_EQ(x.identity.product_code, 0x30924u);
  EXPECT_FALSE(x.identity.has_revision);
  EXPECT_FALSE(x.identity.has_device_type);
  EXPECT_EQ(x.hints.identity, "axes[0].drive.identity");
  EXPECT_EQ(x.homing_timeout_ns, 20'000'000'000);
  ASSERT_EQ(x.needed_modes.size(), 2u);
  EXPECT_EQ(x.needed_modes[0].mode, cia402::Mode::kCst);
  EXPECT_EQ(x.needed_modes[0].key, "axes[0].direct_control.mode: torque (MDS)");
  EXPECT_EQ(x.needed_modes[1].mode, cia402::Mode::kHoming);
  bool qs = false;
  for (std::size_t i = 0; i < x.extra_writes.size(); ++i)
    if (x.extra_writes[i].index == cia402::obj::kQuickStopOptionCode) {
      qs = true;
      EXPECT_EQ(x.extra_writes[i].value, 6u);
      EXPECT_EQ(x.extra_writes[i].size, 2u);
      EXPECT_EQ(x.hints.extra[i], "axes[0].drive.quick_stop_option (or drives.quick_stop_option) (leave it out to keep the drive's own)");
    }
  EXPECT_TRUE(qs);
  EXPECT_TRUE(c.axes[0].axis.homing.write_offset);
  EXPECT_DOUBLE_EQ(c.axes[0].axis.homing.offset, 1.5);
}

TEST(DriveWriteHints, BadIdentityKeyNamesIt) {
  try {
    (void)load_string(R"(buses: [{name: can0, interface: sim}]
axes:
  - {name: X, type: AXIS_CIP_DRIVE, bus: can0, node: 2, drive: {identity: {vendor: 1}}}
)",
                      "bad.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("axes[0].drive.identity"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("vendor"), std::string::npos) << e.what();
  }
}
}  // namespace
}  // namespace canmotion::config
