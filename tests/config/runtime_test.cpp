// From a configuration to a running controller: cams declared in the file are
// computed at load and run by MATC; an invalid cam is refused with its name.
#include <gtest/gtest.h>

#include "config/runtime.hpp"
#include "rt/controller/host.hpp"

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
  Runtime rt = build_runtime(load_string(kYaml, "cams.yaml"), true);
  rt::Controller& c = *rt.controller;
  ASSERT_EQ(c.cam_count(), 1u);
  rt::ControllerHost host(c);
  std::int64_t now = 0;
  auto cycles = [&](int n) {
    for (int i = 0; i < n; ++i) {
      rt.sim->begin_cycle(now);
      c.cycle(now);
      rt.sim->end_cycle(now);
      now += 1'000'000;
    }
  };
  auto read = [&](const std::string& tag) {
    std::string e;
    const auto v = host.read(tag, &e);
    EXPECT_TRUE(v) << e;
    return v.value_or(-1.0);
  };
  rt.sim->power_on(0);
  cycles(1);  // the first snapshot
  EXPECT_EQ(read("rise[0].Status"), 2.0);  // calculated, not in use
  std::string ctl;
  ASSERT_EQ(host.execute("MSO(C, mso)", &ctl), std::nullopt);
  for (int i = 0; i < 3000 && read("mso.DN") == 0.0; ++i) cycles(1);
  ASSERT_EQ(read("mso.DN"), 1.0);
  ASSERT_EQ(host.execute("MATC(C, matc, Same, rise, 1, 1, Once, Immediate, 0, None, TimeDrivenMode)", &ctl),
            std::nullopt);
  cycles(2);
  EXPECT_EQ(read("matc.IP"), 1.0) << "ERR " << read("matc.ERR");
  EXPECT_EQ(read("C.TimeCamStatus"), 1.0);
  EXPECT_EQ(read("rise[0].Status"), 3.0);  // in use by one cam
  cycles(1000);  // one second of cam time: the cubic rise is done
  EXPECT_NEAR(read("C.CommandPosition"), 90.0, 0.5);
  cycles(1100);  // past the end of the profile: Once completes
  EXPECT_EQ(read("matc.PC"), 1.0);
  EXPECT_EQ(read("C.TimeCamStatus"), 0.0);
  EXPECT_EQ(read("rise[0].Status"), 2.0);
  EXPECT_NEAR(read("C.ActualPosition"), 90.0, 0.05);
  std::string e;
  EXPECT_FALSE(host.read("rise[1].Status", &e));
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
