// From a configuration to a running controller: the spec built without I/O
// (build_spec: a SocketCAN bus described, not opened), the period converted
// in one place; cams declared in the file are computed at load and run by
// MATC; an invalid cam is refused with its name.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

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

// Two buses: `field` on a SocketCAN interface that does not exist (opening
// it would throw), `bench` simulated in process.
const char* kTwoBuses = R"(controller: {period_ms: 2}
buses:
  - {name: field, interface: cmtest9, master_heartbeat_ms: 50, sync_counter_overflow: 8}
  - {name: bench, interface: sim}
axes:
  - {name: A, type: AXIS_CIP_DRIVE, bus: field, node: 5, max_speed: 10, max_accel: 100, max_decel: 100}
  - {name: V, type: AXIS_VIRTUAL, max_speed: 10, max_accel: 100, max_decel: 100}
  - {name: B, type: AXIS_CIP_DRIVE, bus: bench, node: 3, max_speed: 10, max_accel: 100, max_decel: 100,
     drive: {timeouts: {wait_ms: 1234}}}
cams:
  - {name: rise, points: [[0, 0], [1, 1]]}
arrays:
  - {name: ed, type: REAL, size: 4, values: [0, 2.5]}
coordinate_systems:
  - {name: AB, axes: [B, A], conversion_ratios: [1, 2], max_speed: 10, max_accel: 10, max_decel: 10}
)";

TEST(ConfigRuntimeSpec, DescribesASocketCanBusWithoutOpeningIt) {
  const Config cfg = load_string(kTwoBuses, "spec.yaml");
  RuntimeSpec r = build_spec(cfg, false);  // would throw if it opened cmtest9
  const rt::ControllerSpec& s = r.controller;
  EXPECT_EQ(s.period_ns, 2'000'000);
  ASSERT_EQ(s.buses.size(), 2u);
  EXPECT_EQ(s.buses[0].name, "field");
  EXPECT_EQ(s.buses[0].transport, nullptr);  // left to the bus opener
  EXPECT_EQ(s.buses[0].network.master.heartbeat_period_ms, 50);
  EXPECT_EQ(s.buses[0].network.master.sync_counter_overflow, 8);
  EXPECT_EQ(s.buses[0].network.tx_queue_frames, 0u);  // the opener sets it from the interface
  EXPECT_NE(s.buses[1].transport, nullptr);
  EXPECT_EQ(r.trace_names, (std::vector<std::string>{"cmtest9", "bench"}));
  // Only the simulated bus is in the world, with an emulated drive for B.
  ASSERT_NE(r.sim, nullptr);
  EXPECT_EQ(r.sim->bus_count(), 1u);
  EXPECT_EQ(r.sim->drive_count(), 1u);
  EXPECT_NE(r.sim->find_drive(0, 3), nullptr);
  ASSERT_EQ(s.axes.size(), 3u);
  EXPECT_EQ(s.axes[0].bus, 0);
  EXPECT_EQ(s.axes[0].drive.node, 5);
  EXPECT_EQ(s.axes[0].drive.cycle_ns, 2'000'000);
  EXPECT_EQ(s.axes[0].config.drive_wait_limit, drive_wait_limit_s(cfg.axes[0].drive.timeouts));
  EXPECT_EQ(s.axes[1].bus, -1);
  EXPECT_EQ(s.axes[2].bus, 1);
  EXPECT_EQ(s.axes[2].config.drive_wait_limit, 1.234);
  ASSERT_EQ(s.cams.size(), 1u);
  EXPECT_EQ(s.cams[0].points.size(), 2u);
  ASSERT_EQ(s.arrays.size(), 1u);
  EXPECT_EQ(s.arrays[0].type, rt::ArraySpec::Type::kReal);
  EXPECT_EQ(s.arrays[0].real_values, (std::vector<double>{0, 2.5}));
  ASSERT_EQ(s.coordinate_systems.size(), 1u);
  EXPECT_EQ(s.coordinate_systems[0].config.dim, 2);
  EXPECT_EQ(s.coordinate_systems[0].config.axes[0], 2);  // B
  EXPECT_EQ(s.coordinate_systems[0].config.axes[1], 0);  // A
  EXPECT_EQ(s.coordinate_systems[0].config.ratio[1], 2.0);
  // A bus left unopened cannot become a controller.
  try {
    (void)build_runtime(cfg, std::move(r));
    FAIL() << "built a controller on an unopened bus";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("spec.yaml: bus 'field' has no transport"), std::string::npos) << e.what();
  }
}

