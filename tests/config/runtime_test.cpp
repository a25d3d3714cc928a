// From a configuration to a running controller: cams declared in the file are
// computed at load and run by MATC; an invalid cam is refused with its name.
#include <gtest/gtest.h>

#include "config/runtime.hpp"
#include "tests/config/runtime_rig.hpp"

namespace canmotion::config {
namespace {

const char* kYaml = R"(controller: {period_ms: 1}
buses:
  - {name: can0, interface: sim}
axes:
  - {name: C, type: AXIS_CIP_DRIVE, bus: can0, node: 3, units: deg, conversion_constant: 100, max_speed: 720, max_accel: 7200, max_decel: 7200}
cams:
  - name: rise
    points: [[0, 0, cubic], [1, 90, linear], [2, 90]]
)";

TEST(ConfigRuntime, CamsAreComputedAtLoadAndRunByMatc) {
  test::RuntimeRig r(load_string(kYaml, "cams.yaml"));
  ASSERT_EQ(r.ctl().cam_count(), 1u);
  r.rt.sim->power_on(0);
  r.cycle();  // the first snapshot
  EXPECT_EQ(r.read("rise[0].Status"), 2.0);  // calculated, not in use
  ASSERT_TRUE(r.execute("MSO(C, mso)"));
  for (int i = 0; i < 3000 && r.read("mso.DN") == 0.0; ++i) r.cycle();
  ASSERT_EQ(r.read("mso.DN"), 1.0);
  ASSERT_TRUE(r.execute("MATC(C, matc, Same, rise, 1, 1, Once, Immediate, 0, None, TimeDrivenMode)"));
  r.cycles(2);
  EXPECT_EQ(r.read("matc.IP"), 1.0) << "ERR " << r.read("matc.ERR");
  EXPECT_EQ(r.read("C.TimeCamStatus"), 1.0);
  EXPECT_EQ(r.read("rise[0].Status"), 3.0);  // in use by one cam
  r.cycles(1000);  // one second of cam time: the cubic rise is done
  EXPECT_NEAR(r.read("C.CommandPosition"), 90.0, 0.5);
  r.cycles(1100);  // past the end of the profile: Once completes
  EXPECT_EQ(r.read("matc.PC"), 1.0);
  EXPECT_EQ(r.read("C.TimeCamStatus"), 0.0);
  EXPECT_EQ(r.read("rise[0].Status"), 2.0);
  EXPECT_NEAR(r.read("C.ActualPosition"), 90.0, 0.05);
  std::string e;
  EXPECT_FALSE(r.host.read("rise[1].Status", &e));
  EXPECT_NE(e.find("rise[0].Status"), std::string::npos) << e;
}

TEST(ConfigRuntime, AnInvalidCamIsRefusedWithItsName) {
  rt::ControllerSpec spec;
  rt::CamSpec bad;
  bad.name = "wobble";
  bad.points = {{0, 0, 0}, {1, 1, 7}, {2, 0, 0}};  // segment type 7: not linear or cubic
  spec.cams.push_back(bad);
  try {
    rt::Controller c(spec);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("cam 'wobble'"), std::string::npos) << ex.what();
    EXPECT_NE(std::string(ex.what()).find("28"), std::string::npos) << ex.what();
  }
}

}  // namespace
}  // namespace canmotion::config
