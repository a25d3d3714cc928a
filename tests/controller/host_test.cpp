// ControllerHost and TagTable: ST calls bound to requests, tag names as users
// write them, and the errors they get.
#include <gtest/gtest.h>

#include "rt/controller/host.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt {
namespace {

struct HostRig : test::SimController {
  std::unique_ptr<ControllerHost> host = std::make_unique<ControllerHost>(*ctl);
  double read(const std::string& tag) {
    std::string e;
    auto v = host->read(tag, &e);
    EXPECT_TRUE(v) << tag << ": " << e;
    return v.value_or(-1);
  }
};

TEST(ControllerHost, ExecutesStCallsAndReadsTheirControlTag) {
  HostRig r;
  std::string ctl;
  ASSERT_EQ(r.host->execute("MSO(Master, mso0)", &ctl), std::nullopt);
  EXPECT_EQ(ctl, "mso0");
  EXPECT_FALSE(r.host->settled());
  r.cycles(1);
  EXPECT_TRUE(r.host->settled());
  EXPECT_EQ(r.read("mso0.DN"), 1.0);
  EXPECT_EQ(r.read("MSO0.dn"), 1.0);  // Logix names are case-insensitive
  EXPECT_EQ(r.read("master.ServoActionStatus"), 1.0);
  ASSERT_EQ(r.host->execute("MAJ(Master, maj0, Forward, 10, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2, "
                            "Trapezoidal, 100, 100, %ofTime, Disabled, Programmed, 0, None)",
                            &ctl),
            std::nullopt);
  r.cycles(500);
  EXPECT_EQ(r.read("maj0.IP"), 1.0);
  EXPECT_EQ(r.read("Master.JogStatus"), 1.0);
  EXPECT_NEAR(r.read("Master.CommandVelocity"), 10.0, 1e-9);
  EXPECT_GT(r.read("Master.CommandPosition"), 0.0);
}

TEST(ControllerHost, InstructionErrorsAreLogixErrCodes) {
  HostRig r;
  std::string ctl;
  // Jog on an axis whose servo is off: ERR 5 (servo off state).
  ASSERT_EQ(r.host->execute("MAJ(Master, maj0, Forward, 10, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2, "
                            "Trapezoidal, 100, 100, %ofTime, Disabled, Programmed, 0, None)",
                            &ctl),
            std::nullopt);
  r.cycles(1);
  EXPECT_EQ(r.read("maj0.ER"), 1.0);
  EXPECT_EQ(r.read("maj0.ERR"), 5.0);
}

TEST(ControllerHost, ParseAndBindErrorsNameTheOperand) {
  HostRig r;
  std::string ctl;
  const auto bad_axis = r.host->execute("MSO(Nope, mso0)", &ctl);
  ASSERT_TRUE(bad_axis);
  EXPECT_NE(bad_axis->find("Nope"), std::string::npos) << *bad_axis;
  const auto bad_count = r.host->check_call("MSO(Master)");
  ASSERT_TRUE(bad_count);
  EXPECT_NE(bad_count->find("MSO"), std::string::npos) << *bad_count;
  EXPECT_EQ(r.host->check_call("MSO(X, mso1)"), std::nullopt);
}

TEST(TagTable, ErrorsSayWhatIsValid) {
  HostRig r;
  std::string e;
  r.host->refresh();
  EXPECT_FALSE(r.host->read("X.ActualPositon", &e));
  EXPECT_NE(e.find("axis 'X' has no attribute 'ActualPositon'"), std::string::npos) << e;
  EXPECT_NE(e.find("ActualPosition"), std::string::npos) << e;
  EXPECT_FALSE(r.host->read("Y.ActualPosition", &e));
  EXPECT_NE(e.find("'Y' is neither an axis (Master, X)"), std::string::npos) << e;
  EXPECT_FALSE(r.host->read("Controller.Nope", &e));
  EXPECT_NE(e.find("Cycle"), std::string::npos) << e;
  EXPECT_EQ(r.host->write("X.ActualPosition", 3), std::optional<std::string>("tag 'X.ActualPosition' is read-only"));
}

TEST(TagTable, UserTagsFeedInstructionOperands) {
  HostRig r;
  std::string ctl;
  ASSERT_EQ(r.host->write("Dist", 25.0), std::nullopt);
  EXPECT_EQ(r.read("dist"), 25.0);
  ASSERT_EQ(r.host->execute("MSO(Master, mso0)", &ctl), std::nullopt);
  r.cycles(1);
  ASSERT_EQ(r.host->execute("MAM(Master, mam0, Absolute, Dist, 100, UnitsPerSec, 1000, UnitsPerSec2, 1000, "
                            "UnitsPerSec2, Trapezoidal, 100, 100, %ofTime, Disabled, Programmed, 0, None, 0, 0)",
                            &ctl),
            std::nullopt);
  r.cycles(2000);
  EXPECT_EQ(r.read("mam0.PC"), 1.0);
  EXPECT_DOUBLE_EQ(r.read("Master.CommandPosition"), 25.0);
}

TEST(TagTable, CipDriveAttributes) {
  HostRig r;
  r.cycles(200);
  EXPECT_EQ(r.read("X.Statusword") != 0, true);
  EXPECT_EQ(r.read("X.DriveState"), static_cast<double>(cia402::State::kSwitchOnDisabled));
  EXPECT_EQ(r.read("Controller.Cycle"), 200.0);
  EXPECT_NEAR(r.read("Controller.Time"), 0.2, 1e-12);
}

TEST(TagTable, TrackingMasterIsReadableByItsLogixName) {
  HostRig r;
  std::string ctl;
  ASSERT_EQ(r.host->execute("MSO(Master, mso0)", &ctl), std::nullopt);
  ASSERT_EQ(r.host->execute("MDAC(Master, X, mdac0, jog, command)", &ctl), std::nullopt);
  // a master-driven jog (1 unit per master unit) on the virtual Master, slaved to X (at rest)
  ASSERT_EQ(r.host->execute("MAJ(Master, maj0, Forward, 1, UnitsPerMasterUnit, 10, UnitsPerMasterUnit2, 10, "
                            "UnitsPerMasterUnit2, Trapezoidal, 0, 0, UnitsPerMasterUnit3, Disabled, Programmed, 0, "
                            "ImmediateForwardOnly)",
                            &ctl),
            std::nullopt);
  r.cycles(5);
  EXPECT_EQ(r.read("maj0.IP"), 1.0);
  EXPECT_EQ(r.read("maj0.TrackingMaster"), 0.0);  // the master has not moved: still on the ramp
  ASSERT_EQ(r.host->execute("MSO(X, mso1)", &ctl), std::nullopt);
  r.cycles(500);
  ASSERT_EQ(r.read("X.ServoActionStatus"), 1.0);
  ASSERT_EQ(r.host->execute("MAJ(X, maj1, Forward, 10, UnitsPerSec, 1000, UnitsPerSec2, 1000, UnitsPerSec2, "
                            "Trapezoidal, 100, 100, %ofTime, Disabled, Programmed, 0, None)",
                            &ctl),
            std::nullopt);
  r.cycles(200);
  EXPECT_EQ(r.read("MAJ0.trackingmaster"), 1.0);  // ramp done: tracking (case-insensitive like every Logix name)
}

}  // namespace
}  // namespace canmotion::rt