TEST(ConfigRuntimeSpec, SimulatesEveryBusWhenForced) {
  const Config cfg = load_string(kTwoBuses, "spec.yaml");
  RuntimeSpec r = build_spec(cfg, true);
  for (const rt::BusSpec& b : r.controller.buses) EXPECT_NE(b.transport, nullptr) << b.name;
  EXPECT_EQ(r.trace_names, (std::vector<std::string>{"field", "bench"}));  // the bus names
  ASSERT_NE(r.sim, nullptr);
  EXPECT_EQ(r.sim->bus_count(), 2u);
  EXPECT_NE(r.sim->find_drive(0, 5), nullptr);
  EXPECT_NE(r.sim->find_drive(1, 3), nullptr);
  const Runtime rt = build_runtime(cfg, std::move(r));
  ASSERT_NE(rt.controller, nullptr);
  EXPECT_EQ(rt.controller->axis_count(), 3u);
  EXPECT_TRUE(rt.sockets.empty());
  EXPECT_EQ(rt.trace_names, (std::vector<std::string>{"field", "bench"}));
}

// controller.sync_first reaches the controller, every bus's network and the
// planner (one cycle more between a command and the feedback showing it).
TEST(ConfigRuntimeSpec, SyncFirstReachesEveryBusAndThePlanner) {
  for (const bool on : {false, true}) {
    const std::string y = std::string("controller: {sync_first: ") + (on ? "true" : "false") + "}\n" +
                          "buses:\n  - {name: a, interface: sim}\n  - {name: b, interface: sim}\n"
                          "axes:\n  - {name: X, type: AXIS_CIP_DRIVE, bus: a, node: 2}\n"
                          "  - {name: Y, type: AXIS_CIP_DRIVE, bus: b, node: 2}\n";
    const Config cfg = load_string(y, "sync.yaml");
    Runtime rt = build_runtime(cfg, build_spec(cfg, false));
    EXPECT_EQ(rt.controller->spec().sync_first, on);
    EXPECT_EQ(rt.controller->network(0).sync_first(), on);
    EXPECT_EQ(rt.controller->network(1).sync_first(), on);
    EXPECT_EQ(rt.controller->planner().command_lag(), on ? 1u : 0u);
  }
}

TEST(ConfigRuntimeSpec, VirtualAxesOnlyNeedNoWorld) {
  const Config cfg = load_string("axes:\n  - {name: V, type: AXIS_VIRTUAL, max_speed: 1, max_accel: 1, max_decel: 1}\n");
  const RuntimeSpec r = build_spec(cfg, false);
  EXPECT_EQ(r.sim, nullptr);
  EXPECT_TRUE(r.controller.buses.empty());
  EXPECT_EQ(r.controller.period_ns, 1'000'000);  // the default 1 ms
}

// The period's one conversion (config.hpp): ms in the file, s in Config, ns
// in the controller and the drives.
TEST(ConfigPeriod, ConvertsBetweenMillisecondsSecondsAndNanoseconds) {
  EXPECT_EQ(period_ns(0.001), 1'000'000);
  EXPECT_EQ(period_ns(0.00025), 250'000);
  EXPECT_EQ(period_ns(period_s_from_ms(0.3)), 300'000);  // rounded to the ns, not truncated
  EXPECT_EQ(period_ms(0.004), 4.0);
  ControllerSettings c;
  c.period_s = period_s_from_ms(2.5);
  EXPECT_EQ(c.period_ns(), 2'500'000);
  EXPECT_EQ(c.period_ms(), 2.5);
  const Config cfg = load_string("controller: {period_ms: 0.5}\naxes:\n  - {name: V, type: AXIS_VIRTUAL, max_speed: 1, "
                                 "max_accel: 1, max_decel: 1}\n");
  EXPECT_EQ(cfg.controller.period_ns(), 500'000);
  EXPECT_EQ(simulated_runtime(cfg).controller->spec().period_ns, 500'000);
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
