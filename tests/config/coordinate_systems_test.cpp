// The `coordinate_systems:` section (issue 14): validation messages
// (file:line:column: key: what would be valid) and the runtime built from it
// (an MCLM through the host moves both members; the CS tags read).
#include <gtest/gtest.h>

#include "tests/config/config_errors.hpp"
#include "tests/config/runtime_rig.hpp"

#include <string>

#include "config/config.hpp"
#include "config/runtime.hpp"

namespace canmotion::config {
namespace {

const std::string kHead = R"(axes:
  - {name: X, type: AXIS_VIRTUAL, max_speed: 100}
  - {name: Y, type: AXIS_VIRTUAL, max_speed: 100}
  - {name: Z, type: AXIS_VIRTUAL, max_speed: 100}
arrays:
  - {name: p1, type: REAL, size: 2, values: [30, 40]}
)";

std::string errors_of(const std::string& yaml) { return test::errors_of(yaml, "cs.yaml"); }

TEST(ConfigCoordinateSystems, LoadsWithDefaults) {
  const Config c = load_string(kHead + R"(coordinate_systems:
  - name: XY
    axes: [X, Y]
    conversion_ratios: [1, 2]
    units: mm
    max_speed: 200
    max_accel: 1000
    max_decel: 1500
    command_position_tolerance: 0.5
  - {name: YZ, axes: [Y, Z], max_speed: 10, max_accel: 10, max_decel: 10}
)", "cs.yaml");
  ASSERT_EQ(c.coordinate_systems.size(), 2u);
  EXPECT_EQ(c.coordinate_systems[0].axes, (std::vector<std::string>{"X", "Y"}));
  EXPECT_EQ(c.coordinate_systems[0].conversion_ratios, (std::vector<double>{1, 2}));
  EXPECT_EQ(c.coordinate_systems[0].max_decel, 1500);
  EXPECT_EQ(c.coordinate_systems[0].command_position_tolerance, 0.5);
  EXPECT_TRUE(c.coordinate_systems[1].conversion_ratios.empty());  // 1 per member
}

TEST(ConfigCoordinateSystems, ErrorsNameFileLineAndKey) {
  const std::string e = errors_of(kHead + R"(coordinate_systems:
  - name: XY
    axes: [X, Yy, X]
    conversion_ratios: [1, 0, 1]
    max_speed: 200
    max_accel: 1000
    max_dcel: 1000
  - {name: X, axes: [], max_speed: -1, max_accel: 1, max_decel: 1}
)");
  EXPECT_NE(e.find("cs.yaml:13:5: error: coordinate_systems[0].max_dcel: unknown key 'max_dcel'; did you mean 'max_decel'?"),
            std::string::npos) << e;
  EXPECT_NE(e.find("cs.yaml:9:15: error: coordinate_systems[0].axes[1]: no axis named 'Yy'; did you mean 'Y'?"),
            std::string::npos) << e;
  EXPECT_NE(e.find("cs.yaml:9:19: error: coordinate_systems[0].axes[2]: axis 'X' is already member 0"), std::string::npos) << e;
  EXPECT_NE(e.find("cs.yaml:10:28: error: coordinate_systems[0].conversion_ratios[1]: must be > 0, got 0"), std::string::npos) << e;
  EXPECT_NE(e.find("coordinate_systems[0].max_decel: missing"), std::string::npos) << e;
  EXPECT_NE(e.find("coordinate_systems[1].axes: must be a list of 1 to 3 axis names"), std::string::npos) << e;
  EXPECT_NE(e.find("coordinate_systems[1].max_speed: must be"), std::string::npos) << e;
  EXPECT_NE(e.find("coordinate_systems[1].name: tag name 'X' is already used"), std::string::npos) << e;
}

TEST(ConfigCoordinateSystems, RatiosMustMatchTheMembers) {
  const std::string e = errors_of(kHead + R"(coordinate_systems:
  - {name: XY, axes: [X, Y], conversion_ratios: [1], max_speed: 1, max_accel: 1, max_decel: 1}
)");
  EXPECT_NE(e.find("coordinate_systems[0].conversion_ratios: must be a list of 2 numbers > 0"), std::string::npos) << e;
}

TEST(ConfigCoordinateSystems, AncillaryMembersAreRefused) {
  const std::string e = errors_of(kHead + R"(coordinate_systems:
  - {name: XY, axes: [X, Y], coordination_modes: [primary, ancillary], max_speed: 1, max_accel: 1, max_decel: 1}
  - {name: YZ, axes: [Y, Z], coordination_modes: [primary, second], max_speed: 1, max_accel: 1, max_decel: 1}
  - {name: XZ, axes: [X, Z], coordination_modes: [primary], max_speed: 1, max_accel: 1, max_decel: 1}
)");
  EXPECT_NE(e.find("cs.yaml:8:60: error: coordinate_systems[0].coordination_modes[1]: ancillary members are not supported: "
                   "every member is primary (part of the vector length)"),
            std::string::npos) << e;
  EXPECT_NE(e.find("coordinate_systems[1].coordination_modes[1]: must be primary, got 'second'"), std::string::npos) << e;
  EXPECT_NE(e.find("coordinate_systems[2].coordination_modes: must be a list of 2 modes (primary), one per member axis"),
            std::string::npos) << e;
  const Config c = load_string(kHead + R"(coordinate_systems:
  - {name: XY, axes: [X, Y], coordination_modes: [primary, primary], max_speed: 1, max_accel: 1, max_decel: 1}
)", "cs.yaml");
  EXPECT_EQ(c.coordinate_systems.size(), 1u);
}

TEST(ConfigCoordinateSystems, RuntimeRunsAnMclmAndReadsTheTags) {
  const Config c = load_string(kHead + R"(coordinate_systems:
  - {name: XY, axes: [X, Y], max_speed: 200, max_accel: 1000, max_decel: 1000}
)", "cs.yaml");
  test::RuntimeRig r(c);
  r.execute("MSO(X, a);");
  r.execute("MSO(Y, b);");
  r.cycles(2);
  EXPECT_EQ(r.read("XY.ReadyStatus"), 1.0);
  r.execute("MCLM(XY, m1, 0, p1, 100, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 0, 0,"
            " unitspersec3, 1, 0, 0, 0, 0, none, 0, 0);");
  r.cycles(10);
  EXPECT_EQ(r.read("XY.MoveStatus"), 1.0);
  EXPECT_EQ(r.read("m1.AC"), 1.0);
  EXPECT_EQ(r.read("X.CoordinatedMotionStatus"), 1.0);
  EXPECT_GT(r.read("XY.Speed"), 0.0);
  r.cycles(1000);
  EXPECT_EQ(r.read("m1.PC"), 1.0);
  EXPECT_EQ(r.read("XY.MoveStatus"), 0.0);
  EXPECT_EQ(r.read("XY.CommandPosition[0]"), 30.0);
  EXPECT_EQ(r.read("XY.CommandPosition[1]"), 40.0);
  EXPECT_EQ(r.read("Y.CommandPosition"), 40.0);
  std::string err;
  EXPECT_FALSE(r.host.read("XY.CommandPosition[2]", &err));
  EXPECT_NE(err.find("has 2 axes"), std::string::npos) << err;
  EXPECT_FALSE(r.host.read("XY.Nonsense", &err));
  EXPECT_NE(err.find("MovePendingStatus"), std::string::npos) << err;
}

}  // namespace
}  // namespace canmotion::config
