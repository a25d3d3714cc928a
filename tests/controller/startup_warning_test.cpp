// Issue 29 part 5: a CIP axis without position_error_tolerance is named once
// at start (config::startup_warnings(), printed by canmotiond): the drive's
// own 0x6065 following error window is then its only guard. And issue 29
// part 3's load check of homing.offset against 0x607C's INTEGER32.
#include <gtest/gtest.h>

#include <string>

#include "config/runtime.hpp"

namespace canmotion::config {
namespace {

const char* kYaml = R"(controller: {period_ms: 1}
buses:
  - {name: can0, interface: sim}
axes:
  - {name: V, type: AXIS_VIRTUAL, units: mm, conversion_constant: 1000, max_speed: 10, max_accel: 100, max_decel: 100}
  - {name: Guarded, type: AXIS_CIP_DRIVE, bus: can0, node: 2, units: mm, conversion_constant: 1000, max_speed: 10,
     max_accel: 100, max_decel: 100, position_error_tolerance: 2}
  - name: Bare
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 3
    units: mm
    conversion_constant: 1000
    max_speed: 10
    max_accel: 100
    max_decel: 100
  - name: Windowed
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 4
    units: mm
    conversion_constant: 1000
    max_speed: 10
    max_accel: 100
    max_decel: 100
    drive: {following_error_window: 3000}
)";

TEST(StartupWarnings, OneLinePerCipAxisWithoutPositionErrorTolerance) {
  const Config cfg = load_string(kYaml, "guard.yaml");
  const auto w = startup_warnings(cfg);
  ASSERT_EQ(w.size(), 2u);
  const std::string bare = w[0].str(), windowed = w[1].str();
  EXPECT_EQ(bare.rfind("guard.yaml:8:", 0), 0u) << bare;  // the axis's line
  EXPECT_NE(bare.find("warning: axes[2].position_error_tolerance"), std::string::npos) << bare;
  EXPECT_NE(bare.find("axis 'Bare'"), std::string::npos) << bare;
  EXPECT_NE(bare.find("the drive's own 0x6065 following error window"), std::string::npos) << bare;
  EXPECT_NE(bare.find("its only guard"), std::string::npos) << bare;
  EXPECT_NE(windowed.find("axis 'Windowed'"), std::string::npos) << windowed;
  EXPECT_NE(windowed.find("3000 counts"), std::string::npos) << windowed;
  for (const Diagnostic& d : cfg.warnings)  // said once, at start: not a load warning as well
    EXPECT_EQ(d.key.find("position_error_tolerance"), std::string::npos) << d.str();
}

TEST(StartupWarnings, NoneWhenEveryCipAxisIsGuarded) {
  std::string yaml = kYaml;
  yaml = yaml.substr(0, yaml.find("  - name: Bare"));
  EXPECT_TRUE(startup_warnings(load_string(yaml, "guarded.yaml")).empty());
}

// 0x607C (home offset) is INTEGER32 and the drive re-references 0x6064 to
// it: an offset that does not fit is refused at load, never clamped.
TEST(HomeOffset, OutsideInteger32IsRefusedNamingTheKey) {
  const std::string head = R"(controller: {period_ms: 1}
buses:
  - {name: can0, interface: sim}
axes:
  - name: X
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    units: mm
    conversion_constant: 1000
    max_speed: 10
    max_accel: 100
    max_decel: 100
    position_error_tolerance: 1
    homing: {mode: Active, sequence: Switch, offset: )";
  EXPECT_NO_THROW((void)load_string(head + "2147483.647}\n", "ok.yaml"));
  try {
    (void)load_string(head + "2147483.648}\n", "big.yaml");
    FAIL() << "an offset of 2^31 counts was accepted";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("big.yaml:15:"), std::string::npos) << what;
    EXPECT_NE(what.find("axes[0].homing.offset"), std::string::npos) << what;
    EXPECT_NE(what.find("0x607C home offset (INTEGER32"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace canmotion::config
